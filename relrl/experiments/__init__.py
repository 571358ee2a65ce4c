"""The paper's experiments: protocols, job runner, results and plots."""

from relrl.experiments.sis import PAPER, SISConfig, run_job

__all__ = ["PAPER", "SISConfig", "run_job", "run_sis"]


def run_sis(config: SISConfig, out_dir, *, workers: int = 1):
    """Run Experiment 1 and write its outputs; returns (results, files written)."""
    from relrl.experiments.main import run_sis as _run

    return _run(config, out_dir, workers=workers)
