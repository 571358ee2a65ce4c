"""``relrl run EPISODE``: run a scripted interaction episode on the simulator or on devices."""

from __future__ import annotations

import argparse
import math
import sys

from relrl.cli.session_flags import add_session_arguments, session_options
from relrl.outdir import add_out_options

HELP = "run a scripted interaction episode (simulator by default, or camera and head)"
EXAMPLE = "relrl run examples/episodes/experiment2.toml --out runs/exp2"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Declare the options of ``relrl run``."""
    parser.add_argument("episode", help="episode script (.toml)")
    add_out_options(parser, default=None,
                    what="output folder: trace.jsonl, summary.json, policy, plots")
    parser.add_argument("--head", default=None, metavar="PORT",
                        help="drive a head: sim, /dev/ttyUSB0, loop://, socket://HOST:PORT")
    parser.add_argument("--protocol", default=None, help="head protocol (ssc32, maestro, ...)")
    parser.add_argument("--calibration", default=None, metavar="FILE",
                        help="the head's calibration TOML (default: examples/heads/wha8030.toml)")
    parser.add_argument("--camera", default=None, metavar="SRC",
                        help="perceive from a camera: 0, video, folder, a bag (BAG.mcap, "
                             "BAG.db3, a rosbag2 folder; [:TOPIC]), synthetic://...")
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
    add_session_arguments(parser)


def run(args: argparse.Namespace) -> int:
    """Check the script, run it, print the summary; 128 + N when stopped by signal N."""
    from relrl.episodes import RunOptions, StopRequest, load_episode
    from relrl.errors import ConfigError, OutputError

    episode = load_episode(args.episode)
    if args.seed is not None:
        if args.seed < 0:
            raise ConfigError(f"--seed must be an integer >= 0, not {args.seed}")
        episode.seed = args.seed
    if args.check:
        print(f"{args.episode}: ok - {episode.name}: {len(episode.phases)} phases, "
              f"{episode.steps} time units ({episode.time_unit}s), {len(episode.events)} events, "
              f"learner {episode.learner} {episode.learner_params}, domain "
              f"{episode.domain.name}")
        return 0
    if args.protocol and not args.head:
        raise ConfigError("--protocol needs --head PORT")
    if args.calibration and not args.head:
        raise ConfigError("--calibration needs --head PORT")
    step = args.step_seconds
    if step is None:
        step = 0.5 if args.live and args.camera is None else 0.0
    if not (math.isfinite(step) and 0 <= step <= 60):
        raise ConfigError(f"--step-seconds must be a number of seconds from 0 to 60, not "
                          f"{step}")
    opts = RunOptions(head=args.head, protocol=args.protocol, calibration=args.calibration,
                      camera=args.camera, live=args.live, step_seconds=step,
                      plots=not args.no_plots)
    stop = StopRequest()
    with session_options(args, episode, opts) as session:  # monitor, recording, words
        # the stop signals are caught from the claim of --out to its record: a signal at
        # any moment ends the run with its outputs and the record written
        with stop.installed():
            summary = _claim_and_run(args, episode, opts, stop, session)
        print(_report(summary))
        if "recording_ended" in summary:
            print(_recording_ended(summary))
        if args.out:
            print(_wrote(args.out, summary.get("written", [])))
        if "policy_error" in summary:  # the run's product is missing: not a success
            raise OutputError(f"the policy was not saved: {summary['policy_error']} (the "
                              f"summary and the trace are in {args.out})")
        if summary["stopped_early"]:
            print(f"stopped after time unit {summary['units']} of {summary['planned_steps']}"
                  f"{' by ' + summary['stopped_by'] if summary['stopped_by'] else ''}; "
                  "everything up to it is written", file=sys.stderr)
            return 128 + (stop.signum or 2)
        session.hold()
    return 0


def _claim_and_run(args, episode, opts, stop, session) -> dict:
    """Claim --out (when given) and run the episode into it."""
    if args.out is None:
        return _run(episode, opts, stop)
    from relrl.episodes.session import run_outputs
    from relrl.outdir import OutDir

    with OutDir.claim(args.out, command=args.command_line, overwrite=args.overwrite,
                      outputs=run_outputs(episode, args.record)) as out:
        opts.out = out.path
        session.log_to(out.path / "run.log")
        summary = _run(episode, opts, stop)
        if not summary["partial"] and "policy_error" not in summary:
            out.status = "complete"
        written = out.written
    return {**summary, "written": written}


def _wrote(folder: str, files: list[str]) -> str:
    """``wrote 5 files to runs/x: summary.json, trace.jsonl, ...`` (the most telling first)."""
    first = ("summary.json", "trace.jsonl", "session.mcap")
    ordered = [f for f in first if f in files] + [f for f in files if f not in first]
    return f"wrote {len(files)} file{'s' * (len(files) != 1)} to {folder}: " + \
        ", ".join(ordered)


def _run(episode, opts, stop) -> dict:
    """Run the episode; a user's error ends with one line that says what was kept."""
    from relrl.episodes import run_episode
    from relrl.errors import USER_ERRORS, UserError

    try:
        return run_episode(episode, opts, stop)
    except USER_ERRORS as exc:
        kept = getattr(exc, "kept", None)
        if kept is None:
            raise
        raise UserError(f"{exc}; {kept}") from None


def _recording_ended(s: dict) -> str:
    """The line of a session whose camera was a recording that ended (a normal end)."""
    end = s["recording_ended"]
    line = f"the recording ended at t = {end['t']} ({end['seconds']:.2f} s into it)"
    if end["t"] < s["planned_steps"]:
        line += (f": the episode asked for {s['planned_steps']} time units, the recording held "
                 f"{end['t']} at the robot's pace")
    return line


def _report(s: dict) -> str:
    from relrl.experiments.exp2.measures import report_lines

    cgi = "n/a" if s["cgi"] is None else f"{s['cgi']:.3f}"
    head = (f"{s['episode']}: {s['units']} time units ({s['time_unit']}s, {s['steps']} control "
            f"steps), CGI {cgi} ({s['correct_shifts']}/{s['shifts']} shifts), eye contacts "
            f"{s['eye_contacts']}/{s['opportunities']}, reward {s['rewards']['total']:+.0f}")
    return "\n".join([head] + report_lines(s))
