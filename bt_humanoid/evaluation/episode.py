"""One evaluation episode: draw the scene, plan the command, inject the fault, run, judge in ground truth.

``run_episode(suite_file, index)`` is all a worker process needs: the suite
is loaded again in the worker, and everything the episode draws comes from
``(suite seed, index)``, so episodes do not depend on which worker runs them
or in what order. The result is a plain dict (JSON, and picklable for
process pools and Ray).
"""

from __future__ import annotations

import math
import statistics
import time
from functools import cache
from pathlib import Path
from typing import Any

import mujoco
import numpy as np

from bt_humanoid.benchmarks.common import FALLEN_HEIGHT, on_a_foot
from bt_humanoid.benchmarks.navigation import free_start
from bt_humanoid.commanding import plan_command
from bt_humanoid.control.motion import REST_SPEED
from bt_humanoid.control.stance import deepest_reach
from bt_humanoid.engine.runner import MissionRun
from bt_humanoid.engine.stack import RobotStack
from bt_humanoid.engine.verdict import check_condition
from bt_humanoid.evaluation import faults as fault_kinds
from bt_humanoid.evaluation.suite import Suite, Task, fill, load_suite, suite_scene
from bt_humanoid.mission.loader import MissionLoader
from bt_humanoid.mission.schema import MissionHeader, OnCondition, UprightCondition
from bt_humanoid.sim.scene_config import Placement, SceneConfig
from bt_humanoid.testing.scene import place_object
from bt_humanoid.testing.spots import nudge, reachable_spot


@cache
def _suite(path: str, scene: str | None = None, robot: str | None = None) -> Suite:
    return load_suite(Path(path), scene, robot)[0]


@cache
def _probe(world: str, robot: str) -> RobotStack:
    """The bare world's stack: its map and surfaces, for drawing scenes (one per worker)."""
    stack = RobotStack.load(world, robot)
    stack.close()
    return stack


class Draw:
    """What one episode drew: task, names, start, spots, fault."""

    def __init__(self, suite: Suite, index: int) -> None:
        self.index = index
        rng = np.random.default_rng([suite.seed, index])
        self.rng = rng
        weights = np.array([task.weight for task in suite.tasks])
        self.task_index = int(rng.choice(len(suite.tasks), p=weights / weights.sum()))
        self.obj = str(rng.choice(suite.objects)) if suite.objects else ""
        self.start_surface = str(rng.choice(suite.randomize.object_on)) if suite.randomize.object_on else None
        others = [s for s in suite.surfaces if s != self.start_surface] or suite.surfaces
        self.surface = str(rng.choice(others)) if others else ""
        kinds = len(suite.faults.kinds)
        self.fault_index: int | None = None
        if kinds and rng.uniform() < suite.faults.share:
            self.fault_index = index % kinds if suite.faults.order == "cycle" else int(rng.integers(kinds))
        self.side_sign = float(rng.choice([-1.0, 1.0]))
        #: the fault's strengths (a span's value): a stream of their own, so the scene draws stay as they were
        self.fault_rng = np.random.default_rng([suite.seed, index, 1])
        self.spare_spots: list[np.ndarray] = []  # filled at set-up: where a moved object may go

    @property
    def slots(self) -> dict[str, str]:
        return {"object": self.obj, "surface": self.surface}


def run_episode(
    suite_file: str,
    index: int,
    seed: int | None = None,
    events: list[dict[str, Any]] | None = None,
    scene: str | None = None,
    plan_only: bool = False,
    robot: str | None = None,
) -> dict[str, Any]:
    """Run episode ``index`` of the suite in ``suite_file`` (its seed, or ``seed``; its scene, or ``scene``: a
    name, or a file's absolute path; its robot, or ``robot``); figures and verdict as a dict.

    ``events``, when given, receives the run's event log (tests look at how a fault was recovered from).
    """
    started, cpu_started = time.perf_counter(), time.process_time()
    suite = _suite(suite_file, scene, robot)
    if seed is not None:
        suite = suite.model_copy(update={"seed": seed})
    if suite.instructions:
        from bt_humanoid.evaluation.household import run_instruction  # it builds on this module's judging

        return run_instruction(suite, suite_file, index, plan_only)
    draw = Draw(suite, index)
    task = suite.tasks[draw.task_index]
    fault = suite.faults.kinds[draw.fault_index] if draw.fault_index is not None else None
    record: dict[str, Any] = {
        "episode": index,
        "task": task.command or task.mission,
        "command": fill(task.command, draw.slots) if task.command else None,
        "object": draw.obj or None,
        "surface": draw.surface or None,
        "fault": fault.kind if fault else None,
    }
    stack = _set_up(suite, draw, record)
    try:
        record |= _play(suite, suite_file, task, draw, fault, stack)
        record["object_on_floor"] = stack.truth.on_floor(draw.obj) if draw.obj else None
        if events is not None:
            events.extend(stack.events.events)
    finally:
        stack.close()
    record["wall_s"] = round(time.perf_counter() - started, 3)
    # CPU seconds too: the real-time factor per core stays true when the episode shares its core with other work
    record["cpu_s"] = round(time.process_time() - cpu_started, 3)
    return record


def _set_up(suite: Suite, draw: Draw, record: dict[str, Any]) -> RobotStack:
    """The episode's robot stack, its scene drawn: obstacles nudged, the object on a random spot, a random start.

    The stack's seed (route planning) comes from the suite's seed and the episode's index, like everything else
    the episode draws, without taking numbers from the draw's own generator.
    """
    probe = _probe(suite.world, suite.robot)
    rng, world = draw.rng, probe.world
    start = free_start(probe.navigator.grid, world, rng) if suite.randomize.start == "random" else None
    seed = int(np.random.SeedSequence([suite.seed, draw.index]).generate_state(1)[0])
    scene = suite_scene(suite, world)
    if suite.randomize.scene is not None:
        scene = _random_scene(suite, draw, probe, scene)
        record["scene"] = [placement.object for placement in scene.objects]
    run = RobotStack.load(suite.world, suite.robot, seed, robot_start=start, scene=scene)
    model = run.sim.model
    for name in suite.randomize.obstacles:  # the furniture rearranged, and the robot's floor plan redrawn
        body = model.body(name).id
        model.body_pos[body] = nudge(model.body_pos[body], suite.randomize.obstacle_shift, rng)
    if suite.randomize.obstacles:
        mujoco.mj_forward(model, run.sim.data)
        run.navigator.remap()
    record["start"] = list(start) if start else None
    if draw.start_surface is None or not draw.obj:
        return run
    surface = run.context.world_model.surface(draw.start_surface)
    base = run.context.robot_config.base
    footprint, bounds, depth = base.footprint_radius, np.array(world.bounds), deepest_reach(base)

    def spot_among(others: list[np.ndarray]) -> np.ndarray:  # where this robot's hand reaches
        return reachable_spot(surface, probe.navigator.grid, footprint, bounds, others, rng, depth)

    objects = list(run.sim.object_bodies)  # the run's: the world's fixed bodies, or its scene's
    if suite.randomize.scene is None:  # a random scene already put it at a reachable spot on that surface
        spot = spot_among([run.truth.object_position(o) for o in objects if o != draw.obj])
        place_object(run, draw.obj, float(spot[0]), float(spot[1]), float(rng.uniform(-math.pi, math.pi)))
    spot = run.truth.object_position(draw.obj)
    record["object_at"] = [draw.start_surface, round(float(spot[0]), 3), round(float(spot[1]), 3)]
    others = [run.truth.object_position(o) for o in objects]  # the object included, where it now stands
    for _ in range(5):  # spots a fault may move it to
        try:
            draw.spare_spots.append(spot_among(others + draw.spare_spots))
        except ValueError:
            break
    return run


def _random_scene(suite: Suite, draw: Draw, probe: RobotStack, base: SceneConfig | None) -> SceneConfig:
    """The episode's own scene: the suite's start and held object, with objects drawn anew at spots the right
    hand reaches (``reachable_spot``), the episode's object first (on its start surface, when the suite names
    some). An object with no reachable spot left on its surface is left out."""
    settings = suite.randomize.scene
    assert settings is not None
    rng, world = draw.rng, probe.world
    belief = probe.context.world_model
    footprint, bounds = probe.context.robot_config.base.footprint_radius, np.array(world.bounds)
    depth = deepest_reach(probe.context.robot_config.base)
    fewest, most = settings.objects
    count = int(rng.integers(fewest, most + 1))
    among = settings.among or world.placeable
    # the episode's object is the only one of its kind: "put the coke on the counter" names one thing, and its
    # verdict judges that one (a second coke might stand there from the start)
    others = [name for name in among if name != draw.obj] or among
    chosen = [draw.obj] if draw.obj else []
    chosen += [str(name) for name in rng.choice(others, size=count - len(chosen))] if count > len(chosen) else []
    placements: list[Placement] = []
    taken: list[np.ndarray] = []
    for index, name in enumerate(chosen):
        first = index == 0 and draw.obj and draw.start_surface is not None
        on = draw.start_surface if first else str(rng.choice(settings.surfaces))
        surface = belief.surface(on)
        try:
            spot = reachable_spot(surface, probe.navigator.grid, footprint, bounds, taken, rng, depth)
        except ValueError:
            if index == 0 and draw.obj:
                raise
            continue
        taken.append(spot)
        at = spot - (surface.region[0] + surface.region[1]) / 2
        yaw = float(rng.uniform(-180.0, 180.0))
        placements.append(Placement(object=name, on=on, at=(float(at[0]), float(at[1])), yaw=yaw))
    start = base or SceneConfig()
    return SceneConfig(
        robot_start=start.robot_start, holding=start.holding, objects=placements, name=f"random {draw.index}"
    )


def _play(suite: Suite, suite_file: str, task: Task, draw: Draw, fault, stack: RobotStack) -> dict[str, Any]:
    """Plan (for commands), run with the fault armed, follow a new command if one arrives, and judge."""
    figures: dict[str, Any] = {"plan_ms": [], "stop_latency_s": None}
    stack.look()
    expect = fill(task.expect, draw.slots)
    spec = _mission(suite, suite_file, task, draw, stack, figures)
    if isinstance(spec, str):
        return episode_verdict(stack, None, figures, expect, failure=spec)
    run = MissionRun(stack, spec)
    injector = _arm(fault, run, draw) if fault is not None else None
    touched = watch_people(run, stack)
    fell = watch_balance(run, stack)
    believed = watch_localisation(run, stack)
    result = run.execute()
    if isinstance(injector, fault_kinds.NewCommand) and injector.fired is not None:
        rest = next((e["t"] for e in reversed(result.events.events) if e["event"] in ("rest", "moving")), None)
        figures["stop_latency_s"] = round(rest - injector.fired.time, 3) if rest is not None else None
        command = fill(injector.settings.command, draw.slots)
        expect = fill(injector.settings.expect, draw.slots)
        follow = _planned(command, suite, stack, figures)
        if isinstance(follow, str):
            return episode_verdict(
                stack,
                result,
                figures,
                expect,
                failure=follow,
                injector=injector,
                touched=touched,
                fell=fell,
                believed=believed,
            )
        result = MissionRun(stack, follow).execute()
    return episode_verdict(
        stack, result, figures, expect, injector=injector, touched=touched, fell=fell, believed=believed
    )


def watch_people(run: MissionRun, stack: RobotStack) -> list[float]:
    """The simulation times at which the robot touches a person, filled while the run steps. A hand-over's touch,
    the robot's hand on the person's hand, is part of it and not counted."""
    model = run.sim.model
    on_person = np.isin(model.geom_bodyid, sorted(run.truth.people_bodies()))  # per geom
    on_robot = np.isin(model.geom_bodyid, sorted(run.sim.robot_bodies))  # per geom
    hand = run.truth.hand_geoms()
    touched: list[float] = []

    def watch() -> None:  # every control step: vectorised over the contacts
        contacts = run.sim.data.contact
        g1, g2 = contacts.geom1, contacts.geom2
        touching = (on_person[g1] & on_robot[g2]) | (on_person[g2] & on_robot[g1])
        if np.any(touching & ~(hand[g1] & hand[g2])):
            touched.append(run.sim.time)

    stack.observers.append(watch)
    return touched


def watch_localisation(run: MissionRun, stack: RobotStack) -> list[float]:
    """How far (cm) the robot's belief of where its base is lies from where it is, every control step, filled
    while the run steps; empty for a robot whose base pose is exact (--ideal-sensors)."""
    errors: list[float] = []
    if run.robot.localisation is None:
        return errors

    def watch() -> None:
        x, y, _ = run.truth.robot_pose()
        belief = run.robot.base.pose()
        errors.append(100.0 * float(np.hypot(belief[0] - x, belief[1] - y)))

    stack.observers.append(watch)
    return errors


def watch_balance(run: MissionRun, stack: RobotStack) -> list[float]:
    """The simulation times at which a legged robot is down in ground truth (``benchmarks.common.has_fallen``:
    its pelvis low, or more than its soles on the floor), filled while the run steps; a wheeled robot's stays
    empty."""
    fallen: list[float] = []
    if not run.sim.robot.base.floating:
        return fallen
    model = run.sim.model
    on_robot = np.isin(model.geom_bodyid, sorted(run.sim.robot_bodies))  # per geom
    footing = np.array([on_a_foot(model.geom(g).name) for g in range(model.ngeom)])
    floor = np.array([model.geom(g).name == "floor" for g in range(model.ngeom)])
    down = on_robot & ~footing  # a robot geom that is not a sole, on the floor: the robot is down

    def watch() -> None:
        contacts = run.sim.data.contact
        g1, g2 = contacts.geom1, contacts.geom2
        on_floor = np.any((down[g1] & floor[g2]) | (down[g2] & floor[g1]))
        if on_floor or run.truth.floating_base()[0][2] < FALLEN_HEIGHT:
            fallen.append(run.sim.time)

    stack.observers.append(watch)
    return fallen


def _mission(suite: Suite, suite_file: str, task: Task, draw: Draw, stack: RobotStack, figures: dict):
    """The episode's validated mission, or why there is none (a string)."""
    if task.mission is not None:
        # the episode's scene, not the mission's: success conditions name the objects of this run
        spec = MissionLoader(scene=stack.sim.scene).load_file(Path(suite_file).parent / task.mission)
        spec.header.safety.time_budget = suite.episode_budget
        return spec
    return _planned(fill(task.command, draw.slots), suite, stack, figures)


def _planned(command: str, suite: Suite, stack: RobotStack, figures: dict):
    """Plan a command from what the robot believes now; the validated mission, or the planner's answer."""
    started = time.perf_counter()
    outcome = plan_command(command, stack.planning_context(), lambda question: None)
    figures["plan_ms"].append(round((time.perf_counter() - started) * 1000, 2))
    if outcome.plan.kind != "mission" or outcome.plan.mission is None:
        return f"planner: {outcome.plan.say}"
    mission = {**outcome.plan.mission, "safety": {"time_budget": suite.episode_budget}}
    return MissionLoader.for_plans().load_data(mission, name="<command>")


def _arm(fault, run: MissionRun, draw: Draw) -> fault_kinds.Injector:
    kind, settings = fault.kind, fault.settings
    if kind == "slip":
        return fault_kinds.Slip(run, draw.obj, settings)
    if kind == "target_moved":
        return fault_kinds.TargetMoved(run, draw.obj, settings, draw.spare_spots)
    if kind == "obstacle_dropped":
        return fault_kinds.ObstacleDropped(run, settings)
    if kind == "way_closed":
        return fault_kinds.WayClosed(run, settings)
    if kind == "push":
        return fault_kinds.Push(run, settings, draw.side_sign, draw.fault_rng)
    if kind == "arm_bump":
        return fault_kinds.ArmBump(run, draw.obj, settings, draw.side_sign, draw.fault_rng)
    if kind == "off_centre":
        return fault_kinds.OffCentre(run, draw.obj, settings, draw.fault_rng)
    if kind == "blind":
        return fault_kinds.Blind(run, settings, draw.fault_rng)
    if kind == "new_command":
        return fault_kinds.NewCommand(run, fill(settings.command, draw.slots), settings)
    raise AssertionError(f"no injector for {kind}")


def episode_verdict(
    run: RobotStack,
    result,
    figures: dict[str, Any],
    expect: list[dict[str, Any]] | None = None,
    failure: str | None = None,
    injector: fault_kinds.Injector | None = None,
    touched: list[float] | None = None,
    fell: list[float] | None = None,
    believed: list[float] | None = None,
) -> dict[str, Any]:
    """Success in ground truth, and the figures the suite aggregates."""
    header = MissionHeader.model_validate({"mission": "expect", "success": expect or []})
    conditions = list(header.success)
    world, kinds = run.context.world, run.sim.object_kinds
    for condition in header.success:  # things people keep upright must arrive upright
        if isinstance(condition, OnCondition) and world.objects[kinds[condition.on[0]]].upright:
            conditions.append(UprightCondition(upright=condition.on[0]))
    checked = [check_condition(c, run.truth) for c in conditions]
    unmet = [f"{c.condition} ({c.detail})" for c in checked if not c.holds]
    if failure is None and result is not None:
        if result.tree_status != "SUCCESS":
            failure = f"safety stop: {result.safety}" if result.safety else (result.cause or result.tree_status)
        elif unmet:
            failure = "not done: " + "; ".join(unmet)
    qp = [t * 1000 for t in run.robot.whole_body.solve_times]
    looks = [t * 1000 for t in run.perceiver.look_times] if run.perceiver is not None else []
    # measured when the tree finished, before the executor braked and waited for rest: a tree that reports done
    # while the robot still moves is what this catches; a safety stop halts a moving robot by design
    finish_speed = result.speed_at_end if result is not None else run.robot.max_speed()
    speed = run.robot.max_speed()  # after braking to rest (up to the executor's BRAKE_TIMEOUT)
    return {
        "success": failure is None and not unmet,
        "failure": failure,
        "fault_fired": injector.fired.what if injector is not None and injector.fired else None,
        "sim_time": round(run.sim.time, 3),
        "person_contacts": len(touched or []),
        "fell": bool(fell),
        "collision": bool(result is not None and result.safety and result.safety.startswith("collision")),
        "ended_moving": finish_speed >= REST_SPEED and not (result is not None and result.safety),
        "speed_at_finish": round(finish_speed, 4),
        "moving_after_brake": speed >= REST_SPEED,
        "final_speed": round(speed, 4),
        "plan_ms": figures["plan_ms"],
        "stop_latency_s": figures["stop_latency_s"],
        "look_ms_median": round(statistics.median(looks), 3) if looks else None,
        "qp_ms_median": round(statistics.median(qp), 4) if qp else None,
        "qp_ms_p95": round(float(np.percentile(qp, 95)), 4) if qp else None,
        "localisation_p95_cm": round(float(np.percentile(believed, 95)), 2) if believed else None,
        "localisation_max_cm": round(max(believed), 2) if believed else None,
    }
