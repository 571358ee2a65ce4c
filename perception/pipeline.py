"""One call from a camera frame to perception facts.

:class:`Perceiver` runs the stages in order -- faces (with tracking), saliency with the face and
the body below it masked out, colour of the salient area -- and turns the results into facts
(:mod:`perception.facts`)::

    see(face).  pose(face, left_1).  pan(face, -27.5).  tilt(face, 3.0).
    see(object).  colour(object, red).  at(object, left_down).

With ``Perceiver(threads=2)`` the stages share two pool threads: the saliency map is computed
while the faces are searched, and a full face search runs each cascade as tasks over bands of
face sizes (see :mod:`perception.faces`). The facts are the same as with one thread; the frame
takes about half the wall time when two cores are free for it (a control loop in the same
process or on the same machine competes for them).

``at(object, Place)`` is the place the head looks at when the caller says so
(``looking_at=...``, the robot knows where its head points); otherwise it is read from where the
area is in the image: thirds across (left, centre column, right) and halves down, giving one of
:data:`perception.vocabulary.PLACES` (upper middle is ``centre``).
"""

from __future__ import annotations

from concurrent.futures import Executor, ThreadPoolExecutor
from dataclasses import dataclass, field

import numpy as np

from perception.colour import ColourSummary, colour_summary
from perception.errors import PerceptionError
from perception.faces import Face, FaceParams, FaceTracker
from perception.facts import Fact
from perception.imagesize import check_frame_size
from perception.saliency import SaliencyParams, SalientArea, most_salient, saliency_map
from perception.vocabulary import PLACES

__all__ = ["Perceiver", "Percept", "annotate", "perceive"]


@dataclass
class Percept:
    """Everything one frame gave, with the facts.

    Attributes:
        face: the face found, or ``None``.
        area: the most salient area outside the caregiver, or ``None``.
        colour: its colour summary, or ``None``.
        place: the place given to the object, or ``None``.
        facts: the perception facts.
    """

    face: Face | None = None
    area: SalientArea | None = None
    colour: ColourSummary | None = None
    place: str | None = None
    facts: list[Fact] = field(default_factory=list)


def _image_place(frame: np.ndarray, centre: tuple[int, int]) -> str:
    h, w = frame.shape[:2]
    col = min(2, int(3 * centre[0] / w))
    low = centre[1] >= h / 2
    return (("left", "centre", "right"), ("left_down", "down", "right_down"))[low][col]


class Perceiver:
    """Frames to facts, keeping the face tracker between frames.

    Args:
        saliency: saliency parameters.
        faces: face detection parameters.
        threads: pool threads for the stages (1: everything in the calling thread).
        pool: an executor to use instead of making one (``threads`` is then ignored).

    A perceiver with threads owns its pool: use it as a context manager or call :meth:`close`.
    """

    def __init__(self, saliency: SaliencyParams | None = None,
                 faces: FaceParams | None = None, threads: int = 1,
                 pool: Executor | None = None) -> None:
        if pool is None and (isinstance(threads, bool) or not isinstance(threads, int)
                             or threads < 1):
            raise PerceptionError(f"threads must be a whole number >= 1, got {threads!r}")
        self.saliency = saliency or SaliencyParams()
        self._own_pool = pool is None and threads > 1
        self.pool = ThreadPoolExecutor(threads, "perception") if self._own_pool else pool
        self.tracker = FaceTracker(faces or FaceParams(), pool=self.pool)

    def reset(self) -> None:
        """Forget tracking state."""
        self.tracker.reset()

    def close(self) -> None:
        """Stop the pool this perceiver made (safe to call twice)."""
        if self._own_pool and self.pool is not None:
            self.pool.shutdown()
            self.pool = self.tracker.pool = None

    def __enter__(self) -> Perceiver:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def analyse(self, frame: np.ndarray, looking_at: str | None = None) -> Percept:
        """Run every stage on a frame.

        Args:
            frame: ``(h, w, 3)`` uint8 BGR image.
            looking_at: where the head points (one of :data:`PLACES`), when known.
        """
        if not isinstance(frame, np.ndarray) or frame.ndim != 3 or frame.shape[2] != 3 \
                or frame.dtype != np.uint8:
            got = getattr(frame, "shape", type(frame).__name__)
            raise PerceptionError(f"a frame must be an (h, w, 3) uint8 BGR array, got {got}")
        if looking_at is not None and looking_at not in PLACES:
            raise PerceptionError(f"unknown place {looking_at!r}; use one of {PLACES}")
        check_frame_size(frame.shape[1], frame.shape[0], "the frame")
        out = Percept()
        # with a pool the saliency map is computed while the faces are searched
        smap = None if self.pool is None else self.pool.submit(saliency_map, frame,
                                                               self.saliency)
        face = self.tracker.detect(frame)
        exclude = []
        if face is not None:
            out.face = face
            out.facts += [("see", "face"), ("pose", "face", face.pose),
                          ("pan", "face", float(face.pan)), ("tilt", "face", float(face.tilt))]
            x, y, w, h = face.box
            # the caregiver: the head (with hair) and the body below it (the whole width of
            # the frame under the face) are not objects
            exclude.append((x - w, y - h, 3 * w, 5 * h // 2))
            exclude.append((0, y + h, frame.shape[1], frame.shape[0]))
        area = most_salient(frame, self.saliency, exclude=exclude,
                            smap=None if smap is None else smap.result())
        if area is not None:
            out.area = area
            out.colour = colour_summary(frame, area.mask)
            if looking_at is not None and looking_at != "centre":
                out.place = looking_at
            else:
                out.place = _image_place(frame, area.centre)
            out.facts.append(("see", "object"))
            if out.colour.name is not None:
                out.facts.append(("colour", "object", out.colour.name))
            out.facts.append(("at", "object", out.place))
        return out

    def perceive(self, frame: np.ndarray, looking_at: str | None = None) -> list[Fact]:
        """The perception facts of a frame (see :meth:`analyse`)."""
        return self.analyse(frame, looking_at).facts


def perceive(frame: np.ndarray, *, state: Perceiver | None = None,
             looking_at: str | None = None) -> list[Fact]:
    """Perception facts of one frame.

    Args:
        frame: ``(h, w, 3)`` uint8 BGR image.
        state: a :class:`Perceiver` to keep tracking between calls; a fresh one when ``None``.
        looking_at: where the head points, when known.

    Returns:
        Facts as plain Python values, e.g. ``[("see", "face"), ("pose", "face", "frontal")]``.
    """
    return (state or Perceiver()).perceive(frame, looking_at)


def annotate(frame: np.ndarray, percept: Percept) -> np.ndarray:
    """A copy of the frame with the face box, pose, salient area and colour drawn on it."""
    import cv2

    img = frame.copy()
    if percept.face is not None:
        x, y, w, h = percept.face.box
        cv2.rectangle(img, (x, y), (x + w, y + h), (0, 255, 0), 2)
        cv2.putText(img, f"{percept.face.pose} pan {percept.face.pan:.0f} tilt "
                    f"{percept.face.tilt:.0f}", (x, max(12, y - 4)), cv2.FONT_HERSHEY_SIMPLEX,
                    0.4, (0, 255, 0), 1, cv2.LINE_AA)
    if percept.area is not None:
        contours, _ = cv2.findContours(percept.area.mask, cv2.RETR_EXTERNAL,
                                       cv2.CHAIN_APPROX_SIMPLE)
        cv2.drawContours(img, contours, -1, (0, 255, 255), 2)
        x, y, _, _ = percept.area.box
        label = f"{percept.colour.name or 'object'} @ {percept.place}"
        cv2.putText(img, label, (x, max(12, y - 4)), cv2.FONT_HERSHEY_SIMPLEX, 0.4,
                    (0, 255, 255), 1, cv2.LINE_AA)
    return img
