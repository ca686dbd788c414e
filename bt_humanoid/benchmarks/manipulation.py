"""Manipulation benchmark: pick and place over randomized object poses on the dining table.

    python -m bt_humanoid.benchmarks.manipulation --trials 50

For each kind (cube, bottle, mug) and each trial, the object stands at a
random spot and yaw within reach of one of the table's free edges, the robot
starts 0.3 m behind that edge's stance, and the mission is the `pick` and
`place` behaviours (recovery included) to another random spot on the same
edge. The objects not in play wait on the counter. Success is judged in ground
truth: a grasp when the pick ends with the object in the hand; a placement
when it rests on the table within 3 cm of the spot (and upright, for things
kept upright). Rates say what they are counted over: grasps of all trials,
placements of the grasped trials (a trial that never held the object is not
a placement attempt) and of all trials. Also prints the whole-body QP time
per control step. The
robot finds the object with its head camera; ``--perception told`` tells it
where the object is instead, to measure control alone. ``--robot
biped_humanoid`` runs the walking robot: spots are drawn within its own
reach (robot.yaml ``base.working_stance``) and falls are counted, in ground
truth. Runs pinned to one CPU core; ``--json PATH`` also writes the figures.
"""

from __future__ import annotations

import math
import statistics
import time
from dataclasses import asdict, dataclass, field

import numpy as np

from bt_humanoid.benchmarks.common import (
    benchmark_parser,
    footing_removed,
    has_fallen,
    parse_benchmark_args,
    percentile,
    save_figures,
)
from bt_humanoid.control.stance import deepest_reach, working_stance
from bt_humanoid.engine.stack import RobotStack
from bt_humanoid.paths import robots_dir
from bt_humanoid.perception.map_knowledge import map_world_model
from bt_humanoid.perception.world_model import SupportSurface
from bt_humanoid.sim.robot_config import BaseConfig
from bt_humanoid.testing.scenario import build_run
from bt_humanoid.testing.scene import place_object
from bt_humanoid.testing.told import tell_object_poses

OBJECTS = {"cube": "red cube", "bottle": "water bottle", "mug": "coffee mug"}
SURFACE = "table"
SIDE = "right"
EDGES = ("west", "south", "east")  # the north edge has the chair behind it
PLACE_TOLERANCE = 0.03  # m from the requested spot
MIN_DEPTH = 0.1  # m behind the edge: room for the pads and the object's radius
CORNER_MARGIN = 0.2  # m from a corner along the edge: another edge would be nearer
SPACING = 0.15  # m between the object's spot and the placement spot
START_BACK = 0.3  # m the robot starts behind its stance
PARKING = [(8.45, 1.45), (8.45, 1.75), (8.45, 3.25), (8.45, 3.55)]  # counter spots for the objects not in play


@dataclass
class Trial:
    kind: str
    edge: str
    spot: tuple[float, float]
    yaw: float
    place: tuple[float, float]
    start: tuple[float, float, float]  # x, y, yaw_deg


@dataclass
class Outcome:
    grasped: bool
    placed: bool
    error_cm: float | None
    failure: str | None
    sim_time: float
    fell: bool
    qp_times: list[float]
    conic_times: list[float]
    compile_times: list[float] = field(default_factory=list)  # s compiling each kind of goal's QP
    bind_times: list[float] = field(default_factory=list)  # s binding a QP compiled before to a goal like it


def _edge_frame(surface: SupportSurface, edge: str) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """A point on the edge's line, the inward normal, the direction along the edge and the edge's length."""
    (x0, y0), (x1, y1) = surface.region
    if edge == "west":
        return np.array([x0, y0]), np.array([1.0, 0.0]), np.array([0.0, 1.0]), y1 - y0
    if edge == "east":
        return np.array([x1, y0]), np.array([-1.0, 0.0]), np.array([0.0, 1.0]), y1 - y0
    if edge == "south":
        return np.array([x0, y0]), np.array([0.0, 1.0]), np.array([1.0, 0.0]), x1 - x0
    raise ValueError(f"unknown edge {edge!r}")


def sample_trial(kind: str, surface: SupportSurface, bounds: np.ndarray, base: BaseConfig, rng) -> Trial:
    """A random spot, yaw and placement spot on one edge within the robot's reach (its ``base``), and a start
    pose from which that edge is nearest."""
    depth = deepest_reach(base)
    while True:
        edge = EDGES[int(rng.integers(len(EDGES)))]
        corner, inward, along, length = _edge_frame(surface, edge)

        pick, place = (
            corner
            + rng.uniform(MIN_DEPTH, depth - 0.06) * inward
            + rng.uniform(CORNER_MARGIN, length - CORNER_MARGIN) * along
            for _ in range(2)
        )
        if np.linalg.norm(pick - place) < SPACING:
            continue
        far = pick - 3.0 * inward
        x, y, yaw = working_stance(pick, surface, SIDE, base, bounds, far)
        start = np.array([x, y]) - START_BACK * np.array([math.cos(yaw), math.sin(yaw)])
        # stand_near picks the reachable edge nearest the robot: make sure it is this one, for both spots
        if any(abs(working_stance(p, surface, SIDE, base, bounds, start)[2] - yaw) > 1e-6 for p in (pick, place)):
            continue
        return Trial(
            kind,
            edge,
            (round(float(pick[0]), 3), round(float(pick[1]), 3)),
            round(float(rng.uniform(-math.pi, math.pi)), 3),
            (round(float(place[0]), 3), round(float(place[1]), 3)),
            (round(float(start[0]), 3), round(float(start[1]), 3), round(math.degrees(yaw), 1)),
        )


def prepare_trial(trial: Trial, perception: str = "camera", robot: str = "wheeled_humanoid") -> RobotStack:
    """The trial's run, ready to execute: its object at its spot, the others parked on the counter."""
    name = OBJECTS[trial.kind]
    mission = {
        "mission": f"benchmark: pick and place the {name}",
        "world": "apartment",
        "robot": robot,
        "tree": {
            "sequence": [
                {"pick": {"object": name, "side": SIDE}},
                {"place": {"surface": SURFACE, "x": trial.place[0], "y": trial.place[1], "side": SIDE}},
            ]
        },
    }
    run = build_run(mission, robot_start=trial.start)
    parking = iter(PARKING)
    surfaces = map_world_model(run.context.world, run.sim.model)
    for other in list(run.sim.object_bodies):
        surface = surfaces.surface_under(run.truth.object_centre(other))
        if other != name and surface is not None and surface.name == SURFACE:
            place_object(run, other, *next(parking), 0.0)
    place_object(run, name, *trial.spot, trial.yaw)
    if perception == "told":  # control alone: the robot is told where everything is (the camera still looks)
        tell_object_poses(run.context.world_model, run.sim)
    return run


def run_trial(trial: Trial, perception: str = "camera", robot: str = "wheeled_humanoid") -> Outcome:
    name = OBJECTS[trial.kind]
    run = prepare_trial(trial, perception, robot)
    grasped: list[bool] = []

    def on_event(event: dict) -> None:
        if event["event"] == "status" and event.get("node") == "sequence[0].pick" and event["new"] != "RUNNING":
            grasped.append(event["new"] == "SUCCESS" and run.truth.in_hand(name) == SIDE)

    run.events.listeners.append(on_event)
    fell = False

    def watch_balance() -> None:  # a legged robot that goes down, in ground truth
        nonlocal fell
        fell = fell or has_fallen(run.truth.floating_base()[0][2], footing_removed(run.truth.robot_contacts()))

    if run.sim.robot.base.floating:
        run.executor.observers.append(watch_balance)
    result = run.execute()
    run.stack.close()  # its cameras' off-screen contexts: one per run adds up over a benchmark
    truth = run.truth
    x, y, _ = truth.object_position(name)
    error = float(np.hypot(x - trial.place[0], y - trial.place[1]))
    upright = truth.upright(name) or not run.context.world.objects[run.sim.object_kinds[name]].upright
    placed = (
        result.tree_status == "SUCCESS"
        and truth.in_hand(name) is None
        and truth.rests_on(name, SURFACE)
        and upright
        and error <= PLACE_TOLERANCE
    )
    failure = None
    if not placed:
        failures = [e for e in result.events.events if e["event"] == "status" and e["new"] == "FAILURE"]
        failure = next((e.get("feedback") for e in failures if e.get("feedback")), result.tree_status)
        failure = f"safety stop: {result.safety}" if result.safety else failure  # which monitor fired, and why
        if result.tree_status == "SUCCESS":
            failure = f"ended {error * 100:.1f} cm from the spot" + ("" if upright else ", tipped over")
        failure = f"fell ({failure})" if fell else failure
    return Outcome(
        grasped=bool(grasped and grasped[0]),
        placed=placed,
        error_cm=round(error * 100, 2) if grasped and grasped[0] else None,
        failure=failure,
        sim_time=result.sim_time,
        fell=fell,
        qp_times=list(run.robot.whole_body.solve_times),
        conic_times=list(run.robot.whole_body.conic_times),
        compile_times=list(run.robot.whole_body.qps.compile_times),
        bind_times=list(run.robot.whole_body.qps.bind_times),
    )


def summarize(kind: str, trials: list[Trial], outcomes: list[Outcome]) -> dict:
    grasped = [o for o in outcomes if o.grasped]
    placed = [o for o in grasped if o.placed]
    errors = [o.error_cm for o in placed if o.error_cm is not None]
    return {
        "kind": kind,
        "trials": len(outcomes),
        "grasped": len(grasped),
        "placed": len(placed),
        "grasp_success": len(grasped) / len(outcomes),  # of all trials
        "place_success": len(placed) / len(grasped) if grasped else 0.0,  # of the grasped trials
        "end_to_end": len(placed) / len(outcomes),  # placed, of all trials
        "median_place_error_cm": statistics.median(errors) if errors else None,  # over the placed trials
        "falls": sum(1 for o in outcomes if o.fell),
        "sim_time_s": round(sum(o.sim_time for o in outcomes), 1),
        "failures": [
            {"trial": asdict(t), "failure": o.failure} for t, o in zip(trials, outcomes, strict=True) if not o.placed
        ],
    }


def table(summaries: list[dict]) -> str:
    """The per-kind rates, each headed by what it is counted over (placements: of the grasped trials, and of all)."""
    lines = [
        f"  {'kind':8} {'trials':>6} {'grasp | of all':>16} {'place | of grasped':>20} {'place | of all':>16} "
        f"{'median error | of placed':>26}"
    ]
    for s in summaries:
        error = f"{s['median_place_error_cm']:.1f} cm" if s["median_place_error_cm"] is not None else "-"
        grasp = f"{s['grasped']}/{s['trials']} {s['grasp_success']:.0%}"
        place = f"{s['placed']}/{s['grasped']} {s['place_success']:.0%}"
        overall = f"{s['placed']}/{s['trials']} {s['end_to_end']:.0%}"
        lines.append(f"  {s['kind']:8} {s['trials']:>6} {grasp:>16} {place:>20} {overall:>16} {error:>26}")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = benchmark_parser(__doc__, "trials", 50, "trials per kind")
    parser.add_argument("--kinds", nargs="+", choices=list(OBJECTS), default=list(OBJECTS), help="object kinds")
    parser.add_argument(
        "--perception",
        choices=["camera", "told"],
        default="camera",
        help="objects known only once the head camera has seen them (default), or told where they are",
    )
    robots = sorted(path.name for path in robots_dir().iterdir() if (path / "robot.yaml").exists())
    parser.add_argument("--robot", choices=robots, default="wheeled_humanoid", help="the robot that works")
    args = parse_benchmark_args(parser, argv, "trials")
    rng = np.random.default_rng(args.seed)
    probe = RobotStack.load("apartment", args.robot)  # the apartment's surfaces and the robot's reach
    probe.close()
    surface = probe.context.world_model.surface(SURFACE)
    bounds = np.array(probe.world.bounds)
    base = probe.robot_config.base
    print(
        f"bt-humanoid manipulation benchmark: {args.robot}, {args.trials} trials per kind, seed {args.seed}, "
        f"perception {args.perception} (one core)"
    )
    started, cpu_started = time.perf_counter(), time.process_time()
    summaries, qp_times, conic_times, compile_times, bind_times = [], [], [], [], []
    for kind in args.kinds:
        trials = [sample_trial(kind, surface, bounds, base, rng) for _ in range(args.trials)]
        outcomes = []
        for i, trial in enumerate(trials, 1):
            outcome = run_trial(trial, args.perception, args.robot)
            outcomes.append(outcome)
            qp_times.extend(outcome.qp_times)
            conic_times.extend(outcome.conic_times)
            compile_times.extend(outcome.compile_times)
            bind_times.extend(outcome.bind_times)
            verdict = "ok" if outcome.placed else f"FAILED: {outcome.failure}"
            where = f"{trial.edge} edge, spot ({trial.spot[0]:.2f}, {trial.spot[1]:.2f}), yaw {trial.yaw:+.2f}"
            print(f"  {kind} {i}/{len(trials)}  {where}: {verdict}", flush=True)
        summaries.append(summarize(kind, trials, outcomes))
    qp_ms = [t * 1000 for t in qp_times]
    sim_time = sum(s["sim_time_s"] for s in summaries)
    figures = {
        "robot": args.robot,
        "perception": args.perception,
        "seed": args.seed,
        "kinds": summaries,
        "qp_steps": len(qp_ms),
        "qp_median_ms": statistics.median(qp_ms),
        "qp_p95_ms": percentile(qp_ms, 0.95),
        "conic_median_ms": statistics.median(conic_times) * 1000,
        "qp_compiles": len(compile_times),
        "qp_compile_median_ms": statistics.median(compile_times) * 1000 if compile_times else 0.0,
        "qp_compile_total_s": round(sum(compile_times), 2),
        "qp_binds": len(bind_times),
        "qp_bind_median_ms": statistics.median(bind_times) * 1000 if bind_times else 0.0,
        "qp_bind_total_s": round(sum(bind_times), 2),
        "wall_s": round(time.perf_counter() - started, 1),
        "cpu_s": round(time.process_time() - cpu_started, 1),
        "falls": sum(s["falls"] for s in summaries),
        "real_time_factor": round(sim_time / (time.perf_counter() - started), 2),
        # per core of CPU time: what another process on the same core does not change
        "real_time_factor_cpu": round(sim_time / (time.process_time() - cpu_started), 2),
    }
    print()
    print(table(summaries))
    print(
        f"  whole-body QP per control step: median {figures['qp_median_ms']:.3f} ms, "
        f"p95 {figures['qp_p95_ms']:.3f} ms over {figures['qp_steps']} steps (target ≤ 0.15 ms, p95 ≤ 0.3 ms); "
        f"of it in the conic solver: median {figures['conic_median_ms']:.3f} ms"
    )
    print(
        f"  QPs compiled: {figures['qp_compiles']} (median {figures['qp_compile_median_ms']:.1f} ms, "
        f"{figures['qp_compile_total_s']:.1f} s in all); goals that reused one: {figures['qp_binds']} "
        f"(median {figures['qp_bind_median_ms']:.2f} ms, {figures['qp_bind_total_s']:.1f} s in all)"
    )
    print(f"  falls: {figures['falls']} (target 0)")
    print(
        f"  wall time {figures['wall_s']:.0f} s, {figures['real_time_factor']:.1f}× real time; "
        f"{figures['real_time_factor_cpu']:.1f}× per core of CPU time ({figures['cpu_s']:.0f} s)"
    )
    save_figures(args.json, figures)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
