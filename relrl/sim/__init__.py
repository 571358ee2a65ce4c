"""The Social Interactive Simulator (SIS): environment, caregiver models and metrics.

See ``docs/simulator.md``. Quick start::

    from relrl.sim import SharedAttentionEnv, GazeMetrics
    env = SharedAttentionEnv(caregiver="paper", max_steps=500)
    obs, info = env.reset(seed=1)
    obs, reward, terminated, truncated, info = env.step(("look", "centre"))
    print(info["percepts"], GazeMetrics().extend(env.trace).cgi())
"""

from __future__ import annotations

from relrl.envs import register_envs
from relrl.sim.caregiver import (
    EVALUATION_SEQUENCE,
    Caregiver,
    CaregiverParams,
    ProtocolCaregiver,
    caregiver_names,
    make_caregiver,
    register_caregiver,
)
from relrl.sim.metrics import (
    CGI,
    EyeContacts,
    GazeMetrics,
    StepRecord,
    cgi,
    eye_contacts,
    mutual_gaze_events,
    summarize,
)
from relrl.sim.places import PLACES, TOY_PLACES
from relrl.sim.sis import ENV_ID, RESPONSES, SharedAttentionEnv

# Gymnasium 1.x does not read the gymnasium.envs entry point: importing the simulator
# registers its environments (relrl.envs).
register_envs()

__all__ = [
    "CGI",
    "ENV_ID",
    "EVALUATION_SEQUENCE",
    "PLACES",
    "RESPONSES",
    "TOY_PLACES",
    "Caregiver",
    "CaregiverParams",
    "EyeContacts",
    "GazeMetrics",
    "ProtocolCaregiver",
    "SharedAttentionEnv",
    "StepRecord",
    "caregiver_names",
    "cgi",
    "eye_contacts",
    "make_caregiver",
    "mutual_gaze_events",
    "register_caregiver",
    "summarize",
]
