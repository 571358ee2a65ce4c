"""The learner registry is Prolog's: a learner declared only in Prolog is chosen by name from
Python with its declared defaults; Python and Prolog cannot disagree on the learners."""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from relrl.errors import RelrlError
from relrl.learners import DOMAINS, WORLDS, learners, make_learner, make_world_learner
from relrl.learners.base import COMMON_DEFAULTS, Learner
from relrl.learners.registry import _CLASSES, PrologLearner, build_registry, catalogue, registry
from relrl.resources import prolog_dir
from tests.conftest import ROOT

#: a learner of the domains written in Prolog alone: it emits the last allowed response.
TOY = """\
:- module(relrl_toy_learner, []).
:- use_module(engine).

relrl_engine:learner(toy).
relrl_engine:learner_property(toy, size).
relrl_engine:learner_property(toy, view(relational)).
relrl_engine:learner_parameter(toy, bias, 0.25, unit).
relrl_engine:learner_parameter(toy, rounds, 3, whole(1)).
relrl_engine:learner_serves(toy, domains, []).
relrl_engine:learner_serves(toy, worlds, [rounds=7]).
relrl_engine:learner_init(toy, _KB, _Params).
relrl_engine:learner_forget(toy, _KB).
relrl_engine:learner_update(toy, _KB, _Transition).
relrl_engine:learner_choose(toy, _KB, _State, _N, Allowed, _Mode, Action) :-
    last(Allowed, Action).
relrl_engine:learner_explain(toy, _KB, _State, _N, last_allowed).
relrl_engine:learner_size(toy, _KB, size(0, [])).
"""

#: run in a process whose relrl Prolog is the copy with the toy learner
SCRIPT = """\
import json, sys
from relrl.errors import ConfigError
from relrl.kb import KnowledgeBase
from relrl.learners import learners, make_learner, make_world_learner
from relrl.loop import Agent

out = {"domains": learners("domains"), "worlds": learners("worlds")}
learner = make_learner("toy", bias=0.5)
out["params"] = learner.params
out["class"] = type(learner).__name__
out["world_params"] = make_world_learner("toy").params
try:
    make_learner("toy", rounds=0.5)
except ConfigError as exc:
    out["bad"] = str(exc)
with KnowledgeBase(sys.argv[1]) as kb:
    agent = Agent(kb, learner, seed=0)
    step = agent.step([("see", "light")])
    out["action"] = str(step.action)
    out["explanation"] = agent.learner.explain()["detail"]
print(json.dumps(out))
"""


def _with_learner(tmp_path: Path, source: str, *command: str) -> subprocess.CompletedProcess:
    """Run SCRIPT (or ``command``) against a copy of relrl's Prolog whose learners.pl loads
    ``source`` too."""
    copy = tmp_path / "prolog"
    shutil.copytree(prolog_dir(), copy)
    (copy / "toy_learner.pl").write_text(source)
    learners_pl = copy / "learners.pl"
    learners_pl.write_text(learners_pl.read_text() + ":- use_module(toy_learner).\n")
    env = {**os.environ, "RELRL_PROLOG_DIR": str(copy)}
    argv = command or ("-c", SCRIPT, str(ROOT / "tests/data/tiny.pl"))
    return subprocess.run([sys.executable, *argv], capture_output=True, text=True, env=env,
                          cwd=ROOT, timeout=120)


@pytest.mark.slow
def test_a_learner_declared_only_in_prolog_is_chosen_by_name(tmp_path: Path) -> None:
    proc = _with_learner(tmp_path, TOY)
    assert proc.returncode == 0, proc.stderr
    out = json.loads(proc.stdout)
    assert out["domains"] == ["contingency", "etg", "qlearning", "tg", "toy"]
    assert out["worlds"] == ["tg", "ptg", "qtable", "toy"]
    assert out["class"] == "PrologLearner"
    assert out["params"] == {**COMMON_DEFAULTS, "bias": 0.5, "rounds": 3.0}
    assert out["world_params"] == {**COMMON_DEFAULTS, "bias": 0.25, "rounds": 7.0}
    assert out["bad"] == "rounds must be a whole number >= 1, not 0.5 (learner 'toy')"
    assert out["action"] == "c"            # the last allowed of tiny.pl's a, b, c
    assert out["explanation"] == "last_allowed"


@pytest.mark.parametrize("change,message", [
    (("relrl_engine:learner_property(toy, view(relational)).\n", ""),
     "learner toy: serves worlds but does not read the relational view"),
    (("bias, 0.25, unit", "bias, 1.5, unit"),
     "learner toy: parameter bias: 1.5 is not in [0, 1]"),
    (("bias, 0.25, unit", "bias, 0.25, percent"), "learner toy: parameter bias: unknown kind"),
    (("[rounds=7]", "[round=7]"), "learner toy: worlds: round=7 overrides no parameter"),
    (("relrl_engine:learner_serves(toy, domains, []).\n", "relrl_engine:learner_serves(toy, "
      "robots, []).\n"), "learner toy: unknown family of tasks robots"),
    (("relrl_engine:learner(toy).\n", ""),
     "learner toy: declares parameters or tasks but is not registered"),
])
@pytest.mark.slow
def test_a_learner_with_bad_declarations_is_an_error(tmp_path: Path, change: tuple[str, str],
                                                     message: str) -> None:
    proc = _with_learner(tmp_path, TOY.replace(*change))
    assert proc.returncode != 0
    assert message in proc.stderr


@pytest.mark.slow
def test_bad_declarations_are_one_line_and_exit_2_at_the_command_line(tmp_path: Path
                                                                       ) -> None:
    proc = _with_learner(tmp_path, TOY.replace("bias, 0.25, unit", "bias, 1.5, unit"),
                         "-m", "relrl", "learn", "examples/worlds/blocks.pl", "--episodes",
                         "1")
    assert proc.returncode == 2
    assert proc.stderr == ("relrl learn: learner toy: parameter bias: 1.5 is not in [0, 1] "
                           "(the learners' declarations, prolog/learners.pl)\n")


def _declared_in_source() -> tuple[set[str], set[str], dict[str, dict[str, float]]]:
    """Read from relrl's Prolog files as text: the learners registered (learner/1), those
    that are external, and each learner's parameters declared as facts."""
    names, external, params = set(), set(), {}
    for path in sorted(Path(prolog_dir()).glob("*.pl")):
        text = path.read_text()
        names |= set(re.findall(r"^relrl_engine:learner\((\w+)\)\.", text, re.M))
        external |= set(re.findall(r"^relrl_engine:learner_property\((\w+), external\)\.",
                                   text, re.M))
        for name, param, default in re.findall(
                r"^relrl_engine:learner_parameter\((\w+), (\w+), ([-\d.e]+),", text, re.M):
            params.setdefault(name, {})[param] = float(default)
    return names, external, params


def test_every_learner_of_prologs_files_is_in_the_registry_with_its_defaults() -> None:
    names, external, params = _declared_in_source()
    assert names == {"etg", "contingency", "external", "tg", "ptg", "qtable"}
    assert external == {"external"}
    python_only = {n for n, c in _CLASSES.items() if c.python_spec is not None}
    assert python_only == {"qlearning"}
    assert set(learners()) == (names - external) | python_only
    for name, declared in params.items():
        spec = registry()[name][0]
        assert {p.name: p.default for p in spec.parameters}.items() >= declared.items()
    # ptg's parameters are tg's and its own, its world defaults tg's
    assert make_world_learner("ptg").params == {**make_world_learner("tg").params,
                                                 "p_margin": 0.0, "p_alpha": 0.02,
                                                 "p_pairs": 1.0}


def test_a_python_class_for_a_learner_prolog_does_not_declare_is_an_error() -> None:
    class Sarsa(Learner):
        name = "sarsa"

        def _explain_from(self, detail, state, necessity):  # pragma: no cover - never made
            return {}

    entries = catalogue()
    with pytest.raises(RelrlError, match="learner 'sarsa', which relrl's Prolog does not "
                                         "declare"):
        build_registry(entries, {**_CLASSES, "sarsa": Sarsa})
    without_etg = [e for e in entries if e[1] != "etg"]
    with pytest.raises(RelrlError, match="learner 'etg', which relrl's Prolog"):
        build_registry(without_etg, _CLASSES)
    without_external = [e for e in entries if e[1] != "external"]
    with pytest.raises(RelrlError, match="'qlearning' chooses through Prolog learner "
                                         "'external', which is not an external learner"):
        build_registry(without_external, _CLASSES)
    # a learner Prolog declares and Python has no class for is made by PrologLearner
    only_prolog = build_registry(entries, {k: v for k, v in _CLASSES.items() if k != "etg"})
    assert only_prolog["etg"][1] is PrologLearner


def test_families_and_world_defaults() -> None:
    assert learners(DOMAINS) == ("contingency", "etg", "qlearning", "tg")
    assert learners(WORLDS) == ("tg", "ptg", "qtable")
    tg = make_world_learner("tg")
    assert (tg.params["q_init"], tg.params["novelty_bonus"], tg.params["stale_bonus"]) == (
        0.0, 0.0, 0.0)
    assert make_learner("tg").params["q_init"] == 30.0
    assert make_world_learner("tg", q_init=5).params["q_init"] == 5.0


def test_a_learners_spec_tells_its_parameters_and_families() -> None:
    from relrl.errors import ConfigError
    from relrl.learners import learner_spec

    tg = learner_spec("tg")
    params = {p.name: p for p in tg.parameters}
    assert params["alpha"].default == 0.2 and params["alpha"].allowed == "in [0, 1]"
    assert params["min_examples"].allowed == "a whole number >= 3"
    assert set(tg.serves) == {"domains", "worlds"} and tg.serves["worlds"]["q_init"] == 0.0
    assert set(learner_spec("ptg").serves) == {"worlds"}
    with pytest.raises(ConfigError, match="unknown learner 'sarsa'"):
        learner_spec("sarsa")
