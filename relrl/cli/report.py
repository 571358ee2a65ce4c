"""``relrl report``: results tables rendered from the runs that produced them."""

from __future__ import annotations

import argparse

HELP = "render results tables from experiment runs (results.json), or refresh a document's"
EXAMPLE = ("relrl report runs/exp1 runs/scaling --out docs/results.md\n"
           "  relrl report --update README.md docs/experiment1.md\n"
           "  relrl report --check README.md      # exit 1 if a table is stale")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Declare the options of ``relrl report``."""
    parser.add_argument("runs", nargs="*", metavar="RUN_DIR",
                        help="run folders (each with results.json) to render")
    parser.add_argument("--out", metavar="FILE.md",
                        help="write a results page there (default: print it)")
    parser.add_argument("--view", metavar="NAME",
                        help="print only this view of each run (e.g. summary, short)")
    parser.add_argument("--update", nargs="+", metavar="FILE.md", default=[],
                        help="re-render every generated block of these Markdown files in place")
    parser.add_argument("--check", nargs="+", metavar="FILE.md", default=[],
                        help="exit 1 and name every generated block that its run no longer "
                             "renders the same")
    parser.add_argument("--root", metavar="DIR",
                        help="the tree whose runs a document's blocks may read (default: the "
                             "git work tree holding the document, else its folder); a block "
                             "naming a run outside it is refused")


def run(args: argparse.Namespace) -> int:
    """Render, update or check."""
    from pathlib import Path

    from relrl.errors import ConfigError
    from relrl.report import load_run, render, render_report, stale_blocks, update_file

    for md in [*args.update, *args.check]:
        if not Path(md).is_file():
            raise ConfigError(f"{md}: " + ("not a regular file (a folder or a device), not "
                                           "a Markdown file" if Path(md).exists() else
                                           "no such Markdown file"))
    if args.root is not None and not Path(args.root).is_dir():
        raise ConfigError(f"--root {args.root}: no such folder")
    if not (args.runs or args.update or args.check):
        raise ConfigError("give run folders to render, or --update/--check FILE.md")
    status = 0
    for md in args.update:
        n = update_file(md, args.root)
        print(f"{md}: {n} block(s) re-rendered" if n else f"{md}: up to date")
    for md in args.check:
        stale = stale_blocks(md, args.root)
        for line in stale:
            print(f"stale: {line}")
        status = max(status, 1 if stale else 0)
    if args.runs:
        if args.view:
            for p in args.runs:
                print(render(load_run(p), args.view))
        elif args.out:
            from relrl.outdir import check_out_file, write_atomic

            out = Path(args.out)
            check_out_file(out, "--out", suffixes=(".md",))
            write_atomic(out, render_report(args.runs, out, args.root))
            print(f"wrote {out}")
        else:
            print(render_report(args.runs, Path.cwd() / "results.md", args.root))
    return status
