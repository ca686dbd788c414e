"""Where a run's time goes, per simulated second: ``bt-eval … --profile PATH``.

The episodes run in this process under cProfile; the statistics are saved to PATH (open them with
``python -m pstats PATH`` or snakeviz) and the top costs are printed as CPU milliseconds per simulated second,
the unit the real-time factor is made of, so that figures before and after a change compare across runs of
different lengths.
"""

from __future__ import annotations

import cProfile
import pstats
from dataclasses import dataclass
from pathlib import Path


@dataclass
class Cost:
    function: str  # file:line(name), shortened to the package
    own_ms: float  # CPU ms per simulated second in the function itself
    total_ms: float  # with what it calls
    calls: float  # per simulated second


def top_costs(profile: cProfile.Profile | pstats.Stats, simulated: float, count: int = 5) -> list[Cost]:
    """The ``count`` functions that take the most time of their own, per ``simulated`` second of the run."""
    stats = profile if isinstance(profile, pstats.Stats) else pstats.Stats(profile)
    rows = []
    for (file, line, name), (_, calls, own, total, _) in stats.stats.items():  # type: ignore[attr-defined]
        rows.append(Cost(_short(file, line, name), 1e3 * own / simulated, 1e3 * total / simulated, calls / simulated))
    rows.sort(key=lambda cost: -cost.own_ms)
    return rows[:count]


def save(profile: cProfile.Profile, path: Path) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    profile.dump_stats(str(path))


def _short(file: str, line: int, name: str) -> str:
    if file == "~":  # a built-in
        return name
    marker = "bt_humanoid/"
    shown = file[file.index(marker) :] if marker in file else Path(file).name
    return f"{shown}:{line}({name})"
