"""The task's reward: one definition for the simulator, the learners, the experiments and
outside agents.

The caregiver decides *when* it gives attention (:mod:`relrl.sim.caregiver`: at most once
per eye-contact opportunity, and when the robot looks at the target toy); the reward turns a
time unit into a number: ``attention`` (+10) in a time unit with ``hear(attention)``,
``other`` (-1) otherwise — the paper's values (section 4.3). relrl's learners compute the
same numbers inside the engine from the reinforcer stimulus: their ``reward_positive`` and
``reward_negative`` parameters default to :data:`PAPER_REWARD`'s values (a test holds the
two together, time unit by time unit).
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["PAPER_REWARD", "Reward"]


@dataclass(frozen=True)
class Reward:
    """Reward per time unit.

    Attributes:
        attention: in a time unit with the caregiver's attention (``hear(attention)``).
        other: in any other time unit.
    """

    attention: float = 10.0
    other: float = -1.0

    def __call__(self, attention: bool) -> float:
        """The reward of a time unit."""
        return self.attention if attention else self.other


#: the paper's reward, the default of the simulator and of the experiments.
PAPER_REWARD = Reward()
