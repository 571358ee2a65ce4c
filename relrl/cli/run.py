"""``relrl run EPISODE``: run a scripted interaction episode on the simulator or on devices."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

HELP = "run a scripted interaction episode (simulator by default, or camera and head)"
EXAMPLE = "relrl run examples/episodes/experiment2.toml --out runs/exp2"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Declare the options of ``relrl run``."""
    parser.add_argument("episode", help="episode script (.toml)")
    parser.add_argument("--out", default=None,
                        help="output folder: trace.jsonl, summary.json, policy, plots")
    parser.add_argument("--head", default=None, metavar="PORT",
                        help="drive a head: sim, /dev/ttyUSB0, loop://, socket://HOST:PORT")
    parser.add_argument("--protocol", default=None, help="head protocol (ssc32, maestro, ...)")
    parser.add_argument("--camera", default=None, metavar="SRC",
                        help="perceive from a camera: 0, video, folder, synthetic://...")
    parser.add_argument("--live", action="store_true",
                        help="print what the robot perceives, wants and does; type words "
                             "to be heard as hear(Word)")
    parser.add_argument("--step-seconds", type=float, default=None,
                        help="pause per time unit (default 0.5 with --live on the simulator, "
                             "else 0)")
    parser.add_argument("--seed", type=int, default=None, help="override the script's seed")
    parser.add_argument("--no-plots", action="store_true", help="do not write PNG plots")
    parser.add_argument("--check", action="store_true",
                        help="only check the script and print what it would run")


def _reader(queue) -> None:
    for line in sys.stdin:
        for word in line.strip().lower().split():
            queue.put(word)


def run(args: argparse.Namespace) -> int:
    """Check the script, run it, print the summary; 130 when stopped by Ctrl-C."""
    import queue
    import threading

    from relrl.episodes import RunOptions, StopRequest, load_episode, run_episode
    from relrl.errors import ConfigError

    episode = load_episode(args.episode)
    if args.seed is not None:
        episode.seed = args.seed
    if args.check:
        print(f"{args.episode}: ok - {episode.name}: {len(episode.phases)} phases, "
              f"{episode.steps} time units ({episode.time_unit}s), {len(episode.events)} events, "
              f"learner {episode.learner} {episode.learner_params}, domain "
              f"{episode.domain.name}")
        return 0
    if args.protocol and not args.head:
        raise ConfigError("--protocol needs --head PORT")
    step = args.step_seconds
    if step is None:
        step = 0.5 if args.live and args.camera is None else 0.0
    if step < 0:
        raise ConfigError(f"--step-seconds must be >= 0, not {step}")
    words = None
    if args.live:
        words = queue.Queue()
        threading.Thread(target=_reader, args=(words,), daemon=True).start()
        print("live session: type words (e.g. apple, attention) and Enter; Ctrl-C stops",
              flush=True)
    opts = RunOptions(out=Path(args.out) if args.out else None, head=args.head,
                      protocol=args.protocol, camera=args.camera, live=args.live,
                      step_seconds=step, words=words, plots=not args.no_plots)
    stop = StopRequest()
    with stop.installed():
        summary = run_episode(episode, opts, stop)
    print(_report(summary))
    if args.out:
        policy = f", {summary['policy']}" if "policy" in summary else ""
        print(f"wrote {args.out}/trace.jsonl, summary.json{policy}")
    if summary["stopped_early"]:
        print(f"stopped after time unit {summary['units']} of {summary['planned_steps']}; "
              "everything up to it is written", file=sys.stderr)
        return 130
    return 0


def _report(s: dict) -> str:
    from relrl.experiments.fruits import report_lines

    cgi = "n/a" if s["cgi"] is None else f"{s['cgi']:.3f}"
    head = (f"{s['episode']}: {s['units']} time units ({s['time_unit']}s, {s['steps']} control "
            f"steps), CGI {cgi} ({s['correct_shifts']}/{s['shifts']} shifts), eye contacts "
            f"{s['eye_contacts']}/{s['opportunities']}, reward {s['rewards']['total']:+.0f}")
    return "\n".join([head] + report_lines(s))
