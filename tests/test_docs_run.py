"""Docs that run: every code block of README.md and docs/*.md that is a command or Python
runs here as written, its shown output checked.

A fenced block says what it is by its language: ``sh`` (command lines), ``console`` (``$ ``
command lines, each followed by the output it prints; a line ``...`` stands for any lines)
and ``python`` run; ``text``, ``toml``, ``prolog``, ``bibtex`` and ``json`` are shown only.
A block without a language fails: say which it is. Each block runs in a fresh folder that
holds the checkout's ``examples``, ``docs``, ``prolog`` and ``bench`` (as a checkout does),
with this checkout's ``relrl`` first on the path; its lines run in order, each seeing what
the ones before wrote. A command that serves (``--monitor``, ``--foxglove``, ``replay``)
runs until it prints its address, then gets Ctrl-C.

What cannot run here is listed in :data:`NOT_RUN` with the reason, by the command's text:
real devices, placeholders a reader replaces, runs of hours, the set-up commands
(``tests/test_first_hour.py`` checks ``make demo`` and runs README.md's first hour). An
entry that no block holds any more fails, so the list stays the docs' own. A command that
reads what another page's command writes has that command in :data:`BEFORE`. Commands
that take minutes are in :data:`SLOW` (``-m "not slow"`` leaves them out). A Python block
that needs a package the tests' set-up does not install is in :data:`PYTHON_NEEDS` with the
marker of the selection that installs it (``sb3``: ``make test-sb3``). In a Python
block, ``print(...)  # VALUE`` shows what it prints when VALUE is a Python literal
(``...`` in it: a sketch, not checked). A failure names the block's ``file:line``, the
command and why.
"""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import pytest

from tests.conftest import ROOT, default_signals
from tests.test_first_hour import _first_hour_block

#: languages whose blocks run, and those only shown.
RUN = {"sh", "console", "python"}
SHOWN = {"text", "toml", "prolog", "bibtex", "json"}
#: what the sandbox holds of the checkout.
LINKED = ("examples", "docs", "prolog", "bench")

#: command (as written, comment left out) -> why it does not run here.
NOT_RUN: dict[str, str] = {
    "relrl check --world maze.pl -q": "a reader's own world file (the text describes it); "
                                      "tests/worlds/test_world_check.py checks these lines",
    "relrl evaluate runs/unstack/policy.pl --world examples/worlds/blocks.pl --task unstack "
    "--sizes 10,20,50 --episodes 20": "a policy learned for minutes first; "
                                      "tests/worlds/test_evaluate.py runs relrl evaluate",
    # the set-up: tests/test_first_hour.py checks `make demo` is `relrl demo` and runs that
    "make demo": "installs Debian packages and a virtual environment; tests/test_first_hour.py "
                 "runs its recipe (relrl demo)",
    "make test": "the whole suite (this test is part of it)",
    "pip install .": "installs the checkout; tests/test_install.py installs a wheel and runs it",
    ".venv/bin/pip install -q -e '.[monitor,mcap]'":
        "installs extras; tests/test_first_hour.py checks they are declared and present",
    # real devices
    "relrl run my.toml --camera 0 --head /dev/ttyUSB0 --protocol ssc32 --live":
        "a webcam and a serial servo controller",
    "relrl run my.toml --camera 0 --head /dev/ttyUSB0 --mic --monitor --out runs/s1 --record":
        "a webcam, a serial servo controller and a microphone",
    "relrl perceive --camera 0 --frames 30": "a webcam",
    "relrl run my.toml --mic": "shows the line printed where no microphone is; "
                               "tests/relrl/test_speech.py makes that case",
    # a cluster
    "ray start --head --port=6379": "starts a Ray cluster's head node",
    "ray start --address=HEAD:6379": "joins a Ray cluster (HEAD: its address)",
    "relrl experiment scaling --engine ray --address HEAD:6379 --learners "
    "contingency,qlearning,etg,tg --sizes 5,9,17,33 --seeds $(seq -s, 0 30) "
    "--out runs/scaling-31-seeds": "992 jobs on a Ray cluster (HEAD: its address)",
    # runs of hours: the docs' results come from them (docs/results/), the suite runs short ones
    ".venv/bin/relrl experiment scaling --out runs/scaling":
        "the full sweep, hours; --quick runs here",
    "relrl experiment sis --seeds 0,1,2,3,4 --out runs/exp1":
        "hours on two cores; docs/results/exp1 is its run",
    "relrl experiment sis --preset paper-2012 --seeds 0,1,2,3,4 --out runs/exp1-2012":
        "hours on two cores; docs/results/exp1-2012 is its run",
    "python -m relrl.experiments.exp2 --seeds 0-4 --out docs/results/exp2":
        "hours on two cores; docs/results/exp2 is its run",
    "relrl experiment worlds --out runs/worlds": "the worlds benchmark, about an hour; "
                                                 "docs/results/worlds is its run",
    "relrl experiment worlds --worlds examples/worlds/blocks.pl,examples/worlds/delivery.pl "
    "--learners tg --seeds 0-9 --workers 2 --no-speed --out runs/worlds":
        "the ten-seed benchmark of worlds.md's results, tens of minutes on two cores; "
        "docs/results/worlds is its run",
    "relrl experiment worlds --worlds examples/worlds/gripper.pl --learners tg --seeds 0-9 "
    "--workers 1 --no-speed --out runs/gripper":
        "worlds.md's gripper run, minutes on two cores; docs/results/gripper is its run",
    "relrl experiment worlds --worlds examples/worlds/blocks.pl --learners tg --seeds 0 "
    "--workers 1 --out runs/worlds-cost":
        "worlds.md's cost run, minutes on two cores; docs/results/worlds-cost is its run",
    "relrl report runs/worlds": "renders the run of the line before it (an hour); "
                                "docs/outputs.md runs relrl report on a shipped run",
    ".venv/bin/relrl experiment scaling --world colours=3,kinds=2,scene=true --sizes 5,9,17 "
    "--caregiver-param reliability=0.8 --transfer kinds --out runs/scaling-scene":
        "a sweep of hours",
    # what a reader's own files stand for
    "relrl run my.toml --check": "my.toml: the reader's script",
    "relrl check --world broken.pl": "broken.pl: a world with this mistake; "
                                     "tests/worlds/ checks each kind of problem",
    "relrl shell examples/domains/fruits.pl": "a session at a terminal (the reader types ; "
                                              "for more answers); tests/relrl/test_shell.py "
                                              "drives it",
    "relrl run hello.toml --out runs/hello": "the second run into a used folder: "
                                             "tests/cli/test_outputs.py checks this message",
    "relrl run bad.toml": "bad.toml: a script with these mistakes; "
                          "tests/episodes/test_script.py checks each message",
    "relrl run my.toml --camera robot_bag.mcap:/camera/image_raw":
        "a robot's own bag; tests/perception/test_bag_camera.py reads one",
    "relrl perceive robot_bag.mcap": "a robot's own bag",
    "relrl run my.toml --camera robot.mcap:/camera/image_raw/compressed": "a robot's own bag",
    "relrl perceive robot.mcap": "a robot's own bag",
    "relrl migrate runs/old-session": "a recording of an older relrl",
    "relrl perceive photo.png --annotate out.png": "photo.png: the reader's photo",
    "relrl tree policy.pl --domain d.pl > tree.dot": "policy.pl, d.pl: the reader's files",
    "relrl tree runs/exp2/policy.pl --domain examples/domains/fruits.pl --out tree.svg":
        "runs/exp2: Experiment 2's run (minutes, docs/episodes.md runs it)",
    "relrl experiment sis --config runs/exp1/results.json --out runs/exp1-again":
        "runs/exp1: the full Experiment 1 (hours); tests/experiments/test_rerun_config.py "
        "reruns a short one from its record",
    "relrl experiment sis --config runs/exp1/results.json --seeds 5,6 --out runs/exp1-more":
        "runs/exp1: the full Experiment 1 (hours)",
    "relrl experiment sis --config runs/exp1/results.json --preset paper-2012 "
    "--out runs/exp1-2012": "runs/exp1: the full Experiment 1 (hours)",
    "relrl experiment scaling --config runs/scaling/results.json --workers 8 --engine ray":
        "runs/scaling: the full sweep (hours) on a Ray cluster",
}

#: command -> what the doc ran before it elsewhere (another block, another page).
BEFORE: dict[str, str] = {
    "relrl tree runs/watch/policy.pl --out tree.png":
        "relrl run examples/episodes/watch.toml --out runs/watch --record",
}

#: a line of a Python block -> why that block does not run here.
PYTHON_NOT_RUN: dict[str, str] = {}

#: a line of a Python block -> the marker of the selection that installs what the block needs:
#: ``sb3``, Stable-Baselines3 and torch (``make test-sb3``; tests/conftest.py deselects these
#: unless ``-m`` names the marker).
PYTHON_NEEDS: dict[str, str] = {
    "from stable_baselines3 import PPO": "sb3",
}

#: commands (as written) that take seconds to minutes: run with ``-m slow``, once a session.
SLOW = {
    ".venv/bin/relrl experiment scaling --quick --out runs/scaling-quick",
    "relrl run examples/episodes/experiment2.toml --out runs/exp2",
    "relrl run examples/episodes/watch.toml --out runs/watch --record",
    ".venv/bin/relrl bench --json runs/bench/results.json",
    "python -m bench.perception_speed",
    "python -m perception.fruits",
    "python -m perception.fruits --plain",
    "relrl learn examples/worlds/blocks.pl --task stack --episodes 500",
    "relrl learn examples/worlds/blocks.pl --task on --learner ptg --monitor",
    "relrl learn examples/worlds/blocks_moves.pl --task on --out runs/on",
    "relrl learn examples/worlds/blocks_moves.pl --task stack --episodes 600 --block 200 "
    "--eval-episodes 60",
    '.venv/bin/python -c "from relrl.sim.policies import bench_step_rate as b; '
    'print(b(500_000)); print(b(500_000, record_trace=False))"',
    ".venv/bin/python examples/tg_gaze_following.py",
}

#: a line that says where a served page or socket is.
ADDRESS = re.compile(r"(?:https?|wss?)://[\w.:\[\]-]+")
SERVES = re.compile(r"--monitor\b|--foxglove\b|\breplay\b")


@dataclass
class Block:
    """A fenced block: where it starts (its first line), its language and its lines."""

    file: str
    line: int
    lang: str
    lines: list[str]

    @property
    def where(self) -> str:
        return f"{self.file}:{self.line}"


def doc_files() -> list[Path]:
    """README.md and every page of docs/."""
    return [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]


def blocks_of(path: Path) -> list[Block]:
    """The fenced blocks of a Markdown file (indented ones too, under a list item)."""
    name = path.relative_to(ROOT).as_posix()
    lines = path.read_text(encoding="utf-8").splitlines()
    found, i = [], 0
    while i < len(lines):
        m = re.match(r"^(\s*)```(\S*)\s*$", lines[i])
        if not m:
            i += 1
            continue
        indent, lang = len(m[1]), m[2]
        end = i + 1
        while end < len(lines) and not re.match(r"^\s*```\s*$", lines[end]):
            end += 1
        found.append(Block(name, i + 2, lang, [x[indent:] for x in lines[i + 1:end]]))
        i = end + 1
    return found


def all_blocks() -> list[Block]:
    return [b for path in doc_files() for b in blocks_of(path)]


def commands(block: Block) -> list[tuple[str, list[str]]]:
    """The block's commands in order, each with the output the doc shows for it (console
    blocks) or none; continued lines (``\\``) joined, a trailing ``  # comment`` left out."""
    out: list[tuple[str, list[str]]] = []
    pending = ""
    for raw in block.lines:
        if block.lang == "console":
            if raw.startswith("$ "):
                pending = raw[2:]
            elif pending:
                pending += " " + raw.strip()
            elif out:
                out[-1][1].append(raw)
                continue
            else:
                continue
        else:
            if not raw.strip() and not pending:
                continue
            pending = (pending + " " + raw.strip()) if pending else raw.strip()
        if pending.endswith("\\"):
            pending = pending[:-1].rstrip()
            continue
        if _uncommented(pending):
            out.append((_uncommented(pending), []))
        pending = ""
    return out


def _uncommented(line: str) -> str:
    """The command without a trailing comment (``#`` after blanks, outside quotes)."""
    quote = None
    for i, ch in enumerate(line):
        if quote:
            quote = None if ch == quote else quote
        elif ch in "'\"":
            quote = ch
        elif ch == "#" and (i == 0 or line[i - 1] == " "):
            return line[:i].rstrip()
    return line.rstrip()


def _params() -> list:
    params = []
    for block in all_blocks():
        if block.lang not in RUN or not _runs(block):
            continue
        slow = block.lang != "python" and any(c in SLOW or BEFORE.get(c) in SLOW
                                              for c, _ in commands(block))
        marks = [pytest.mark.slow] if slow or _slow_python(block) else []
        marks += [getattr(pytest.mark, PYTHON_NEEDS[x.strip()]) for x in block.lines
                  if block.lang == "python" and x.strip() in PYTHON_NEEDS]
        params.append(pytest.param(block, id=block.where, marks=marks))
    return params


def _first_hour() -> set[str]:
    """README.md's first hour: tests/test_first_hour.py runs it, serving pages included."""
    return {_first_hour_block("sh"), _first_hour_block("python")}


def _runs(block: Block) -> bool:
    """Whether anything of the block runs here (the rest is listed with its reason, or
    runs in tests/test_first_hour.py)."""
    if "\n".join(block.lines) + "\n" in _first_hour():
        return False
    if block.lang == "python":
        return not any(x.strip() in PYTHON_NOT_RUN for x in block.lines)
    return any(c not in NOT_RUN for c, _ in commands(block))


def _slow_python(block: Block) -> bool:
    return block.lang == "python" and any("learn(50_000)" in x for x in block.lines)


# -- the sandbox -------------------------------------------------------------------------------

def _sandbox(tmp_path: Path) -> dict[str, str]:
    """Link the checkout's folders into ``tmp_path``; the environment the commands see."""
    for name in LINKED:
        (tmp_path / name).symlink_to(ROOT / name)
    venv = Path(sys.executable).parent.parent
    (tmp_path / ".venv").symlink_to(venv)
    env = {k: v for k, v in os.environ.items() if k not in ("MAKEFLAGS", "MFLAGS")}
    env["PATH"] = f"{venv / 'bin'}{os.pathsep}{env.get('PATH', '')}"
    env["PYTHONPATH"] = str(ROOT)   # this checkout's relrl, whatever the venv installed
    env["COLUMNS"] = "100"
    return env


def _run(command: str, cwd: Path, env: dict[str, str], where: str,
         stdin: str | None = None, *, fails: bool = False) -> str:
    """Run one command line with bash; returns what it printed (stdout, then stderr). It
    must exit 0, or (``fails``: the doc shows the problems it reports) 1 or 2."""
    if SERVES.search(command):
        return _serve(command, cwd, env, where)
    try:
        proc = subprocess.run(["bash", "-c", command], cwd=cwd, env=env, input=stdin or "",
                              capture_output=True, text=True, timeout=1800,
                              preexec_fn=default_signals)
    except subprocess.TimeoutExpired:
        pytest.fail(f"{where}: `{command}` ran over 1800 s")
    text = proc.stdout + proc.stderr
    assert proc.returncode in ((0, 1, 2) if fails else (0,)), \
        f"{where}: `{command}` exit {proc.returncode}:\n{text[-3000:]}"
    assert "Traceback" not in proc.stderr, f"{where}: `{command}`:\n{proc.stderr[-3000:]}"
    return text


def _serve(command: str, cwd: Path, env: dict[str, str], where: str) -> str:
    """A command that serves: it must print its address; then Ctrl-C ends it (exit 0, or
    130 for a session stopped by it)."""
    proc = subprocess.Popen(["bash", "-c", f"exec {command}"], cwd=cwd, env=env, text=True,
                            stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, start_new_session=True,
                            preexec_fn=default_signals)
    assert proc.stdout is not None
    out: list[str] = []
    try:
        for text in proc.stdout:
            out.append(text)
            if ADDRESS.search(text):
                break
        else:
            proc.wait(timeout=60)
            pytest.fail(f"{where}: `{command}` printed no address (exit {proc.returncode}):\n"
                        + "".join(out)[-3000:])
        proc.send_signal(signal.SIGINT)
        rest, _ = proc.communicate(timeout=300)
        out.append(rest)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
    text = "".join(out)
    assert proc.returncode in (0, 128 + signal.SIGINT), \
        f"{where}: `{command}` exit {proc.returncode} on Ctrl-C:\n{text[-3000:]}"
    assert "Traceback" not in text, f"{where}: `{command}`:\n{text[-3000:]}"
    return text


def _printed_literal(line: str) -> str | None:
    """What ``print(X)  # VALUE`` shows it prints, when VALUE is a Python literal."""
    import ast

    m = re.match(r"\s*print\(.*\)\s+#\s*(.+?)\s*$", line)
    if not m or "..." in m[1]:
        return None
    try:
        value = ast.literal_eval(m[1])
    except (ValueError, SyntaxError):
        return None
    return value if isinstance(value, str) else repr(value)


def _check_shown(shown: list[str], printed: str, where: str, command: str) -> None:
    """Each line the doc shows is printed, in order (``...``: any lines between); an
    interactive session's ``?- query`` lines are what was typed, not printed."""
    got = [x.strip() for x in printed.splitlines()]
    at = 0
    for want in (x.strip() for x in shown):
        if not want or want == "..." or want.startswith("?- "):
            continue
        while at < len(got) and got[at] != want and not got[at].endswith(want):
            at += 1
        assert at < len(got), (f"{where}: `{command}` does not print, in the doc's order:\n"
                               f"  {want}\nit printed:\n{printed[-3000:]}")
        at += 1


#: a slow command run by an earlier block: its folder and what it printed. The same command
#: in another block (Experiment 2's run stands on two places of episodes.md) is run once; the
#: later block gets what it printed and the folder it wrote (``--out``), and checks them.
_RAN: dict[str, tuple[Path, str]] = {}


def _run_once(command: str, tmp_path: Path, env: dict[str, str], where: str,
              stdin: str | None = None, *, fails: bool = False) -> str:
    """:func:`_run`, or for a slow command an earlier block ran, what it printed and wrote."""
    import shlex
    import shutil

    if command not in SLOW or command not in _RAN:
        printed = _run(command, tmp_path, env, where, stdin, fails=fails)
        if command in SLOW:
            _RAN[command] = (tmp_path, printed)
        return printed
    ran_in, printed = _RAN[command]
    args = shlex.split(command)
    if "--out" in args:
        out = args[args.index("--out") + 1]
        shutil.copytree(ran_in / out, tmp_path / out, symlinks=True)
    return printed


# -- the tests ---------------------------------------------------------------------------------

def test_every_block_says_what_it_is() -> None:
    """A block without a language, or with one this test does not know, names its place."""
    bad = [f"{b.where}: ```{b.lang or '(no language)'}: say sh, console or python (it "
           f"runs here) or {', '.join(sorted(SHOWN))} (shown only)"
           for b in all_blocks() if b.lang not in RUN | SHOWN]
    assert not bad, "\n".join(bad)


def test_every_listed_command_is_still_in_the_docs() -> None:
    written = {c for b in all_blocks() if b.lang in RUN - {"python"} for c, _ in commands(b)}
    python = {x.strip() for b in all_blocks() if b.lang == "python" for x in b.lines}
    stale = sorted((set(NOT_RUN) | SLOW) - written) + \
        sorted((set(PYTHON_NOT_RUN) | set(PYTHON_NEEDS)) - python)
    assert not stale, "listed in tests/test_docs_run.py but in no block: " + "; ".join(stale)


@pytest.mark.parametrize("block", _params())
def test_the_block_runs_as_written(block: Block, tmp_path: Path) -> None:
    env = _sandbox(tmp_path)
    if block.lang == "python":
        code = "\n".join(block.lines) + "\n"
        (tmp_path / "block.py").write_text(code)
        printed = _run(f"{sys.executable} block.py", tmp_path, env, block.where)
        for line in block.lines:
            shown = _printed_literal(line)
            if shown is not None:
                assert shown in printed, (f"{block.where}: `{line.strip()}` does not print "
                                          f"{shown}; it printed:\n{printed[-3000:]}")
        return
    for command, shown in commands(block):
        if command in NOT_RUN:
            continue
        if command in BEFORE:
            _run_once(BEFORE[command], tmp_path, env, f"{block.where} (before it)")
        queries = [x[3:] for x in shown if x.startswith("?- ")]
        printed = _run_once(command, tmp_path, env, block.where,
                            stdin="\n".join(queries) + "\n" if queries else None,
                            fails=bool(shown))
        _check_shown(shown, printed, block.where, command)
