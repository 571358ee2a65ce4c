"""relrl: relational reinforcement learning for social robots.

Knowledge (declarations, working memory, state code, rules, the ETG tree) lives in SWI-Prolog,
reached through one gateway (:mod:`relrl.kb`); numbers, pixels and wires live in Python.
"""

from __future__ import annotations

__version__ = "0.1.0"

__all__ = ["__version__"]

# The Social Interactive Simulator as a Gymnasium environment (entry point loaded on make):
# v0 observes the focus; v1 adds the toy's kind and, in whole-scene worlds, every toy in view.
import gymnasium as _gym

if "relrl/SharedAttention-v0" not in _gym.registry:
    _gym.register(id="relrl/SharedAttention-v0", entry_point="relrl.sim.sis:SharedAttentionEnv")
if "relrl/SharedAttention-v1" not in _gym.registry:
    _gym.register(id="relrl/SharedAttention-v1", entry_point="relrl.sim.sis:SharedAttentionEnv",
                  kwargs={"observation": 1})
