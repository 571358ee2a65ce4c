"""The Social Interactive Simulator (SIS): environment, worlds, caregiver models, metrics
and the evaluation protocol.

See ``docs/simulator.md`` and ``docs/benchmark.md``. Quick start::

    from relrl.sim import SharedAttentionEnv, World, evaluate
    env = SharedAttentionEnv(caregiver="paper", max_steps=500)
    obs, info = env.reset(seed=1)
    obs, reward, terminated, truncated, info = env.step(("look", "centre"))
    print(info["percepts"], env.metrics()["cgi"])
    big = SharedAttentionEnv(world=World(places=17, colours=3, scene=True))
"""

from __future__ import annotations

from relrl.envs import register_envs
from relrl.reward import PAPER_REWARD, Reward
from relrl.sim.caregiver import (
    EVALUATION_SEQUENCE,
    Caregiver,
    CaregiverParams,
    ProtocolCaregiver,
    caregiver_names,
    evaluation_sequence,
    make_caregiver,
    register_caregiver,
)
from relrl.sim.evaluation import Evaluation, evaluate, evaluation_env, evaluation_seeds
from relrl.sim.metrics import (
    CGI,
    EyeContacts,
    GazeMetrics,
    StepRecord,
    cgi,
    cgi_literal,
    eye_contacts,
    mutual_gaze_events,
    summarize,
)
from relrl.sim.places import PLACES, TOY_PLACES, Layout, layout, place_names
from relrl.sim.sis import ENV_ID, ENV_ID_V1, RESPONSES, SharedAttentionEnv
from relrl.sim.world import World

# Gymnasium 1.x does not read the gymnasium.envs entry point: importing the simulator
# registers its environments (relrl.envs).
register_envs()

__all__ = [
    "CGI",
    "ENV_ID",
    "ENV_ID_V1",
    "EVALUATION_SEQUENCE",
    "PAPER_REWARD",
    "PLACES",
    "RESPONSES",
    "TOY_PLACES",
    "Caregiver",
    "CaregiverParams",
    "Evaluation",
    "EyeContacts",
    "GazeMetrics",
    "Layout",
    "ProtocolCaregiver",
    "Reward",
    "SharedAttentionEnv",
    "StepRecord",
    "World",
    "caregiver_names",
    "cgi",
    "cgi_literal",
    "evaluate",
    "evaluation_env",
    "evaluation_seeds",
    "evaluation_sequence",
    "eye_contacts",
    "layout",
    "make_caregiver",
    "mutual_gaze_events",
    "place_names",
    "register_caregiver",
    "summarize",
]
