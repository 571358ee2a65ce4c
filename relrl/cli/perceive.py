"""``relrl perceive``: perception facts of an image or camera frames, as Prolog terms."""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from perception.pipeline import Perceiver

HELP = "print the perception facts of an image (or camera frames) as Prolog terms"
EXAMPLE = "relrl perceive photo.png --annotate out.png"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Declare the options of ``relrl perceive``."""
    parser.add_argument("image", nargs="?", help="an image file (PNG, JPEG, ...)")
    parser.add_argument("--camera", metavar="SRC",
                        help="a camera source instead: 0, cam://0, video.mp4, a folder, "
                             "synthetic://?looking_at=left&objects=left:apple")
    parser.add_argument("--frames", type=int, default=1,
                        help="frames to read from --camera (default 1)")
    parser.add_argument("--looking-at", metavar="PLACE",
                        help="where the head points (left, left_down, down, right_down, right, "
                             "centre); gives at(object, PLACE)")
    parser.add_argument("--threads", type=int, default=1,
                        help="perception threads (default 1; 2 searches faces and saliency at "
                             "once: same facts, about half the time on two free cores)")
    parser.add_argument("--annotate", metavar="OUT.png",
                        help="write the (last) frame with what was found drawn on it")


def run(args: argparse.Namespace) -> int:
    """Print one fact per line; frames from a camera are separated by a ``% frame N`` line."""
    from perception.errors import PerceptionError
    from perception.pipeline import Perceiver

    if (args.image is None) == (args.camera is None):
        raise PerceptionError("give either an IMAGE or --camera SRC (not both)")
    if args.frames < 1:
        raise PerceptionError(f"--frames must be at least 1, got {args.frames}")
    if args.threads < 1:
        raise PerceptionError(f"--threads must be at least 1, got {args.threads}")
    with Perceiver(threads=args.threads) as perceiver:
        return _perceive(args, perceiver)


def _perceive(args: argparse.Namespace, perceiver: Perceiver) -> int:
    """Read the frames and print their facts with ``perceiver``."""
    import cv2

    from perception.camera import open_camera, read_image
    from perception.errors import PerceptionError
    from perception.facts import format_fact
    from perception.pipeline import annotate

    if args.image is not None:
        frames = [read_image(args.image)]
    else:
        with open_camera(args.camera) as cam:
            frames = []
            for _ in range(args.frames):
                frame = cam.read()
                if frame is None:
                    break
                frames.append(frame)
        if not frames:
            raise PerceptionError(f"camera {args.camera!r} gave no frame")
    percept = None
    for i, frame in enumerate(frames):
        if len(frames) > 1:
            print(f"% frame {i}")
        percept = perceiver.analyse(frame, args.looking_at)
        for fact in percept.facts:
            print(format_fact(fact))
    if args.annotate and not cv2.imwrite(args.annotate, annotate(frames[-1], percept)):
        raise PerceptionError(f"cannot write {args.annotate!r}; use a .png or .jpg path in "
                              "an existing folder")
    return 0
