"""``relrl experiment sis|scaling --config RESULTS.json``: a recorded configuration run again
gives the same results.json, byte for byte; options beside it override it; ``--preset``
composes with it; a bad record is one line and exit 2."""

from __future__ import annotations

import json
import shlex
from pathlib import Path

import pytest

from relrl.cli import build_parser, main
from relrl.cli.experiment import build_config, build_scaling_config
from relrl.experiments.scaling import ScalingConfig
from relrl.experiments.sis import SISConfig
from tests.conftest import ROOT

SIS = ["--learners", "contingency,etg", "--seeds", "0", "--points", "1", "--eval-runs", "2",
       "--eval-steps", "50", "--block", "50"]
SCALING = ["--learners", "qlearning", "--sizes", "5", "--seeds", "0", "--budget", "200",
           "--block", "100", "--eval-runs", "1", "--eval-steps", "50", "--transfer", "none",
           "--world", "colours=3,scene=true"]


def _config(*argv: str):
    """The configuration ``relrl experiment ARGV`` would run (nothing is run)."""
    args = build_parser().parse_args(["experiment", *argv])
    args.command_line = "relrl " + shlex.join(["experiment", *argv])
    return (build_config if argv[0] == "sis" else build_scaling_config)(args)


def _record(tmp_path: Path, config, experiment: str = "sis", name: str = "r.json") -> Path:
    path = tmp_path / name
    path.write_text(json.dumps({"experiment": experiment, "config": config.to_dict(),
                                "summary": {}}))
    return path


@pytest.mark.slow
def test_sis_run_again_gives_the_same_results_byte_for_byte(tmp_path: Path) -> None:
    a, b, c = tmp_path / "a", tmp_path / "b", tmp_path / "c"
    assert main(["experiment", "sis", *SIS, "--workers", "1", "--out", str(a)]) == 0
    again = ["experiment", "sis", "--config", str(a / "results.json")]
    assert main([*again, "--workers", "1", "--out", str(b)]) == 0
    assert main([*again, "--workers", "2", "--out", str(c)]) == 0
    assert (b / "results.json").read_bytes() == (a / "results.json").read_bytes()
    assert (c / "results.json").read_bytes() == (a / "results.json").read_bytes()


@pytest.mark.slow
def test_scaling_run_again_gives_the_same_results_byte_for_byte(tmp_path: Path) -> None:
    a, b = tmp_path / "a", tmp_path / "b"
    assert main(["experiment", "scaling", *SCALING, "--workers", "1", "--out", str(a)]) == 0
    assert main(["experiment", "scaling", "--config", str(a / "results.json"), "--workers", "1",
                 "--out", str(b)]) == 0
    assert (b / "results.json").read_bytes() == (a / "results.json").read_bytes()


SIS_CONFIGS = [
    SISConfig(learners=["etg"], seeds=[3, 1], points=2, block=40, eval_runs=3, eval_steps=60),
    SISConfig.from_preset("paper-2012", learners=["contingency", "qlearning"], seeds=[0]),
    SISConfig(learners=["tg", "qlearning"], train_places=["left", "down"],
              eval_places=["left", "down", "right"], caregiver_params={"reliability": 0.7},
              learner_params={"qlearning": {"alpha": 0.3}}, eval_policy="greedy",
              timeout=30.0, opportunities=50,
              domain=str(ROOT / "examples" / "domains" / "sis.pl")),
]


@pytest.mark.parametrize("config", SIS_CONFIGS, ids=["fixed", "preset", "places-params"])
@pytest.mark.slow
def test_a_recorded_sis_configuration_comes_back_field_for_field(tmp_path, config) -> None:
    assert _config("sis", "--config", str(_record(tmp_path, config))).to_dict() == \
        config.to_dict()
    # the configuration object alone does as well as the whole results.json
    alone = tmp_path / "config.json"
    alone.write_text(json.dumps(config.to_dict()))
    assert _config("sis", "--config", str(alone)).to_dict() == config.to_dict()


def test_a_recorded_scaling_configuration_comes_back_field_for_field(tmp_path) -> None:
    config = ScalingConfig(learners=["etg", "tg"], sizes=[5, 9], seeds=[2], budget=3000,
                           block=500, world={"colours": 3, "kinds": 2, "scene": True},
                           caregiver_params={"latency": 1}, threshold=0.8, patience=0,
                           transfer="kinds", transfer_sizes=[9], holdout=0.5, transfer_from=9)
    config.world = _config("scaling", "--world", "colours=3,kinds=2,scene=true").world
    path = _record(tmp_path, config, "scaling")
    assert _config("scaling", "--config", str(path)).to_dict() == config.to_dict()


def test_options_beside_the_record_override_it(tmp_path: Path) -> None:
    path = _record(tmp_path, SIS_CONFIGS[2])
    got = _config("sis", "--config", str(path), "--seeds", "7,8", "--eval-runs", "9",
                  "--caregiver-param", "latency=2", "--param", "tg.epsilon=0.2")
    assert got.seeds == [7, 8] and got.eval_runs == 9
    assert got.caregiver_params == {"reliability": 0.7, "latency": 2}
    assert got.learner_params == {"qlearning": {"alpha": 0.3}, "tg": {"epsilon": 0.2}}
    assert got.train_places == ["left", "down"] and got.timeout == 30.0  # the rest recorded
    # fewer learners typed: the recorded parameters of the others are left out
    got = _config("sis", "--config", str(path), "--learners", "tg")
    assert got.learners == ["tg"] and got.learner_params == {}


def test_a_preset_with_a_record_is_the_record_in_the_presets_setting(tmp_path, caplog) -> None:
    fixed = SISConfig(learners=["contingency", "etg"], seeds=[4], points=3, block=70,
                      eval_runs=4, caregiver_params={"reliability": 0.9})
    path = _record(tmp_path, fixed)
    got = _config("sis", "--config", str(path), "--preset", "paper-2012")
    typed = _config("sis", "--preset", "paper-2012", "--learners", "contingency,etg",
                    "--seeds", "4", "--points", "3", "--block", "70", "--eval-runs", "4",
                    "--eval-steps", "500", "--caregiver-param", "reliability=0.9")
    assert got.to_dict() == typed.to_dict()
    assert got.caregiver == "paper_2012" and got.learner_params["contingency"]["max_fitness"] == 1
    assert "replaces the recorded setting (the fixed task)" in caplog.text
    # a preset's record with its own preset again: nothing changes
    preset = _record(tmp_path, SIS_CONFIGS[1], name="p.json")
    assert _config("sis", "--config", str(preset), "--preset", "paper-2012").to_dict() == \
        SIS_CONFIGS[1].to_dict()


def _case(tmp_path: Path, name: str) -> list[str]:
    path = tmp_path / "r.json"
    if name == "missing":
        return ["sis", "--config", str(tmp_path / "nowhere.json")]
    content = {
        "not-json": "{\"config\": [1,\n",
        "array": "[1, 2]",
        "no-config": json.dumps({"experiment": "sis", "summary": {}}),
        "other-experiment": json.dumps({"experiment": "scaling", "config": {}}),
        "unknown-field": json.dumps({"experiment": "sis", "config": {"learnrs": ["etg"]}}),
        "bad-value": json.dumps({"experiment": "sis", "config": {"eval_runs": 0}}),
        "bad-learner": json.dumps({"experiment": "sis", "config": {"learners": ["nope"]}}),
        "missing-domain": json.dumps({"experiment": "sis",
                                      "config": {"domain": str(tmp_path / "gone.pl")}}),
        "quick": json.dumps({"experiment": "sis", "config": {}}),
    }[name]
    path.write_text(content)
    return ["sis", "--config", str(path)] + (["--quick"] if name == "quick" else [])


BAD = {"missing": "no such file", "not-json": ":2: not JSON", "array": "not a JSON object",
       "no-config": "no \"config\" object", "other-experiment": "relrl experiment scaling --config",
       "unknown-field": "config.learnrs is not a setting", "bad-value": "--eval-runs must be at "
       "least 1, not 0", "bad-learner": "unknown learner 'nope'",
       "missing-domain": "gone.pl is missing", "quick": "--quick with --config"}


@pytest.mark.parametrize("name", list(BAD))
def test_a_bad_record_is_one_line(tmp_path: Path, capsys, name: str) -> None:
    assert main(["experiment", *_case(tmp_path, name), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and BAD[name] in err[0], err
    assert not (tmp_path / "out").exists()
