"""Episodes on real devices: a camera for the eyes, a head for the responses.

:class:`DeviceWorld` is an :class:`~relrl.interfaces.Environment` over a camera source
(:func:`perception.open_camera`): every time unit it reads a frame, runs the perception
pipeline with the head's direction as ``looking_at``, and adds ``at(Place)`` and the words
heard (typed, recognised, or scripted with ``say``; the word ``attention`` is the caregiver's
attention, ``hear(attention)``). There is no ground truth on real devices: for the metrics,
the caregiver's gaze is estimated from the head pose perception reports (the inverse of
:data:`~relrl.episodes.world.GAZE_POSE`), held until the face is seen again.

:class:`HeadActuator` adapts a :class:`head.Head` (``emit(text)``) to the
:class:`~relrl.interfaces.Actuator` role (``emit(term)``).
"""

from __future__ import annotations

from typing import Any

from relrl.episodes.script import PLACES, Episode
from relrl.episodes.world import GAZE_POSE
from relrl.errors import UserError
from relrl.interfaces import Actuator, Environment
from relrl.sim.metrics import StepRecord
from relrl.terms import Term, format_term

__all__ = ["DeviceWorld", "HeadActuator", "RecordingEnded"]

_POSE_GAZE = {pose: place for place, pose in GAZE_POSE.items()}


class RecordingEnded(UserError):
    """The camera is a recording (a bag) and it has no more frames: the session's normal end
    (:func:`relrl.episodes.session.run_episode` ends there, with everything written).

    Attributes:
        seconds: how much of the recording was played (from its first frame to its last).
    """

    def __init__(self, seconds: float) -> None:
        super().__init__(f"the recording ended after {seconds:.2f} s")
        self.seconds = seconds


class HeadActuator(Actuator):
    """A head (simulated or serial) as the control loop's actuator."""

    def __init__(self, head: Any) -> None:
        self.head = head

    def emit(self, response: Term) -> None:
        """Play the response's motor script."""
        self.head.emit(format_term(response))

    def looking_at(self) -> str | None:
        """Where the head points, when it is at a calibrated direction."""
        return self.head.looking_at()

    def close(self) -> None:
        """Centre and release the head (safe twice)."""
        self.head.close()


class DeviceWorld(Environment):
    """Camera frames (and a head's direction) as an environment.

    Args:
        episode: the script (its ``say`` events are heard at their time units).
        camera: an open camera (``read()`` returns a BGR frame or ``None`` at the end).
        head: the head actuator, for where the robot looks (else the last ``look(P)``).
    """

    def __init__(self, episode: Episode, camera: Any, head: HeadActuator | None = None) -> None:
        from perception import Perceiver

        self.episode = episode
        self.camera = camera
        self.head = head
        self.perceiver = Perceiver()
        self.focus = "centre"
        self.gaze = "frontal"
        self.t = 0
        self.heard: list[str] = []
        self.last_frame: Any = None    # the frame perceived last and what perception found
        self.last_percept: Any = None  # in it (the monitor and the recording show them)
        self._say = {}
        for ev in episode.events:
            self._say.setdefault(ev.t, []).extend(ev.say)

    def hear(self, word: str) -> None:
        """A word typed or recognised, perceived in the next time unit."""
        self.heard.append(word)

    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None
              ) -> tuple[Any, dict[str, Any]]:
        """Start: perceive the first frame."""
        self.t = 0
        self.perceiver.reset()
        return None, self._observe()

    def step(self, action: Term) -> tuple[Any, float, bool, bool, dict[str, Any]]:
        """The head has moved (the actuator ran first); perceive the next frame."""
        if isinstance(action, tuple) and action[0] == "look" and action[1] in PLACES:
            self.focus = action[1]
        self.t += 1
        self.heard += self._say.get(self.t, [])
        info = self._observe()
        return None, 0.0, False, False, info

    def _observe(self) -> dict[str, Any]:
        from perception.art2 import colour_features

        frame = self.camera.read()
        if frame is None:
            if getattr(self.camera, "ended", False):  # a bag: the end of the recording
                if self.t == 0:
                    raise UserError(f"{self.camera.name}: no frame in it")
                raise RecordingEnded(float(getattr(self.camera, "seconds", 0.0)))
            raise UserError("the camera gave no more frames (end of the video or folder)")
        if self.head is not None:
            self.focus = self.head.looking_at() or self.focus
        percept = self.perceiver.analyse(frame, looking_at=self.focus)
        self.last_frame, self.last_percept = frame, percept
        facts = [f for f in percept.facts if f[0] not in ("pan", "tilt")]
        if percept.face is not None:
            self.gaze = "frontal" if percept.face.pose == "frontal" else \
                _POSE_GAZE.get(percept.face.pose, self.gaze)
        words, self.heard = self.heard, []
        attention = "attention" in words
        percepts = (facts or [("see", "environment")]) + [("at", self.focus)]
        percepts += [("hear", w) for w in words]
        record = StepRecord(self.t, self.focus, self.gaze, "device", 0, -1, (), None,
                            attention, False)
        features = colour_features(percept.colour) if percept.colour is not None else None
        return {"percepts": percepts, "record": record, "features": features,
                "words": [w for w in words if w != "attention"],
                "scene": {"look": self.gaze, "estimated": True}, "named": False}

    def close(self) -> None:
        """Release the camera (safe twice)."""
        self.camera.close()
