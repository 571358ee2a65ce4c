"""The robotic head: motor scripts, serial servo protocols with safety limits, a simulated head.

Open a head with :func:`open_head` and use it as a context manager::

    from head import open_head

    with open_head("sim") as h:          # or "/dev/ttyUSB0", "socket://host:4000", "loop://"
        h.emit("look(left_down)")        # play the motor script of a response
        print(h.looking_at())            # -> "left_down"

Every pose is clamped to the calibration (``examples/heads/wha8030.toml`` by default)
before anything is sent.
"""

from __future__ import annotations

from pathlib import Path

from head.base import Head
from head.calibration import DIRECTIONS, Calibration, Servo, load_calibration, save_calibration
from head.errors import HeadError
from head.protocols import PROTOCOLS, get_protocol
from head.sim import HeadEvent, SimHead

__all__ = [
    "DIRECTIONS",
    # protocols and errors
    "PROTOCOLS",
    # calibration as data
    "Calibration",
    "Head",
    "HeadError",
    "HeadEvent",
    "Servo",
    "SimHead",
    "get_protocol",
    "load_calibration",
    # opening a head
    "open_head",
    "save_calibration",
]

#: the ``port`` value that means the simulated head.
SIM_PORT = "sim"


def open_head(port: str, protocol: str | None = None,
              calibration: str | Path | Calibration | None = None, **options) -> Head:
    """Open a head.

    Args:
        port: ``"sim"`` for the simulated head, else a serial device path or pyserial URL
            (``loop://``, ``socket://HOST:PORT``).
        protocol: ``ssc32``, ``maestro`` or ``pms5005``; default: the calibration's
            ``[head] protocol``. Ignored by the simulated head.
        calibration: a calibration file or object; default: the shipped WHA8030 file.
        **options: passed to :class:`SimHead` or :class:`head.serial_head.SerialHead`
            (``timeout``, ``feedback``, ``realtime``, ...).

    Returns:
        An open head, looking at the centre.

    Raises:
        CalibrationError, UnknownProtocol, PortUnavailable: one line saying what to fix.
    """
    cal = calibration if isinstance(calibration, Calibration) else load_calibration(calibration)
    if port == SIM_PORT or port == "sim://":
        if protocol is not None:
            get_protocol(protocol)  # a typo in --protocol is an error even with the sim
        return SimHead(cal, **options)
    from head.serial_head import SerialHead

    return SerialHead(port, protocol, cal, **options)
