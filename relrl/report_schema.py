"""What ``relrl report`` reads of a run's records, checked once when the run is loaded.

A results.json (and the run's timing.json and ``.relrl-run.json``) is data a user may have
edited, cut or forged. :func:`check` compares it with the shape its experiment's views read
-- the keys, their JSON types, lists that must not be empty, sizes named as integers -- and
raises one :class:`~relrl.errors.UserError` naming the file and the key path
(``results.json: config.points is "20" (a string), expected an integer``), so the views
themselves index without guarding each look-up.

A shape is written as data: a type (``int``, ``float`` for any number, ``str``, ``bool``,
``dict``, ``list``, ``object`` for anything), a dict of keys (``"name?"``: optional; keys not
named are allowed), :class:`ListOf`, :class:`MapOf` (any keys, one shape for their values) or
:class:`Maybe` (that shape, or null).
"""

from __future__ import annotations

import json
import re
from dataclasses import dataclass
from typing import Any

from relrl.errors import UserError

__all__ = ["MANIFEST", "RESULTS", "TIMING", "ListOf", "MapOf", "Maybe", "check", "check_run"]


@dataclass(frozen=True)
class Maybe:
    """``shape``, or null."""

    shape: Any


@dataclass(frozen=True)
class ListOf:
    """A list of ``least`` to ``most`` items, each of ``shape``."""

    shape: Any
    least: int = 0
    most: int | None = None


@dataclass(frozen=True)
class MapOf:
    """An object with any keys (integers written as strings, with ``int_keys``), each value
    of ``shape``."""

    shape: Any
    int_keys: bool = False


_PLAIN_KEY = re.compile(r"[\w<=>.+-]{1,60}")
_NAMES = {int: "an integer", float: "a number", str: "a string", bool: "true or false",
          dict: "an object", list: "a list"}


def _found(value: Any) -> str:
    if value is None:
        return "null"
    kind = _NAMES.get(type(value), type(value).__name__)
    if isinstance(value, (dict, list)):
        return kind
    shown = repr(value) if not isinstance(value, str) else json.dumps(value[:40])
    return f"{shown} ({kind})"


def _expected(shape: Any) -> str:
    if isinstance(shape, Maybe):
        return _expected(shape.shape) + " or null"
    if isinstance(shape, ListOf):
        return "a list" + (f" of at least {shape.least} item(s)" if shape.least else "")
    if isinstance(shape, (MapOf, dict)):
        return "an object"
    return _NAMES.get(shape, "a value")


def _fits(value: Any, kind: type) -> bool:
    if kind is object:
        return True
    if kind is float:
        return isinstance(value, (int, float)) and not isinstance(value, bool)
    if kind is int:
        return isinstance(value, int) and not isinstance(value, bool)
    return isinstance(value, kind)


def _walk(value: Any, shape: Any, path: str, where: str) -> None:
    def wrong() -> UserError:
        return UserError(f"{where}: {path or 'the whole file'} is {_found(value)}, expected "
                         f"{_expected(shape)}")

    if isinstance(shape, Maybe):
        if value is not None:
            _walk(value, shape.shape, path, where)
        return
    if isinstance(shape, dict):
        if not isinstance(value, dict):
            raise wrong()
        for key, inner in shape.items():
            name = key.rstrip("?")
            if name not in value:
                if key.endswith("?"):
                    continue
                raise UserError(f"{where}: no {_join(path, name)} (not written by this "
                                "relrl's experiment, or cut)")
            _walk(value[name], inner, _join(path, name), where)
        return
    if isinstance(shape, MapOf):
        if not isinstance(value, dict):
            raise wrong()
        for key, inner in value.items():
            if shape.int_keys and not key.lstrip("-").isdigit():
                raise UserError(f"{where}: {_join(path, key)}: a size is an integer, not "
                                f"{key[:40]!r}")
            _walk(inner, shape.shape, _join(path, key), where)
        return
    if isinstance(shape, ListOf):
        if not isinstance(value, list):
            raise wrong()
        if len(value) < shape.least or (shape.most is not None and len(value) > shape.most):
            many = (f"{shape.least}" if shape.most == shape.least
                    else f"at least {shape.least}" if shape.most is None
                    else f"{shape.least} to {shape.most}")
            raise UserError(f"{where}: {path} holds {len(value)} item(s), expected {many}")
        for i, item in enumerate(value):
            _walk(item, shape.shape, f"{path}[{i}]", where)
        return
    if not _fits(value, shape):
        raise wrong()


def _join(path: str, key: str) -> str:
    """A key path, a key that is not a plain name written as JSON (so a message stays on
    one line and shows exactly which key)."""
    if not _PLAIN_KEY.fullmatch(key):
        key = json.dumps(key)
    return f"{path}.{key}" if path else key


def check(value: Any, shape: Any, where: str) -> None:
    """Raise a :class:`UserError` naming ``where`` and the key path of the first part of
    ``value`` that does not have ``shape``."""
    _walk(value, shape, "", where)


# ---- the shapes the views read ----------------------------------------------------------

_POINT = {"cgi_mean": float, "cgi_std": Maybe(float)}
_CLAIMS = MapOf({"held": Maybe(bool), "values": MapOf(MapOf(float))})
_SIS = {
    "seeds": ListOf(int),
    "config": {"points": int, "eval_runs": int, "eval_steps": int, "block": int,
               "caregiver": str, "preset?": Maybe(str)},
    "summary": MapOf({"curve": ListOf(_POINT, least=1), "cgi_final": Maybe(float),
                      "cgi_literal_final": Maybe(float),
                      "eye_contacts": {"mean": float, "opportunities": int},
                      "memory": {"positions?": float}, "states_met?": Maybe(float)}),
    "paper?": {"memory_positions?": {"qlearning?": float, "etg?": float}},
    "claims?": Maybe(_CLAIMS),
}
_EXP2 = {
    "summary": MapOf({
        "fig6": ListOf({"units": float, "cgi_mean": float, "cgi_sd_over_seeds": Maybe(float)}),
        "table1": Maybe({"all_executions": Maybe(MapOf(ListOf(float, least=2)))}),
        "confusion?": Maybe(MapOf(MapOf(int)))}),
    "paper?": {"table1?": MapOf(ListOf(float, least=2, most=2))},
}
_RATIO = {"ratio?": float, "ratio_range?": ListOf(float, least=2, most=2)}
_BENCH = {
    "cpus?": Maybe(int),
    "gateway_call_us": float,
    "learners": MapOf({"steps_per_second": float, "gateway_calls_per_step": float,
                       "step_in_gateway_calls?": float}),
    "tg_step_in_etg_steps?": Maybe(float),
    "tg_step_by_size?": {"ratio?": MapOf(float, int_keys=True)},
    "etg_prolog_side?": {"cpu_us_per_step?": float, "inferences_per_step?": float},
    "sis_env_steps_per_second": {"steps_per_second": float},
    "monitor?": _RATIO, "recording?": _RATIO,
    "perception?": {"fps_photos_320x240_cold?": float,
                    "fps_photos_320x240_cold_2threads?": float},
    "targets?": dict,
}
_WORLDS = {
    "seeds": ListOf(int),
    "config": {"episodes": int, "eval_episodes": int, "train_sizes": ListOf(int, least=1),
               "test_sizes": ListOf(int, least=1)},
    "summary": ListOf({"world": str, "task": str, "learner": str, "seeds": int,
                       "train_optimality": float, "train_optimality_min": float,
                       "test": MapOf({"optimality": Maybe(float), "optimality_min?": Maybe(float),
                                      "success_min?": Maybe(float)}, int_keys=True),
                       "episodes_to_095": Maybe(float), "memory_positions": Maybe(float)}),
}
_LEARN = MapOf({"reached": int, "seeds": int, "steps_to_threshold": Maybe(float),
                "cgi_final": Maybe(float), "memory_positions": Maybe(float),
                "candidates_per_leaf?": Maybe(float)}, int_keys=True)
_TRANSFER = MapOf({"seeds": int, "cgi_trained?": Maybe(float), "cgi_unseen?": Maybe(float)},
                  int_keys=True)
_SCALING = {
    "seeds": ListOf(int),
    "config": {"sizes": ListOf(int), "block": int, "eval_runs": int, "eval_steps": int,
               "budget": int, "threshold": float, "transfer?": Maybe(str),
               "transfer_from?": Maybe(int)},
    "summary": {"learn": MapOf(_LEARN), "transfer?": MapOf(_TRANSFER)},
}
#: results.json's shape for each experiment ``relrl report`` renders.
RESULTS: dict[str, Any] = {"sis": _SIS, "exp2": _EXP2, "bench": _BENCH, "worlds": _WORLDS,
                           "scaling": _SCALING}
_MACHINE = {"cpu?": Maybe(str), "machine?": Maybe(str), "arch?": Maybe(str)}
#: what the provenance line reads of results.json besides its experiment's tables.
_PROVENANCE = {"command?": Maybe(str), "partial?": Maybe(bool), "machine_info?": Maybe(_MACHINE)}
#: timing.json (the machine; the worlds' cost by size).
TIMING: dict[str, Any] = {
    "machine_info?": Maybe(_MACHINE), "machine?": Maybe(str),
    "jobs?": ListOf({"step_cost_by_size?": Maybe({
        "clock?": str, "sizes": ListOf(int, least=1), "us_per_step": MapOf(float),
        "cost_ratio": MapOf(float), "size_ratio": MapOf(float), "slope?": Maybe(float),
        "fit_sizes?": ListOf(int), "fit_slope?": Maybe(float)}),
        "greedy_episode_cost_by_size?": Maybe({"clock?": str, "sizes": MapOf({
            "episodes": int, "steps": int, "cpu_ms_per_episode": float,
            "cpu_us_per_step?": Maybe(float)})})}),
}
#: ``.relrl-run.json`` (the command and when it ran).
MANIFEST: dict[str, Any] = {"command?": Maybe(str), "started?": Maybe(str),
                            "ended?": Maybe(str)}


def _has(mapping: dict[str, Any], key: str, path: str, where: str) -> None:
    if key not in mapping:
        raise UserError(f"{where}: no {path}.{key} (every size the run names needs one)")


def _consistent(kind: str, results: dict[str, Any], timing: dict[str, Any],
                where: str, timing_where: str) -> None:
    """What one key says of another: a worlds run's summary has every test size, a cost by
    size has every size it lists, a job with a cost names its world, task and learner."""
    if kind == "worlds":
        for i, row in enumerate(results["summary"]):
            for size in results["config"]["test_sizes"]:
                _has(row["test"], str(size), f"summary[{i}].test", where)
        for i, job in enumerate(timing.get("jobs") or []):
            cost = job.get("step_cost_by_size")
            if not cost:
                continue
            check(job, {"world": str, "task": str, "learner": str, "seed": int,
                        "learning_steps_per_second?": Maybe(float)}, timing_where)
            for size in cost["sizes"]:
                _has(cost["us_per_step"], str(size), f"jobs[{i}].step_cost_by_size.us_per_step",
                     timing_where)
            for key in ("cost_ratio", "size_ratio"):
                _has(cost[key], str(cost["sizes"][-1]), f"jobs[{i}].step_cost_by_size.{key}",
                     timing_where)


def check_run(folder: Any, results: dict[str, Any], timing: dict[str, Any],
              manifest: dict[str, Any]) -> None:
    """Check a run's three records against what the views of its experiment read.

    Raises:
        UserError: an experiment ``relrl report`` does not render, or the first key that is
            missing or of another type, naming the file and the key path.
    """
    where = f"{folder}/results.json"
    kind = results["experiment"]
    if not isinstance(kind, str) or kind not in RESULTS:
        raise UserError(f"{where}: experiment {_found(kind)} is not one relrl report renders "
                        f"(known: {', '.join(sorted(RESULTS))})")
    check(results, {**_PROVENANCE, **RESULTS[kind]}, where)
    check(timing, TIMING, f"{folder}/timing.json")
    check(manifest, MANIFEST, f"{folder}/.relrl-run.json")
    _consistent(kind, results, timing, where, f"{folder}/timing.json")
