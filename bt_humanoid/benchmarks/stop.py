"""Stop benchmark: how fast a typed or spoken "stop" brings every motion to rest, in mid-motion.

    python -m bt_humanoid.benchmarks.stop --trials 25

Each trial runs one of several missions planned from commands (drive to the
kitchen or the living room, turn around, wave, pick up the red cube) and, at a
random moment while the robot moves faster than 5 cm/s, delivers "stop" the
way the terminal does: it is planned (the planner answers "stop") and the
run's stop request is raised. Latency is simulation time from that moment to
every joint and base speed below 1 cm/s (or rad/s), measured at every
control step. Prints the median, p95 and worst latency and the speed when
the stop came (for a spoken one: when the person began to say it). Pinned
to one CPU core; ``--json PATH`` also writes the figures.
"""

from __future__ import annotations

import statistics
import time

import mujoco
import numpy as np

from bt_humanoid.benchmarks.common import benchmark_parser, parse_benchmark_args, percentile, save_figures
from bt_humanoid.control.base_driver import BRAKE_ACCEL
from bt_humanoid.engine.runner import MissionRun
from bt_humanoid.engine.stack import RobotStack
from bt_humanoid.language.asr import CommandRecognizer
from bt_humanoid.language.audio import RATE, spoken, with_noise
from bt_humanoid.language.embedded import EmbeddedPlanner, is_stop
from bt_humanoid.language.listening import Listener
from bt_humanoid.language.plan import PlanningContext
from bt_humanoid.mission.loader import MissionLoader
from bt_humanoid.sim.simulation import Simulation

COMMANDS = (  # from the start pose; walking straight ahead would meet the storage box (move_base does not steer)
    "go to the kitchen",
    "go to the living room",
    "turn around",
    "wave three times",
    "pick up the red cube",
)
VOICES = ("en-us", "en-gb")
SNR_DB = 20.0
MOVING = 0.05  # m/s (or rad/s): the robot counts as in motion above this
EARLIEST = 1.0  # s of simulation before a stop may come


def braking_margin(world: str, robot: str) -> dict[str, float]:
    """How hard the base brakes against the deceleration that would tip the robot forward on a real floor.

    The base here slides on joints and cannot tip, so this is checked from the model instead: at its start
    posture the robot tips over the front edge of its base (the narrowest cylinder of the base body, its
    support) when deceleration × height of the centre of mass exceeds g × the centre's distance to that edge.
    """
    sim = Simulation.load(world, robot)
    model, data = sim.model, sim.data
    mujoco.mj_forward(model, data)
    base = int(model.body_rootid[model.joint(sim.robot.base.joints["x"]).bodyid[0]])
    cylinder = mujoco.mjtGeom.mjGEOM_CYLINDER
    radii = [
        model.geom_size[g][0]
        for g in range(model.ngeom)
        if model.geom_bodyid[g] == base and model.geom_type[g] == cylinder
    ]
    support = float(min(radii))
    centre = data.xmat[base].reshape(3, 3).T @ (data.subtree_com[base] - data.xpos[base])  # in the base's frame
    return {
        "brake_accel": BRAKE_ACCEL * sim.robot.base.limits.max_accel,
        "tip_accel": 9.81 * (support - float(centre[0])) / float(centre[2]),
        "mass": float(model.body_subtreemass[base]),
        "com_height": float(centre[2]),
        "com_ahead": float(centre[0]),
        "support_radius": support,
    }


class SpokenStop:
    """ "stop" said into a listener from a moment on, the sound fed as simulation time passes."""

    def __init__(self, listener: Listener, speech: np.ndarray, rng: np.random.Generator) -> None:
        lead = np.zeros(RATE // 2, dtype=np.int16)  # the room before the word: the detector settles
        self.sound = with_noise(np.concatenate([lead, speech, np.zeros(RATE, dtype=np.int16)]), SNR_DB, rng)
        self.word_end = (len(lead) + np.nonzero(speech)[0][-1] + 1) / RATE  # s into the sound
        self.listener = listener
        self.fed = 0
        self.started: float | None = None

    def heard_stop(self, now: float) -> bool:
        """Feed the sound up to simulation time ``now``; whether the listener has spotted the stop."""
        if self.started is None:
            self.started = now  # the sound starts when it is first asked for
        upto = min(int((now - self.started) * RATE), len(self.sound))
        heard = self.listener.feed(self.sound[self.fed : upto]) if upto > self.fed else []
        self.fed = max(self.fed, upto)
        return any(item.kind == "stop" for item in heard)


def stop_trial(
    command: str, context: PlanningContext, rng: np.random.Generator, spoken_stop: SpokenStop | None = None
) -> tuple[float, float, float] | None:
    """(latency s, speed when stopped, s from the end of the word to the stop request) for one run of ``command``
    stopped at a random moving moment (the last is 0 for a typed stop)."""
    plan = EmbeddedPlanner().plan(command, context)
    stack = RobotStack.load("apartment", "wheeled_humanoid")
    run = MissionRun(stack, MissionLoader.for_plans().load_data(plan.mission))
    stop_after = EARLIEST + float(rng.uniform(0.0, 3.0))
    state: dict[str, float] = {}

    def watch() -> None:
        now, speed = run.sim.time, run.robot.max_speed()
        if "stopped" not in state and now >= stop_after and (speed > MOVING or "word_end" in state):
            # a spoken stop keeps listening until it is heard: the person has begun to speak
            if spoken_stop is None:
                if is_stop("stop"):  # what the terminal does with a typed line
                    run.request_stop("stop (typed)")
                    state["stopped"], state["speed"] = now, speed
            else:
                if "word_end" not in state:  # the sound starts now; the word ends a little later
                    state["speed"] = speed
                    state["word_end"] = now + spoken_stop.word_end
                if spoken_stop.heard_stop(now):
                    run.request_stop("stop (spoken)")
                    state["stopped"], state["spotted"] = state["word_end"], now - state["word_end"]
        elif "stopped" in state and "rest" not in state and run.robot.at_rest():
            state["rest"] = now

    stack.observers.append(watch)
    run.execute()
    stack.close()
    if spoken_stop is not None:
        spoken_stop.listener.close()  # the recogniser is shared by the trials
    if "stopped" not in state or "rest" not in state:
        return None  # finished before a moving moment came, or never came to rest (reported)
    return state["rest"] - state["stopped"], state["speed"], state.get("spotted", 0.0)


def main(argv: list[str] | None = None) -> int:
    parser = benchmark_parser(__doc__, "trials", 25, "stopped runs")
    parser.add_argument("--spoken", action="store_true", help='say "stop" into the listener instead of typing it')
    args = parse_benchmark_args(parser, argv, "trials")
    rng = np.random.default_rng(args.seed)
    looking = RobotStack.load("apartment", "wheeled_humanoid")
    looking.look()
    context = looking.planning_context()  # what bt-run --command plans with: one look from the start pose
    looking.close()
    recognizer = CommandRecognizer(context.world) if args.spoken else None
    how = "spoken" if args.spoken else "typed"
    print(f"bt-humanoid stop benchmark: {args.trials} {how} stops in mid-motion, seed {args.seed} (one core)")
    margin = braking_margin("apartment", "wheeled_humanoid")
    print(
        f"  the base brakes at {margin['brake_accel']:.1f} m/s²; the robot would tip forward at "
        f"{margin['tip_accel']:.1f} m/s² ({margin['mass']:.0f} kg, centre of mass {margin['com_height']:.2f} m up and "
        f"{margin['com_ahead']:.2f} m ahead of the base centre, support radius {margin['support_radius']:.2f} m)"
    )
    started = time.perf_counter()
    latencies: list[float] = []
    speeds: list[float] = []
    spotting: list[float] = []
    missed = 0
    for index in range(args.trials):
        command = COMMANDS[index % len(COMMANDS)]
        said = None
        if recognizer is not None:
            said = SpokenStop(Listener(recognizer), spoken("stop", VOICES[index % len(VOICES)]), rng)
        outcome = stop_trial(command, context, rng, said)
        if outcome is None:
            missed += 1
            print(f"  {index + 1}/{args.trials} {command!r}: no stop in mid-motion (finished first or kept moving)")
            continue
        latency, speed, spotted = outcome
        latencies.append(latency)
        speeds.append(speed)
        spotting.append(spotted)
        heard = f"heard {spotted * 1000:.0f} ms after the word, " if said is not None else ""
        print(
            f"  {index + 1}/{args.trials} {command!r}: stopped at {speed:.2f} m/s, "
            f"{heard}at rest after {latency * 1000:.0f} ms"
        )
    figures = {
        "trials": args.trials,
        "stopped": len(latencies),
        "missed": missed,
        "latency_median_ms": statistics.median(latencies) * 1000 if latencies else None,
        "latency_p95_ms": percentile(latencies, 0.95) * 1000 if latencies else None,
        "latency_max_ms": max(latencies) * 1000 if latencies else None,
        "speed_at_stop_median": statistics.median(speeds) if speeds else None,
        "spotting_median_ms": statistics.median(spotting) * 1000 if args.spoken and spotting else None,
        **{f"braking_{key}": round(value, 3) for key, value in margin.items()},
        "wall_s": round(time.perf_counter() - started, 1),
    }
    print()
    if latencies:
        print(
            f"  stop → every speed below 1 cm/s: median {figures['latency_median_ms']:.0f} ms, "
            f"p95 {figures['latency_p95_ms']:.0f} ms, worst {figures['latency_max_ms']:.0f} ms of simulation time "
            f"(target median ≤ 300 ms) over {len(latencies)} stops"
        )
        if args.spoken:
            print(f"  of which the listener spotting the word: median {figures['spotting_median_ms']:.0f} ms")
    save_figures(args.json, figures)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
