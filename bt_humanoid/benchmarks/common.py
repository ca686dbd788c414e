"""What every benchmark does the same way: its options, one core, a percentile, the figures saved."""

from __future__ import annotations

import argparse
import json
import os
from pathlib import Path


def benchmark_parser(doc: str, count: str, default: int, what: str) -> argparse.ArgumentParser:
    """The options every benchmark takes: how many (``--COUNT``), ``--seed`` and ``--json``; add its own."""
    parser = argparse.ArgumentParser(description=doc.splitlines()[0])
    parser.add_argument(f"--{count}", type=int, default=default, help=f"{what} (default {default})")
    parser.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    parser.add_argument("--json", type=Path, help="also write the figures here")
    return parser


def parse_benchmark_args(parser: argparse.ArgumentParser, argv: list[str] | None, count: str) -> argparse.Namespace:
    """Parse, check that the count is at least 1, and pin the process to one core."""
    args = parser.parse_args(argv)
    if getattr(args, count) < 1:
        parser.error(f"--{count} must be at least 1")
    pin_to_one_core()
    return args


def pin_to_one_core() -> None:
    """Figures comparable between machines and runs: the benchmark gets one CPU core to itself."""
    if hasattr(os, "sched_setaffinity"):
        os.sched_setaffinity(0, {sorted(os.sched_getaffinity(0))[0]})


def percentile(values: list[float], q: float) -> float:
    """The value at quantile ``q`` (0..1) of ``values``, nearest rank."""
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, round(q * (len(ordered) - 1)))]


def save_figures(path: Path | None, figures: dict) -> None:
    """Write the figures as JSON when ``--json PATH`` was given."""
    if path is not None:
        path.write_text(json.dumps(figures, indent=2) + "\n")
