"""``relrl tree POLICY``: the learned tree of a saved policy as a picture (Graphviz)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

HELP = "draw the learned tree of a saved policy (etg, tg) as SVG, PNG, PDF or DOT"
EXAMPLE = "relrl tree runs/exp2/policy.pl --domain examples/domains/fruits.pl --out tree.svg"

_FORMATS = ("svg", "png", "pdf", "dot")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Declare the options of ``relrl tree``."""
    parser.add_argument("policy", help="a policy saved by a tree learner (.pl)")
    parser.add_argument("--domain", default=None,
                        help="the domain the policy was learned in (default: domain.pl "
                             "beside the policy, as in a recorded session folder)")
    parser.add_argument("--out", default=None,
                        help="the picture to write; its suffix gives the format (svg, png, "
                             "pdf, dot). Default: the DOT text on standard output")
    parser.add_argument("--format", choices=_FORMATS, default=None,
                        help="the format, when --out has no usual suffix")


def run(args: argparse.Namespace) -> int:
    """Load the policy in its domain, draw the tree, write it."""
    from relrl.errors import ConfigError, UserError
    from relrl.kb import KnowledgeBase
    from relrl.learners import make_learner
    from relrl.loop import Agent
    from relrl.monitor.graph import GraphError, learner_graph, render
    from relrl.outdir import check_out_file, write_atomic
    from relrl.policy import not_a_policy_file, policy_learner

    policy = Path(args.policy)
    if (problem := not_a_policy_file(policy)) is not None:
        raise UserError(f"{policy}: {problem}")
    domain = Path(args.domain) if args.domain else policy.parent / "domain.pl"
    if not domain.is_file():
        raise ConfigError(f"{domain}: no such domain file; name the policy's domain with "
                          "--domain DOMAIN.pl")
    out = Path(args.out) if args.out else None
    fmt = args.format or (out.suffix.lstrip(".").lower() if out is not None else "dot")
    if fmt not in _FORMATS:
        raise ConfigError(f"--out {out}: unknown picture format {fmt!r}; use "
                          f"{', '.join(_FORMATS)} (or --format)")
    if out is not None:  # before the work: a folder, a link, no permission, a file above
        check_out_file(out, "--out")
    with KnowledgeBase(domain) as kb:
        name = policy_learner(policy, kb)
        learner = make_learner(name)
        Agent(kb, learner, seed=0)
        learner.load(policy)
        graph = learner_graph(learner)
        if not graph or not graph.get("nodes"):
            raise GraphError(f"{policy}: a {name} policy has no tree to draw (the tree "
                             "learners are etg and tg)")
        tests = sum(1 for n in graph["nodes"] if n.get("kind") == "test")
        leaves = sum(1 for n in graph["nodes"] if n.get("kind") == "leaf")
        title = f"{name} tree of {policy.name}: {tests} tests, {leaves} leaves"
        data = render(graph, fmt, title=title)
    if out is None:
        sys.stdout.write(data.decode())
        return 0
    write_atomic(out, data)
    print(f"wrote {out}: {title}")
    return 0
