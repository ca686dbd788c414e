"""Kitchen manipulation benchmark: each of the kitchen's sixteen objects picked and placed on each surface, and
thrown away into the trash can.

    python -m bt_humanoid.benchmarks.kitchen_manipulation --trials 12 --throws 10 --seed 0

Control alone: the robot is told where the object is and its head camera is off (``testing/told.py``), so
the figures do not move with the detector. Each trial has the object in play alone in the kitchen, standing
(or lying) at a random spot and yaw that the right hand reaches from every free stance beside it
(``testing/spots.py``), and the robot starts 0.3 m behind one of those stances, drawn at random.
Pick-and-place trials take the surfaces in turn (table, close counter, far counter) and run the `pick` and
`place` behaviours to another such spot on the same surface; throw-away trials start the same way and run
the `throw_away` behaviour into the trash can. Judged in ground truth: a grasp when a pick ends with the
object between the pads; a placement when the tree succeeds and the object rests on the surface within
3 cm of the spot (upright, for things kept upright); into the bin when the tree succeeds and the object lies
within the bin's opening, below its rim. Rates say what they are counted over. Runs pinned to one CPU
core; ``--json PATH`` also writes the figures.
"""

from __future__ import annotations

import math
import statistics
import time
from dataclasses import asdict, dataclass

import numpy as np

from bt_humanoid.benchmarks.common import benchmark_parser, parse_benchmark_args, save_figures
from bt_humanoid.control.stance import stances_for
from bt_humanoid.engine.runner import MissionRun
from bt_humanoid.perception.world_model import SupportSurface
from bt_humanoid.sim.robot_config import RobotConfig, load_robot_config
from bt_humanoid.sim.scene_config import Placement, SceneConfig
from bt_humanoid.sim.world_config import WorldConfig, load_world_config
from bt_humanoid.testing.scenario import load_mission
from bt_humanoid.testing.spots import STANCE_ROOM, reachable_spot
from bt_humanoid.testing.told import told_stack

WORLD = "kitchen"
ROBOT = "wheeled_humanoid"
SURFACES = ("table", "close_counter", "far_counter")
BIN = "trash_can"
SIDE = "right"
PLACE_TOLERANCE = 0.03  # m from the requested spot
START_BACK = 0.3  # m the robot starts behind its stance
ATTEMPTS = 200


@dataclass
class Trial:
    object: str
    task: str  # "place": pick and place on the same surface; "throw": pick and drop into the bin
    surface: str
    spot: tuple[float, float]
    yaw: float  # rad
    start: tuple[float, float, float]  # x, y, yaw_deg
    place: tuple[float, float] | None = None
    into: str = BIN  # the bin a throw-away drops it into


@dataclass
class Outcome:
    grasped: bool
    done: bool  # placed, or in the bin
    error_cm: float | None  # from the placement spot, once grasped (pick and place)
    failure: str | None
    sim_time: float


@dataclass
class Kitchen:
    """What drawing trials needs: the world, the robot, the surfaces, the floor plan."""

    world: WorldConfig
    robot: RobotConfig
    surfaces: dict[str, SupportSurface]
    grid: object  # the navigator's occupancy grid (clearance_at)
    bounds: np.ndarray
    footprint: float

    @classmethod
    def load(cls) -> Kitchen:
        world, robot = load_world_config(WORLD), load_robot_config(ROBOT)
        probe = told_stack(world, robot, scene=SceneConfig())
        probe.close()
        belief = probe.context.world_model
        return cls(
            world,
            robot,
            {name: belief.surface(name) for name in SURFACES},
            probe.navigator.grid,
            np.array(world.bounds),
            robot.base.footprint_radius,
        )


def sample_trial(kitchen: Kitchen, name: str, task: str, surface: str, rng: np.random.Generator) -> Trial:
    """A random reachable spot and yaw for ``name`` on ``surface`` (and a placement spot), and a start pose 0.3 m
    behind a stance beside it on a random side."""
    region = kitchen.surfaces[surface]
    args = (region, kitchen.grid, kitchen.footprint, kitchen.bounds)
    spot = reachable_spot(*args, [], rng)
    place = reachable_spot(*args, [spot], rng) if task == "place" else None
    centre = region.region.mean(axis=0)
    for _ in range(ATTEMPTS):
        heading = rng.uniform(-math.pi, math.pi)
        x, y, yaw = stances_for(spot, region, SIDE, kitchen.footprint, kitchen.bounds, centre + 3.0 * _unit(heading))[0]
        start = np.array([x, y]) - START_BACK * _unit(yaw)
        if kitchen.grid.clearance_at(start[None, :])[0] >= kitchen.footprint + STANCE_ROOM:
            break
    else:
        raise ValueError(f"no free start beside ({spot[0]:.2f}, {spot[1]:.2f}) on the {surface}")
    return Trial(
        name,
        task,
        surface,
        (round(float(spot[0]), 3), round(float(spot[1]), 3)),
        round(float(rng.uniform(-math.pi, math.pi)), 3),
        (round(float(start[0]), 3), round(float(start[1]), 3), round(math.degrees(yaw), 1)),
        (round(float(place[0]), 3), round(float(place[1]), 3)) if place is not None else None,
    )


def _unit(angle: float) -> np.ndarray:
    return np.array([math.cos(angle), math.sin(angle)])


def scene_of(kitchen: Kitchen, trial: Trial) -> SceneConfig:
    """The object in play alone on its surface, the robot at the trial's start."""
    centre = kitchen.surfaces[trial.surface].region.mean(axis=0)
    at = (round(trial.spot[0] - float(centre[0]), 4), round(trial.spot[1] - float(centre[1]), 4))
    placement = Placement(object=trial.object, on=trial.surface, at=at, yaw=math.degrees(trial.yaw))
    return SceneConfig(description="one object", robot_start=trial.start, objects=[placement])


def mission_of(trial: Trial) -> dict:
    name = trial.object
    if trial.task == "throw":
        tree = {"throw_away": {"object": name, "into": trial.into, "side": SIDE}}
    else:
        x, y = trial.place
        tree = {
            "sequence": [
                {"pick": {"object": name, "side": SIDE}},
                {"place": {"surface": trial.surface, "x": x, "y": y, "side": SIDE}},
            ]
        }
    return {"mission": f"benchmark: {trial.task} the {name}", "world": WORLD, "robot": ROBOT, "tree": tree}


def run_trial(kitchen: Kitchen, trial: Trial) -> Outcome:
    stack = told_stack(kitchen.world, kitchen.robot, scene=scene_of(kitchen, trial))
    run = MissionRun(stack, load_mission(mission_of(trial)))
    name = trial.object
    grasped: list[bool] = []

    def on_event(event: dict) -> None:
        ended = event["event"] == "status" and event["new"] != "RUNNING"
        if ended and event.get("node", "").split(">")[-1].endswith(".pick"):
            grasped.append(event["new"] == "SUCCESS" and run.truth.in_hand(name) == SIDE)

    run.events.listeners.append(on_event)
    result = run.execute()
    stack.close()
    truth = run.truth
    succeeded = result.tree_status == "SUCCESS" and truth.in_hand(name) is None
    error = None
    detail = ""
    if trial.task == "throw":
        done = succeeded and truth.inside(name, trial.into)
        if result.tree_status == "SUCCESS" and not done:
            x, y, z = truth.object_centre(name)
            detail = f"ended at ({x:.2f}, {y:.2f}, {z:.2f}), not in the {trial.into}"
    else:
        x, y, _ = truth.object_position(name)
        error = float(np.hypot(x - trial.place[0], y - trial.place[1]))
        upright = truth.upright(name) or not kitchen.world.objects[name].upright
        done = succeeded and truth.rests_on(name, trial.surface) and upright and error <= PLACE_TOLERANCE
        if result.tree_status == "SUCCESS" and not done:
            detail = f"ended {error * 100:.1f} cm from the spot" + ("" if upright else ", tipped over")
    failure = None
    if not done:
        failure = detail or result.cause or result.tree_status
        failure = f"safety stop: {result.safety}" if result.safety else failure
    return Outcome(
        grasped=any(grasped),
        done=done,
        error_cm=round(error * 100, 2) if error is not None and any(grasped) else None,
        failure=failure,
        sim_time=result.sim_time,
    )


def summarize(name: str, trials: list[Trial], outcomes: list[Outcome]) -> dict:
    pairs = list(zip(trials, outcomes, strict=True))
    places = [o for t, o in pairs if t.task == "place"]
    throws = [o for t, o in pairs if t.task == "throw"]
    grasped_places = [o for o in places if o.grasped]
    placed = [o for o in grasped_places if o.done]
    errors = [o.error_cm for o in placed if o.error_cm is not None]
    return {
        "object": name,
        "trials": len(outcomes),
        "grasped": sum(o.grasped for o in outcomes),  # of all trials, pick and place and throw-away
        "place_trials": len(places),
        "place_grasped": len(grasped_places),
        "placed": len(placed),  # of the grasped pick-and-place trials
        "throw_trials": len(throws),
        "thrown": sum(o.done for o in throws),  # into the bin, of all throw-away trials
        "median_place_error_cm": statistics.median(errors) if errors else None,
        "place_errors_cm": errors,
        "by_surface": {
            s: f"{sum(o.done for t, o in pairs if t.task == 'place' and t.surface == s)}/"
            f"{sum(1 for t, _ in pairs if t.task == 'place' and t.surface == s)}"
            for s in SURFACES
        },
        "failures": [{"trial": asdict(t), "failure": o.failure} for t, o in pairs if not o.done],
    }


def overall(summaries: list[dict]) -> dict:
    total = {key: sum(s[key] for s in summaries) for key in summaries[0] if isinstance(summaries[0][key], int)}
    errors = [e for s in summaries for e in s["place_errors_cm"]]
    return {"object": "all", **total, "median_place_error_cm": statistics.median(errors) if errors else None}


def _rate(count: int, of: int) -> str:
    return f"{count}/{of} {count / of:.0%}" if of else "-"


def table(summaries: list[dict]) -> str:
    """Per object and overall: grasps of all trials, placements of the grasped, into the bin of the throw-aways."""
    lines = [
        f"  {'object':17} {'grasp | of all':>16} {'place | of grasped':>19} {'place | of all':>16} "
        f"{'into bin | of all':>18} {'median error':>13}"
    ]
    for s in [*summaries, overall(summaries)]:
        error = f"{s['median_place_error_cm']:.1f} cm" if s["median_place_error_cm"] is not None else "-"
        lines.append(
            f"  {s['object']:17} {_rate(s['grasped'], s['trials']):>16} "
            f"{_rate(s['placed'], s['place_grasped']):>19} {_rate(s['placed'], s['place_trials']):>16} "
            f"{_rate(s['thrown'], s['throw_trials']):>18} {error:>13}"
        )
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = benchmark_parser(__doc__, "trials", 12, "pick-and-place trials per object (the surfaces in turn)")
    parser.add_argument("--throws", type=int, default=10, help="throw-away trials per object (default 10)")
    parser.add_argument("--objects", nargs="+", help="only these objects (default: all sixteen)")
    args = parse_benchmark_args(parser, argv, "trials")
    rng = np.random.default_rng(args.seed)
    kitchen = Kitchen.load()
    names = args.objects or list(kitchen.world.objects)
    unknown = [n for n in names if n not in kitchen.world.objects]
    if unknown:
        parser.error(f"unknown objects: {', '.join(unknown)}")
    print(
        f"bt-humanoid kitchen manipulation benchmark: {args.trials} pick-and-place and {args.throws} throw-away "
        f"trials per object, seed {args.seed}, told (camera off, one core)"
    )
    started = time.perf_counter()
    summaries = []
    for index, name in enumerate(names):
        trials = [
            sample_trial(kitchen, name, "place", SURFACES[(index + i) % len(SURFACES)], rng) for i in range(args.trials)
        ]
        trials += [
            sample_trial(kitchen, name, "throw", SURFACES[(index + i) % len(SURFACES)], rng) for i in range(args.throws)
        ]
        outcomes = []
        for i, trial in enumerate(trials, 1):
            outcome = run_trial(kitchen, trial)
            outcomes.append(outcome)
            verdict = "ok" if outcome.done else f"FAILED: {outcome.failure}"
            where = f"{trial.surface} ({trial.spot[0]:.2f}, {trial.spot[1]:.2f}) yaw {trial.yaw:+.2f}"
            print(f"  {name} {trial.task} {i}/{len(trials)}  {where}: {verdict}", flush=True)
        summaries.append(summarize(name, trials, outcomes))
    figures = {
        "seed": args.seed,
        "objects": summaries,
        "overall": overall(summaries),
        "wall_s": round(time.perf_counter() - started, 1),
    }
    print()
    print(table(summaries))
    print(f"  wall time {figures['wall_s']:.0f} s")
    save_figures(args.json, figures)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
