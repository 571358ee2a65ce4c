"""A head's robot description (URDF) read as data: its joints and where each frame sits.

The head ships ``wha8030.urdf`` beside its calibration (:data:`DEFAULT_URDF`): the same
servo names as joints, x forward, y left, z up. :func:`load_urdf` reads the joints of any
URDF (revolute, continuous and fixed; links' visuals are for viewers and are not read), and
:meth:`Kinematics.transforms` gives every joint's transform from its parent link to its child
link for joint positions in radians -- what a 3D viewer needs to move the head.

The file is parsed with the standard library's XML parser, which expands no external
entities; a file over :data:`MAX_BYTES` is refused before it is parsed.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from importlib.resources import files
from pathlib import Path

from head.errors import CalibrationError

__all__ = ["DEFAULT_URDF", "Joint", "Kinematics", "load_urdf", "quaternion"]

#: the shipped description of the WHA-8030 (and the simulated head, which shares its
#: calibration).
DEFAULT_URDF = Path(str(files("head") / "calibrations" / "wha8030.urdf"))
#: the largest URDF read, in bytes (a head's is a few kilobytes).
MAX_BYTES = 1 << 20
_MOVING = ("revolute", "continuous")

Vec3 = tuple[float, float, float]
Quat = tuple[float, float, float, float]


@dataclass(frozen=True)
class Joint:
    """One joint of a URDF.

    Attributes:
        name: the joint's name (a servo's name for the moving ones).
        kind: ``revolute``, ``continuous`` or ``fixed``.
        parent, child: the links it joins (frame names).
        xyz: the child's origin in the parent's frame at position 0, metres.
        rpy: the child's orientation at position 0 (roll, pitch, yaw), radians.
        axis: the unit axis it turns about, in the child's frame.
        lower, upper: its limits in radians (``None`` when it has none).
    """

    name: str
    kind: str
    parent: str
    child: str
    xyz: Vec3 = (0.0, 0.0, 0.0)
    rpy: Vec3 = (0.0, 0.0, 0.0)
    axis: Vec3 = (1.0, 0.0, 0.0)
    lower: float | None = None
    upper: float | None = None


def quaternion(axis: Vec3, angle: float) -> Quat:
    """The rotation by ``angle`` radians about the unit ``axis`` as ``(x, y, z, w)``."""
    s = math.sin(angle / 2)
    return (axis[0] * s, axis[1] * s, axis[2] * s, math.cos(angle / 2))


def _multiply(a: Quat, b: Quat) -> Quat:
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return (aw * bx + ax * bw + ay * bz - az * by, aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw, aw * bw - ax * bx - ay * by - az * bz)


def _from_rpy(rpy: Vec3) -> Quat:
    roll, pitch, yaw = rpy  # fixed axes x, then y, then z (URDF's convention)
    return _multiply(quaternion((0.0, 0.0, 1.0), yaw),
                     _multiply(quaternion((0.0, 1.0, 0.0), pitch),
                               quaternion((1.0, 0.0, 0.0), roll)))


@dataclass(frozen=True)
class Kinematics:
    """A head's joints, as read from its URDF.

    Attributes:
        name: the robot's name.
        joints: the joints in file order.
    """

    name: str
    joints: tuple[Joint, ...]

    @property
    def moving(self) -> tuple[str, ...]:
        """The names of the joints that turn (the servos a viewer moves)."""
        return tuple(j.name for j in self.joints if j.kind in _MOVING)

    @property
    def root(self) -> str:
        """The frame every other hangs from (a link that is no joint's child)."""
        children = {j.child for j in self.joints}
        return next(j.parent for j in self.joints if j.parent not in children)

    def transforms(self, positions: dict[str, float]) -> list[tuple[Joint, Vec3, Quat]]:
        """Every joint's transform, parent link to child link: the joint, the child's origin
        in the parent's frame and its rotation ``(x, y, z, w)``. A moving joint turns by its
        position in ``positions`` (radians; 0 when absent, clamped to its limits)."""
        out = []
        for joint in self.joints:
            rotation = _from_rpy(joint.rpy)
            if joint.kind in _MOVING:
                angle = float(positions.get(joint.name, 0.0))
                if joint.lower is not None and joint.upper is not None:
                    angle = min(joint.upper, max(joint.lower, angle))
                rotation = _multiply(rotation, quaternion(joint.axis, angle))
            out.append((joint, joint.xyz, rotation))
        return out


def _vector(text: str | None, default: Vec3, where: str) -> Vec3:
    if text is None:
        return default
    try:
        values = tuple(float(v) for v in text.split())
    except ValueError:
        values = ()
    if len(values) != 3 or not all(math.isfinite(v) for v in values):
        raise CalibrationError(f"{where}: expected three numbers, not {text[:60]!r}")
    return values  # type: ignore[return-value]


def _limit(element: ET.Element | None, key: str, where: str) -> float | None:
    text = None if element is None else element.get(key)
    if text is None:
        return None
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not math.isfinite(value):
        raise CalibrationError(f"{where}: limit {key} must be a number, not {text[:40]!r}")
    return value


def _joint(element: ET.Element, path: Path) -> Joint:
    name = element.get("name") or ""
    where = f"{path}: joint {name!r}"
    kind = element.get("type", "")
    if kind not in (*_MOVING, "fixed"):
        raise CalibrationError(f"{where}: type {kind!r} is not read (revolute, continuous, "
                               "fixed)")
    parent, child = element.find("parent"), element.find("child")
    if not name or parent is None or child is None or not parent.get("link") \
            or not child.get("link"):
        raise CalibrationError(f"{where}: a joint needs a name, a parent and a child link")
    origin = element.find("origin")
    axis = _vector(None if element.find("axis") is None else element.find("axis").get("xyz"),
                   (1.0, 0.0, 0.0), where)
    norm = math.sqrt(sum(v * v for v in axis))
    if norm == 0:
        raise CalibrationError(f"{where}: its axis is zero")
    limit = element.find("limit")
    return Joint(name=name, kind=kind, parent=parent.get("link", ""),
                 child=child.get("link", ""),
                 xyz=_vector(None if origin is None else origin.get("xyz"), (0.0, 0.0, 0.0),
                             where),
                 rpy=_vector(None if origin is None else origin.get("rpy"), (0.0, 0.0, 0.0),
                             where),
                 axis=(axis[0] / norm, axis[1] / norm, axis[2] / norm),
                 lower=_limit(limit, "lower", where) if kind == "revolute" else None,
                 upper=_limit(limit, "upper", where) if kind == "revolute" else None)


def load_urdf(path: str | Path | None = None) -> Kinematics:
    """Read a URDF's joints (default: :data:`DEFAULT_URDF`).

    Raises:
        CalibrationError: the file cannot be read, is not a URDF, or a joint is malformed
            (the message names the file and the joint).
    """
    path = Path(path) if path is not None else DEFAULT_URDF
    try:
        size = path.stat().st_size
        if size > MAX_BYTES:
            raise CalibrationError(f"{path}: {size} bytes, more than a robot description "
                                   f"({MAX_BYTES})")
        root = ET.fromstring(path.read_bytes())
    except OSError as exc:
        raise CalibrationError(f"{path}: {exc.strerror or exc}") from None
    except ET.ParseError as exc:
        raise CalibrationError(f"{path}: not XML ({exc})") from None
    if root.tag != "robot":
        raise CalibrationError(f"{path}: not a URDF (its root is <{root.tag}>, not <robot>)")
    joints = tuple(_joint(e, path) for e in root.findall("joint"))
    if not joints:
        raise CalibrationError(f"{path}: the robot has no joint")
    return Kinematics(name=root.get("name", "robot"), joints=joints)
