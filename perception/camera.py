"""Camera sources behind one interface, chosen by URL or name (a registry, no if-chains).

=========================  ==========================================================
source                     meaning
=========================  ==========================================================
``0``, ``cam://0``         webcam by index (OpenCV ``VideoCapture``)
``video.mp4``              a video file (``file://video.mp4`` also works)
``frames/``                a folder of images, read in name order (``dir://frames``)
``session/``               a session recorded by relrl (``recording://session``): every frame of
                           its ``session.mcap``, in order
``photo.png``              one image, read once (``image://photo.png``)
``bag.mcap[:TOPIC]``       a bag's images at their recorded times (``bag://bag.mcap``): an
``bag.db3[:TOPIC]``        MCAP file, a SQLite ROS 2 bag or a rosbag2 folder; ROS 2 and
``rosbag2/[:TOPIC]``       Foxglove images (:mod:`perception.bag`; the ``mcap`` extra)
``synthetic://``           :func:`perception.render.render` of a :class:`SceneView`
=========================  ==========================================================

``synthetic://`` takes query options for its first view, e.g.
``synthetic://?looking_at=left_down&objects=left_down:apple,right:lemon&pose=frontal&lighting=0.8
&seed=3&size=640x480``; the simulator then sets each step's view with
:meth:`SyntheticCamera.set_view`.

Every source is a context manager; ``read()`` returns the next BGR frame or ``None`` at the end;
``close()`` is safe to call twice.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from urllib.parse import parse_qs, urlsplit

import numpy as np

from perception.bag import BagCamera, is_bag, parse_bag_source
from perception.errors import CameraError, ImageError
from perception.imagesize import check_frame_size, header_size
from perception.render import SceneView, render
from perception.source import Camera

__all__ = ["SOURCES", "Camera", "SyntheticCamera", "open_camera", "read_image"]

_IMAGE_EXT = {".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff", ".ppm", ".pgm", ".webp"}


def read_image(path: str | Path) -> np.ndarray:
    """Read an image file as BGR.

    The size in the file's header is checked (:func:`perception.imagesize.check_frame_size`)
    before the image is decoded, so a small file claiming a huge image costs nothing.

    Raises:
        ImageError: the file is missing, not an image, too large or too thin, or damaged.
    """
    import cv2

    p = Path(path)
    if p.is_dir():
        raise ImageError(f"{str(path)!r} is a folder; give an image file (or --camera DIR)")
    if p.exists() and not p.is_file():
        raise ImageError(f"{str(path)!r} is not a regular file (a device or a pipe?)")
    if not p.is_file():
        raise ImageError(f"no such image file: {str(path)!r}")
    width, height, kind = header_size(p)
    check_frame_size(width, height, f"image {str(path)!r}")
    try:
        img = cv2.imread(str(p), cv2.IMREAD_COLOR)
    except cv2.error as exc:
        raise ImageError(f"cannot decode {str(path)!r}: {_cv_reason(exc)}") from None
    if img is None:
        raise ImageError(f"cannot decode {str(path)!r} as a {kind} image (damaged or cut "
                         "short?)")
    return img


def _cv_reason(exc: Exception) -> str:
    """The one useful line of an OpenCV error."""
    lines = [x.strip() for x in str(exc).splitlines() if x.strip()]
    return lines[-1] if lines else type(exc).__name__


class _Capture(Camera):
    """A webcam or a video file through ``cv2.VideoCapture``."""

    def __init__(self, target: int | str, what: str) -> None:
        import cv2

        super().__init__()
        self.name = what
        level = cv2.utils.logging.getLogLevel()
        cv2.utils.logging.setLogLevel(cv2.utils.logging.LOG_LEVEL_ERROR)  # one-line errors
        try:
            self._cap = cv2.VideoCapture(target)
        finally:
            cv2.utils.logging.setLogLevel(level)
        if not self._cap.isOpened():
            self._cap.release()
            self._closed = True
            raise CameraError(f"cannot open {what}; check the device or path, or use "
                              "synthetic:// for the simulated camera")
        width = int(self._cap.get(cv2.CAP_PROP_FRAME_WIDTH))
        height = int(self._cap.get(cv2.CAP_PROP_FRAME_HEIGHT))
        if width > 0 and height > 0:  # known before the first frame is decoded
            try:
                check_frame_size(width, height, what)
            except ImageError:
                self.close()
                raise

    def read(self) -> np.ndarray | None:
        if self._closed:
            return None
        ok, frame = self._cap.read()
        return frame if ok else None

    def _release(self) -> None:
        self._cap.release()


class _Folder(Camera):
    """The images of a folder, in name order."""

    def __init__(self, path: str) -> None:
        super().__init__()
        folder = Path(path)
        if not folder.is_dir():
            raise CameraError(f"no such folder of images: {path!r}")
        self.name = f"folder {path}"
        self._files = sorted(p for p in folder.iterdir() if p.suffix.lower() in _IMAGE_EXT)
        if not self._files:
            raise CameraError(f"folder {path!r} holds no images ({', '.join(sorted(_IMAGE_EXT))})")
        self._next = 0

    def read(self) -> np.ndarray | None:
        if self._closed or self._next >= len(self._files):
            return None
        self._next += 1
        path = self._files[self._next - 1]
        if not path.exists():
            raise CameraError(f"lost the camera ({self.name}): {path} is gone (moved or "
                              "deleted while reading)")
        return read_image(path)


class _Image(_Folder):
    """One image file, read once."""

    def __init__(self, path: str) -> None:
        Camera.__init__(self)
        read_image(path)  # fail early with a clear message
        self.name = f"image {path}"
        self._files = [Path(path)]
        self._next = 0


class SyntheticCamera(Camera):
    """Renders the simulator's scene (see :mod:`perception.render`).

    Args:
        view: the first view.
        size: ``(width, height)`` of the frames.
    """

    name = "synthetic"

    def __init__(self, view: SceneView | None = None, size: tuple[int, int] = (320, 240)) -> None:
        super().__init__()
        self.view = view or SceneView("centre")
        self.size = size

    def set_view(self, view: SceneView) -> None:
        """Set what the next frames show."""
        self.view = view

    def read(self) -> np.ndarray | None:
        return None if self._closed else render(self.view, self.size)


def _synthetic(url: str) -> Camera:
    query = {k: v[-1] for k, v in parse_qs(urlsplit(url).query).items()}
    known = {"looking_at", "pose", "objects", "lighting", "seed", "size"}
    if set(query) - known:
        raise CameraError(f"unknown synthetic:// option(s) {sorted(set(query) - known)}; "
                          f"use {sorted(known)}")
    try:
        objects = dict(item.split(":", 1) for item in query.get("objects", "").split(",") if item)
        w, h = (int(v) for v in query.get("size", "320x240").lower().split("x"))
        pose = query.get("pose", "frontal")
        lighting = float(query.get("lighting", 1.0))
        if not 0.05 <= lighting <= 3.0:  # also refuses nan
            raise ValueError(f"lighting={query['lighting']} is not within 0.05..3")
        view = SceneView(query.get("looking_at", "centre"), None if pose == "none" else pose,
                         objects, lighting, int(query.get("seed", 0)))
    except ValueError as exc:
        raise CameraError(f"bad synthetic:// URL {url!r}: {exc}") from None
    check_frame_size(w, h, f"synthetic:// size={w}x{h}")
    return SyntheticCamera(view, (w, h))


def _webcam(rest: str) -> Camera:
    if not rest.isdigit():
        raise CameraError(f"bad webcam index {rest!r}; use a number such as cam://0")
    return _Capture(int(rest), f"webcam {rest}")


def _recording(path: str) -> Camera:
    """Every frame of a session folder's ``session.mcap``, in order (not paced: perception
    run again on what the robot saw)."""
    folder = Path(path)
    if (folder / "session.mcap").is_file():
        return BagCamera(folder / "session.mcap", paced=False)
    if (folder / "frames.jsonl").is_file():
        raise CameraError(f"{path}: a session recorded as a folder of frames by an earlier "
                          f"relrl; convert it once with: relrl migrate {path}")
    raise CameraError(f"{path}: not a recorded session (no session.mcap); record one with "
                      "relrl run EPISODE --out DIR --record")


def _bag(source: str) -> Camera:
    path, topic = parse_bag_source(source)
    return BagCamera(path, topic)


def _video(path: str) -> Camera:
    if not Path(path).is_file():
        raise CameraError(f"no such video file: {path!r}")
    return _Capture(path, f"video {path}")


#: URL scheme -> factory taking the rest of the URL.
SOURCES: dict[str, Callable[[str], Camera]] = {
    "cam": _webcam,
    "file": _video,
    "dir": _Folder,
    "image": _Image,
    "recording": _recording,
    "bag": _bag,
    "mcap": _bag,
    "synthetic": lambda rest: _synthetic("synthetic://" + rest),
}


def open_camera(source: str | int) -> Camera:
    """Open a camera source by URL or name (see the module table).

    Raises:
        CameraError: the source does not exist or cannot be opened.
    """
    src = str(source).strip()
    if "://" in src:
        scheme, rest = src.split("://", 1)
    elif src.isdigit():
        scheme, rest = "cam", src
    elif is_bag(src):
        scheme, rest = "bag", src
    elif Path(src).is_dir():
        recorded = any((Path(src) / name).is_file() for name in ("session.mcap",
                                                                  "frames.jsonl"))
        scheme = "recording" if recorded else "dir"
        rest = src
    elif Path(src).suffix.lower() in _IMAGE_EXT:
        scheme, rest = "image", src
    else:
        scheme, rest = "file", src
    factory = SOURCES.get(scheme)
    if factory is None:
        raise CameraError(f"unknown camera scheme {scheme + '://'!r}; use one of "
                          f"{', '.join(s + '://' for s in SOURCES)}, a webcam index, or a path")
    return factory(rest)
