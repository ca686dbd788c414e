"""Navigation benchmark: random start poses to every named goal of the apartment.

    python -m bt_humanoid.benchmarks.navigation --starts 20
    python -m bt_humanoid.benchmarks.navigation --starts 20 --robot biped_humanoid   # walking

Each start is a random free pose (clearance for the base, random heading);
each run is the `navigate` behaviour (replanning and recovery included) from
that start to one of table, counter, shelf, kitchen and living room. Judged
in ground truth: success when the tree succeeds and the base stops within
5 cm and 5° of the goal; contacts between the robot and anything are counted
at every control step, and so is how far the robot's belief of where it is
(localisation) lies from where it is. Prints success, errors, contacts, average speed while
driving, planning time (median, p95) and route length relative to a grid-A*
route on the same map. Runs pinned to one CPU core; ``--json PATH`` also
writes the figures.

``--robot biped_humanoid`` walks the same runs: judged within 10 cm and 10° (its goals are footsteps), its
feet's contacts with the floor are not counted as contacts, and falls are counted (the pelvis below 0.35 m,
or anything but a sole touching the floor).
"""

from __future__ import annotations

import itertools
import math
import statistics
import time
from dataclasses import dataclass, field

import numpy as np

from bt_humanoid.benchmarks.common import (
    benchmark_parser,
    footing_removed,
    has_fallen,
    parse_benchmark_args,
    percentile,
    save_figures,
)
from bt_humanoid.engine.stack import RobotStack
from bt_humanoid.navigation.grid_astar import grid_route_length
from bt_humanoid.testing.scenario import build_run

GOALS = ("table", "counter", "shelf", "kitchen", "living_room")
START_CLEARANCE = 0.8  # m of free floor around a random start: the arms of the home posture reach 0.7 m
#: m and degrees a run must end within, per robot (a biped's goals are footsteps: issue 24 asks for 10 cm, 10°)
TOLERANCES = {"wheeled_humanoid": (0.05, 5.0), "biped_humanoid": (0.10, 10.0)}
SPEED = 0.8  # m/s cap for the drive (the biped's base limits it to 0.35)
MOVING = 0.02  # m/s: the base counts as driving above this speed


@dataclass
class Outcome:
    start: tuple[float, float, float]
    goal: str
    success: bool
    position_error: float
    heading_error: float
    contacts: int
    drive_time: float
    distance: float
    planning_times: list[float]
    route_ratio: float | None
    failure: str | None
    fell: bool = False
    localisation_errors: list[float] = field(default_factory=list)  # m, believed vs true base position, each step
    heading_beliefs: list[float] = field(default_factory=list)  # degrees, believed vs true heading, each step


def random_starts(count: int, rng: np.random.Generator, world: str = "apartment") -> list[tuple[float, float, float]]:
    """Free poses (x, y, yaw_deg) spread over the apartment (away from any walker's loop)."""
    probe = RobotStack.load(world, "wheeled_humanoid")
    probe.close()
    return [free_start(probe.navigator.grid, probe.world, rng) for _ in range(count)]


def free_start(grid, world, rng: np.random.Generator, clearance: float = START_CLEARANCE) -> tuple[float, float, float]:
    """One random pose (x, y, yaw_deg) with ``clearance`` of free floor on the map, away from walkers' loops."""
    (x0, y0), (x1, y1) = world.bounds
    while True:
        xy = np.array([rng.uniform(x0, x1), rng.uniform(y0, y1)])
        if grid.clearance_at(xy[None, :])[0] >= clearance and _clear_of_walkers(xy, world):
            return (round(float(xy[0]), 3), round(float(xy[1]), 3), round(float(rng.uniform(-180, 180)), 1))


def _clear_of_walkers(xy: np.ndarray, world) -> bool:
    """At least START_CLEARANCE from every leg of every walker's loop (nobody starts inside a person)."""
    for walker in world.walkers.values():
        corners = np.array(walker.route)
        for a, b in zip(corners, np.roll(corners, -1, axis=0), strict=True):
            t = np.clip((xy - a) @ (b - a) / max(float((b - a) @ (b - a)), 1e-9), 0.0, 1.0)
            if np.hypot(*(xy - (a + t * (b - a)))) < START_CLEARANCE + walker.radius:
                return False
    return True


def run_one(
    start: tuple[float, float, float], goal: str, world: str = "apartment", robot: str = "wheeled_humanoid"
) -> Outcome:
    mission = {
        "mission": f"navigate to the {goal}",
        "world": world,
        "robot": robot,
        "tree": {"navigate": {"place": goal, "speed": SPEED}},
    }
    run = build_run(mission, robot_start=start)
    contacts: list[tuple[str, str]] = []
    track: list[tuple[float, np.ndarray, float]] = []
    floating = run.sim.robot.base.floating
    fell = False
    believed: list[float] = []
    heading: list[float] = []

    def observe() -> None:
        nonlocal fell
        touching = run.truth.robot_contacts()
        if floating:  # a biped stands on its soles: those contacts with the floor are its footing
            touching = footing_removed(touching)
            fell = fell or has_fallen(run.truth.floating_base()[0][2], touching)
        contacts.extend(touching)
        x, y, yaw = run.truth.robot_pose()
        belief = run.robot.base.pose()
        believed.append(float(np.hypot(belief[0] - x, belief[1] - y)))
        heading.append(abs(math.degrees(math.remainder(float(belief[2]) - yaw, 2 * math.pi))))
        track.append((run.sim.time, np.array([x, y]), float(np.hypot(*run.robot.base.speeds()[:2]))))

    run.executor.observers.append(observe)
    result = run.execute()
    run.stack.close()  # its cameras' off-screen contexts: one per run adds up over a benchmark
    x, y, yaw = run.truth.robot_pose()
    gx, gy, gyaw = run.context.world.place(goal).pose
    position_error = math.hypot(x - gx, y - gy)
    heading_error = abs(math.degrees(math.remainder(yaw - math.radians(gyaw), 2 * math.pi)))
    steps = [np.hypot(*(b[1] - a[1])) for a, b in itertools.pairwise(track)]
    driving = [t for t, _, speed in track if speed > MOVING]
    drive_time = driving[-1] - driving[0] if len(driving) > 1 else 0.0
    navigator = run.navigator
    reference = grid_route_length(
        navigator.grid, np.array(start[:2]), np.array([gx, gy]), navigator.clearance.preferred
    )
    route_ratio = navigator.route_lengths[0] / reference if reference and navigator.route_lengths else None
    position_tolerance, heading_tolerance = TOLERANCES.get(robot, TOLERANCES["wheeled_humanoid"])
    success = (
        result.tree_status == "SUCCESS"
        and position_error <= position_tolerance
        and heading_error <= heading_tolerance
        and not fell
    )
    failure = None if success else (result.cause or f"stopped {position_error * 100:.1f} cm, {heading_error:.1f}° off")
    if fell:
        failure = f"fell ({failure})"
    return Outcome(
        start,
        goal,
        success,
        position_error,
        heading_error,
        len(contacts),
        drive_time,
        float(sum(steps)),
        list(navigator.planning_times),
        route_ratio,
        failure,
        fell,
        believed,
        heading,
    )


def main(argv: list[str] | None = None) -> int:
    parser = benchmark_parser(__doc__, "starts", 20, "random start poses")
    parser.add_argument("--goals", nargs="+", choices=GOALS, default=list(GOALS), help="named goals")
    parser.add_argument(
        "--world", default="apartment", help="apartment, or apartment_busy (a person walks a loop across the middle)"
    )
    parser.add_argument("--robot", default="wheeled_humanoid", choices=sorted(TOLERANCES), help="robot that goes")
    args = parse_benchmark_args(parser, argv, "starts")
    started = time.perf_counter()
    starts = random_starts(args.starts, np.random.default_rng(args.seed), args.world)
    total = len(starts) * len(args.goals)
    print(
        f"bt-humanoid navigation benchmark in {args.world} ({args.robot}): {len(starts)} starts × "
        f"{len(args.goals)} goals, seed {args.seed}"
    )
    outcomes = []
    for start in starts:
        for goal in args.goals:
            outcome = run_one(start, goal, args.world, args.robot)
            outcomes.append(outcome)
            verdict = "ok" if outcome.success else f"FAILED: {outcome.failure}"
            speed = outcome.distance / outcome.drive_time if outcome.drive_time > 0 else 0.0
            print(
                f"  {len(outcomes)}/{total}  ({start[0]:.2f}, {start[1]:.2f}, {start[2]:.0f}°) → {goal}: "
                f"{outcome.position_error * 100:.1f} cm, {outcome.heading_error:.1f}°, {speed:.2f} m/s, "
                f"{outcome.contacts} contacts, "
                f"believed within {max(outcome.localisation_errors, default=0) * 100:.1f} cm: {verdict}",
                flush=True,
            )
    successes = [o for o in outcomes if o.success]
    plans = [t * 1000 for o in outcomes for t in o.planning_times if t > 0]
    ratios = [o.route_ratio for o in outcomes if o.route_ratio is not None]
    drive = sum(o.drive_time for o in outcomes)
    believed = [e * 100 for o in outcomes for e in o.localisation_errors]
    heading = [e for o in outcomes for e in o.heading_beliefs]
    figures = {
        "runs": len(outcomes),
        "success_rate": len(successes) / len(outcomes),
        "max_position_error_cm": max(o.position_error for o in successes) * 100 if successes else None,
        "max_heading_error_deg": max(o.heading_error for o in successes) if successes else None,
        "runs_with_contacts": sum(1 for o in outcomes if o.contacts),
        "falls": sum(1 for o in outcomes if o.fell),
        "average_speed": sum(o.distance for o in outcomes) / drive if drive > 0 else 0.0,
        "planning_median_ms": statistics.median(plans) if plans else None,
        "planning_p95_ms": percentile(plans, 0.95) if plans else None,
        "route_vs_grid_astar_median": statistics.median(ratios) if ratios else None,
        "route_vs_grid_astar_max": max(ratios) if ratios else None,
        # where the robot believed it was against where it was, every control step of every run
        "localisation_median_cm": statistics.median(believed) if believed else None,
        "localisation_p95_cm": percentile(believed, 0.95) if believed else None,
        "localisation_max_cm": max(believed) if believed else None,
        "heading_belief_p95_deg": percentile(heading, 0.95) if heading else None,
        "failures": [{"start": o.start, "goal": o.goal, "failure": o.failure} for o in outcomes if not o.success],
        "wall_s": round(time.perf_counter() - started, 1),
    }
    print()
    position_tolerance, heading_tolerance = TOLERANCES[args.robot]
    print(f"  success {figures['success_rate']:.0%} of {len(outcomes)} runs")
    if successes:
        print(
            f"  worst final error of the successes: {figures['max_position_error_cm']:.1f} cm "
            f"(≤ {position_tolerance * 100:.0f} cm), "
            f"{figures['max_heading_error_deg']:.1f}° (≤ {heading_tolerance:.0f}°)"
        )
    print(f"  runs with a robot contact: {figures['runs_with_contacts']} (target 0); falls: {figures['falls']}")
    if believed:
        print(
            f"  localisation error: median {figures['localisation_median_cm']:.1f} cm, "
            f"p95 {figures['localisation_p95_cm']:.1f} cm (targets 3, 8), "
            f"worst {figures['localisation_max_cm']:.1f} cm; "
            f"heading p95 {figures['heading_belief_p95_deg']:.2f}°"
        )
    print(f"  average speed while driving: {figures['average_speed']:.2f} m/s (target ≥ 0.4 m/s)")
    if plans:
        median, p95 = figures["planning_median_ms"], figures["planning_p95_ms"]
        print(f"  planning time: median {median:.1f} ms, p95 {p95:.1f} ms")
    if ratios:
        print(
            f"  route length / grid-A* route: median {figures['route_vs_grid_astar_median']:.2f}, "
            f"worst {figures['route_vs_grid_astar_max']:.2f}"
        )
    print(f"  wall time {figures['wall_s']:.0f} s")
    save_figures(args.json, figures)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
