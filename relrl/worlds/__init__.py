"""Worlds written in Prolog: any relational task stated as objects, relations, actions with
preconditions and effects, a goal and a reward (docs/worlds.md), learned by relrl's
relational learner and measured against the task's optimal number of steps.

Example:
    >>> from relrl.worlds import World, make_world_learner, score
    >>> with World("examples/worlds/blocks.pl") as world:
    ...     world.attach(make_world_learner("tg"), seed=0)
    ...     _ = world.episodes("stack", [3, 4, 5], 200)
    ...     print(score(world.episodes("stack", [6, 8, 10], 30, "greedy", optimal=True)))
"""

from relrl.learners import make_world_learner
from relrl.worlds.world import Episode, World, score

__all__ = ["Episode", "World", "make_world_learner", "score"]
