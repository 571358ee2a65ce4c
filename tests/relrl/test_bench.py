"""``relrl bench`` reports every figure (no speed assertions: those live in the output)."""

from __future__ import annotations

import json
from pathlib import Path

from relrl.cli import main


def test_bench_json(tmp_path: Path, capsys) -> None:
    path = tmp_path / "bench.json"
    assert main(["bench", "--no-perception", "--steps", "200", "--json", str(path)]) == 0
    figures = json.loads(path.read_text())
    assert figures["gateway_call_us"] > 0
    for name in ("etg", "contingency", "qlearning", "tg"):
        learner = figures["learners"][name]
        assert learner["steps_per_second"] > 0
        assert 0.99 <= learner["gateway_calls_per_step"] <= 1.01
        assert learner["cpu_us_per_step"] > 0 and learner["gateway_call_us"] > 0
        assert learner["step_in_gateway_calls"] == \
            learner["us_per_step"] / learner["gateway_call_us"]
    assert "etg_calls_per_step<=1.5" in figures["targets"]
    assert "tg_steps_per_second>=3000" in figures["targets"]
    assert "steps_per_second" in capsys.readouterr().out
