"""``relrl bench`` reports every figure (no speed assertions: those live in the output)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from relrl.cli import main

pytestmark = pytest.mark.slow  # every test here takes a second or more


def test_bench_json(tmp_path: Path, capsys) -> None:
    path = tmp_path / "bench.json"
    assert main(["bench", "--no-perception", "--steps", "200", "--json", str(path)]) == 0
    figures = json.loads(path.read_text())
    assert figures["gateway_call_us"] > 0
    for name in ("etg", "contingency", "qlearning", "tg"):
        learner = figures["learners"][name]
        assert learner["steps_per_second"] > 0
        assert 0.99 <= learner["gateway_calls_per_step"] <= 1.01
        assert learner["cpu_us_per_step"] > 0
        assert learner["gateway_call_us"] > 0
        assert learner["step_in_gateway_calls"] == \
            learner["agent_us_per_step"] / learner["gateway_call_us"]
        assert learner["interaction_step_in_gateway_calls"] == \
            learner["us_per_step"] / learner["gateway_call_us"]
        assert 0 < learner["agent_us_per_step"] < learner["us_per_step"]
    side = figures["etg_prolog_side"]
    assert side["cpu_us_per_step"] > 0 and side["gateway_cpu_us_per_step"] > 0
    assert side["inferences_per_step"] > 100
    assert "etg_calls_per_step<=1.5" in figures["targets"]
    assert "tg_steps_per_second>=3000" in figures["targets"]
    assert figures["tg_step_in_etg_steps"] == (figures["learners"]["tg"]["cpu_us_per_step"]
                                               / figures["learners"]["etg"]["cpu_us_per_step"])
    assert "tg_step<=2x_etg_step" in figures["targets"]
    by_size = figures["tg_step_by_size"]
    assert set(by_size["sizes"]) == {"5", "129"} and by_size["ratio"]["5"] == 1.0
    assert by_size["ratio"]["129"] > 0 and by_size["sizes"]["129"]["positions"] > 0
    assert "tg_step_P129<=1.5x_P5" in figures["targets"]
    rec = figures["recording"]
    assert rec["units_per_second_out"] > 0 and rec["units_per_second_record"] > 0
    assert rec["mcap_bytes_per_unit"] > 0
    assert "recording_units_ratio>=0.9" in figures["targets"]
    assert "steps_per_second" in capsys.readouterr().out
    # the file is a run record: relrl report renders it with the command that made it
    path.rename(tmp_path / "results.json")
    from relrl.report import load_run, render

    text = render(load_run(tmp_path), "summary", "bench")
    assert f"{figures['learners']['tg']['steps_per_second']:,.0f} (1.00)" in text
    assert "made by `relrl bench --no-perception --steps 200 --json" in text


def test_perception_photo_target_line(monkeypatch) -> None:
    from bench import perception_speed as perception_bench
    from relrl.bench import bench_all

    for fps, met in ((59.9, False), (60.0, True)):
        monkeypatch.setattr(perception_bench, "bench",
                            lambda faces=True, fps=fps: {"fps_photos_320x240_cold": fps})
        figures = bench_all(steps=100)
        assert figures["targets"]["perception_photos_320x240_fps>=60"] is met
    monkeypatch.setattr(perception_bench, "bench", lambda faces=True: {"fps_320x240": 1.0})
    assert "perception_photos_320x240_fps>=60" not in bench_all(steps=100)["targets"]


def test_perception_two_thread_target_lines(monkeypatch) -> None:
    from bench import perception_speed as perception_bench
    from relrl.bench import bench_all

    figures = {"fps_photos_320x240_cold": 30.0, "fps_photos_320x240_cold_2threads": 59.0,
               "free_cores_fps_photos_320x240_cold_2threads": 61.0}
    monkeypatch.setattr(perception_bench, "bench", lambda faces=True: figures)
    targets = bench_all(steps=100)["targets"]
    assert targets["perception_photos_320x240_fps>=60"] is False
    assert targets["perception_photos_320x240_2threads_fps>=60"] is False
    assert targets["perception_photos_320x240_2threads_free_cores_fps>=60"] is True


def test_bench_without_the_source_tree_is_one_line(tmp_path: Path, monkeypatch,
                                                   capsys) -> None:
    """The harnesses (bench/) are not installed: without them, relrl bench says so in one
    line and exits 2 before any measuring."""
    import relrl.cli.bench as cli_bench

    monkeypatch.setattr(cli_bench, "SOURCE_TREE", tmp_path)
    assert main(["bench", "--no-perception", "--steps", "100"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "bench/ beside relrl/" in err
    assert "Traceback" not in err


def test_bench_loads_the_harnesses_of_its_own_checkout(tmp_path: Path, monkeypatch) -> None:
    import sys
    import types

    import relrl.cli.bench as cli_bench
    from relrl.errors import ConfigError

    for name in [m for m in sys.modules if m == "bench" or m.startswith("bench.")]:
        monkeypatch.delitem(sys.modules, name)
    cli_bench.load_harnesses()
    loaded = sys.modules["bench"]
    assert Path(loaded.__file__) == cli_bench.SOURCE_TREE / "bench" / "__init__.py"
    from bench.monitor_cost import bench_monitor  # a harness, found in that folder

    assert callable(bench_monitor)
    other = types.ModuleType("bench")
    other.__file__ = str(tmp_path / "bench.py")
    monkeypatch.setitem(sys.modules, "bench", other)
    with pytest.raises(ConfigError, match="another module named bench"):
        cli_bench.load_harnesses()
