"""A world's rules misbehaving, and ``relrl learn`` / ``relrl check --world`` /
``relrl experiment worlds`` stopped: one line, the right status, nothing learned lost."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from tests.conftest import ROOT, default_signals

BLOCKS = ROOT / "examples" / "worlds" / "blocks.pl"
PRECONDITION = "precondition(move(X, Y), State) :-\n"


def world_with(tmp_path: Path, clause: str, name: str = "w.pl") -> tuple[Path, int]:
    """blocks.pl with ``clause`` put before its precondition/2; the path and the clause's
    line."""
    text = BLOCKS.read_text()
    assert PRECONDITION in text
    line = text[:text.index(PRECONDITION)].count("\n") + 1
    path = tmp_path / name
    path.write_text(text.replace(PRECONDITION, clause + "\n" + PRECONDITION, 1))
    return path, line


def relrl(*argv: str, timeout: float = 120) -> subprocess.CompletedProcess:
    """``relrl ARGV`` in a process of its own (a halt or a hang cannot end the test run)."""
    return subprocess.run([sys.executable, "-m", "relrl", *argv], cwd=ROOT, text=True,
                          capture_output=True, timeout=timeout, stdin=subprocess.DEVNULL,
                          preexec_fn=default_signals)


def one_line(proc: subprocess.CompletedProcess) -> str:
    """The one line on stderr of a command that ended with status 2."""
    lines = proc.stderr.strip().splitlines()
    assert proc.returncode == 2 and len(lines) == 1 and "Traceback" not in proc.stderr, \
        (proc.returncode, proc.stderr[-3000:])
    return lines[0]


# ---- A: halt in a world rule --------------------------------------------------------------

@pytest.mark.slow
@pytest.mark.parametrize("goal", ["halt", "halt(3)"])
def test_halt_in_a_world_rule_is_one_line_naming_the_rule(tmp_path: Path, goal: str) -> None:
    world, line = world_with(tmp_path, f"precondition(move(_, _), _) :- {goal}.")
    check = one_line(relrl("check", "--world", str(world)))
    assert f"w.pl:{line}: rule precondition(" in check and "called halt/0,1" in check
    out = tmp_path / "out"
    learn = one_line(relrl("learn", str(world), "--episodes", "4", "--eval-episodes", "2",
                           "--no-speed", "--out", str(out)))
    assert f"w.pl:{line}: rule precondition(" in learn and "called halt/0,1" in learn
    assert not (out / ".relrl-run.json").exists()       # refused before the folder is claimed


# ---- C: a world rule that loops or sleeps -------------------------------------------------

def started(*argv: str) -> subprocess.Popen:
    """``relrl ARGV`` started with Ctrl-C and SIGTERM at their defaults, as from a shell."""
    return subprocess.Popen([sys.executable, "-m", "relrl", *argv], cwd=ROOT, text=True,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            stdin=subprocess.DEVNULL, preexec_fn=default_signals)


def wait_for(stream, marker: str, proc: subprocess.Popen, timeout: float = 240) -> str:
    """Read ``stream`` line by line until a line holds ``marker``; what was read."""
    import time

    seen, deadline = [], time.monotonic() + timeout
    while time.monotonic() < deadline:
        line = stream.readline()
        if not line:
            break
        seen.append(line)
        if marker in line:
            return "".join(seen)
    proc.kill()
    raise AssertionError(f"no {marker!r} (exit {proc.poll()}): {''.join(seen)[-2000:]}")


@pytest.mark.slow
@pytest.mark.parametrize("body", ["repeat, fail", "sleep(1000)"])
def test_a_world_rule_that_never_ends_is_stopped_at_the_rule_limit(tmp_path: Path,
                                                                     body: str) -> None:
    """The limit is a rule's, in seconds (--rule-seconds), not the batch's 600 s; the
    message names the rule and the limit."""
    import time

    world, line = world_with(tmp_path, f"precondition(move(_, _), _) :- {body}.")
    t0 = time.monotonic()
    check = one_line(relrl("check", "--world", str(world), "--rule-seconds", "1"))
    assert time.monotonic() - t0 < 60
    assert f"w.pl:{line}: rule precondition(" in check and "longer than 1 s" in check
    learn = one_line(relrl("learn", str(world), "--episodes", "4", "--no-speed",
                           "--rule-seconds", "0.5"))
    assert f"w.pl:{line}: rule precondition(" in learn and "longer than 0.5 s" in learn


@pytest.mark.slow
def test_a_long_batch_of_a_world_is_not_a_rule_that_never_ends(tmp_path: Path) -> None:
    """Every step is a rule's end: a batch of episodes that runs many times the limit, each
    step slow but ending, is not stopped."""
    world, _ = world_with(tmp_path, "precondition(move(_, _), _) :- sleep(0.02), fail.")
    proc = relrl("learn", str(world), "--size", "3", "--eval-sizes", "3", "--episodes", "30",
                 "--block", "30", "--eval-episodes", "2", "--no-speed", "--restarts", "0",
                 "--rule-seconds", "0.5")
    assert proc.returncode == 0, proc.stderr[-2000:]


@pytest.mark.slow
def test_ctrl_c_stops_a_world_rule_that_never_ends_at_once(tmp_path: Path) -> None:
    """Ctrl-C reaches a rule that loops in `check --world` (the world's directive says when
    it has loaded): exit 130 within a second or so, not at the rule limit."""
    import signal
    import time

    world, _ = world_with(tmp_path, ":- format(user_error, \"loaded~n\", []).\n"
                                    "precondition(move(_, _), _) :- repeat, fail.")
    proc = started("check", "--world", str(world), "--rule-seconds", "200")
    wait_for(proc.stderr, "loaded", proc)
    time.sleep(0.5)                                    # into the check's episodes
    t0 = time.monotonic()
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    assert time.monotonic() - t0 < 5, err
    assert proc.returncode == 130 and "Traceback" not in err, err


# ---- I: relrl experiment worlds takes its options as given -----------------------------------

@pytest.mark.parametrize("argv, needle", [
    (["--episodes", "0"], "--episodes must be at least 1, not 0"),
    (["--block", "0"], "--block must be at least 1, not 0"),
    (["--eval-episodes", "0"], "--eval-episodes must be at least 1, not 0"),
    (["--seeds="], "--seeds"),
    (["--worlds", f"{BLOCKS},{BLOCKS}"], "--worlds names blocks.pl twice"),
    (["--tasks", "stack,stack"], "--tasks names stack twice"),
    (["--learners", "tg,tg"], "--learners names tg twice"),
])
def test_experiment_worlds_options_are_errors_not_defaults(capsys, tmp_path: Path,
                                                           argv: list[str],
                                                           needle: str) -> None:
    from tests.cli.conftest import one_line_exit_2

    one_line_exit_2(capsys, ["experiment", "worlds", *argv, "--out", str(tmp_path / "o")],
                    needle)
    assert not (tmp_path / "o").exists()


def test_experiment_worlds_quick_runs_tg_alone() -> None:
    """--quick is tg, seed 0 (its help says so); a learner given is kept."""
    import argparse

    from relrl.cli.experiment import add_arguments, build_worlds_config

    parser = argparse.ArgumentParser()
    add_arguments(parser)
    quick = build_worlds_config(parser.parse_args(["worlds", "--quick", "--worlds",
                                                   str(BLOCKS), "--tasks", "stack"]))
    assert (quick.learners, quick.seeds, quick.episodes, quick.block) == (["tg"], [0], 200, 50)
    given = build_worlds_config(parser.parse_args(["worlds", "--quick", "--worlds",
                                                   str(BLOCKS), "--tasks", "stack",
                                                   "--learners", "ptg", "--episodes", "7"]))
    assert (given.learners, given.episodes) == (["ptg"], 7)



def test_experiment_worlds_takes_each_worlds_declared_sizes() -> None:
    """Without --sizes and --test-sizes each world learns and is tested on its own
    sizes(train, ...) and sizes(test, ...) (gripper.pl's, blocks.pl's), as relrl learn
    does; given, they hold for every world; config's sizes are the union."""
    import argparse

    from relrl.cli.experiment import add_arguments, build_worlds_config
    from relrl.worlds import World

    gripper = BLOCKS.parent / "gripper.pl"
    with World(gripper) as world:
        train, test = world.declared_sizes["train"], world.declared_sizes["test"]
    assert train and train != [3, 4, 5] and test
    parser = argparse.ArgumentParser()
    add_arguments(parser)
    both = [str(BLOCKS), str(gripper)]
    own = build_worlds_config(parser.parse_args(["worlds", "--worlds", ",".join(both),
                                                 "--learners", "tg"]))
    g = own.learn_config(str(gripper.resolve()), "deliver", "tg", 0)
    b = own.learn_config(str(BLOCKS.resolve()), "stack", "tg", 0)
    assert (g.train_sizes, g.test_sizes) == (train, test)
    assert (b.train_sizes, b.test_sizes) == ([3, 4, 5], [10, 20, 50])
    assert own.train_sizes == sorted({*train, 3, 4, 5})
    assert own.to_dict()["world_sizes"]["gripper.pl"] == {"train": train, "test": test}
    given = build_worlds_config(parser.parse_args(["worlds", "--worlds", ",".join(both),
                                                   "--learners", "tg", "--sizes", "2",
                                                   "--test-sizes", "6,7"]))
    for world, task in [(gripper, "deliver"), (BLOCKS, "stack")]:
        c = given.learn_config(str(world.resolve()), task, "tg", 0)
        assert (c.train_sizes, c.test_sizes) == ([2], [6, 7])


def test_a_world_gives_its_learners_parameters() -> None:
    """learner_param/3: gripper.pl's tg explores at temperature 1, over tg's worlds default
    (blocks.pl: 0.1) and under a parameter given; its discount is tg's gamma."""
    from relrl.worlds import World

    with World(BLOCKS.parent / "gripper.pl") as world:
        assert world.learner_params == {"tg": {"temperature": 1.0}}
        tg = world.learner("tg")
        assert (tg.params["temperature"], tg.params["gamma"]) == (1.0, 0.95)
        given = world.learner("tg", temperature=0.3, gamma=0.9)
        assert (given.params["temperature"], given.params["gamma"]) == (0.3, 0.9)
    with World(BLOCKS) as world:
        assert world.learner_params == {}
        assert world.learner("tg").params["temperature"] == 0.1

# ---- B: relrl learn stopped keeps what it learned ------------------------------------------

LONG_LEARN = ("learn", str(BLOCKS), "--task", "stack", "--episodes", "1000000", "--block",
              "20", "--eval-episodes", "4", "--no-speed")


def assert_partial(out: Path, points: int) -> dict:
    """results.json marked partial with at least ``points`` evaluation points, the policy
    of the last of them, the folder's record partial."""
    import json

    from relrl.worlds import World

    results = json.loads((out / "results.json").read_text())
    assert results["partial"] and len(results["curve"]) >= points
    assert results["policy_episodes"] >= results["curve"][-1]["episodes"] >= 20
    assert (out / "curve.csv").read_text().count("\n") == len(results["curve"]) + 1
    policy = out / "policy.pl"
    assert f"(after {results['policy_episodes']} of 1000000" in policy.read_text()
    with World(BLOCKS) as world:                 # the policy kept loads, as data
        world.attach(world.learner("tg"), 0, "stack")
        world.load_policy(policy)
    record = json.loads((out / ".relrl-run.json").read_text())
    assert record["status"] == "partial" and "policy.pl" in record["files"]
    assert not [p.name for p in out.iterdir() if p.name.endswith(".tmp")
                or p.name in (".relrl-run.files", ".relrl-run.spare")]
    return results


@pytest.mark.slow
@pytest.mark.parametrize("signame", ["SIGINT", "SIGTERM", "SIGHUP"])
def test_a_stopped_learn_keeps_its_policy_and_partial_results(tmp_path: Path,
                                                               signame: str) -> None:
    import signal

    signum = getattr(signal, signame)
    out = tmp_path / "out"
    proc = started(*LONG_LEARN, "--out", str(out))
    wait_for(proc.stdout, "episodes     40", proc)
    proc.send_signal(signum)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 128 + signum, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in err, err
    assert "interrupted" in lines[0] and "policy.pl (learned from" in lines[0]
    assert_partial(out, 3)


@pytest.mark.slow
@pytest.mark.parametrize("gap", [0.0, 0.05])
def test_a_second_ctrl_c_does_not_lose_what_was_learned(tmp_path: Path, gap: float) -> None:
    import signal
    import time

    out = tmp_path / "out"
    proc = started(*LONG_LEARN, "--out", str(out))
    wait_for(proc.stdout, "episodes     20", proc)
    proc.send_signal(signal.SIGINT)
    time.sleep(gap)
    if proc.poll() is None:
        proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode in (130, -signal.SIGINT), err
    assert "policy.pl (learned from" in err and "Traceback" not in err, err
    assert_partial(out, 2)


@pytest.mark.slow
@pytest.mark.parametrize("goal, words", [("atom_length(S, _)", "atom_length/2"),
                                         ("halt", "called halt/0,1")])
def test_a_rule_error_mid_run_keeps_the_policy_learned_before_it(tmp_path: Path, goal: str,
                                                                 words: str) -> None:
    """A rule that fails (or halts) only on the larger test size: exit 2 naming it, and the
    policy (saved before that evaluation), the curve and the finished test size are
    written; the folder's record is not left running."""
    import json

    world, line = world_with(tmp_path, "precondition(move(_, _), S) :- "
                                       "aggregate_all(count, member(on(_, _), S), N), N > 5, "
                                       f"{goal}.")
    out = tmp_path / "out"
    proc = relrl("learn", str(world), "--size", "3", "--eval-sizes", "4,8", "--episodes",
                 "40", "--block", "20", "--eval-episodes", "3", "--no-speed", "--out",
                 str(out))
    message = one_line(proc)
    assert f"w.pl:{line}: rule precondition(" in message and words in message
    assert "policy.pl (learned from 40 of 40 episodes)" in message
    results = json.loads((out / "results.json").read_text())
    assert results["partial"] and f"w.pl:{line}: rule precondition(" in results["error"]
    assert list(results["test"]) == ["4"] and len(results["curve"]) == 3
    assert "task stack\n" in (out / "policy.pl").read_text().splitlines(True)[0]
    assert json.loads((out / ".relrl-run.json").read_text())["status"] == "partial"


# ---- J: a stopped relrl experiment worlds keeps every finished evaluation point -------------

def test_a_stopped_experiment_worlds_keeps_every_finished_point(tmp_path: Path,
                                                               monkeypatch) -> None:
    """Stopped while its jobs ran (run_jobs as a signal leaves it: no job finished, each
    reported some points), it writes those points -- jobs and curves.csv -- marked partial,
    as its last line says."""
    import csv
    import json

    import relrl.worlds.experiment as experiment
    from relrl.experiments.runner import Outcome

    def point(i: int) -> dict:
        return {"kind": "point", "entry": {
            "point": i, "episodes": 10 * i, "learning_steps": 40 * i, "optimality": 0.5,
            "success": 1.0, "memory_positions": 3 + i, "episodes_evaluated": 5}}

    def stopped(fn, tasks, **kwargs) -> Outcome:
        events = [[] if len(t) == 3 else [point(0), point(1)] for t in tasks]
        return Outcome([None] * len(tasks), events, interrupted="SIGINT")

    monkeypatch.setattr(experiment, "run_jobs", stopped)
    config = experiment.WorldsConfig(worlds=[str(BLOCKS)], tasks=["stack"],
                                     learners=["tg", "ptg"], seeds=[0], episodes=50, block=10)
    results, _ = experiment.run_worlds(config, tmp_path)
    assert results["partial"] and results["interrupted_by"] == "SIGINT"
    assert [(j["learner"], len(j["curve"]), j["partial"]) for j in results["jobs"]] == \
        [("tg", 2, True), ("ptg", 2, True)]
    assert results["summary"] == []                     # no job finished
    saved = json.loads((tmp_path / "results.json").read_text())
    assert len(saved["jobs"]) == 2
    rows = list(csv.DictReader((tmp_path / "curves.csv").open()))
    assert [(r["learner"], r["episodes"]) for r in rows] == \
        [("tg", "0"), ("tg", "10"), ("ptg", "0"), ("ptg", "10")]


@pytest.mark.slow
def test_a_real_sigint_to_experiment_worlds_keeps_each_unfinished_jobs_policy(
        tmp_path: Path) -> None:
    """B's sibling on experiment worlds: a job stopped by Ctrl-C keeps its evaluation
    points and the policy it last saved (it kept the points only)."""
    import json
    import signal
    import time

    out = tmp_path / "out"
    proc = started("experiment", "worlds", "--worlds", str(BLOCKS), "--tasks", "stack",
                   "--learners", "tg", "--seeds", "0", "--episodes", "10000000", "--block",
                   "20", "--eval-episodes", "2", "--sizes", "3", "--test-sizes", "4",
                   "--workers", "1", "--no-speed", "--out", str(out))
    time.sleep(15)
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 130, err
    results = json.loads((out / "results.json").read_text())
    assert results["partial"] and results["jobs"][0]["partial"], results["jobs"]
    policies = list((out / "policies").glob("*.pl"))
    assert [p.name for p in policies] == ["blocks-stack-tg-s0.pl"], err
    assert "tg_tree(" in policies[0].read_text()


@pytest.mark.slow
def test_a_bad_policy_to_start_from_claims_no_folder(tmp_path: Path) -> None:
    """`relrl learn --policy BAD.pl` refuses the policy in one line before it makes the
    output folder (it wrote results.json and the rest, marked partial, for a bad input)."""
    bad = tmp_path / "twice.pl"
    bad.write_bytes(b"% caf\xe9\nrelrl_policy(tg, []).\n")
    out = tmp_path / "out"
    line = one_line(relrl("learn", str(BLOCKS), "--task", "stack", "--policy", str(bad),
                          "--out", str(out)))
    assert "twice.pl" in line and "UTF-8" in line, line
    assert not out.exists()


# ---- G, H: relrl learn's seed, traces and task instances -------------------------------------

LEARN = ["learn", str(BLOCKS), "--episodes", "1", "--eval-episodes", "1", "--no-speed"]


@pytest.mark.parametrize("argv, needles", [
    (["--seed", "-1"], ["--seed", "-1"]),
    (["--traces", "-1"], ["--traces", "-1"]),
    (["--sizes="], ["--sizes", "''"]),
    (["--eval-sizes="], ["--eval-sizes", "''"]),
    (["--task", "on(b1, b1)"], ["on(b1, b1)", "cannot be reached", "3 objects"]),
    (["--task", "on(b1, b99)"], ["on(b1, b99)", "cannot be reached"]),
    (["--task", "on(b1, shell(x))"], ["on(b1, shell(x))", "cannot be reached"]),
    (["--task", "on(b4, b5)", "--sizes", "5,3"], ["on(b4, b5)", "3 objects"]),
    # sizes too large to search: the objects are still checked (no search needed)
    (["--task", "on(b1, b99)", "--sizes", "10", "--eval-sizes", "50"],
     ["on(b1, b99)", "names b99", "10 objects"]),
    (["--task", "on(b1, shell(x))", "--sizes", "10"], ["names shell(x)", "10 objects"]),
])
def test_learn_options_are_checked(capsys, argv: list[str], needles: list[str]) -> None:
    from tests.cli.conftest import one_line_exit_2

    one_line_exit_2(capsys, [*LEARN, *argv], *needles)


def test_a_reachable_task_instance_is_learned() -> None:
    from relrl.worlds import World

    with World(BLOCKS) as world:
        world.check_instance("on(b1, b2)", [3, 4, 8])       # 8: too many states to tell
        world.check_instance("on", [3])


@pytest.mark.slow
@pytest.mark.parametrize("value", ["0", "-1", "nan", "inf", "soon"])
def test_a_rule_limit_that_is_no_positive_number_is_refused(value: str) -> None:
    for argv in (LEARN, ["check", "--world", str(BLOCKS)], ["experiment", "worlds"]):
        line = one_line(relrl(*argv, f"--rule-seconds={value}"))
        assert "--rule-seconds" in line and repr(value) in line


def test_ctrl_c_stops_a_domain_directive_that_never_ends_at_once(tmp_path: Path) -> None:
    """C's sibling on domains: `relrl check DOMAIN.pl` whose directive loops waited for the
    load's time limit; Ctrl-C now stops it at once."""
    import signal
    import time

    domain = tmp_path / "d.pl"
    domain.write_text("stimulus(face).\n:- format(user_error, \"loaded~n\", []).\n"
                      ":- repeat, fail.\nresponse(look).\n")
    proc = started("check", str(domain))
    wait_for(proc.stderr, "loaded", proc)
    t0 = time.monotonic()
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    assert time.monotonic() - t0 < 3, err
    assert proc.returncode == 130 and "Traceback" not in err, err


@pytest.mark.slow
def test_a_goal_no_searchable_size_reaches_is_a_warning_at_larger_sizes(tmp_path: Path) -> None:
    """H at sizes too large to search: on(b1, b1) at 10 blocks is learned as asked, with a
    warning that no world of 1 to 5 blocks (searched whole) reaches it; on(b1, b2) is not."""
    warned = relrl("learn", str(BLOCKS), "--task", "on(b1, b1)", "--sizes", "10",
                   "--eval-sizes", "10", "--episodes", "2", "--eval-episodes", "1",
                   "--no-speed", "--out", str(tmp_path / "a"))
    assert warned.returncode == 0, warned.stderr
    assert "reached in no world of 1 to 5 objects" in warned.stderr, warned.stderr
    quiet = relrl("learn", str(BLOCKS), "--task", "on(b1, b2)", "--sizes", "10",
                  "--eval-sizes", "10", "--episodes", "2", "--eval-episodes", "1",
                  "--no-speed", "--out", str(tmp_path / "b"))
    assert quiet.returncode == 0 and "reached in no world" not in quiet.stderr, quiet.stderr


@pytest.mark.slow
def test_ctrl_c_while_a_domain_loads_is_a_stop_not_a_problem_of_the_file(tmp_path: Path) -> None:
    """Ctrl-C while `relrl run` reads a domain's clauses (not in a directive): exit 130 and
    "interrupted", as anywhere else (it said "d.pl: interrupted", exit 2)."""
    import signal
    import time

    domain = tmp_path / "d.pl"
    with domain.open("w") as fh:
        fh.write((ROOT / "examples" / "domains" / "fruits.pl").read_text())
        fh.write(":- format(user_error, \"reading~n\", []).\n")
        for i in range(300_000):
            fh.write(f"bigfact(f{i}, g({i}, [a, b, c])).\n")
    script = (ROOT / "examples" / "episodes" / "hello.toml").read_text()
    (tmp_path / "h.toml").write_text(script.replace("../domains/fruits.pl", str(domain)))
    proc = started("run", str(tmp_path / "h.toml"), "--out", str(tmp_path / "out"))
    wait_for(proc.stderr, "reading", proc)
    time.sleep(0.5)                         # in the clauses after the directive
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130 and "Traceback" not in err, err
    assert "d.pl" not in err, err


@pytest.mark.slow
def test_a_failed_experiment_worlds_job_keeps_its_points_and_policy(tmp_path: Path) -> None:
    """A job whose rule fails on the larger test size: the run stops (exit 2, one line), the
    job's evaluation points and the policy it saved before that evaluation are kept."""
    import json

    world, line = world_with(tmp_path, "precondition(move(_, _), S) :- "
                                       "aggregate_all(count, member(on(_, _), S), N), N > 5, "
                                       "atom_length(S, _).")
    out = tmp_path / "out"
    message = one_line(relrl("experiment", "worlds", "--worlds", str(world), "--tasks",
                             "stack", "--learners", "tg", "--seeds", "0", "--episodes", "20",
                             "--block", "10", "--eval-episodes", "3", "--sizes", "3",
                             "--test-sizes", "4,8", "--workers", "1", "--out", str(out)))
    assert f"w.pl:{line}: rule precondition(" in message and "partial" in message
    results = json.loads((out / "results.json").read_text())
    assert results["partial"] and [len(j["curve"]) for j in results["jobs"]] == [3]
    assert "task stack\n" in (out / "policies" / "w-stack-tg-s0.pl").read_text()


DEEP_WORLD = """initial_state(_, [pos(0), deep(T)]) :- deep(600, T).
deep(0, x) :- !.
deep(N, f(T)) :- N1 is N - 1, deep(N1, T).
task(reach).
action(step).
precondition(step, S) :- memberchk(pos(P), S), P < 3.
effect(step, S, [pos(P)], [pos(P1)]) :- memberchk(pos(P), S), P1 is P + 1.
goal(reach, S) :- memberchk(pos(3), S).
"""


@pytest.mark.slow
def test_an_answer_too_deep_to_cross_is_one_line_and_keeps_the_policy(tmp_path: Path) -> None:
    """S's other way: an answer relrl cannot read (the kept greedy episodes' states hold a
    term 600 deep) fails with one line, exit 2 -- not a traceback -- after the policy and
    the points before it were written."""
    import json

    world = tmp_path / "deep.pl"
    world.write_text(DEEP_WORLD)
    out = tmp_path / "out"
    message = one_line(relrl("learn", str(world), "--learner", "qtable", "--episodes", "4",
                             "--block", "2", "--eval-episodes", "2", "--size", "1",
                             "--eval-sizes", "1", "--no-speed", "--out", str(out)))
    assert "nested deeper than 400 levels" in message and "policy.pl (learned from 4" in message
    assert json.loads((out / "results.json").read_text())["partial"]
    assert (out / "policy.pl").is_file()


@pytest.mark.slow
def test_a_world_directive_that_never_ends_is_stopped_at_the_rule_limit(tmp_path: Path) -> None:
    """Loading a world is bounded by --rule-seconds too (it waited 600 s)."""
    import time

    world = tmp_path / "w.pl"
    world.write_text(":- repeat, fail.\n" + BLOCKS.read_text())
    t0 = time.monotonic()
    proc = relrl("check", "--world", str(world), "--rule-seconds", "1")
    assert time.monotonic() - t0 < 60
    assert proc.returncode == 2 and "w.pl:1:" in proc.stderr, proc.stderr
    assert "loading ran longer than the time limit" in proc.stderr


def test_a_signal_after_the_learning_says_the_outputs_are_complete(capsys) -> None:
    """As relrl experiment does: a stop that came as the outputs were written ends the
    command with 128 + N and says they are whole."""
    from types import SimpleNamespace

    from relrl.cli.learn import _late

    assert _late(SimpleNamespace(signum=None)) == 0
    assert _late(SimpleNamespace(signum=15)) == 143
    assert "SIGTERM came as the outputs were written: they are complete" in \
        capsys.readouterr().err
