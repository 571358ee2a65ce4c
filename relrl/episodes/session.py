"""Running an episode: the learning time line, evaluations, naming, trace, summary, plots.

:func:`run_episode` builds the knowledge base, learner and agent of a script, the world
(:class:`~relrl.episodes.world.EpisodeWorld` on the simulator, or
:class:`~relrl.episodes.devices.DeviceWorld` on a camera and a head) and runs the phases one
time unit at a time. With an output folder it writes, as it goes, ``trace.jsonl`` (one line
per time unit, flushed) and at the end ``summary.json`` (atomic), ``timing.json``, the learned
policy and plots. A stop request (Ctrl-C, SIGTERM, SIGHUP) ends the run after the current time
unit with everything up to it written. Nothing learned is lost on an error either: a lost
serial port or camera, a fault in a domain's rules, a second Ctrl-C -- the summary and the
policy so far are written, marked ``"partial": true``, before the error goes on
(:func:`keep_partial`). Those writes -- the summary, the policy, the timing -- are made whole
while further signals wait (:func:`relrl.outdir.deferred_signals`); only the plots after them
can be cut short by a second Ctrl-C. Every file goes through relrl's one writer
(:mod:`relrl.outdir`): atomic, never through a link, a full disk ending the run with what
fits written.
"""

from __future__ import annotations

import logging
import math
import signal
import sys
import threading
import time
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TextIO

import numpy as np

from relrl.episodes.outputs import RECORDED, RUN_FILES, policy_save_problem
from relrl.episodes.provenance import provenance, session_manifest
from relrl.episodes.recording import SessionTap, write_manifest
from relrl.episodes.script import Episode
from relrl.outdir import check_inside, deferred_signals, write_json_atomic
from relrl.progress import progress
from relrl.terms import format_term

__all__ = ["STOP_SIGNALS", "RunOptions", "StopRequest", "keep_partial", "run_episode",
           "run_outputs"]



#: signals that stop a run after the current time unit (SIGHUP: the terminal was closed).
STOP_SIGNALS = tuple(getattr(signal, name) for name in ("SIGINT", "SIGTERM", "SIGHUP")
                     if hasattr(signal, name))

log = logging.getLogger(__name__)


class StopRequest:
    """A flag set by SIGINT, SIGTERM or SIGHUP (a second SIGINT raises KeyboardInterrupt).

    Args:
        force: whether a second SIGINT raises KeyboardInterrupt (a run whose step may be
            held up in Python); False for a command whose calls into Prolog each signal
            stops by itself (:meth:`relrl.kb.KnowledgeBase.interruptible`): a second Ctrl-C
            then only asks again, and cannot cut the writing of what was learned.

    Attributes:
        requested: a stop was asked for.
        signum: the signal that asked (``None`` when set by code).
    """

    def __init__(self, *, force: bool = True) -> None:
        self.requested = False
        self.signum: int | None = None
        self.force = force

    def __call__(self) -> bool:
        return self.requested

    @contextmanager
    def installed(self):
        """Catch the :data:`STOP_SIGNALS` while the block runs (main thread only)."""
        if threading.current_thread() is not threading.main_thread():
            yield self
            return

        def handler(signum: int, frame: Any) -> None:
            if self.requested and signum == signal.SIGINT and self.force:
                raise KeyboardInterrupt
            self.requested = True
            self.signum = self.signum or signum

        old = {s: signal.signal(s, handler) for s in STOP_SIGNALS}
        try:
            yield self
        finally:
            for s, h in old.items():
                signal.signal(s, h)


@dataclass
class RunOptions:
    """How to run an episode (the ``relrl run`` flags).

    Attributes:
        out: output folder (``None``: nothing written).
        head: head port (``sim``, a serial device, a pyserial URL) or ``None``.
        protocol: head protocol name.
        calibration: the head's calibration file (default: the shipped example).
        camera: camera source (perception's ``open_camera``) or ``None`` for the simulator.
        live: print what the robot perceives, wants and does; read typed words.
        step_seconds: pause per time unit (a live session on the simulator is slowed down so
            a person can follow and type).
        stream: where the live view goes.
        words: a source of typed/recognised words: a :class:`relrl.listen.WordSource`
            (``poll()`` once per time unit) or a queue (``get_nowait()``), or ``None``.
        plots: write PNG plots (needs matplotlib).
        monitor: the live monitor's :class:`relrl.monitor.Hub`, or ``None``.
        recorder: a :class:`relrl.recording.recorder.Recorder` serving Foxglove, or ``None``.
        live_rate: time units sent to Foxglove per second at most, when not recording.
        record: record the session into ``out/session.mcap`` (:mod:`.recording`).
        record_rate: recorded frames per second at most (0: every time unit).
        record_quality: JPEG quality of recorded frames.
        timeout: seconds one control step (one gateway call) may run before the run stops
            naming the rule (the robot's 10 s; batch sweeps on a loaded machine need more).
    """

    out: Path | None = None
    head: str | None = None
    protocol: str | None = None
    calibration: str | None = None
    camera: str | None = None
    live: bool = False
    step_seconds: float = 0.0
    stream: TextIO = field(default_factory=lambda: sys.stdout)
    words: Any = None
    plots: bool = True
    monitor: Any = None
    recorder: Any = None
    live_rate: float = 10.0
    record: bool = False
    record_rate: float = 10.0
    record_quality: int = 85
    timeout: float = 10.0


def run_outputs(episode: Episode, record: bool = False) -> list[str]:
    """The files and folders a session of ``episode`` writes (checked when ``--out`` is
    claimed, before the run)."""
    names = [n for n in RUN_FILES if record or n not in RECORDED]
    if episode.policy_save:
        names.append(episode.policy_save)
    return names


def _json_num(x: float) -> float | None:
    return None if isinstance(x, float) and math.isnan(x) else x


class _Run:
    """The state of one episode run."""

    def __init__(self, episode: Episode, opts: RunOptions) -> None:
        from relrl.experiments.exp2.measures import Naming
        from relrl.kb import KnowledgeBase
        from relrl.learners import make_learner
        from relrl.loop import Agent
        from relrl.sim.metrics import GazeMetrics
        from relrl.speech import Speaker

        self.episode, self.opts = episode, opts
        self.kb = KnowledgeBase(episode.domain, timeout=opts.timeout)
        self.learner = make_learner(episode.learner, **episode.learner_params)
        self.agent = Agent(self.kb, self.learner, seed=episode.seed)
        if episode.policy_load is not None:
            self.learner.load(episode.policy_load)
        self.metrics = GazeMetrics(hold=episode.caregiver.get("contact_hold", 3))
        vocab = {episode.word_for(k) for k in episode.fruits}
        self.naming = Naming(vocab, (episode.naming or {}).get("confident_after", 3))
        self.speaker = Speaker(episode.speech.get("voice", "en"),
                               aloud=bool(episode.speech.get("say")),
                               stream=opts.stream if opts.live else None)
        self.rewards: list[float] = []
        self.phase_stats: dict[str, dict[str, Any]] = {}
        self.curve: list[dict[str, Any]] = []
        self.executions: list[dict[str, Any]] = []
        self.t = 0
        self.done = 0  # control steps of learning finished (traced)
        self.units = 0  # learning time units finished
        self.in_view = None
        self.tap: Any = None
        self.saved: dict[str, Any] | None = None  # the summary, once it is written

    def close(self) -> None:
        self.kb.close()


def _live_line(t: int, phase: str, record: Any, outcome: str | None, said: str | None) -> str:
    out = record.out
    wants = (f"{out.necessity} ({out.outputs.get(out.necessity, 0.0):.2f})"
             if out.necessity != "none" else
             "nothing (" + ", ".join(f"{k} {v:.2f}" for k, v in out.outputs.items()) + ")")
    does = format_term(out.action) if out.action is not None else "nothing"
    text = (f"t={t:<4d} [{phase}] perceives: "
            f"{', '.join(format_term(p) for p in record.percepts)}\n"
            f"       wants: {wants}  does: {does}  reward {out.reward:+.0f}")
    if said:
        text += f'  says: "{said}"'
    if outcome:
        text += f"  naming: {outcome}"
    return text


def _status(opts: RunOptions, activity: str, detail: str = "", **data: Any) -> None:
    """Tell the live monitor what the session is doing now (nothing without a monitor)."""
    if opts.monitor is not None:
        opts.monitor.status(activity, detail, **data)


def _on_step(run: _Run, record: Any, phase: str) -> None:
    """Naming, metrics, the trace and the monitor (:class:`SessionTap`), live output."""
    info = record.info
    said = None
    if record.out.action == "name_object":
        said = run.naming.point(run.in_view)
        run.speaker.say(said)
    outcome = run.naming.hear(info["words"], info.get("features"))
    run.in_view = info.get("features")
    run.metrics.add(info["record"])
    run.rewards.append(float(record.out.reward))
    stats = run.phase_stats.setdefault(phase, {"steps": 0, "reward": 0.0, "attention": 0})
    stats["steps"] += 1
    stats["reward"] += float(record.out.reward)
    stats["attention"] += int(info["record"].attention)
    traced = run.tap.traced
    try:
        run.tap.step(record, phase, outcome=outcome, said=said)
    except BaseException:
        if run.tap.traced > traced:  # its trace line was written before the recording or
            run.done += 1            # the monitor failed: the step is the trace's
        raise
    run.done += 1  # traced: a step whose trace line could not be written is not counted
    if run.opts.live:
        print(_live_line(run.t, phase, record, outcome, said), file=run.opts.stream,
              flush=True)


def _pull_words(run: _Run, env: Any) -> None:
    """Words heard in this time unit (typed, recognised from the microphone or a file)."""
    source = run.opts.words
    if source is None:
        return
    if hasattr(source, "poll"):  # a relrl.listen.WordSource
        words = source.poll()
    else:  # a queue of words (get_nowait)
        import queue

        words = []
        while True:
            try:
                words.append(source.get_nowait())
            except queue.Empty:
                break
    for word in words:
        if word:
            env.hear(word)


def run_episode(episode: Episode, opts: RunOptions | None = None,
                stop: StopRequest | None = None) -> dict[str, Any]:
    """Run an episode; returns the summary (also written to ``out/summary.json``).

    Raises:
        UserError: a bad device, domain or policy.
    """
    from relrl.episodes.devices import RecordingEnded
    from relrl.errors import ConfigError
    from relrl.experiments.exp2 import measures
    from relrl.loop import Interaction

    opts = opts or RunOptions()
    stop = stop or StopRequest()
    out = opts.out
    if episode.policy_save and (problem := policy_save_problem(episode.policy_save)):
        raise ConfigError(f"{episode.path}: {problem}")
    t0 = time.perf_counter()
    _status(opts, "starting", f"loading the domain {Path(episode.domain).name} and building "
                              "the world")
    run = _Run(episode, opts)
    where = provenance(opts)
    unit_name = f"{episode.time_unit}s"
    env = actuator = None
    bar = None
    failed = False
    try:
        if opts.camera is not None:
            _status(opts, "waiting for the camera", f"opening camera {opts.camera}: the "
                    "session starts with its first frame")
        env, actuator = _world(episode, opts)
        run.tap = SessionTap(run, out, env, getattr(actuator, "head", None), hub=opts.monitor,
                             record=opts.record, record_rate=opts.record_rate,
                             record_quality=opts.record_quality, recorder=opts.recorder,
                             live_rate=opts.live_rate)
        phase_name = episode.phase_at(1).name
        interaction = Interaction(env, run.agent, actuator=actuator,
                                  on_step=lambda r: _on_step(run, r, phase_name))
        info = interaction.reset(seed=episode.seed)
        run.tap.start()
        run.in_view = info.get("features")
        ev = episode.evaluation
        eval_seeds = [int(s) for s in np.random.SeedSequence([episode.seed, 2])
                      .generate_state(ev["runs"])] if ev else []
        bar = progress(episode.steps, f"{episode.name}", unit="unit",
                       enabled=not opts.live)

        def evaluate() -> None:
            first = run.units == 0
            activity = "initial evaluation" if first else "evaluating"
            detail = (("the robot before any learning" if first else
                       f"after {run.units} {unit_name} of learning (paused meanwhile)")
                      + f": {len(eval_seeds)} runs of {ev['steps']} {unit_name} without "
                        f"learning, on the {where['evaluation']}")
            point = measures.evaluate_cgi(
                run.agent, episode, eval_seeds, stop,
                on_run=lambda k: _status(opts, activity, detail, done=k,
                                         total=len(eval_seeds)))
            point["units"], point["control_steps_learning"] = run.units, run.t
            point["on"] = where["evaluation"]
            _flag_cut_short(point, "cgi_runs", len(eval_seeds))
            run.curve.append(point)
            run.tap.event("evaluation", cgi_mean=point["cgi_mean"], cgi_std=point["cgi_std"],
                          on=where["evaluation"], units=run.units)
            line = (f"evaluation{where['evaluation_label']} after {run.units} "
                    f"{episode.time_unit}s: CGI "
                    f"{point['cgi_mean']:.3f} +- {point['cgi_std']:.3f}")
            if opts.live:
                print(line, file=opts.stream, flush=True)
            log.info(line)
            # learning resumes where it stopped: the world keeps its time line (and phase)

        cycles = episode.time_unit == "interaction"
        bound = measures.unit_bound(episode) if cycles else 1
        shown = None  # the phase the monitor's status line names
        ended: dict[str, Any] | None = None  # where a bag as the camera ended
        for unit in range(1, episode.steps + 1):
            if stop() or ended:
                break
            if ev and (unit - 1) % ev["every"] == 0:
                evaluate()
                shown = None
            phase = episode.phase_at(unit)
            phase_name = phase.name
            if phase is not shown:
                shown = phase
                _status(opts, "learning" if phase.learning else "acting",
                        f"phase {phase.name!r} ({phase.steps} {unit_name}"
                        + ("" if phase.learning else ", without learning") + ")",
                        phase=phase.name, steps=episode.steps)
            for _ in range(bound):   # one time unit: a control step, or a whole cycle
                if stop():
                    break
                _pull_words(run, env)
                run.t += 1
                try:
                    interaction.run(1, learning=phase.learning, keep=False,
                                    want=run.tap.want())
                except RecordingEnded as end:  # a bag as the camera: its end is the session's
                    run.t, ended = run.done, {"t": run.units, "seconds": round(end.seconds, 3)}
                    break
                if opts.step_seconds:
                    time.sleep(opts.step_seconds)
                if not cycles or env.units_done >= unit:
                    break
            if not stop() and not ended:
                run.units = unit
                bar.update(1)
        bar.close()
        if ended:  # the policy as learned when the recording ended, unless just evaluated
            last = not (run.curve and run.curve[-1]["units"] == run.units)
        else:
            last = episode.steps % ev["every"] == 0 if ev else False
        if ev and not stop() and last:
            evaluate()
        if episode.naming and not stop():
            bar = progress(episode.naming["executions"], "naming executions",
                           unit="execution", enabled=not opts.live)
            for k in range(episode.naming["executions"]):
                if stop():
                    break
                _status(opts, "naming", "declarative pointing: the robot points at a fruit "
                        "and names it, and keeps learning; execution "
                        f"{k + 1} of {episode.naming['executions']}, on the "
                        f"{where['naming']}", done=k, total=episode.naming["executions"])
                res = measures.naming_execution(run.agent, episode, episode.seed * 1000 + k,
                                              stop=stop)
                res["on"] = where["naming"]
                if stop():
                    res["interrupted"] = True  # kept, flagged, left out of the rates
                run.executions.append(res)
                run.tap.event("naming", execution=k + 1, counts=res["counts"],
                              on=where["naming"])
                line = (f"naming execution {k + 1}{where['naming_label']}: {res['counts']} "
                        f"({res['presentations']} presentations)")
                if opts.live:
                    print(line, file=opts.stream, flush=True)
                log.info(line)
                bar.update(1)
            bar.close()
        _status(opts, "stopped" if stop() else "finished",
                (f"stopped by {_signal_name(stop)}" if stop() else
                 "the recording (the camera) ended" if ended else "the session ended")
                + f" after {run.units} of {episode.steps} {unit_name}"
                + (f"; writing the summary and the policy to {out}" if out is not None
                   else ""))
        recorded = run.tap.finish()
        summary = _summary(run, stopped=stop(), why=_signal_name(stop), ended=ended)
        summary["where"] = {k: v for k, v in where.items() if not k.endswith("_label")}
        timing = {"seconds": time.perf_counter() - t0, "learning_steps": run.t,
                  "evaluation_steps": sum(p["control_steps"] for p in run.curve),
                  "naming_steps": sum(e["steps"] for e in run.executions)}
        if out is not None:
            manifest = None
            if opts.record:
                def manifest() -> None:
                    data = session_manifest(run, opts, summary, timing, recorded)
                    write_manifest(out, data)
                    run.tap.close(data, summary)  # both also inside the recording
            _write_outputs(run, out, summary, timing, manifest)
        return summary
    except BaseException as exc:  # a lost device, a fault, a full disk, a second Ctrl-C
        failed = True
        _status(opts, "stopped", f"stopped by {type(exc).__name__}"
                + (f": {str(exc).splitlines()[0]}" if str(exc) else ""))
        if out is not None and not run.saved:
            keep_partial(run, out, t0, exc)
        elif out is not None:  # stopped while drawing the plots: the rest is written
            exc.kept = (f"summary.json{_policy_note(run.saved)} written to "  # type: ignore
                        f"{out}")
        raise
    finally:
        if bar is not None:
            bar.close()
        try:
            if getattr(run, "tap", None) is not None:
                _close_tap(run.tap, quiet=failed)
            _release(actuator, env, quiet=failed)
        finally:
            run.close()


def _close_tap(tap: SessionTap, *, quiet: bool) -> None:
    """Close the trace and the recording. After an error (``quiet``) an error of closing them
    -- the recording's process stopped by the same full disk, say -- goes to the run's log
    file only, not the console: the user reads one line, the first error with what was kept,
    whichever of the session and the recording's process noticed the full disk first."""
    if not quiet:
        tap.close()
        return
    try:
        tap.close()
    except Exception as exc:  # noqa: BLE001 - the session already failed; report that one
        log.debug("closing the session's outputs after the error: %s", exc)


def _release(*things: Any, quiet: bool) -> None:
    """Close the head and the camera (each, even when one fails). After an error (``quiet``)
    their errors are dropped: a lost port cannot centre the head, and the first error is
    the one to report."""
    from relrl.errors import USER_ERRORS

    first: Exception | None = None
    for thing in things:
        if thing is None:
            continue
        try:
            thing.close()
        except USER_ERRORS as exc:
            first = first or exc
    if first is not None and not quiet:
        raise first


def _world(episode: Episode, opts: RunOptions) -> tuple[Any, Any]:
    from relrl.episodes.devices import DeviceWorld, HeadActuator
    from relrl.errors import ConfigError

    if opts.camera is not None and episode.time_unit != "step":
        raise ConfigError(f"{episode.path}: time_unit = {episode.time_unit!r} counts the "
                          "simulated caregiver's cycles; on a camera use time_unit = \"step\"")
    actuator = None
    if opts.head is not None:
        from head import open_head

        actuator = HeadActuator(open_head(opts.head, opts.protocol, opts.calibration))
    if opts.camera is not None:
        from perception import open_camera

        return DeviceWorld(episode, open_camera(opts.camera), actuator), actuator
    from relrl.episodes.world import EpisodeWorld

    return EpisodeWorld(episode), actuator


def _signal_name(stop: StopRequest) -> str | None:
    if not stop():
        return None
    return signal.Signals(stop.signum).name if stop.signum else "stop request"


def _flag_cut_short(point: dict[str, Any], runs_key: str, planned: int) -> None:
    """Mark an evaluation point that a stop request cut short (kept, never silently)."""
    done = len(point[runs_key])
    point["runs"] = {"done": done, "planned": planned}
    point["interrupted"] = done < planned


def _summary(run: _Run, *, stopped: bool, why: str | None = None,
             ended: dict[str, Any] | None = None) -> dict[str, Any]:
    """The summary; ``ended`` is where a recording as the camera ended (``{"t", "seconds"}``):
    the session's normal end, so the summary is not partial for the time units it lacked."""
    from relrl.experiments.exp2 import measures

    m = run.metrics
    c = m.cgi()
    e = m.eye_contacts()
    ep = run.episode
    summary: dict[str, Any] = {
        "episode": ep.name, "script": str(ep.path), "seed": ep.seed,
        "learner": {"name": ep.learner, "params": run.learner.params},
        "time_unit": ep.time_unit, "units": run.units, "steps": run.t,
        "planned_steps": ep.steps, "stopped_early": stopped,
        "partial": stopped or (run.units < ep.steps and not ended), "stopped_by": why,
        "cgi": _json_num(c.value), "correct_shifts": c.correct, "shifts": c.shifts,
        "eye_contacts": e.established, "opportunities": e.opportunities,
        "mutual_gaze_events": m.mutual_gaze_events,
        "rewards": {"total": float(sum(run.rewards)),
                    "mean": float(np.mean(run.rewards)) if run.rewards else 0.0},
        "phases": run.phase_stats,
        "naming": {"outcomes": run.naming.counts(), "presentations": len(run.naming.outcomes)},
        "memory": _memory(run),
    }
    if ended:
        summary["recording_ended"] = ended
    if run.curve:
        summary["evaluation"] = run.curve
    if run.executions:
        summary["table1"] = measures.table1(run.executions)
    return summary


def _memory(run: _Run) -> dict[str, Any]:
    from relrl.errors import RelrlError

    try:
        return run.learner.size()
    except RelrlError as exc:  # the knowledge base failed: the summary is still written
        return {"error": str(exc)}


def keep_partial(run: _Run, out: Path, t0: float, exc: BaseException) -> None:
    """Write the summary and the policy learned so far, marked partial, after ``exc`` ended
    the run early; ``exc.kept`` then says what was written (the command line adds it to
    its one-line message). Never raises: the original error is what the user must see (a
    further Ctrl-C waits until the writes are done)."""
    ep = run.episode
    run.t = min(run.t, run.done)  # the time unit in progress did not finish
    try:
        summary = _summary(run, stopped=True, why=type(exc).__name__)
        summary["error"] = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        _write_outputs(run, out, summary, {"seconds": time.perf_counter() - t0,
                                           "learning_steps": run.t}, plots=False)
    except BaseException as inner:  # whatever it is, the first error is the one that goes on
        if run.saved:  # only the plots were cut short
            summary = run.saved
        else:
            exc.kept = f"nothing could be written to {out} ({inner})"  # type: ignore
            return
    exc.kept = (f"learned up to time unit {run.units} of {ep.steps}: summary.json"  # type: ignore
                f"{_policy_note(summary)} written to {out} (partial)")


def _policy_note(summary: Any) -> str:
    if isinstance(summary, dict) and "policy" in summary:
        return f" and {summary['policy']}"
    return ""


def _write_outputs(run: _Run, out: Path, summary: dict[str, Any], timing: dict[str, Any],
                   manifest: Any = None, *, plots: bool = True) -> None:
    """The summary, the policy, the timing (and ``manifest()``, session.json) -- whole, while
    signals wait -- then the plots. The summary goes first: on a full disk it is what the
    space held back is for; a policy that cannot be written is then named in it."""
    from relrl.errors import RelrlError

    ep = run.episode
    with deferred_signals():
        if ep.policy_save:
            summary["policy"] = ep.policy_save
        write_json_atomic(out / "summary.json", summary)
        if ep.policy_save:
            try:
                check_inside(out, ep.policy_save)  # (a claimed folder checks it again)
                run.learner.save(out / ep.policy_save,
                                 f"relrl policy: {ep.learner} learner, episode {ep.name}, "
                                 f"seed {ep.seed}, {run.units} time units ({ep.time_unit}s), "
                                 f"{run.t} control steps"
                                 + (" (partial)" if summary.get("partial") else ""))
            except RelrlError as exc:  # the summary says why, and the run ends with it
                del summary["policy"]
                summary["policy_error"] = f"{ep.policy_save}: {exc}"
                write_json_atomic(out / "summary.json", summary)
        write_json_atomic(out / "timing.json", timing)
        if manifest is not None:
            manifest()
        run.saved = summary
    if plots and run.opts.plots:
        from relrl.episodes.plots import plot_episode

        plot_episode(out, summary, run.rewards)
