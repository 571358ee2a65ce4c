"""relrl's Gymnasium environments and their registration.

relrl declares :func:`register_envs` as its ``gymnasium.envs`` entry point (pyproject.toml), the
plugin hook through which Gymnasium registers third-party environments: ``import relrl`` does
not import Gymnasium. Gymnasium 1.x no longer reads that entry point itself, so importing the
simulator (``import relrl.sim``) registers the environments too, and
``gymnasium.make("relrl.sim:relrl/SharedAttention-v0")`` works from a bare interpreter::

    import gymnasium as gym
    import relrl.sim                                  # registers relrl/SharedAttention-v0
    env = gym.make("relrl/SharedAttention-v0", caregiver="paper")
"""

from __future__ import annotations

__all__ = ["ENVS", "register_envs"]

#: environment id -> ``module:class`` (imported only when the environment is made).
ENVS: dict[str, str] = {
    "relrl/SharedAttention-v0": "relrl.sim.sis:SharedAttentionEnv",
    "relrl/SharedAttention-v1": "relrl.sim.sis:SharedAttentionEnvV1",
}


def register_envs() -> None:
    """Register every environment of :data:`ENVS` with Gymnasium (once; safe to call again)."""
    import gymnasium

    for env_id, entry_point in ENVS.items():
        if env_id not in gymnasium.registry:
            gymnasium.register(id=env_id, entry_point=entry_point)
