"""The paper's experiments: protocols, job runner, results and plots."""

from relrl.experiments.sis import PAPER, SISConfig, run_job, run_sis

__all__ = ["PAPER", "SISConfig", "run_job", "run_sis"]
