"""``relrl perceive``: perception facts of an image or camera frames, as Prolog terms."""

from __future__ import annotations

import argparse

HELP = "print the perception facts of an image (or camera frames) as Prolog terms"
EXAMPLE = "relrl perceive photo.png --annotate out.png"
#: the file types --annotate writes.
IMAGE_OUT = (".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff", ".webp", ".ppm", ".pgm")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Declare the options of ``relrl perceive``."""
    parser.add_argument("image", nargs="?", help="an image file (PNG, JPEG, ...), or a bag "
                                                 "(BAG.mcap, BAG.db3 or a rosbag2 folder, "
                                                 "[:TOPIC]): every frame's facts")
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
    """Print one fact per line; with ``--frames N`` (N > 1) each frame starts with a
    ``% frame I`` line. Frames are read and analysed one at a time."""
    import cv2

    from perception.camera import open_camera, read_image
    from perception.errors import PerceptionError
    from perception.facts import format_fact
    from perception.pipeline import Perceiver, annotate
    from perception.vocabulary import PLACES
    from relrl.outdir import check_out_file, write_atomic

    if (args.image is None) == (args.camera is None):
        raise PerceptionError("give either an IMAGE or --camera SRC (not both)")
    if args.frames < 1:
        raise PerceptionError(f"--frames must be at least 1, got {args.frames}")
    if args.threads < 1:
        raise PerceptionError(f"--threads must be at least 1, got {args.threads}")
    if args.looking_at is not None and args.looking_at not in PLACES:
        raise PerceptionError(f"--looking-at {args.looking_at!r}: use one of "
                              f"{', '.join(PLACES)}")
    annotate_to = check_out_file(args.annotate, "--annotate", suffixes=IMAGE_OUT) \
        if args.annotate else None  # before reading a single frame
    perceiver = Perceiver(threads=args.threads)

    from perception.bag import is_bag

    bag = args.image is not None and is_bag(args.image)

    def frames():  # one at a time: --frames 1000000 holds one frame, not a million
        if bag:  # every frame of the bag, in order, with its recorded time
            from perception.bag import BagCamera, parse_bag_source

            with BagCamera(*parse_bag_source(args.image), paced=False) as cam:
                while (frame := cam.read()) is not None:
                    yield frame, f" t={cam.stamp / 1e9:.6f}"
            return
        if args.image is not None:
            yield read_image(args.image), ""
            return
        with open_camera(args.camera) as cam:
            for _ in range(args.frames):
                frame = cam.read()
                if frame is None:
                    return
                yield frame, ""

    last = percept = None
    with perceiver:
        for i, (frame, stamp) in enumerate(frames()):
            if args.frames > 1 or bag:
                print(f"% frame {i}{stamp}")
            percept = perceiver.analyse(frame, args.looking_at)
            for fact in percept.facts:
                print(format_fact(fact))
            last = frame
    if last is None:
        raise PerceptionError(f"{args.image if bag else 'camera ' + repr(args.camera)} gave "
                              "no frame")
    if annotate_to is not None:
        ext = annotate_to.suffix.lower() if annotate_to.suffix.lower() in IMAGE_OUT else ".png"
        ok, data = cv2.imencode(ext, annotate(last, percept))
        if not ok:
            raise PerceptionError(f"--annotate {annotate_to}: OpenCV cannot write {ext} files")
        write_atomic(annotate_to, data.tobytes())
    return 0
