"""``relrl experiment sis|scaling --config RESULTS.json``: a recorded configuration run again.

A run's ``results.json`` records its full configuration (``"config"``); given to ``--config``
(the whole results.json, or the configuration object alone), it is the starting point of the
new run, and the options given beside it override what it records -- the record stands in
for the defaults, never for what is typed. With no option beside it the configuration is the
recorded one, field for field, and the same seeds give the same results.json, byte for byte.

``--preset NAME`` with ``--config``: the record's configuration in that preset's setting.
The preset replaces the recorded setting -- the caregiver model, the preset's caregiver and
learner parameters (the earlier preset's, when the record had one, are taken out first) --
and keeps the rest (learners, seeds, points, runs, parameters given on the earlier command
line); options typed beside both override them too. ``--quick`` cannot be combined with
``--config`` (the record says how long the run is).

Everything a user can get wrong is one line and exit 2: no such file, not JSON, the results
of another experiment, a field this relrl does not know (a record from another version), a
field whose value is not of the setting's type (``"points": "20"``, ``2.5`` or ``true``:
JSON's true is no number of points, though Python's bool is an int).
A record written by another relrl version, or whose caregiver resolves to other parameters
here, is run with a warning that the numbers may differ.
"""

from __future__ import annotations

import argparse
import json
import logging
import shlex
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from relrl.errors import ConfigError

__all__ = ["Record", "add_config_option", "apply_record", "finish_record", "read_record"]

log = logging.getLogger(__name__)

#: the largest --config file read (a results.json of a long sweep is a few megabytes).
MAX_BYTES = 256 << 20


def _joined(values: Any) -> str | None:
    return None if values is None else ",".join(str(v) for v in values)


def _world(values: dict[str, Any]) -> str:
    return ",".join(f"{k}={str(v).lower() if isinstance(v, bool) else v}"
                    for k, v in values.items())


#: settings whose option takes another form than the recorded value: the option's dest and
#: the recorded value as that option's parsed value. Every other setting whose name is an
#: option's dest goes through that option (a list as ``a,b,c``); one that no option sets is
#: put back as recorded after the configuration is built.
FORMS: dict[str, tuple[str, Any]] = {
    "caregiver_params": ("caregiver_param", lambda v: list(v.items())),
    "learner_params": ("param", lambda v: [(lr, k, x) for lr, ps in v.items()
                                           for k, x in ps.items()]),
    "world": ("world", _world),
}
#: settings put back as written unless their option is typed (the domain's path: not
#: resolved again through a link).
AS_WRITTEN = ("domain",)
#: what a configuration records besides its settings (derived from them; not read back).
DERIVED = {"sis": ("caregiver_resolved", "eval_caregiver_resolved", "setting"),
           "scaling": ("worlds", "caregiver_resolved")}


def _settings(experiment: str) -> list[str]:
    """The settings of ``experiment``'s configuration (its dataclass's fields)."""
    return list(_types(experiment))


def _types(experiment: str) -> dict[str, Any]:
    """Each setting of ``experiment``'s configuration and its type (the dataclass's hints)."""
    from dataclasses import fields
    from typing import get_type_hints

    from relrl.experiments.scaling import ScalingConfig
    from relrl.experiments.sis import SISConfig

    cls = SISConfig if experiment == "sis" else ScalingConfig
    hints = get_type_hints(cls)
    return {f.name: hints[f.name] for f in fields(cls)}


_KINDS = {bool: "true or false", int: "an integer", float: "a number", str: "a string",
          list: "a list", dict: "an object", type(None): "null"}


def _fits(value: Any, hint: Any) -> bool:
    """Whether a JSON value is of a setting's type (``bool`` is no integer here, an integer
    is a number)."""
    import types
    import typing

    origin = typing.get_origin(hint)
    if hint is Any:
        return True
    if origin in (typing.Union, types.UnionType):
        return any(_fits(value, h) for h in typing.get_args(hint))
    if hint is type(None):
        return value is None
    if origin is list:
        (item,) = typing.get_args(hint)
        return isinstance(value, list) and all(_fits(v, item) for v in value)
    if origin is dict:
        key, item = typing.get_args(hint)
        return isinstance(value, dict) and all(_fits(v, item) for v in value.values())
    if isinstance(value, bool):
        return hint is bool
    if hint is float:
        return isinstance(value, (int, float))
    return isinstance(value, hint)


def _described(hint: Any, plural: bool = False) -> str:
    """A setting's type in words (``a list of integers``, ``an object of numbers``)."""
    import typing

    args = typing.get_args(hint)
    origin = typing.get_origin(hint)
    if origin in (list, dict):
        inner = "" if args[-1] is Any else f" of {_described(args[-1], True)}"
        return ("lists" if plural else "a list") + inner if origin is list else \
            ("objects" if plural else "an object") + inner
    if args:
        return " or ".join(_described(a, plural) for a in args)
    if plural:
        return {int: "integers", float: "numbers", str: "strings"}.get(hint, str(hint))
    return _KINDS.get(hint, str(hint))


def _shown(value: Any) -> str:
    kind = _KINDS.get(type(value), type(value).__name__)
    if isinstance(value, (list, dict)) or value is None:
        return kind
    return f"{json.dumps(value)[:40]} ({kind})"


def _plan(experiment: str, parser: argparse.ArgumentParser
          ) -> tuple[dict[str, tuple[str, Any]], list[str]]:
    """How each setting comes back: through an option (``{name: (dest, form)}``), or put
    back after the configuration is built (the rest)."""
    dests = {a.dest for a in parser._actions}
    through, after = {}, []
    for name in _settings(experiment):
        if name in FORMS:
            through[name] = FORMS[name]
        elif name in dests and name not in AS_WRITTEN:
            through[name] = (name, None)
        else:
            after.append(name)
    return through, after


#: options whose values add to the recorded ones (repeatable NAME=VALUE options).
_ADDING = ("caregiver_param", "param")


def add_config_option(parser: argparse.ArgumentParser) -> None:
    """Declare ``--config`` on an experiment's parser (and remember the parser, which tells
    which options were typed)."""
    parser.add_argument("--config", default=None, metavar="RESULTS.json",
                        help="run a recorded configuration again: the results.json of an "
                             "earlier run (or its \"config\" object alone); options given "
                             "beside it override what it records")
    parser.set_defaults(experiment_parser=parser)


def _typed(args: argparse.Namespace) -> set[str]:
    """The dests of the options typed on the command line, whatever their values."""
    parser = args.experiment_parser
    words = shlex.split(args.command_line)[1:]
    start = words.index("experiment")
    words = words[words.index(args.name, start + 1) + 1:]
    saved = [(a, a.default) for a in parser._actions]
    try:
        for action, _ in saved:
            action.default = argparse.SUPPRESS
        typed, _ = parser.parse_known_args(words)
    finally:
        for action, default in saved:
            action.default = default
    return set(vars(typed))


def read_record(path: str | Path, experiment: str) -> dict[str, Any]:
    """The configuration recorded in ``path`` (a results.json, or a configuration alone).

    Raises:
        ConfigError: no such file, not a JSON object, another experiment's results.
    """
    path = Path(path)
    where = f"--config {path}"
    try:
        if not path.is_file():
            raise ConfigError(f"{where}: no such file (give the results.json of a run)")
        if path.stat().st_size > MAX_BYTES:
            raise ConfigError(f"{where}: larger than {MAX_BYTES >> 20} MB; not a results.json")
        data = json.loads(path.read_text(encoding="utf-8"))
    except OSError as exc:
        raise ConfigError(f"{where}: cannot be read ({exc.strerror or exc})") from None
    except UnicodeDecodeError:
        raise ConfigError(f"{where}: not text (give the results.json of a run)") from None
    except json.JSONDecodeError as exc:
        raise ConfigError(f"{where}:{exc.lineno}: not JSON ({exc.msg})") from None
    if not isinstance(data, dict):
        raise ConfigError(f"{where}: not a JSON object (give the results.json of a run)")
    other = data.get("experiment")
    if other is not None and other != experiment:
        raise ConfigError(f"{where}: the results of relrl experiment {other}, not "
                          f"{experiment} (run relrl experiment {other} --config {path})")
    config = data.get("config", data if other is None else None)
    if not isinstance(config, dict):
        raise ConfigError(f"{where}: no \"config\" object (give the results.json of a run)")
    types = _types(experiment)
    for name, value in config.items():
        if name in DERIVED[experiment]:
            continue
        if name not in types:
            raise ConfigError(f"{where}: config.{name} is not a setting of relrl "
                              f"experiment {experiment} (a record of another relrl version?)")
        if not _fits(value, types[name]):
            raise ConfigError(f"{where}: config.{name} is {_shown(value)}, expected "
                              f"{_described(types[name])}")
    version = data.get("relrl_version")
    from relrl import __version__

    if version is not None and version != __version__:
        log.warning("%s was recorded by relrl %s, this is %s: the numbers may differ",
                    path, version, __version__)
    return config


def _in_preset(config: dict[str, Any], name: str) -> dict[str, Any]:
    """The recorded ``config`` with its setting taken out for preset ``name`` to set: the
    caregiver, the evaluation's caregiver parameters, and what an earlier preset put in the
    caregiver's and the learners' parameters."""
    from relrl.experiments.sis import PRESETS

    old = PRESETS.get(str(config.get("preset")), {})
    out = {k: v for k, v in config.items() if k not in ("caregiver", "eval_caregiver_params")}
    out["caregiver_params"] = {k: v for k, v in (config.get("caregiver_params") or {}).items()
                               if old.get("caregiver_params", {}).get(k, object()) != v}
    out["learner_params"] = {
        lr: kept for lr, ps in (config.get("learner_params") or {}).items()
        if (kept := {k: v for k, v in ps.items()
                     if old.get("learner_params", {}).get(lr, {}).get(k, object()) != v})}
    out["preset"] = name
    log.warning("--preset %s replaces the recorded setting (%s) and keeps the rest of the "
                "recorded configuration", name,
                f"preset {config['preset']}" if config.get("preset") else "the fixed task")
    return out


@dataclass
class Record:
    """A recorded configuration, the options typed beside it, and the settings to put
    back after the configuration is built."""

    config: dict[str, Any]
    typed: set[str]
    after: list[str]


def apply_record(args: argparse.Namespace, experiment: str) -> Record | None:
    """With ``--config``: the recorded values put in ``args`` for every option not typed
    (the repeatable NAME=VALUE options add to the recorded ones), so that building the
    configuration from ``args`` checks them as it checks typed ones. Returns the record
    (``None`` without ``--config``) for :func:`finish_record`.

    Raises:
        ConfigError: a bad record (see :func:`read_record`), or ``--quick`` beside it.
    """
    if getattr(args, "config", None) is None:
        return None
    config = read_record(args.config, experiment)
    typed = _typed(args)
    if "quick" in typed:
        raise ConfigError("--quick with --config: the recorded configuration says how long "
                          "the run is (give --points, --eval-runs, ... to change it)")
    if experiment == "sis" and "preset" in typed and args.preset != config.get("preset"):
        config = _in_preset(config, args.preset)
    through, after = _plan(experiment, args.experiment_parser)
    for name, (dest, form) in through.items():
        if name not in config:
            continue
        value = config[name]
        if value is not None:
            value = form(value) if form is not None else \
                _joined(value) if isinstance(value, list) else value
        if dest in _ADDING:  # the recorded ones first: the typed ones override them
            if dest == "param" and "learners" in typed:  # of the learners still run
                chosen = {x.strip() for x in args.learners.split(",")}
                value = [p for p in value if p[0] in chosen]
            setattr(args, dest, value + list(getattr(args, dest) or []))
        elif dest not in typed:
            setattr(args, dest, value)
    return Record(config, typed, after)


def finish_record(config: Any, recorded: Record | None) -> Any:
    """The recorded fields no option set put back into the built ``config``, and a warning
    when its caregiver resolves to other parameters here than in the record.

    Raises:
        ConfigError: the recorded domain file is missing.
    """
    if recorded is None:
        return config
    record = recorded.config
    for name in recorded.after:
        if name in record and name not in recorded.typed:
            setattr(config, name, record[name])
    domain = getattr(config, "domain", None)
    if domain is not None and not Path(domain).is_file():
        raise ConfigError(f"the recorded domain {domain} is missing (give --domain FILE)")
    now = config.to_dict().get("caregiver_resolved")
    then = record.get("caregiver_resolved")
    if then is not None and now != then and record.get("caregiver") == config.caregiver and \
            record.get("caregiver_params") == config.caregiver_params:
        log.warning("the recorded caregiver resolves to other parameters in this relrl "
                    "(its defaults changed): the numbers may differ from the record")
    return config
