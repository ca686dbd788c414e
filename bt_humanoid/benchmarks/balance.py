"""Standing balance benchmark: the biped held up by the inverse-dynamics QP alone, measured in ground truth.

    python -m bt_humanoid.benchmarks.balance --directions 8          # about 6 minutes on one core

1. Standing still for ``--seconds`` (10): the pelvis's drift, the state estimator's worst position and velocity
   error (after the first 0.1 s, while the soles settle into the floor), the QP's solve time per control step
   (median, p95; the QP alone, built and solved, and DAQP's share) and of the whole control step (estimator,
   dynamics, QP, commands), and the real-time factor of the loop with physics.
2. Pushes on the pelvis for 0.2 s towards ``--directions`` directions evenly spread round the robot's heading
   (0° forward, 90° to its left): the largest force it survives in each, by bisection to 5 N. Survived: no robot
   geom but a sole touches anything, the soles neither step nor slip 1 cm, and 3 s after the push the DCM is back
   within 2 cm of the middle of the feet with no QP failure.

The robot stands on an open stretch of the apartment's floor (the kitchen end, 2 m from anything). Pinned to one
core; ``--json PATH`` also writes the figures.
"""

from __future__ import annotations

import math
import statistics
import time

import numpy as np

from bt_humanoid.benchmarks.common import benchmark_parser, parse_benchmark_args, percentile, save_figures
from bt_humanoid.control.walking.balance import BalanceController
from bt_humanoid.sim.ground_truth import GroundTruth
from bt_humanoid.sim.robot_config import load_robot_config
from bt_humanoid.sim.scene_config import SceneConfig
from bt_humanoid.sim.simulation import Simulation
from bt_humanoid.sim.world_config import load_world_config

ROBOT = "biped_humanoid"
START = (6.5, -0.5, 30.0)
PUSH_AT = 1.0  # s after the start
PUSH_TIME = 0.2  # s
SETTLE = 3.0  # s after the push before judging
LOWEST, HIGHEST, RESOLUTION = 50.0, 500.0, 5.0  # N: the bisection's bracket and resolution
SETTLED = 0.1  # s: the soles sink into the soft floor at the start (tests/test_estimator.py); errors count after


def _sim() -> Simulation:
    return Simulation(load_world_config("apartment"), load_robot_config(ROBOT), SceneConfig(robot_start=START))


def _on_its_soles(truth: GroundTruth) -> bool:
    return all("_sole_" in mine for mine, _ in truth.robot_contacts())


def standing(seconds: float) -> dict:
    """Stand still: drift, estimation error, solve and control-step times, real-time factor."""
    sim = _sim()
    truth = GroundTruth(sim)
    controller = BalanceController(sim)
    start = truth.floating_base()[0]
    steps, control_times = round(seconds / sim.timestep), []
    worst_position = worst_velocity = 0.0
    began = time.perf_counter()
    for _ in range(steps):
        tick = time.perf_counter()
        controller.step()
        control_times.append(time.perf_counter() - tick)
        if sim.time >= SETTLED:
            position, _, velocity, _ = truth.floating_base()  # the state the controller just estimated
            state = controller.state
            worst_position = max(worst_position, float(np.linalg.norm(state.position - position)))
            worst_velocity = max(worst_velocity, float(np.linalg.norm(state.linear_velocity - velocity)))
        sim.step()
    wall = time.perf_counter() - began  # includes the ground-truth reads, a few µs a step
    solve = controller.solve_times
    return {
        "seconds": seconds,
        "drift_m": float(np.linalg.norm(truth.floating_base()[0] - start)),
        "upright": _on_its_soles(truth),
        "qp_failures": controller.failures,
        "estimate_position_error_m": worst_position,
        "estimate_velocity_error_m_s": worst_velocity,
        "qp_median_ms": statistics.median(solve) * 1e3,
        "qp_p95_ms": percentile(solve, 0.95) * 1e3,
        "daqp_median_ms": statistics.median(controller.conic_times) * 1e3,
        "daqp_p95_ms": percentile(controller.conic_times, 0.95) * 1e3,
        "control_step_median_ms": statistics.median(control_times) * 1e3,
        "control_step_p95_ms": percentile(control_times, 0.95) * 1e3,
        "real_time_factor": seconds / wall,
    }


def survives(force: float, direction_deg: float) -> bool:
    """One push of ``force`` N for PUSH_TIME towards ``direction_deg`` of the robot's heading."""
    sim = _sim()
    truth = GroundTruth(sim)
    controller = BalanceController(sim)
    soles = [leg.sole for leg in (sim.robot.legs.left, sim.robot.legs.right)]  # type: ignore[union-attr]
    feet = [sim.data.site(s).xpos[:2].copy() for s in soles]
    pelvis = sim.model.body("pelvis").id
    angle = math.radians(START[2] + direction_deg)
    push = force * np.array([math.cos(angle), math.sin(angle), 0.0])
    for _ in range(round((PUSH_AT + PUSH_TIME + SETTLE) / sim.timestep)):
        controller.step()
        sim.data.xfrc_applied[pelvis, :3] = push if PUSH_AT <= sim.time < PUSH_AT + PUSH_TIME else 0.0
        sim.step()
        if not _on_its_soles(truth):
            return False
    if controller.failures:
        return False
    if any(np.linalg.norm(sim.data.site(s).xpos[:2] - f) > 0.01 for s, f in zip(soles, feet, strict=True)):
        return False
    return bool(np.linalg.norm(controller.dcm() - (feet[0] + feet[1]) / 2) < 0.02)


def largest_push(direction_deg: float) -> float:
    """The largest force (N, for PUSH_TIME) survived towards ``direction_deg``: bisection, assuming that a robot
    that survives a push survives any smaller one (checked at the bracket's low end only)."""
    low, high = LOWEST, HIGHEST
    if not survives(low, direction_deg):
        return 0.0
    while high - low > RESOLUTION:
        middle = (low + high) / 2
        low, high = (middle, high) if survives(middle, direction_deg) else (low, middle)
    return low


def main(argv: list[str] | None = None) -> int:
    parser = benchmark_parser(__doc__, "directions", 8, "push directions round the robot")
    parser.add_argument("--seconds", type=float, default=10.0, help="how long it stands still (default 10)")
    args = parse_benchmark_args(parser, argv, "directions")
    still = standing(args.seconds)
    print(
        f"standing {args.seconds:.0f} s: drift {still['drift_m'] * 1e3:.2f} mm, "
        f"estimate within {still['estimate_position_error_m'] * 1e3:.2f} mm and "
        f"{still['estimate_velocity_error_m_s'] * 1e3:.1f} mm/s, QP failures {still['qp_failures']}"
    )
    print(
        f"QP per control step: median {still['qp_median_ms']:.3f} ms, p95 {still['qp_p95_ms']:.3f} ms "
        f"(DAQP itself {still['daqp_median_ms']:.3f}, {still['daqp_p95_ms']:.3f}); "
        f"whole control step: median {still['control_step_median_ms']:.3f} ms, "
        f"p95 {still['control_step_p95_ms']:.3f} ms; real-time factor {still['real_time_factor']:.2f}"
    )
    pushes = {}
    for i in range(args.directions):
        direction = 360.0 * i / args.directions
        pushes[direction] = largest_push(direction)
        print(
            f"push towards {direction:5.1f}°: survives {pushes[direction]:.0f} N for {PUSH_TIME} s "
            f"({pushes[direction] * PUSH_TIME:.0f} N·s)",
            flush=True,
        )
    save_figures(args.json, {"standing": still, "largest_push_N": {f"{d:g}": f for d, f in pushes.items()}})
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
