"""What every benchmark does the same way: run on one core, take a percentile, save the figures."""

from __future__ import annotations

import json
import os
from pathlib import Path


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
