"""The bad-input corpus, every subcommand: one line naming the value, exit 2.

Each case is ``relrl ARGV`` run in this process (an escaping exception fails the test with its
traceback) and the words the one line must contain. ``{d}`` is the corpus folder
(``conftest.corpus``: hostile files, policies and TOML included), ``{fruits}`` the fruits
domain. Outputs that must *not* be written are
checked in ``test_outputs.py``; lost devices, faults, signals and full disks in
``test_nothing_lost.py``.

The corpus holds 277 cases: 201 bad inputs in ``CASES`` and 32 more tests here, 26 in
``test_outputs.py``, 18 in ``test_nothing_lost.py`` (each parametrized case counted once;
:func:`test_the_corpus_says_how_many_cases_it_holds` keeps these numbers true).
"""

from __future__ import annotations

import importlib
import io
import re
import sys

import pytest

from relrl.cli import main
from tests.cli.conftest import FRUITS, one_line_exit_2

#: a tiny Experiment 1 (seconds, one process), for cases that must fail before running it.
EXP = ["experiment", "sis", "--learners", "etg", "--points", "1", "--eval-runs", "1",
       "--eval-steps", "10", "--block", "10", "--workers", "1"]
BENCH = ["bench", "--steps", "100", "--no-perception", "--no-faces"]
SMALL = "synthetic://?size=64x48"
#: a world written in Prolog (relrl learn, relrl experiment worlds).
BLOCKS = str(__import__("pathlib").Path(__file__).resolve().parents[2] / "examples" / "worlds"
             / "blocks.pl")
LEARN = ["learn", BLOCKS, "--task", "stack", "--episodes", "1", "--eval-episodes", "1",
         "--no-speed"]

CASES: list[tuple[str, list[str], list[str]]] = [
    # ---- shell -----------------------------------------------------------------------------
    ("shell-missing-domain", ["shell", "{d}/nope.pl"], ["nope.pl"]),
    ("shell-missing-policy", ["shell", "{fruits}", "--policy", "{d}/nope.pl"], ["nope.pl"]),
    ("shell-unknown-learner", ["shell", "{fruits}", "--learner", "nope"], ["nope"]),
    # ---- bench -----------------------------------------------------------------------------
    ("bench-steps", BENCH[:1] + ["--steps", "-1"], ["--steps", "-1"]),
    ("bench-json-dir", BENCH + ["--json", "{d}/adir"], ["adir", "folder"]),
    ("bench-json-proc", BENCH + ["--json", "/proc/relrl-bench.json"], ["/proc"]),
    ("bench-json-file-as-dir", BENCH + ["--json", "{d}/afile/b.json"], ["afile"]),
    # ---- experiment ------------------------------------------------------------------------
    ("experiment-out-file", EXP + ["--out", "{d}/afile"], ["afile", "not a folder"]),
    ("experiment-out-dev-null", EXP + ["--out", "/dev/null"], ["/dev/null", "not a folder"]),
    ("experiment-out-proc", EXP + ["--out", "/proc/foo"], ["/proc/foo"]),
    ("experiment-out-under-file", EXP + ["--out", "{d}/afile/x"], ["afile"]),
    ("experiment-negative-seed", EXP + ["--seeds", "0,-1"], ["--seeds", "-1"]),
    ("experiment-bad-seed", EXP + ["--seeds", "one"], ["--seeds", "one"]),
    ("experiment-points", EXP + ["--points", "0"], ["--points", "0"]),
    ("experiment-workers", EXP + ["--workers", "0"], ["--workers", "0"]),
    ("experiment-unknown-learner", EXP + ["--learners", "nope"], ["nope"]),
    ("experiment-nan-param", EXP + ["--param", "etg.q_init=nan"], ["q_init", "nan"]),
    ("experiment-inf-param", EXP + ["--param", "etg.alpha=inf"], ["alpha", "inf"]),
    ("experiment-eval-runs-1e30", EXP + ["--eval-runs", str(10**30)],
     ["--eval-runs", "at most 1,000,000,000"]),
    ("experiment-points-1e30", EXP + ["--points", str(10**30)], ["--points", "1,000,000,000"]),
    ("experiment-config-points-a-string", ["experiment", "sis", "--config",
                                           "{d}/run_points_text/results.json"],
     ["run_points_text/results.json", 'config.points is "20" (a string)', "an integer"]),
    ("experiment-config-points-2.5", ["experiment", "sis", "--config",
                                      "{d}/config_points_float.json"],
     ["config_points_float.json", "config.points is 2.5", "an integer"]),
    ("experiment-config-points-true", ["experiment", "sis", "--config",
                                       "{d}/config_points_true.json"],
     ["config_points_true.json", "config.points is true", "an integer"]),
    ("experiment-config-sizes-text", ["experiment", "scaling", "--config",
                                      "{d}/config_sizes_text.json"],
     ["config_sizes_text.json", "config.sizes", "a list of integers"]),
    # ---- run -------------------------------------------------------------------------------
    ("run-missing", ["run", "{d}/nope.toml"], ["nope.toml"]),
    ("run-directory", ["run", "{d}/adir"], ["adir"]),
    ("run-random-bytes", ["run", "{d}/random.toml"], ["random.toml"]),
    ("run-latin1", ["run", "{d}/latin1.toml"], ["latin1.toml", "UTF-8"]),
    ("run-negative-seed-flag", ["run", "{d}/ok.toml", "--seed", "-5"], ["--seed", "-5"]),
    ("run-negative-seed-script", ["run", "{d}/negative_seed.toml"],
     ["negative_seed.toml:3", "seed", "-1"]),
    ("run-step-seconds-nan", ["run", "{d}/ok.toml", "--step-seconds", "nan"],
     ["--step-seconds", "nan"]),
    ("run-step-seconds-inf", ["run", "{d}/ok.toml", "--step-seconds", "inf"],
     ["--step-seconds", "inf"]),
    ("run-step-seconds-negative", ["run", "{d}/ok.toml", "--step-seconds", "-1"],
     ["--step-seconds", "-1"]),
    ("run-out-file", ["run", "{d}/ok.toml", "--out", "{d}/afile"], ["afile", "not a folder"]),
    ("run-out-dev-null", ["run", "{d}/ok.toml", "--out", "/dev/null"], ["/dev/null"]),
    ("run-out-proc", ["run", "{d}/ok.toml", "--out", "/proc/foo"], ["/proc/foo"]),
    ("run-policy-traversal", ["run", "{d}/traversal.toml", "--out", "{d}/out-trav"],
     ["traversal.toml:4", "policy_save", "../../escaped-policy.pl"]),
    ("run-policy-absolute", ["run", "{d}/absolute.toml", "--out", "{d}/out-abs"],
     ["absolute.toml:4", "policy_save", "abs-policy.pl"]),
    ("run-policy-reserved", ["run", "{d}/reserved.toml", "--out", "{d}/out-res"],
     ["reserved.toml:4", "summary.json"]),
    ("run-policy-folder", ["run", "{d}/dir_policy.toml", "--out", "{d}/out-dirp"],
     ["dir_policy.toml:4", "policies/"]),
    ("run-policy-300-characters", ["run", "{d}/long_policy.toml", "--check"],
     ["long_policy.toml:4", "policy_save", "255"]),
    ("run-policy-nul", ["run", "{d}/nul_policy.toml", "--out", "{d}/out-nul"],
     ["nul_policy.toml:4", "policy_save", "NUL"]),
    ("run-policy-nul-check", ["run", "{d}/nul_policy.toml", "--check"],
     ["nul_policy.toml:4", "NUL"]),
    ("run-domain-nul", ["run", "{d}/nul_domain.toml", "--check"],
     ["nul_domain.toml:2", "domain", "NUL"]),
    ("run-policy-load-nul", ["run", "{d}/nul_load.toml", "--check"],
     ["nul_load.toml:4", "policy_load", "NUL"]),
    *[(f"run-policy-own-{own}", ["run", f"{{d}}/own_{own}.toml", "--check"],
       [f"own_{own}.toml:4", "file of the run itself"])
      for own in ("session.json", "session.mcap", "summary.json", "trace.jsonl", "domain.pl",
                  "episode.toml", "run.log", "timing.json", ".relrl-run.files")],
    ("run-protocol-without-head", ["run", "{d}/ok.toml", "--protocol", "ssc32"],
     ["--protocol"]),
    ("run-missing-head", ["run", "{d}/ok.toml", "--head", "/dev/ttyNOPE0", "--protocol",
                          "ssc32"], ["/dev/ttyNOPE0"]),
    ("run-missing-camera", ["run", "{d}/ok.toml", "--camera", "{d}/no-frames/"],
     ["no-frames"]),
    ("run-huge-synthetic-camera", ["run", "{d}/ok.toml", "--camera",
                                   "synthetic://?size=100000x100000"], ["100000"]),
    ("run-missing-calibration", ["run", "{d}/ok.toml", "--head", "sim", "--calibration",
                                 "{d}/nope.toml"], ["nope.toml"]),
    # ---- perceive --------------------------------------------------------------------------
    ("perceive-missing", ["perceive", "{d}/nope.png"], ["nope.png"]),
    ("perceive-directory", ["perceive", "{d}/adir"], ["adir"]),
    ("perceive-random-bytes", ["perceive", "{d}/random.bin"], ["random.bin"]),
    ("perceive-text-as-png", ["perceive", "{d}/text.png"], ["text.png"]),
    ("perceive-truncated-png", ["perceive", "{d}/truncated.png"], ["truncated.png"]),
    ("perceive-header-100000x100000", ["perceive", "{d}/huge.png"],
     ["huge.png", "100000x100000"]),
    ("perceive-1x10000", ["perceive", "{d}/tall.png"], ["tall.png", "1x10000"]),
    ("perceive-jpeg-60000x60000", ["perceive", "{d}/huge.jpg"], ["huge.jpg", "60000x60000"]),
    ("perceive-annotate-weird", ["perceive", "--camera", SMALL, "--annotate", "{d}/x.weird"],
     ["x.weird"]),
    ("perceive-annotate-dir", ["perceive", "--camera", SMALL, "--annotate", "{d}/adir"],
     ["adir"]),
    ("perceive-frames", ["perceive", "--camera", SMALL, "--frames", "0"], ["--frames", "0"]),
    ("perceive-looking-at", ["perceive", "--camera", SMALL, "--looking-at", "up"], ["up"]),
    ("perceive-both", ["perceive", "{d}/tall.png", "--camera", SMALL], ["IMAGE", "--camera"]),
    ("perceive-missing-folder", ["perceive", "--camera", "dir://{d}/no-frames"],
     ["no-frames"]),
    ("perceive-synthetic-huge", ["perceive", "--camera", "synthetic://?size=100000x100000"],
     ["100000"]),
    ("perceive-synthetic-empty", ["perceive", "--camera", "synthetic://?size=0x0"], ["0x0"]),
    ("perceive-synthetic-nan", ["perceive", "--camera", "synthetic://?lighting=nan"],
     ["lighting", "nan"]),
    ("perceive-synthetic-place", ["perceive", "--camera", "synthetic://?looking_at=up"],
     ["up"]),
    # ---- head ------------------------------------------------------------------------------
    ("head-missing-port", ["head", "--port", "/dev/ttyNOPE0", "--protocol", "ssc32", "look",
                           "left"], ["/dev/ttyNOPE0"]),
    ("head-binary-calibration", ["head", "--calibration", "{d}/calibration.bin", "status"],
     ["calibration.bin"]),
    ("head-latin1-calibration", ["head", "--calibration", "{d}/latin1.toml", "status"],
     ["latin1.toml"]),
    ("head-calibration-dir", ["head", "--calibration", "{d}/adir", "status"], ["adir"]),
    ("head-calibration-scripts-nul", ["head", "--calibration", "{d}/nul_scripts.toml",
                                      "status"], ["nul_scripts.toml", "head.scripts", "NUL"]),
    ("head-timeout-nan", ["head", "--port", "/dev/ttyNOPE0", "--protocol", "ssc32",
                          "--timeout", "nan", "status"], ["--timeout", "nan"]),
    ("head-timeout-negative", ["head", "--port", "/dev/ttyNOPE0", "--protocol", "ssc32",
                               "--timeout", "-1", "status"], ["--timeout", "-1"]),
    ("head-unknown-direction", ["head", "look", "up"], ["up"]),
    ("head-unknown-response", ["head", "emit", "look("], ["look("]),
    ("head-calibrate-dir", ["head", "calibrate", "-o", "{d}/adir"], ["adir"]),
    ("head-calibrate-proc", ["head", "calibrate", "-o", "/proc/head.toml"], ["/proc"]),
    # ---- watch, record, listen (run), replay, tree ------------------------------------------
    ("run-monitor-address", ["run", "{d}/ok.toml", "--monitor", "host:port"], ["host:port"]),
    ("run-monitor-rate", ["run", "{d}/ok.toml", "--monitor", "--monitor-rate", "0"],
     ["--monitor-rate", "0"]),
    ("run-record-without-out", ["run", "{d}/ok.toml", "--record"], ["--record", "--out"]),
    ("run-record-quality", ["run", "{d}/ok.toml", "--out", "{d}/rq", "--record",
                            "--record-quality", "101"], ["--record-quality", "101"]),
    ("run-record-rate-nan", ["run", "{d}/ok.toml", "--out", "{d}/rr", "--record",
                             "--record-rate", "nan"], ["--record-rate", "nan"]),
    ("run-record-rate-inf", ["run", "{d}/ok.toml", "--out", "{d}/rr", "--record",
                             "--record-rate", "inf"], ["--record-rate", "inf"]),
    ("run-calibration-scripts-nul", ["run", "{d}/ok.toml", "--head", "sim", "--calibration",
                                     "{d}/nul_scripts.toml"],
     ["nul_scripts.toml", "head.scripts", "NUL"]),
    ("run-audio-missing", ["run", "{d}/ok.toml", "--audio", "{d}/nope.wav"], ["nope.wav"]),
    ("run-audio-not-wav", ["run", "{d}/ok.toml", "--audio", "{d}/afile"], ["afile"]),
    ("run-mic-missing", ["run", "{d}/ok.toml", "--mic", "no-such-microphone"],
     ["no-such-microphone"]),
    ("replay-missing", ["replay", "{d}/nope"], ["nope", "no such folder"]),
    ("replay-not-a-session", ["replay", "{d}/adir"], ["adir", "trace.jsonl"]),
    ("replay-a-file", ["replay", "{d}/afile"], ["afile"]),
    ("replay-not-mcap", ["replay", "{d}/junk.mcap"], ["junk.mcap", "not an MCAP file"]),
    ("replay-mcap-cut", ["replay", "{d}/cut.mcap"], ["cut.mcap", "cut short"]),
    ("run-camera-not-a-bag", ["run", "{d}/ok.toml", "--camera", "{d}/junk.mcap"],
     ["junk.mcap", "not an MCAP file"]),
    ("run-foxglove-address", ["run", "{d}/ok.toml", "--foxglove", "host:port"],
     ["host:port"]),
    ("perceive-not-a-bag", ["perceive", "{d}/junk.mcap"], ["junk.mcap", "not an MCAP file"]),
    ("perceive-bag-topic", ["perceive", "{d}/junk.mcap:/camera"], ["junk.mcap"]),
    ("migrate-missing", ["migrate", "{d}/nope"], ["nope", "no such folder"]),
    ("report-missing", ["report", "{d}/nope"], ["nope", "not a run folder"]),
    ("migrate-a-file", ["migrate", "{d}/afile"], ["afile"]),
    ("migrate-seconds-nan", ["migrate", "{d}/old_nan"], ["old_nan/session.json", "seconds",
                                                         "NaN"]),
    ("migrate-seconds-1e300", ["migrate", "{d}/old_1e300"],
     ["old_1e300/session.json", "seconds", "1e+300"]),
    ("migrate-seconds-text", ["migrate", "{d}/old_text"], ["old_text/session.json", "'3'"]),
    ("migrate-recorded-1960", ["migrate", "{d}/old_1960"],
     ["old_1960/session.json", "1960-03-02", "outside 1970"]),
    ("migrate-event-without-t", ["migrate", "{d}/old_event"],
     ["old_event/events.jsonl", "event 1 has no t"]),
    ("tree-missing", ["tree", "{d}/nope.pl", "--domain", "{fruits}"], ["nope.pl"]),
    ("tree-no-domain", ["tree", "{d}/afile"], ["domain.pl", "--domain"]),
    ("tree-random-bytes", ["tree", "{d}/random.toml", "--domain", "{fruits}"],
     ["random.toml"]),
    ("tree-format", ["tree", "{d}/afile", "--domain", "{fruits}", "--out", "{d}/t.gif"],
     ["t.gif", "format"]),
    ("tree-out-a-folder-named-svg", ["tree", "{d}/tree-run/policy.pl", "--domain", "{fruits}",
                                     "--out", "{d}/adir.svg"], ["adir.svg", "folder"]),
    ("tree-out-under-a-file", ["tree", "{d}/tree-run/policy.pl", "--domain", "{fruits}",
                               "--out", "{d}/afile/t.svg"], ["afile"]),
    ("tree-out-unwritable", ["tree", "{d}/tree-run/policy.pl", "--domain", "{fruits}",
                             "--out", "/proc/relrl-tree.svg"], ["/proc"]),
    ("examples-copy-file", ["examples", "--copy", "{d}/afile"], ["afile", "not a folder"]),
    # ---- policies: refused whole, naming the file and line (conftest.hostile_policies) ----
    ("tree-policy-id-1e9", ["tree", "{d}/p_id1e9.pl", "--domain", "{fruits}"],
     ["p_id1e9.pl:", "node id 1000000000 is out of range"]),
    ("tree-policy-id-1e40", ["tree", "{d}/p_id1e40.pl", "--domain", "{fruits}"],
     ["p_id1e40.pl:", "is out of range"]),
    ("tree-policy-dangling-branch", ["tree", "{d}/p_dangling.pl", "--domain", "{fruits}"],
     ["p_dangling.pl:", "node 7", "dangling branch"]),
    ("tree-policy-cycle", ["tree", "{d}/p_cycle.pl", "--domain", "{fruits}"],
     ["p_cycle.pl:", "back to the root (a cycle)"]),
    ("shell-policy-q-inf", ["shell", "{fruits}", "--policy", "{d}/p_q_inf.pl"],
     ["p_q_inf.pl:", "1.0Inf is not a finite number"]),
    ("shell-policy-q-400-digits", ["shell", "{fruits}", "--policy", "{d}/p_q_400_digits.pl"],
     ["p_q_400_digits.pl:", "an integer of 401 digits", "out of range"]),
    ("shell-policy-q-rational", ["shell", "{fruits}", "--policy", "{d}/p_q_rational.pl"],
     ["p_q_rational.pl:", "1r3 is a rational number"]),
    ("shell-policy-halt", ["shell", "{fruits}", "--policy", "{d}/p_halt.pl"],
     ["p_halt.pl:", "halt is not a response of this domain"]),
    ("shell-policy-look-var", ["shell", "{fruits}", "--policy", "{d}/p_look_var.pl"],
     ["p_look_var.pl:", "look(_) is not a response of this domain"]),
    ("shell-policy-script", ["shell", "{fruits}", "--policy", "{d}/p_script.pl"],
     ["p_script.pl:", "'<script>' is not a response of this domain"]),
    ("shell-policy-necessity", ["shell", "{fruits}", "--policy", "{d}/p_necessity.pl"],
     ["p_necessity.pl:", "'<script>' is not a necessity of this domain"]),
    ("shell-policy-contingency-halt", ["shell", "{fruits}", "--policy", "{d}/c_halt.pl"],
     ["c_halt.pl:", "halt is not a response of this domain"]),
    ("shell-policy-contingency-inf", ["shell", "{fruits}", "--policy", "{d}/c_inf.pl"],
     ["c_inf.pl:", "1.0Inf is not a finite number"]),
    ("shell-policy-contingency-state", ["shell", "{fruits}", "--policy",
                                        "{d}/c_state_1e40.pl"],
     ["c_state_1e40.pl:", "is not a state of this domain"]),
    ("tree-policy-tg-halt", ["tree", "{d}/t_halt.pl", "--domain", "{fruits}"],
     ["t_halt.pl:", "halt is not a literal of the domain's language bias"]),
    ("tree-policy-tg-id-1e9", ["tree", "{d}/t_id1e9.pl", "--domain", "{fruits}"],
     ["t_id1e9.pl:", "node id 1000000000 is out of range"]),
    ("shell-policy-qtable-inf", ["shell", "{fruits}", "--policy", "{d}/q_inf.npz"],
     ["q_inf.npz", "the Q of", "inf"]),
    ("shell-policy-million-clauses", ["shell", "{fruits}", "--policy", "{d}/p_million.pl"],
     ["p_million.pl", "larger than a policy relrl reads"]),
    ("run-policy-load-cycle", ["run", "{d}/load_cycle.toml", "--out", "{d}/out-cycle"],
     ["p_cycle.pl:", "a cycle"]),
    ("run-policy-load-halt", ["run", "{d}/load_halt.toml", "--out", "{d}/out-halt"],
     ["p_halt.pl:", "halt is not a response"]),
    ("tree-policy-tg-tree-twice", ["tree", "{d}/t_twice.pl", "--domain", "{fruits}"],
     ["t_twice.pl:", "a second tg_tree/1", "the first is on line"]),
    ("shell-policy-latin1-comment", ["shell", "{fruits}", "--policy",
                                     "{d}/p_latin1_comment.pl"],
     ["p_latin1_comment.pl:", "byte 0xe9 is not UTF-8"]),
    ("learn-world-latin1-comment", ["learn", "{d}/w_latin1_comment.pl", "--task", "stack"],
     ["w_latin1_comment.pl:1:", "byte 0xe9 is not UTF-8"]),
    ("shell-policy-dev-zero", ["shell", "{fruits}", "--policy", "/dev/zero"],
     ["/dev/zero", "not a regular file"]),
    ("shell-policy-folder", ["shell", "{fruits}", "--policy", "{d}/adir"],
     ["adir", "a folder, not a policy file"]),
    ("tree-policy-dev-zero", ["tree", "/dev/zero", "--domain", "{fruits}"],
     ["/dev/zero", "not a regular file"]),
    ("learn-policy-folder", LEARN + ["--policy", "{d}/adir"], ["adir", "a folder"]),
    ("run-policy-load-folder", ["run", "{d}/load_dir.toml", "--check"],
     ["load_dir.toml:", "'adir' is a folder"]),
    ("experiment-worlds-task-with-arguments", ["experiment", "worlds", "--worlds", BLOCKS,
                                               "--tasks", "stack,fly(b1,b2)"],
     ["fly(b1,b2)", "no such task"]),
    # ---- TOML nested 3,000 deep, or a device (conftest.hostile_tomls) ----------------------
    ("run-nested-arrays", ["run", "{d}/deep_array.toml"],
     ["deep_array.toml:", "nested more than 32 deep"]),
    ("run-nested-inline-tables", ["run", "{d}/deep_table.toml"],
     ["deep_table.toml:", "nested more than 32 deep"]),
    ("run-dev-zero", ["run", "{d}/dev_zero.toml"], ["dev_zero.toml", "not a regular file"]),
    ("head-calibration-nested-arrays", ["head", "--calibration", "{d}/cal_deep_array.toml",
                                        "status"],
     ["cal_deep_array.toml:", "nested more than 32 deep"]),
    ("head-calibration-nested-tables", ["head", "--calibration", "{d}/cal_deep_table.toml",
                                        "status"],
     ["cal_deep_table.toml:", "nested more than 32 deep"]),
    ("head-calibration-scripts-dev-zero", ["head", "--calibration",
                                           "{d}/cal_scripts_dev_zero.toml", "status"],
     ["cal_scripts_dev_zero.toml", "head.scripts", "/dev/zero", "not a regular file"]),
    ("report-out-unwritable", ["report", "{d}/adir", "--out", "/proc/relrl.md"], ["/proc"]),
    # ---- learn (worlds written in Prolog) ---------------------------------------------------
    ("learn-missing-world", ["learn", "{d}/nope.pl"], ["nope.pl", "no such world file"]),
    ("evaluate-missing-policy", ["evaluate", "{d}/nope.pl", "--world",
                                 BLOCKS, "--task", "stack"],
     ["nope.pl", "no such"]),
    ("evaluate-policy-a-folder", ["evaluate", "{d}/adir", "--world", BLOCKS, "--task", "stack"],
     ["adir", "a folder, not a policy file"]),
    ("evaluate-policy-dev-zero", ["evaluate", "/dev/zero", "--world", BLOCKS, "--task",
                                  "stack"], ["/dev/zero", "not a regular file"]),
    ("learn-world-a-folder", ["learn", "{d}/adir"], ["adir", "no such world file"]),
    ("learn-random-bytes", ["learn", "{d}/random.toml"], ["random.toml"]),
    ("learn-unknown-task", LEARN + ["--task", "fly"], ["fly", "no such task"]),
    ("learn-bad-task-term", LEARN + ["--task", "on(("], ["on((", "not a task term"]),
    ("learn-episodes", LEARN + ["--episodes", "-1"], ["--episodes", "-1"]),
    ("learn-sizes", LEARN + ["--sizes", "3,0"], ["--sizes", "3,0"]),
    ("learn-size-and-sizes", LEARN + ["--size", "3", "--sizes", "4"], ["--size", "--sizes"]),
    ("learn-unknown-learner", LEARN + ["--learner", "etg"], ["etg"]),
    ("learn-unknown-param", LEARN + ["--param", "nope=1"], ["nope"]),
    ("learn-nan-param", LEARN + ["--param", "alpha=nan"], ["alpha", "nan"]),
    ("learn-missing-policy", LEARN + ["--policy", "{d}/nope.pl"], ["nope.pl"]),
    ("learn-out-file", LEARN + ["--out", "{d}/afile"], ["afile", "not a folder"]),
    ("experiment-worlds-missing", ["experiment", "worlds", "--worlds", "{d}/nope.pl"],
     ["nope.pl", "no such world file"]),
    ("experiment-worlds-learner", ["experiment", "worlds", "--worlds", BLOCKS, "--learners",
                                   "etg"], ["etg", "learners of worlds"]),
    ("experiment-worlds-task", ["experiment", "worlds", "--worlds", BLOCKS, "--tasks", "fly"],
     ["fly", "no such task"]),
    # ---- demo ------------------------------------------------------------------------------
    ("demo-out-file", ["demo", "--out", "{d}/afile"], ["afile", "not a folder"]),
    ("demo-out-dev-null", ["demo", "--out", "/dev/null"], ["/dev/null"]),
    ("demo-out-proc", ["demo", "--out", "/proc/foo"], ["/proc/foo"]),
    ("demo-workers", ["demo", "--workers", "0"], ["--workers", "0"]),
    # ---- report ----------------------------------------------------------------------------
    ("report-nothing", ["report"], ["run folders", "--update"]),
    ("report-missing-run", ["report", "{d}/nope"], ["nope", "run folder"]),
    ("report-not-a-run", ["report", "{d}/adir"], ["results.json", "no such file"]),
    ("report-random-bytes", ["report", "{d}/random.toml"], ["random.toml", "run folder"]),
    ("report-missing-markdown", ["report", "--check", "{d}/nope.md"], ["nope.md"]),
    ("report-out-dir", ["report", "{d}/adir", "--out", "{d}/adir"], ["adir"]),
    ("report-no-config", ["report", "{d}/run_no_config"],
     ["run_no_config/results.json", "no config"]),
    ("report-points-a-string", ["report", "{d}/run_points_text"],
     ["run_points_text/results.json", 'config.points is "20" (a string)', "an integer"]),
    ("report-markdown-latin1", ["report", "--check", "{d}/latin1.md"],
     ["latin1.md:3", "byte 0xe9 is not UTF-8"]),
    ("report-markdown-a-folder", ["report", "--update", "{d}/adir"],
     ["adir", "not a regular file"]),
    ("report-key-with-a-newline", ["report", "{d}/run_key_newline"],
     ['summary."etg\\nFAKE LINE".curve is "z"']),
    ("report-results-dev-zero", ["report", "{d}/run_dev_zero"],
     ["run_dev_zero/results.json", "not a regular file"]),
    ("report-unknown-experiment", ["report", "{d}/run_unknown_kind"],
     ["run_unknown_kind/results.json", '"nope"', "not one relrl report renders"]),
    ("report-marker-traversal", ["report", "--check", "{d}/md_traversal.md"],
     ["md_traversal.md:3", "../../../../etc", "leads outside"]),
    ("report-marker-absolute", ["report", "--update", "{d}/md_absolute.md"],
     ["md_absolute.md:3", "'/etc'", "relative path"]),
    ("report-marker-link-out", ["report", "--check", "{d}/md_link.md"],
     ["md_link.md:3", "linked_run", "leads outside"]),
    ("report-marker-results-link-out", ["report", "--check", "{d}/md_results_link.md"],
     ["md_results_link.md:3", "run_results_link/results.json", "leads outside"]),
    ("report-marker-ends-the-comment", ["report", "--check", "{d}/md_space.md"],
     ["md_space.md:3", "a-->b", "cannot be named in a block"]),
    ("report-root-missing", ["report", "--check", "{d}/md_space.md", "--root", "{d}/nope"],
     ["--root", "nope", "no such folder"]),
]


@pytest.mark.parametrize("argv, needles", [c[1:] for c in CASES], ids=[c[0] for c in CASES])
@pytest.mark.slow
def test_bad_input_is_one_line_and_exit_2(capsys, monkeypatch, corpus, argv, needles):
    monkeypatch.setattr(sys, "stdin", io.StringIO(""))  # nothing typed, nothing jogged
    argv = [a.format(d=corpus, fruits=FRUITS) for a in argv]
    needles = [n.format(d=corpus) for n in needles]
    one_line_exit_2(capsys, argv, *needles)


@pytest.mark.slow
def test_report_renders_html_and_markdown_in_a_run_as_text(capsys, corpus):
    """Names and commands from a run are shown as the characters they are: no HTML tag, no
    table column or line of their own, no block end, no link with a scheme."""
    from relrl.report import BLOCK

    assert main(["report", str(corpus / "run_html"), "--out", str(corpus / "html.md")]) == 0
    page = (corpus / "html.md").read_text()
    ours = re.compile(r"<!-- /?relrl-report[^\n]*-->$")
    body = "\n".join(line for line in page.splitlines() if not ours.fullmatch(line))
    assert re.findall(r"(?<!\\)[<>]", body) == [] and "\n# heading" not in page
    assert ("\\<script\\>alert(1)\\</script\\>\\|\\<img src=x onerror=alert(1)\\> "
            "\\# heading") in page
    assert "made by relrl \\`x\\` \\<\\!-- /relrl-report --\\> \\| a \\| on" in page
    assert "](./run_html/f%29%20%21%5Bx%5D%28javascript%3Aalert%281%29.png)" in page
    blocks = list(BLOCK.finditer(page))
    assert [b["view"] for b in blocks] == ["summary", "cost"]
    rows = [line for line in blocks[0]["body"].splitlines() if line.startswith("|")]
    assert any("alert(1)" in line for line in rows)
    assert len({len(re.findall(r"(?<!\\)\|", line)) for line in rows}) == 1  # same columns
    assert all(b["body"].rstrip().endswith(".*") for b in blocks)  # each ends at its own end
    assert main(["report", "--check", str(corpus / "html.md")]) == 0


def _paths(value, path=()):
    """Every key path of a JSON value (a list's first item only)."""
    yield path
    items = (value.items() if isinstance(value, dict)
             else [(0, value[0])] if value and isinstance(value, list) else [])
    for key, inner in items:
        yield from _paths(inner, (*path, key))


@pytest.mark.slow
@pytest.mark.parametrize("name", ["exp1", "exp2", "bench", "worlds", "scaling", "transfer"])
def test_report_on_a_results_json_with_a_key_missing_or_of_another_type(tmp_path, name):
    """Every key of a shipped run's results.json taken out, or made a string, null or a
    list, in turn: each view renders, or says in one line which file and key
    is wrong (the run is checked once, when loaded); never a traceback."""
    import json

    from relrl.errors import UserError
    from relrl.report import VIEWS, load_run, render
    from tests.cli.conftest import small_results

    results = small_results(name)
    whole = json.dumps(results)
    views = [v for kind, v in VIEWS if kind == results["experiment"]]
    refused = 0
    for path in list(_paths(results))[1:]:
        for swap in ("missing", "20", None, []):
            data = json.loads(whole)
            *up, last = path
            parent = data
            for key in up:
                parent = parent[key]
            if swap == "missing":
                if isinstance(parent, list):
                    continue
                del parent[last]
            else:
                parent[last] = swap
            (tmp_path / "results.json").write_text(json.dumps(data))
            try:
                run = load_run(tmp_path)
                for v in views:
                    render(run, v)
            except UserError as exc:
                assert "\n" not in str(exc) and str(exc).startswith(str(tmp_path)), exc
                refused += 1
    assert refused > 0


@pytest.mark.parametrize("name, words", [
    ("t_twice.pl", "a second tg_tree/1 (the first is on line {first})"),
    ("p_latin1_comment.pl", "byte 0xe9 is not UTF-8")])
def test_a_policy_refusal_names_the_line_at_fault(capsys, corpus, name, words):
    """The second tree is the last line of t_twice.pl (the first, the line holding
    ``tg_tree(`` before it); the byte in a comment is on p_latin1_comment.pl's last line."""
    lines = (corpus / name).read_bytes().split(b"\n")[:-1]
    first = next((i for i, x in enumerate(lines, 1) if x.startswith(b"tg_tree(")), 0)
    line = one_line_exit_2(capsys, ["shell", str(FRUITS), "--policy", str(corpus / name)])
    assert f"{corpus / name}:{len(lines)}: {words.format(first=first)}" in line


def test_every_subcommand_is_in_the_corpus():
    from relrl.cli import SUBCOMMANDS

    # check has its own format (one line per problem, then a count): tested below
    assert {c[1][0] for c in CASES} | {"check"} == set(SUBCOMMANDS)


@pytest.mark.parametrize("name, words", [
    ("nope.pl", "no such file"), ("adir", ""), ("random.bin", ""), ("latin1.pl", ""),
    ("afile", ""), ("/dev/null", "")])
def test_check_a_file_that_is_no_domain(capsys, corpus, name, words):
    """``relrl check`` lists every problem, one line each naming the file, then a count."""
    code = main(["check", str(corpus / name)])
    err = capsys.readouterr().err
    assert code == 2 and "Traceback" not in err
    lines = err.splitlines()
    assert lines[-1].endswith(("problem", "problems")) and len(lines) >= 2
    assert all(line.startswith(str(corpus / name)) for line in lines[:-1]), lines
    assert words in lines[0]


def test_an_episode_file_reports_all_its_errors(capsys, corpus):
    assert main(["run", str(corpus / "empty.toml")]) == 2
    err = capsys.readouterr().err.splitlines()
    assert err[0] == f'{corpus}/empty.toml:1: [episode] needs domain = "path/to/domain.pl"'
    assert err[1] == (f"{corpus}/empty.toml:1: the script needs at least one [[phase]] "
                      "with steps = N")
    assert err[2] == f"relrl run: 2 problems in {corpus}/empty.toml" and len(err) == 3


def test_bytes_typed_under_live_that_are_not_utf8_are_skipped(capsys, monkeypatch, corpus):
    typed = io.TextIOWrapper(io.BytesIO(b"\xff\xfe\n apple caf\xc3 Lemon!\n"), encoding="utf-8")
    monkeypatch.setattr(sys, "stdin", typed)
    assert main(["run", str(corpus / "ok.toml"), "--live", "--step-seconds", "0.05"]) == 0
    captured = capsys.readouterr()
    assert "Traceback" not in captured.err and "hear(apple)" in captured.out
    assert "ignored '\ufffd\ufffd'" in captured.err and "ignored 'lemon!'" in captured.err


def test_bytes_piped_into_the_shell_that_are_not_utf8(capsys, monkeypatch):
    piped = io.TextIOWrapper(io.BytesIO(b"response(R).\n\xff\xfe.\n"), encoding="utf-8")
    monkeypatch.setattr(sys, "stdin", piped)
    assert main(["shell", str(FRUITS)]) == 2  # the second query is an error, said in a line
    captured = capsys.readouterr()
    assert "Traceback" not in captured.err + captured.out and "R = look(centre)" in captured.out


def test_an_image_path_that_is_a_device(capsys, tmp_path):
    (tmp_path / "zero.png").symlink_to("/dev/zero")
    one_line_exit_2(capsys, ["perceive", str(tmp_path / "zero.png")], "zero.png",
                    "not a regular file")


@pytest.mark.parametrize("name", ["good_etg.pl", "good_contingency.pl", "good_tg.pl",
                                  "good_qlearning.npz"])
def test_check_a_good_policy(capsys, corpus, name):
    assert main(["check", str(FRUITS), "--policy", str(corpus / name)]) == 0
    assert f"ok: {corpus / name} is a valid" in capsys.readouterr().out


@pytest.mark.parametrize("name, words", [
    ("p_cycle.pl", "back to the root (a cycle)"), ("p_dangling.pl", "dangling branch"),
    ("c_halt.pl", "halt is not a response"), ("t_halt.pl", "halt is not a literal"),
    ("q_inf.npz", "the Q of")])
def test_check_a_policy_that_is_refused(capsys, corpus, name, words):
    """``relrl check --policy`` makes every check a load makes: the problem, then a count."""
    assert main(["check", "-q", str(FRUITS), "--policy", str(corpus / name)]) == 2
    err = capsys.readouterr().err.splitlines()
    assert err[0].startswith(str(corpus / name)) and words in err[0], err
    assert err[1:] == ["1 problem"]


def test_a_refused_policy_is_never_saved_again(capsys, corpus):
    """A cyclic tree is refused before the run starts: nothing learned, nothing re-saved
    (it used to loop until the time limit, then be written back as a partial policy)."""
    out = corpus / "out-cycle-again"
    one_line_exit_2(capsys, ["run", str(corpus / "load_cycle.toml"), "--out", str(out)],
                    "p_cycle.pl:", "a cycle")
    assert not (out / "again.pl").exists() and not (out / "summary.json").exists()


def test_user_clauses_piped_into_the_shell(capfd, monkeypatch):
    """``[user].`` then clauses, piped: loaded as a file named user; a bad clause is one
    line naming user and its line, nothing loaded, exit 2."""
    monkeypatch.setattr(sys, "stdin", io.StringIO("[user].\nok(1).\nend_of_file.\nok(X).\n"))
    assert main(["shell", str(FRUITS)]) == 0
    assert capfd.readouterr().out == "true.\nX = 1.\n"
    monkeypatch.setattr(sys, "stdin", io.StringIO("[user].\nok(1).\nbad(\n"))
    assert main(["shell", str(FRUITS)]) == 2
    captured = capfd.readouterr()
    assert captured.out.startswith("error: user:2: Syntax error")
    assert "iri_scheme" not in captured.err and "Traceback" not in captured.err


def _cases(module: str) -> int:
    """The test cases of a module: its test functions, each parametrization counted."""
    n = 0
    for name, fn in vars(importlib.import_module(module)).items():
        if name.startswith("test_") and callable(fn):
            k = 1
            for mark in getattr(fn, "pytestmark", []):
                if mark.name == "parametrize":
                    k *= len(mark.args[1])
            n += k
    return n


def test_the_corpus_says_how_many_cases_it_holds():
    said = re.search(r"holds (\d+) cases: (\d+) bad inputs in ``CASES`` and (\d+) more tests "
                     r"here, (\d+) in\s+``test_outputs.py``, (\d+) in ``test_nothing_lost.py``",
                     __doc__)
    assert said, "the docstring no longer says how many cases the corpus holds"
    total, cases, here, outputs, lost = map(int, said.groups())
    counted = {"cases": len(CASES), "here": _cases(__name__) - len(CASES),
               "outputs": _cases("tests.cli.test_outputs"),
               "lost": _cases("tests.cli.test_nothing_lost")}
    assert counted == {"cases": cases, "here": here, "outputs": outputs, "lost": lost}
    assert total == sum(counted.values())
