"""What machine a run ran on, for the records a run leaves (``timing.json``) and the reports
made from them: processor, cores, operating system, Python, SWI-Prolog and relrl."""

from __future__ import annotations

import os
import platform
import shutil
import subprocess
from functools import cache
from typing import Any

__all__ = ["machine_info", "describe"]


def _cpu_model() -> str:
    try:
        with open("/proc/cpuinfo", encoding="utf-8", errors="replace") as fh:
            for line in fh:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


@cache
def _swipl_version() -> str | None:
    swipl = shutil.which("swipl")
    if swipl is None:
        return None
    try:
        out = subprocess.run([swipl, "--version"], capture_output=True, text=True, timeout=10,
                             check=False).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return None
    return out or None


def machine_info() -> dict[str, Any]:
    """The machine, as plain JSON values (the same on every call in one process)."""
    from relrl import __version__

    return {"cpu": _cpu_model(), "cores": os.cpu_count(), "arch": platform.machine(),
            "os": f"{platform.system()} {platform.release()}",
            "python": platform.python_version(), "swipl": _swipl_version(),
            "relrl": __version__}


def describe(info: dict[str, Any]) -> str:
    """One line for a report: ``Intel(R) Xeon(R) ..., 2 cores, Linux 6.1, Python 3.11.7``."""
    parts = [info.get("cpu") or info.get("machine") or info.get("arch") or "unknown machine"]
    if info.get("cores"):
        parts.append(f"{info['cores']} cores")
    if info.get("os"):
        parts.append(str(info["os"]))
    if info.get("python"):
        parts.append(f"Python {info['python']}")
    if info.get("swipl"):
        parts.append(str(info["swipl"]).replace("SWI-Prolog version ", "SWI-Prolog ")
                     .split(" for ")[0])
    return ", ".join(parts)
