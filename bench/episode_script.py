"""The short Experiment-2-like episode script that harnesses and tests run.

One template: the fruits domain, ETG, the protocol caregiver with the fruits apple, lime
(named "lemon") and orange, a warm-up phase without objects when asked for, then a phase with
fruits. :mod:`bench.recording_cost` times sessions of it; the monitor's and the recording's
tests (``tests/monitor/conftest.py``'s ``episode``) run it.
"""

from __future__ import annotations

from pathlib import Path

__all__ = ["fruits_episode"]


def fruits_episode(domain: str | Path, *, name: str, seed: int, steps: int,
                   perception: str = "render", warm_up: int = 0, policy_save: str = "",
                   extra: str = "") -> str:
    """The text of the episode script (TOML).

    Args:
        domain: the fruits domain file (``examples/domains/fruits.pl`` or a copy).
        name: the episode's name.
        seed: its seed.
        steps: time units in all, the warm-up's included.
        perception: ``render`` (frames rendered and perceived) or ``symbolic``.
        warm_up: time units of a first phase without objects (0: none).
        policy_save: where the policy is saved, relative to the output folder ("": not).
        extra: text added at the end, in the fruits phase's table (its keys, or new tables).
    """
    save = f'policy_save = "{policy_save}"\n' if policy_save else ""
    first = (f'[[phase]]\nname = "no objects"\nsteps = {warm_up}\nobjects = false\n'
             if warm_up else "")
    return f"""[episode]
name = "{name}"
domain = "{domain}"
seed = {seed}
learner = "etg"
{save}[world]
perception = "{perception}"
fruits = ["apple", "lime", "orange"]
names = {{ lime = "lemon" }}
[caregiver]
contact_hold = 1
{first}[[phase]]
name = "fruits"
steps = {steps - warm_up}
objects = true
{extra}"""
