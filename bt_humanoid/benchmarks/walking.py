"""Walking benchmark: the biped on its own legs in MuJoCo physics, measured in ground truth.

    python -m bt_humanoid.benchmarks.walking --pushes 50     # about 25 minutes on one core

On the open floor (worlds/open_floor), with the walking controller alone (docs/walking.md):

1. straight: 0.3 m/s forwards for ``--seconds`` (60): distance, average speed (and once under way, after 5 s),
   sideways and heading drift, the state estimator's position error per metre walked and its yaw error, the
   inverse-dynamics QP's time per control step (median, p95; DAQP's share), the whole control step's, and the
   real-time factor with physics;
2. a full turn in place at 0.3 rad/s; backwards at 0.15 m/s and sideways at 0.05 m/s for 10 s each; an arc
   (0.25 m/s turning 0.2 rad/s) for 20 s; start and stop (0.3 m/s, a stop in mid-swing): the steps it takes to
   stand, and how far it drifts standing after;
3. pushes on the pelvis of ``--impulse`` (30 N·s: 150 N for 0.2 s) towards random directions, ``--pushes`` while
   standing and as many while walking at ``--push-speed`` (0.3 m/s; at a random moment of the gait): survived
   when nothing of the robot but its feet touches anything and the pelvis stays above 0.4 m for 3 s after it;
   the share survived, and the largest push survived towards each of eight directions while walking
   (bisection to 5 N over 0.2 s).

``--largest-only --push-time 0.3 --directions 4 --phases 8`` measures only the largest push, over 0.3 s (the fetch
suite's shove), towards four directions at eight moments of a stride: how strong a shove the walker takes
depends on which foot is in the air when it comes (docs/walking.md, "Working on legs").

A fall ends a run. Pinned to one core; ``--json PATH`` also writes the figures.
"""

from __future__ import annotations

import argparse
import math
import statistics
import time

import numpy as np

from bt_humanoid.benchmarks.common import benchmark_parser, on_a_foot, parse_benchmark_args, percentile, save_figures
from bt_humanoid.control.walking.walker import Phase, WalkingController
from bt_humanoid.sim.ground_truth import GroundTruth
from bt_humanoid.sim.robot_config import load_robot_config
from bt_humanoid.sim.scene_config import SceneConfig
from bt_humanoid.sim.simulation import Simulation
from bt_humanoid.sim.world_config import load_world_config

ROBOT, WORLD = "biped_humanoid", "open_floor"
STANDING_HEIGHT = 0.4  # m: a pelvis below this has fallen
PUSH_TIME = 0.2  # s
SETTLE = 3.0  # s after a push before judging
LOWEST, HIGHEST, RESOLUTION = 50.0, 400.0, 5.0  # N: the largest-push bisection's bracket and resolution
FIRST_MOMENT, STRIDE = 2.0, 1.4  # s: walking is under way 2 s after setting off; a stride is two 0.7 s steps


class Fell(Exception):
    """The robot fell: a run ends."""


class Trial:
    """The walking controller on the open floor, stepped and watched in ground truth."""

    def __init__(self) -> None:
        self.sim = Simulation(load_world_config(WORLD), load_robot_config(ROBOT), SceneConfig())
        self.truth = GroundTruth(self.sim)
        self.walker = WalkingController(self.sim)
        self.start = self.truth.floating_base()[0].copy()
        self.turned = 0.0
        self._yaw = self.yaw()
        self.pelvis = self.sim.model.body(self.sim.robot_root).id
        self.push = np.zeros(3)
        self.push_until = -1.0
        self.control_times: list[float] = []
        self.estimate_errors: list[tuple[float, float]] = []  # (position m, yaw rad) each control step

    def yaw(self) -> float:
        rotation = self.truth.floating_base()[1]
        return math.atan2(rotation[1, 0], rotation[0, 0])

    def run(self, seconds: float, until=None) -> None:  # until: a predicate that ends the run early
        sim, walker = self.sim, self.walker
        for _ in range(round(seconds / sim.timestep)):
            tick = time.perf_counter()
            walker.step()
            self.control_times.append(time.perf_counter() - tick)
            sim.data.xfrc_applied[self.pelvis, :3] = self.push if sim.time < self.push_until else 0.0
            sim.step()
            yaw = self.yaw()
            self.turned += math.remainder(yaw - self._yaw, 2 * math.pi)
            self._yaw = yaw
            position = self.truth.floating_base()[0]
            state = walker.state
            self.estimate_errors.append(
                (
                    float(np.linalg.norm((state.position - position)[:2])),
                    abs(math.remainder(state.yaw - yaw, 2 * math.pi)),
                )
            )
            if position[2] < STANDING_HEIGHT or any(not on_a_foot(m) for m, _ in self.truth.robot_contacts()):
                raise Fell(f"fell at {sim.time:.2f} s")
            if until is not None and until():
                return

    def moved(self) -> np.ndarray:
        """(forward, leftward) of the pelvis since the start, in the start's frame (it faces +x)."""
        return (self.truth.floating_base()[0] - self.start)[:2]


STEADY_AFTER = 5.0  # s: the straight walk's speed once under way, measured from here to the end


def straight(seconds: float, speed: float = 0.3) -> dict:
    trial = Trial()
    trial.walker.command(speed)
    began = time.perf_counter()
    trial.run(STEADY_AFTER)
    under_way = float(trial.moved()[0])
    trial.run(seconds - STEADY_AFTER)
    wall = time.perf_counter() - began
    forward, sideways = trial.moved()
    walker = trial.walker
    position_errors = [e[0] for e in trial.estimate_errors]
    return {
        "seconds": seconds,
        "commanded_m_s": speed,
        "distance_m": float(forward),
        "average_speed_m_s": float(forward / seconds),
        "steady_speed_m_s": float((forward - under_way) / (seconds - STEADY_AFTER)),
        "sideways_drift_m": float(sideways),
        "heading_drift_deg": math.degrees(trial.turned),
        "steps": len(walker.touchdowns),
        "estimate_error_per_metre": position_errors[-1] / max(float(forward), 1e-9),
        "estimate_worst_error_m": max(position_errors),
        "estimate_worst_yaw_error_deg": math.degrees(max(e[1] for e in trial.estimate_errors)),
        "qp_median_ms": statistics.median(walker.solve_times) * 1e3,
        "qp_p95_ms": percentile(walker.solve_times, 0.95) * 1e3,
        "daqp_median_ms": statistics.median(walker.conic_times) * 1e3,
        "daqp_p95_ms": percentile(walker.conic_times, 0.95) * 1e3,
        "control_step_median_ms": statistics.median(trial.control_times) * 1e3,
        "control_step_p95_ms": percentile(trial.control_times, 0.95) * 1e3,
        "qp_failures": walker.failures,
        "real_time_factor": seconds / wall,
    }


def turn_in_place() -> dict:
    trial = Trial()
    trial.walker.command(0.0, 0.0, 0.3)
    trial.run(60.0, until=lambda: trial.turned >= 2 * math.pi)
    seconds = trial.sim.time
    trial.walker.brake()
    trial.run(3.0)
    return {
        "seconds_for_360": seconds,
        "steps": len(trial.walker.touchdowns),
        "drift_m": float(np.linalg.norm(trial.moved())),
    }


def constant(command: tuple[float, float, float], seconds: float) -> dict:
    trial = Trial()
    trial.walker.command(*command)
    trial.run(seconds)
    forward, sideways = trial.moved()
    return {
        "forward_m": float(forward),
        "leftward_m": float(sideways),
        "turned_deg": math.degrees(trial.turned),
        "seconds": seconds,
    }


def start_stop() -> dict:
    trial = Trial()
    trial.walker.command(0.3)
    trial.run(3.0, until=lambda: trial.sim.time > 3.0 and trial.walker.phase is Phase.SINGLE)
    taken = len(trial.walker.touchdowns)
    braked = trial.sim.time
    trial.walker.brake()
    trial.run(5.0, until=lambda: trial.walker.phase is Phase.STANDING)
    stood = trial.sim.time
    standing = trial.truth.floating_base()[0].copy()
    trial.run(3.0)
    return {
        "steps_after_stop": len(trial.walker.touchdowns) - taken,
        "seconds_to_stand": stood - braked,
        "drift_standing_m": float(np.linalg.norm((trial.truth.floating_base()[0] - standing)[:2])),
    }


def survives(force: float, direction: float, speed: float, at: float, push_time: float = PUSH_TIME) -> bool:
    """A push of ``force`` N for ``push_time`` s towards ``direction`` (rad, world; the robot faces +x) at ``at`` s."""
    trial = Trial()
    if speed > 0.0:
        trial.walker.command(speed)
    try:
        trial.run(at)
        trial.push = force * np.array([math.cos(direction), math.sin(direction), 0.0])
        trial.push_until = trial.sim.time + push_time
        trial.run(push_time + SETTLE)
    except Fell:
        return False
    return True


def pushes(count: int, impulse: float, speed: float, rng: np.random.Generator, push_time: float = PUSH_TIME) -> dict:
    """``count`` pushes of ``impulse`` N·s over ``push_time`` s towards random directions at random moments (2 to
    3.4 s: a stride once walking has started)."""
    force = impulse / push_time
    survived = []
    for i in range(count):
        direction, at = float(rng.uniform(0.0, 2 * math.pi)), float(rng.uniform(FIRST_MOMENT, FIRST_MOMENT + STRIDE))
        ok = survives(force, direction, speed, at, push_time)
        survived.append(ok)
        print(
            f"    push {i + 1}/{count} {'walking' if speed else 'standing'} towards {math.degrees(direction):5.1f}° "
            f"at {at:.2f} s: {'survived' if ok else 'fell'}",
            flush=True,
        )
    return {"pushes": count, "impulse_N_s": impulse, "speed_m_s": speed, "survived": sum(survived)}


def largest_push(direction_deg: float, speed: float, at: float = 2.5, push_time: float = PUSH_TIME) -> float:
    """The largest force (N, for ``push_time`` s) survived towards ``direction_deg`` while walking at ``speed``,
    pushed ``at`` s after setting off."""
    low, high = LOWEST, HIGHEST
    direction = math.radians(direction_deg)
    if not survives(low, direction, speed, at, push_time):
        return 0.0
    while high - low > RESOLUTION:
        middle = (low + high) / 2
        low, high = (middle, high) if survives(middle, direction, speed, at, push_time) else (low, middle)
    return low


def push_moments(phases: int) -> list[float]:
    """When the largest push comes (s after setting off): 2.5 s for one; else ``phases`` moments spread over one
    stride (two steps) once walking is under way, from 2.0 s."""
    if phases == 1:
        return [2.5]
    return [round(FIRST_MOMENT + STRIDE * i / phases, 3) for i in range(phases)]


def largest_pushes(directions: int, phases: int, speed: float, push_time: float) -> dict:
    """The largest push survived towards each of ``directions`` directions, at each of ``push_moments(phases)``:
    {direction (deg): {moment (s): N·s}} (N for ``push_time`` s before: N·s is what compares across durations)."""
    largest: dict[str, dict[str, float]] = {}
    for i in range(directions):
        direction = 360.0 * i / directions
        largest[f"{direction:g}"] = row = {}
        for at in push_moments(phases):
            row[f"{at:g}"] = largest_push(direction, speed, at, push_time) * push_time
            print(
                f"  largest push walking towards {direction:5.1f}° at {at:.2f} s: {row[f'{at:g}']:.1f} N·s", flush=True
            )
    return largest


def _run(name: str, function, *args) -> dict:
    try:
        figures = function(*args)
    except Fell as fall:
        figures = {"fell": str(fall)}
    print(f"  {name}: {figures}", flush=True)
    return figures


def _at_least_one(text: str) -> int:
    value = int(text)
    if value < 1:
        raise argparse.ArgumentTypeError(f"{value} is not a count: give 1 or more")
    return value


def _seconds(text: str) -> float:
    value = float(text)
    if not 0.0 < value <= 2.0:
        raise argparse.ArgumentTypeError(f"{value} s is not a push's length: give more than 0 and at most 2")
    return value


def main(argv: list[str] | None = None) -> int:
    parser = benchmark_parser(__doc__, "pushes", 50, "random pushes while standing and again while walking")
    parser.add_argument("--seconds", type=float, default=60.0, help="straight walking (default 60 s)")
    parser.add_argument(
        "--speed", type=float, default=0.3, help="straight walking's commanded speed (default 0.3 m/s; it makes 0.298)"
    )
    parser.add_argument("--impulse", type=float, default=30.0, help="N·s of each random push (default 30)")
    parser.add_argument("--push-speed", type=float, default=0.3, help="walking speed pushed at (default 0.3 m/s)")
    parser.add_argument("--directions", type=int, default=8, help="directions of the largest push (0: none)")
    parser.add_argument(
        "--phases",
        type=_at_least_one,
        default=1,
        help="moments of a stride the largest push comes at (default 1: at 2.5 s)",
    )
    parser.add_argument(
        "--push-time", type=_seconds, default=PUSH_TIME, help=f"s each push lasts (default {PUSH_TIME:g})"
    )
    parser.add_argument("--largest-only", action="store_true", help="measure only the largest push")
    args = parse_benchmark_args(parser, argv, "pushes")
    began = time.perf_counter()
    print(f"bt-humanoid walking benchmark ({ROBOT} on {WORLD}), seed {args.seed}")
    figures: dict = {"push_time_s": args.push_time}
    if not args.largest_only:
        figures |= {
            "straight": _run(
                f"straight at {args.speed:g} m/s for {args.seconds:g} s", straight, args.seconds, args.speed
            ),
            "turn_in_place": _run("a full turn in place at 0.3 rad/s", turn_in_place),
            "backwards": _run("backwards at 0.15 m/s for 10 s", constant, (-0.15, 0.0, 0.0), 10.0),
            "sideways": _run("sideways at 0.05 m/s for 10 s", constant, (0.0, 0.05, 0.0), 10.0),
            "arc": _run("an arc at 0.25 m/s, 0.2 rad/s for 20 s", constant, (0.25, 0.0, 0.2), 20.0),
            "start_stop": _run("start and stop", start_stop),
        }
        rng = np.random.default_rng(args.seed)
        force = args.impulse / args.push_time
        print(f"  pushes of {args.impulse:g} N·s ({force:.0f} N for {args.push_time:g} s):")
        figures["pushes_standing"] = pushes(args.pushes, args.impulse, 0.0, rng, args.push_time)
        figures["pushes_walking"] = pushes(args.pushes, args.impulse, args.push_speed, rng, args.push_time)
        for key in ("pushes_standing", "pushes_walking"):
            result = figures[key]
            print(f"  {key}: survived {result['survived']}/{result['pushes']}", flush=True)
    figures["largest_push_walking_N_s"] = largest_pushes(args.directions, args.phases, args.push_speed, args.push_time)
    figures["wall_s"] = round(time.perf_counter() - began, 1)
    print(f"  wall time {figures['wall_s']:.0f} s")
    save_figures(args.json, figures)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
