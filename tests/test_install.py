"""A proper package: ``pip install .`` (not editable) into a fresh virtual environment outside
the checkout; then ``relrl check``, ``relrl demo``, the shell, the head's default calibration and
the Gymnasium environment work from another folder, with nothing read from the source tree.

Offline and cache-friendly: the wheel is built with ``--no-build-isolation --no-deps
--no-index`` from a copy of the checkout's files, and the fresh environment sees the test
suite's site-packages (numpy, numba, gymnasium, ...) through a ``.pth`` line, which does not
run that environment's editable-install hook: ``relrl``, ``head`` and ``perception``
come from the wheel alone.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import sysconfig
import venv
from pathlib import Path

import pytest

pytestmark = pytest.mark.slow  # every test here takes a second or more

ROOT = Path(__file__).resolve().parents[1]


def _source_files() -> list[str]:
    """The checkout's files as git sees them (tracked and new, not ignored)."""
    out = subprocess.run(["git", "ls-files", "-co", "--exclude-standard", "-z"], cwd=ROOT,
                         capture_output=True, check=True)
    return [f for f in out.stdout.decode().split("\0") if f]


def _copy_tree(dest: Path) -> None:
    for rel in _source_files():
        src = ROOT / rel
        target = dest / rel
        target.parent.mkdir(parents=True, exist_ok=True)
        if src.is_symlink():
            os.symlink(os.readlink(src), target)
        elif src.is_file():
            shutil.copy2(src, target)


@pytest.fixture(scope="module")
def installed(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    if shutil.which("git") is None or not (ROOT / ".git").exists():
        pytest.fail("the install test builds from the git checkout; git or .git is missing")
    base = tmp_path_factory.mktemp("install")
    src, wheels, env, work = base / "src", base / "wheels", base / "venv", base / "elsewhere"
    _copy_tree(src)
    subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation",
                    "--no-index", "-q", "-w", str(wheels), str(src)],
                   check=True, capture_output=True, cwd=base)
    wheel = next(wheels.glob("relrl-*.whl"))
    venv.EnvBuilder(with_pip=False).create(env)
    python = env / "bin" / "python"
    site = Path(subprocess.run([python, "-c", "import sysconfig; print(sysconfig.get_paths()"
                                "['purelib'])"], capture_output=True, text=True,
                               check=True).stdout.strip())
    (site / "_relrl_test_deps.pth").write_text(sysconfig.get_paths()["purelib"] + "\n")
    subprocess.run([sys.executable, "-m", "pip", "--python", str(python), "install", "-q",
                    "--no-deps", "--no-index", str(wheel)], check=True, capture_output=True)
    shutil.rmtree(src)  # nothing may be read from a source tree
    work.mkdir()
    return {"python": python, "relrl": env / "bin" / "relrl", "work": work, "site": site}


def _run(cmd: list, installed: dict[str, Path], stdin: str | None = None,
         timeout: float = 600) -> subprocess.CompletedProcess:
    environ = {k: v for k, v in os.environ.items()
               if k not in ("PYTHONPATH", "RELRL_PROLOG_DIR", "VIRTUAL_ENV")}
    return subprocess.run([str(c) for c in cmd], input=stdin, capture_output=True, text=True,
                          cwd=installed["work"], env=environ, timeout=timeout)


def test_packages_and_data_come_from_the_wheel(installed) -> None:
    proc = _run([installed["python"], "-c", """
import sys
import head, perception, relrl
from relrl.resources import examples_dir, prolog_dir
from head.calibration import DEFAULT_CALIBRATION
from head.urdf import DEFAULT_URDF
from relrl.recording.layout import LAYOUT
for m in (head, perception, relrl):
    print(m.__file__)
print(prolog_dir() / "gateway.pl")
print(examples_dir() / "domains" / "sis.pl")
print(DEFAULT_CALIBRATION)
print(DEFAULT_URDF)
print(LAYOUT)
"""], installed)
    assert proc.returncode == 0, proc.stderr
    paths = [Path(p) for p in proc.stdout.split()]
    assert len(paths) == 8
    for p in paths:
        assert p.is_relative_to(installed["site"]), p
        assert p.is_file() and not p.is_symlink(), p


def test_relrl_check_from_another_folder(installed) -> None:
    proc = _run([installed["relrl"], "examples", "--copy", "."], installed)
    assert proc.returncode == 0, proc.stderr
    proc = _run([installed["relrl"], "check", "examples/domains/fruits.pl"], installed)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.splitlines()[-1] == "ok: examples/domains/fruits.pl is valid"
    proc = _run([installed["relrl"], "check", "--world", "examples/worlds/blocks.pl"], installed)
    assert proc.returncode == 0, proc.stderr
    bad = installed["work"] / "bad.pl"
    bad.write_text("stimulus(face).\nresponse(look(centre)).\nfoo(X) :- bar(.\n")
    proc = _run([installed["relrl"], "check", "bad.pl"], installed)
    assert proc.returncode == 2
    assert proc.stderr.startswith("bad.pl:3:") and "Traceback" not in proc.stderr


def test_relrl_demo_from_another_folder(installed) -> None:
    proc = _run([installed["relrl"], "demo", "--out", "demo", "--workers", "1"], installed)
    assert proc.returncode == 0, proc.stderr
    assert (installed["work"] / "demo" / "results.json").is_file()
    assert "ETG" in proc.stdout or "etg" in proc.stdout


def test_shell_and_head_from_another_folder(installed) -> None:
    proc = _run([installed["relrl"], "shell", "examples/domains/sis.pl"], installed,
                stdin="response(look(P)).\n")
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.splitlines()[0] == "P = centre ;"
    proc = _run([installed["relrl"], "head", "--port", "sim", "look", "left"], installed)
    assert proc.returncode == 0, proc.stderr


def test_gymnasium_env_through_the_entry_point(installed) -> None:
    # What Gymnasium's plugin loader does with the gymnasium.envs entry point; and
    # `import relrl` alone imports no Gymnasium.
    proc = _run([installed["python"], "-c", """
import sys
from importlib.metadata import entry_points
import relrl
assert "gymnasium" not in sys.modules, "import relrl imported gymnasium"
(ep,) = {e.value: e for e in entry_points(group="gymnasium.envs") if e.name == "relrl"}.values()
ep.load()()
import gymnasium as gym
env = gym.make("relrl/SharedAttention-v0", max_steps=3)
env.reset(seed=0)
print(env.step(0)[4]["percepts"])
"""], installed)
    assert proc.returncode == 0, proc.stderr
    assert "('at', 'centre')" in proc.stdout


def test_bench_harnesses_stay_in_the_checkout(installed) -> None:
    """The measuring harnesses (bench/ beside relrl/) are not in the wheel; relrl bench from
    the installed package says what it needs in one line, exit 2."""
    site = installed["site"]
    assert not (site / "bench").exists()
    for gone in ("relrl/monitor/bench.py", "relrl/recording/bench.py", "perception/bench.py",
                 "perception/bagbench.py", "relrl/experiments/scaling_speed.py"):
        assert not (site / gone).exists(), gone
    proc = _run([installed["relrl"], "bench", "--steps", "100"], installed)
    assert proc.returncode == 2, proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1 and "bench/ beside relrl/" in proc.stderr
