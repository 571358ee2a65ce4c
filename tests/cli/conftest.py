"""The bad-input and fault corpus: shared files and the one-line-exit-2 check."""

from __future__ import annotations

import random
import struct
import zlib
from pathlib import Path

import pytest

from relrl.cli import main

ROOT = Path(__file__).resolve().parents[2]
FRUITS = ROOT / "examples" / "domains" / "fruits.pl"


def episode_text(body: str = "", *, steps: int = 6, head: str = "") -> str:
    """A small symbolic episode on the fruits domain (``head`` goes into [episode])."""
    return (f'[episode]\ndomain = "{FRUITS}"\nseed = 1\n{head}\n[world]\n'
            f'perception = "symbolic"\n[[phase]]\nsteps = {steps}\ncaregiver = "script"\n'
            + body)


def _chunk(kind: bytes, data: bytes) -> bytes:
    return (struct.pack(">I", len(data)) + kind + data
            + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF))


def png_bytes(width: int, height: int, pixels: bytes | None = None) -> bytes:
    """A PNG whose header says ``width`` x ``height`` (RGB); ``pixels`` default: all black."""
    if pixels is None:
        pixels = b"".join(b"\x00" + bytes(3 * width) for _ in range(height))
    ihdr = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    return (b"\x89PNG\r\n\x1a\n" + _chunk(b"IHDR", ihdr)
            + _chunk(b"IDAT", zlib.compress(pixels, 9)) + _chunk(b"IEND", b""))


def jpeg_header(width: int, height: int) -> bytes:
    """The start of a baseline JPEG whose frame header says ``width`` x ``height``."""
    sof = b"\xff\xc0" + struct.pack(">HBHHB", 11, 8, height, width, 1) + b"\x01\x11\x00"
    return b"\xff\xd8" + b"\xff\xe0" + struct.pack(">H", 16) + b"JFIF\x00\x01\x01\x00" \
        + b"\x00\x01\x00\x01\x00\x00" + sof + b"\xff\xd9"


def _mcap_start() -> bytes:
    """The first bytes an MCAP writer writes (magic and header record)."""
    import io

    from mcap.writer import Writer

    buf = io.BytesIO()
    Writer(buf).start(profile="", library="relrl")
    return buf.getvalue()


@pytest.fixture(scope="session")
def corpus(tmp_path_factory) -> Path:
    """A folder of hostile inputs shared by the corpus tests."""
    d = tmp_path_factory.mktemp("corpus")
    rng = random.Random(14)
    noise = bytes(rng.randrange(256) for _ in range(2048))
    (d / "afile").write_text("not a folder\n")
    (d / "adir").mkdir()
    (d / "random.bin").write_bytes(noise)
    (d / "latin1.pl").write_bytes("stimulus(caf\xe9).\n".encode("latin-1"))
    (d / "random.toml").write_bytes(noise)
    (d / "latin1.toml").write_bytes('[episode]\nname = "caf\xe9"\n'.encode("latin-1"))
    (d / "empty.toml").write_text("")
    (d / "huge.png").write_bytes(png_bytes(100000, 100000, b"\x00" * 1000))
    (d / "tall.png").write_bytes(png_bytes(1, 10000))
    (d / "huge.jpg").write_bytes(jpeg_header(60000, 60000))
    (d / "truncated.png").write_bytes(png_bytes(64, 48)[:40])
    (d / "text.png").write_text("this is not an image\n")
    (d / "calibration.bin").write_bytes(noise)
    (d / "junk.mcap").write_bytes(noise)
    (d / "cut.mcap").write_bytes(_mcap_start()[:30])  # a recording cut in its header
    eps = {
        "ok.toml": episode_text(),
        "negative_seed.toml": episode_text().replace("seed = 1", "seed = -1"),
        "traversal.toml": episode_text(head='policy_save = "../../escaped-policy.pl"'),
        "absolute.toml": episode_text(head=f'policy_save = "{d}/abs-policy.pl"'),
        "reserved.toml": episode_text(head='policy_save = "summary.json"'),
        "dir_policy.toml": episode_text(head='policy_save = "policies/"'),
        "long_policy.toml": episode_text(head=f'policy_save = "{"p" * 300}.pl"'),
        "nul_policy.toml": episode_text(head='policy_save = "p\\u0000.pl"'),
        "nul_load.toml": episode_text(head='policy_load = "p\\u0000.pl"'),
        "nul_domain.toml": episode_text().replace('.pl"\n', '.pl\\u0000"\n', 1),
    }
    for own in ("session.json", "session.mcap", "summary.json", "trace.jsonl", "domain.pl",
                "episode.toml", "run.log", "timing.json", ".relrl-run.files"):
        eps[f"own_{own.replace('/', '_')}.toml"] = episode_text(head=f'policy_save = "{own}"')
    for name, text in eps.items():
        (d / name).write_text(text)
    hostile_policies(d)
    hostile_tomls(d)
    hostile_runs(d)
    hostile_sessions(d)
    head = (ROOT / "examples" / "heads" / "wha8030.toml").read_text()
    (d / "nul_scripts.toml").write_text(
        head.replace("[head]\n", '[head]\nscripts = "more\\u0000.toml"\n', 1))
    (d / "adir.svg").mkdir()
    from relrl.episodes import RunOptions, parse_episode, run_episode

    # a policy with a tree to draw (30 time units of etg)
    run_episode(parse_episode(episode_text(steps=30), d / "tree.toml"),
                RunOptions(out=d / "tree-run", plots=False))
    return d


def small_results(name: str) -> dict:
    """A shipped run's results.json with its lists cut to two items and its jobs and
    resolved settings left out (what no view renders): the same shape, small enough to write
    many times."""
    import json

    unread = ("jobs", "worlds", "caregiver_resolved", "eval_caregiver_resolved")

    def cut(value):
        if isinstance(value, dict):
            return {k: cut(v) for k, v in value.items() if k not in unread}
        if isinstance(value, list):
            return [cut(v) for v in value[:2]] if len(value) > 2 else [cut(v) for v in value]
        return value

    return cut(json.loads((ROOT / "docs" / "results" / name / "results.json").read_text()))


def hostile_sessions(d: Path) -> None:
    """Sessions recorded as folders of frames (``relrl migrate``) whose session.json says a
    duration that is no number of seconds, or a clock before 1970; an event with no time."""
    sessions = {"nan": '{"seconds": NaN}', "1e300": '{"seconds": 1e300}',
                "text": '{"seconds": "3"}', "1960": '{"seconds": 3, "recorded": '
                                                    '"1960-03-02T10:14:05+0000"}'}
    for name, manifest in {**sessions, "event": "{}"}.items():
        (d / f"old_{name}").mkdir()
        (d / f"old_{name}" / "trace.jsonl").write_text('{"t": 1}\n{"t": 2}\n')
        (d / f"old_{name}" / "session.json").write_text(manifest)
    (d / "old_event" / "events.jsonl").write_text('{"kind": "evaluation"}\n')


def hostile_runs(d: Path) -> None:
    """Run folders and Markdown files for ``relrl report``: a results.json with no config,
    an experiment relrl does not render, block markers leading out of the document's tree
    (``..``, an absolute path, a link), and names that are HTML."""
    import json

    def run(name: str, results: dict, records: dict | None = None) -> None:
        (d / name).mkdir()
        for file, data in {"results.json": results, **(records or {})}.items():
            (d / name / file).write_text(json.dumps(data))

    sis = small_results("exp1")
    run("run_no_config", {k: v for k, v in sis.items() if k != "config"})
    run("run_points_text", {**sis, "config": {**sis["config"], "points": "20"}})
    run("run_unknown_kind", {"experiment": "nope", "summary": {}})
    run("run_key_newline", {**sis, "summary": {"etg\nFAKE LINE": {"curve": "z"}}})
    for name, config in {"points_float": {"points": 2.5}, "points_true": {"points": True},
                         "sizes_text": {"sizes": [5, "9"]}}.items():
        (d / f"config_{name}.json").write_text(json.dumps(config))
    evil = "<script>alert(1)</script>"
    worlds = small_results("worlds")
    worlds["summary"][0]["task"] = f"{evil}|<img src=x onerror=alert(1)>\n# heading"
    run("run_html", worlds, {".relrl-run.json": {
        "command": "relrl `x` <!-- /relrl-report -->\n| a |"}})
    (d / "run_html" / "f) ![x](javascript:alert(1).png").write_bytes(b"")
    docs = {"md_traversal.md": "../../../../etc", "md_absolute.md": "/etc",
            "md_link.md": "linked_run", "md_results_link.md": "run_results_link",
            "md_space.md": "a-->b"}
    for name, path in docs.items():
        (d / name).write_text(f"# doc\n\n<!-- relrl-report {path} summary -->\n"
                              "<!-- /relrl-report -->\n")
    (d / "linked_run").symlink_to(ROOT / "docs" / "results" / "exp1")
    (d / "latin1.md").write_bytes("# doc\n\ncaf\xe9\n".encode("latin-1"))
    (d / "run_dev_zero").mkdir()
    (d / "run_dev_zero" / "results.json").symlink_to("/dev/zero")
    (d / "run_results_link").mkdir()
    (d / "run_results_link" / "results.json").symlink_to(
        ROOT / "docs" / "results" / "exp1" / "results.json")


def hostile_tomls(d: Path) -> None:
    """Episode scripts and calibrations nested 3,000 deep, or naming a device."""
    from head.calibration import DEFAULT_CALIBRATION

    deep = {"array": "[" * 3000 + "]" * 3000, "table": "{ a = " * 3000 + "1" + " }" * 3000}
    cal = DEFAULT_CALIBRATION.read_text()
    for name, nest in deep.items():
        (d / f"deep_{name}.toml").write_text(episode_text() + f"[learner]\nx = {nest}\n")
        (d / f"cal_deep_{name}.toml").write_text(cal + f"\n[extra]\nx = {nest}\n")
    (d / "dev_zero.toml").symlink_to("/dev/zero")
    (d / "cal_scripts_dev_zero.toml").write_text(
        cal.replace("[head]\n", '[head]\nscripts = "/dev/zero"\n', 1))


#: a hand-made ETG tree over the fruits domain's tests: {q} is the Q of the one entry.
_TREE = ("etg_node(0, test(0, stimulus(face), 1, 2)).\n"
         "etg_node(1, leaf(none, [])).\n"
         "etg_node(2, leaf(none, [e({response}, {q}, {necessity})])).\n")


def hostile_policies(d: Path) -> None:
    """Policies for the fruits domain that must be refused whole, one line naming the file
    and line: node ids out of range, trees that are not trees, numbers that are not finite
    or too large, responses and necessities the domain does not have; for every learner.
    ``p_*.pl`` are ETG policies, ``c_*`` contingency, ``t_*`` tg, ``q_*`` Q-tables; episodes
    ``load_*.toml`` load one into a run."""
    import numpy as np

    from relrl.kb import KnowledgeBase
    from relrl.learners import make_learner
    from relrl.loop import Agent

    good: dict[str, str] = {}
    with KnowledgeBase(FRUITS) as kb:
        for name in ("etg", "contingency", "tg", "qlearning"):
            agent = Agent(kb, make_learner(name), seed=0)
            for percepts in ([("see", "face")], [("see", "face"), ("hear", "attention")],
                             [("see", "object")]):
                agent.step(percepts)
            suffix = "npz" if name == "qlearning" else "pl"
            path = agent.learner.save(d / f"good_{name}.{suffix}")
            if suffix == "pl":
                good[name] = path.read_text()
    head = good["etg"].split("etg_node(")[0]

    def tree(response: str = "look(left)", q: str = "1.5", necessity: str = "socialize") -> str:
        return head + _TREE.format(response=response, q=q, necessity=necessity)

    ok = tree()
    etg = {
        "id1e9": ok.replace("1, 2)).", "1, 1000000000)).").replace(
            "etg_node(2,", "etg_node(1000000000,"),
        "id1e40": ok.replace("1, 2)).", f"1, {10**40})).").replace(
            "etg_node(2,", f"etg_node({10**40},"),
        "dangling": ok.replace("1, 2)).", "1, 7))."),
        "cycle": ok.replace("etg_node(1, leaf(none, [])).",
                            "etg_node(1, test(1, stimulus(object), 0, nil))."),
        "q_inf": tree(q="1.0Inf"),
        "q_400_digits": tree(q=str(10**400)),
        "q_rational": tree(q="1r3"),
        "halt": tree(response="halt"),
        "look_var": tree(response="look(_)"),
        "script": tree(response="'<script>'"),
        "necessity": tree(necessity="'<script>'"),
    }
    for name, text in etg.items():
        (d / f"p_{name}.pl").write_text(text)
    rule = "learned_behaviour(state(1), {r}, socialize, {f}).\n"
    contingency = {"halt": rule.format(r="halt", f="1.0"),
                   "inf": rule.format(r="look(left)", f="1.0Inf"),
                   "state_1e40": rule.format(r="look(left)", f="1.0").replace(
                       "state(1)", f"state({10**40})")}
    for name, extra in contingency.items():
        (d / f"c_{name}.pl").write_text(good["contingency"] + extra)
    tg_head = good["tg"].split("tg_tree(")[0]
    (d / "t_halt.pl").write_text(tg_head + "tg_tree(node(1, [halt], [], leaf(2, 1.0, 1), "
                                           "leaf(3, 2.0, 1))).\n")
    (d / "t_id1e9.pl").write_text(tg_head + "tg_tree(node(1, [sees(object)], [], "
                                            "leaf(1000000000, 1.0, 1), leaf(3, 2.0, 1))).\n")
    # a second tree after the first: refused at its line, not one of the two restored
    (d / "t_twice.pl").write_text(good["tg"] + "tg_tree(leaf(1, 0.0, 0)).\n")
    # a byte that is not UTF-8, in a comment (Prolog's reader passes it silently)
    (d / "p_latin1_comment.pl").write_bytes(good["etg"].encode() + "% caf\xe9\n".encode(
        "latin-1"))
    blocks = (ROOT / "examples" / "worlds" / "blocks.pl").read_bytes()
    (d / "w_latin1_comment.pl").write_bytes("% caf\xe9\n".encode("latin-1") + blocks)
    (d / "load_dir.toml").write_text(episode_text(head='learner = "etg"\npolicy_load = "adir"'))
    with np.load(d / "good_qlearning.npz") as table:
        arrays = {k: table[k] for k in table.files}
    arrays["q"] = arrays["q"].copy()
    arrays["q"][0, 0] = np.inf
    np.savez(d / "q_inf.npz", **arrays)
    # a million clauses (34 MB): refused from its size, before reading
    with open(d / "p_million.pl", "w") as fh:
        fh.write(head)
        fh.writelines(f"etg_node({i}, leaf(none, [])).\n" for i in range(1_000_000))
    for name in ("cycle", "halt"):
        (d / f"load_{name}.toml").write_text(episode_text(
            head=f'learner = "etg"\npolicy_load = "p_{name}.pl"\npolicy_save = "again.pl"'))


def one_line_exit_2(capsys, argv: list[str], *needles: str) -> str:
    """Run ``relrl ARGV`` in this process; it must print one line naming ``needles`` and
    return 2 (an exception escaping ``main`` fails the test with its traceback)."""
    code = main(argv)
    captured = capsys.readouterr()
    err = captured.err
    assert code == 2, f"exit {code}, stderr: {err!r}"
    assert "Traceback" not in err, err
    lines = [x for x in err.splitlines() if x.strip()]
    assert len(lines) == 1, f"expected one line, got {lines!r}"
    for needle in needles:
        assert needle in lines[0], f"{needle!r} not in {lines[0]!r}"
    return lines[0]
