"""A suite's figures from its episodes: success with a 95 % confidence interval, times, safety, timings."""

from __future__ import annotations

import math
import statistics
from collections import defaultdict
from typing import Any

from bt_humanoid.benchmarks.common import percentile

Z95 = 1.959964  # two-sided 95 % normal quantile


def wilson_interval(successes: int, trials: int, z: float = Z95) -> tuple[float, float]:
    """The Wilson score interval of a success rate: sound at 0 % and 100 % and for small counts."""
    if trials == 0:
        return (0.0, 1.0)
    p = successes / trials
    denominator = 1 + z * z / trials
    centre = (p + z * z / (2 * trials)) / denominator
    half = z * math.sqrt(p * (1 - p) / trials + z * z / (4 * trials * trials)) / denominator
    return (max(0.0, centre - half), min(1.0, centre + half))


def _rate(episodes: list[dict[str, Any]], key: str = "success") -> dict[str, Any]:
    wins = sum(e[key] for e in episodes)
    low, high = wilson_interval(wins, len(episodes))
    return {"episodes": len(episodes), "successes": wins, "rate": wins / len(episodes), "ci95": [low, high]}


def _median(values: list[float]) -> float | None:
    return statistics.median(values) if values else None


def _p95(values: list[float]) -> float | None:
    return percentile(values, 0.95) if values else None


def _groups(episodes: list[dict[str, Any]], key: str, missing: str) -> dict[str, list[dict[str, Any]]]:
    grouped: dict[str, list[dict[str, Any]]] = defaultdict(list)
    for e in episodes:
        grouped[e[key] or missing].append(e)
    return grouped


def safe_failure(episode: dict[str, Any]) -> bool:
    """A failure that left everyone and everything safe: the robot at rest and upright, no one touched, the thing
    not dropped on the floor.

    At rest means after the executor braked: a tree that fails mid-motion ends with the robot moving, and braking
    it is the stop (``ended_moving`` matters for a tree that reports success while it moves).
    """
    hurt = episode["person_contacts"] > 0 or episode.get("fell", False)
    return (
        not episode["success"]
        and not hurt
        and not episode["moving_after_brake"]
        and not episode.get("object_on_floor", True)
    )


def _handled(episodes: list[dict[str, Any]]) -> dict[str, Any]:
    """The rate of episodes that succeeded or failed safely."""
    return _rate([{"success": e["success"] or safe_failure(e)} for e in episodes])


def summarize(episodes: list[dict[str, Any]], wall_s: float, workers: int) -> dict[str, Any]:
    """Everything ``bt-eval`` prints and saves, from the episodes' records."""
    by = {"task": _groups(episodes, "task", "-"), "object": _groups(episodes, "object", "-")}
    by["fault"] = _groups(episodes, "fault", "none")
    done = [e for e in episodes if e["success"]]
    sim = sum(e["sim_time"] for e in episodes)
    # CPU time where every episode has it (runs saved before it was recorded have wall time only)
    timed = "cpu_s" if all("cpu_s" in e for e in episodes) else "wall_s"
    busy = sum(e[timed] for e in episodes)
    latencies = [e["stop_latency_s"] for e in episodes if e["stop_latency_s"] is not None]
    planning = {}
    if episodes and "planned" in episodes[0]:  # household instructions: the plan judged too, per family
        families = _groups(episodes, "family", "-")
        planning = {
            "planning": _rate(episodes, "planned"),
            "by_family": {k: {"planned": _rate(v, "planned"), "success": _rate(v)} for k, v in families.items()},
        }
    return {
        "success": _rate(episodes),
        **planning,
        "by_task": {k: _rate(v) for k, v in by["task"].items()},
        "by_object": {k: _rate(v) for k, v in by["object"].items()},
        "by_fault": {k: _rate(v) for k, v in by["fault"].items()},
        # issue 26's count for faults: recovered, or failed safely (at rest, no one touched, the thing not on the floor)
        **(
            {"by_fault_recovered_or_safe": {k: _handled(v) for k, v in by["fault"].items()}}
            if all("object_on_floor" in e for e in episodes)
            else {}
        ),
        "time_to_complete_s": {
            "median": _median([e["sim_time"] for e in done]),
            "p95": _p95([e["sim_time"] for e in done]),
        },
        "episodes_with_person_contact": sum(e["person_contacts"] > 0 for e in episodes),
        "episodes_with_fall": sum(e.get("fell", False) for e in episodes),  # runs saved before falls were watched
        "episodes_with_collision_stop": sum(e["collision"] for e in episodes),
        "episodes_ended_moving": sum(e["ended_moving"] for e in episodes),
        "episodes_moving_after_brake": sum(e["moving_after_brake"] for e in episodes),
        "stop_latency_s": {"median": _median(latencies), "p95": _p95(latencies), "count": len(latencies)},
        "plan_ms_median": _median([t for e in episodes for t in e["plan_ms"]]),
        "look_ms_median": _median([e["look_ms_median"] for e in episodes if e["look_ms_median"] is not None]),
        "qp_ms_median": _median([e["qp_ms_median"] for e in episodes if e["qp_ms_median"] is not None]),
        "qp_ms_p95_median": _median([e["qp_ms_p95"] for e in episodes if e["qp_ms_p95"] is not None]),
        # where the robot believed its base was against where it was: each episode's p95 (their median), the worst
        "localisation_p95_cm_median": _median(
            [e["localisation_p95_cm"] for e in episodes if e.get("localisation_p95_cm") is not None]
        ),
        "localisation_max_cm": max(
            (e["localisation_max_cm"] for e in episodes if e.get("localisation_max_cm") is not None), default=None
        ),
        "real_time_factor_per_core": sim / busy if busy else None,
        "wall_s": round(wall_s, 1),
        "workers": workers,
        "failures": [
            {"episode": e["episode"], "task": e["command"], "fault": e["fault"], "failure": _failure(e)}
            for e in episodes
            if not e["success"] or e.get("plan_failure")
        ],
    }


def _failure(episode: dict[str, Any]) -> str:
    """Why an episode failed: its plan (household instructions judge it too), its run, or both."""
    plan = episode.get("plan_failure")
    if plan is None:
        return episode["failure"]
    return f"plan: {plan}" + (f"; run: {episode['failure']}" if episode["failure"] else "")


def markdown(figures: dict[str, Any], command: str) -> str:
    """The results section of docs/results.md for one saved run: the command and commit, the rates with
    intervals, the figures."""

    def rate(r: dict[str, Any]) -> str:
        low, high = r["ci95"]
        return f"{r['rate']:.1%} | {low:.1%}–{high:.1%} | {r['successes']}/{r['episodes']}"

    def number(value: float | None, digits: int = 1) -> str:
        return f"{value:.{digits}f}" if value is not None else "–"

    rows = ["| group | success | 95 % interval | episodes |", "| --- | --- | --- | --- |"]
    rows.append(f"| all | {rate(figures['success'])} |")
    if "planning" in figures:
        rows.append(f"| planned right, all | {rate(figures['planning'])} |")
        for name, rates in figures["by_family"].items():
            rows.append(f"| planned right, {name} | {rate(rates['planned'])} |")
            rows.append(f"| done, {name} | {rate(rates['success'])} |")
    for key, label in (("by_task", "task"), ("by_object", "object"), ("by_fault", "fault")):
        if key == "by_task" and "planning" in figures:
            continue  # a household episode's task is its family
        rows += [f"| {label}: {name} | {rate(r)} |" for name, r in sorted(figures[key].items())]
    for name, r in sorted(figures.get("by_fault_recovered_or_safe", {}).items()):
        if name != "none":
            rows.append(f"| fault: {name}, recovered or stopped safely (at rest, thing not on the floor) | {rate(r)} |")
    done, latency = figures["time_to_complete_s"], figures["stop_latency_s"]
    falls = (  # runs saved before falls were watched did not count them
        [f"| episodes in which the robot fell (ground truth) | {figures['episodes_with_fall']} |"]
        if "episodes_with_fall" in figures
        else []
    )
    lines = [
        f"Suite `{figures['suite']}` ({figures['file']}), seed {figures['seed']}, "
        f"{figures['success']['episodes']} episodes, measured at commit {figures.get('commit') or '(not recorded)'} "
        "with",
        "",
        "```bash",
        command,
        "```",
        "",
        *rows,
        "",
        "| figure | measured |",
        "| --- | --- |",
        f"| time to complete, successful episodes | median {number(done['median'])} s, p95 {number(done['p95'])} s |",
        f"| episodes in which the robot touched a person | {figures['episodes_with_person_contact']} |",
        *falls,
        f"| episodes stopped by the bumper | {figures['episodes_with_collision_stop']} |",
        "| episodes whose tree finished with the robot still moving (faster than 0.01 m/s or rad/s; "
        f"safety stops not counted) | {figures['episodes_ended_moving']} |",
        f"| episodes with the robot still moving 5 s after braking | {figures['episodes_moving_after_brake']} |",
        f"| stop latency, new command → at rest | median {number(latency['median'], 2)} s, "
        f"p95 {number(latency['p95'], 2)} s ({latency['count']} episodes) |",
        f"| planning, text → validated mission | median {number(figures['plan_ms_median'])} ms |",
        f"| perception, one camera look | median {number(figures['look_ms_median'])} ms |",
        f"| whole-body QP per control step | median {number(figures['qp_ms_median'], 3)} ms |",
        f"| real-time factor, per core | {number(figures['real_time_factor_per_core'])}× |",
        f"| wall time | {figures['wall_s'] / 60:.1f} min with {figures['workers']} worker(s) |",
    ]
    failures = figures["failures"]
    if failures:
        lines += ["", "Episodes that failed, and why:", ""]
        lines += [
            f"- {f['episode']}: {f['task']}{' (fault: ' + f['fault'] + ')' if f['fault'] else ''} — {f['failure']}"
            for f in failures
        ]
    return "\n".join(lines) + "\n"
