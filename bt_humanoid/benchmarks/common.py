"""What every benchmark does the same way: its options, one core, a percentile, the figures saved."""

from __future__ import annotations

import argparse
import json
import os
from pathlib import Path

from bt_humanoid.sim.sensor_models import ideal_sensors_requested, request_ideal_sensors


def benchmark_parser(doc: str, count: str, default: int, what: str) -> argparse.ArgumentParser:
    """The options every benchmark takes: how many (``--COUNT``), ``--seed`` and ``--json``; add its own."""
    parser = argparse.ArgumentParser(description=doc.splitlines()[0])
    parser.add_argument(f"--{count}", type=int, default=default, help=f"{what} (default {default})")
    parser.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    parser.add_argument("--json", type=Path, help="also write the figures here")
    parser.add_argument("--ideal-sensors", action="store_true", help="exact sensors: no noise, nothing lost")
    return parser


def parse_benchmark_args(parser: argparse.ArgumentParser, argv: list[str] | None, count: str) -> argparse.Namespace:
    """Parse, check that the count is at least 1, and pin the process to one core."""
    args = parser.parse_args(argv)
    if getattr(args, count) < 1:
        parser.error(f"--{count} must be at least 1")
    if args.ideal_sensors:
        request_ideal_sensors()
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
        sensors = "ideal" if ideal_sensors_requested() else "modelled"  # which the figures were measured with
        path.write_text(json.dumps({"sensors": sensors, **figures}, indent=2) + "\n")


FALLEN_HEIGHT = 0.35  # m: a legged robot's pelvis below this has fallen


def on_a_foot(geom: str) -> bool:
    """A geom of a foot: its sole's corners or its box (which touches the floor when the foot rolls 3°)."""
    return "_sole_" in geom or geom in ("l_foot", "r_foot")


def footing_removed(touching: list[tuple[str, str]]) -> list[tuple[str, str]]:
    """The robot's contacts (robot geom, other geom) less its soles on the floor: those are its footing."""
    return [(mine, other) for mine, other in touching if not (on_a_foot(mine) and other == "floor")]


def has_fallen(pelvis_height: float, touching: list[tuple[str, str]]) -> bool:
    """In ground truth, a legged robot is down: its pelvis low, or something other than a sole on the floor
    (``touching`` without the footing)."""
    return pelvis_height < FALLEN_HEIGHT or any(other == "floor" for _, other in touching)
