"""``roughwalk bench NAME [ARGS...]``: run a benchmark script from ``benchmarks/``.

Benchmarks are not tests: each prints a table and writes JSON with the
machine's description. They live in the source checkout's ``benchmarks/``
folder (``bench_NAME.py``); this command finds that folder beside the
package (an editable or source install) and runs the script with the
remaining arguments.
"""

from __future__ import annotations

import argparse
import runpy
import sys
from pathlib import Path
from typing import Any

from roughwalk.errors import RoughwalkError


def benchmarks_dir() -> Path | None:
    """The ``benchmarks/`` folder of the source checkout, if this install has one."""
    here = Path(__file__).resolve()
    for parent in here.parents:
        candidate = parent / "benchmarks"
        if candidate.is_dir() and any(candidate.glob("bench_*.py")):
            return candidate
    return None


def available() -> dict[str, Path]:
    """Benchmark names → script paths."""
    folder = benchmarks_dir()
    if folder is None:
        return {}
    return {p.stem.removeprefix("bench_"): p for p in sorted(folder.glob("bench_*.py"))}


def register(sub: Any) -> None:
    """Add the ``bench`` command."""
    names = ", ".join(available()) or "none found"
    p = sub.add_parser(
        "bench",
        help=f"run a benchmark (table + JSON): {names}",
        description="Run benchmarks/bench_NAME.py; arguments after NAME go to the script "
        "(try `roughwalk bench NAME --help`).",
    )
    p.add_argument("name", help=f"benchmark name ({names})")
    p.add_argument("args", nargs=argparse.REMAINDER, help="arguments for the benchmark")
    p.set_defaults(func=cmd_bench)


def cmd_bench(args: argparse.Namespace) -> int:
    """Run one benchmark script in this interpreter."""
    scripts = available()
    if args.name not in scripts:
        raise RoughwalkError(
            f"unknown benchmark '{args.name}'; known: {', '.join(scripts) or 'none'}"
            + ("" if scripts else " (benchmarks/ ships with the source checkout only)")
        )
    saved = sys.argv
    sys.argv = [str(scripts[args.name]), *args.args]
    try:
        runpy.run_path(str(scripts[args.name]), run_name="__main__")
    except SystemExit as e:
        return int(e.code or 0) if isinstance(e.code, int | None) else 1
    finally:
        sys.argv = saved
    return 0
