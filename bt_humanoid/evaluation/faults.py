"""Fault injection: things that go wrong in a home, declared in YAML, injected into a running episode.

Each kind has a settings model (what a suite or a test writes, e.g.
``- push: {force: 250}``) and an injector that watches the run after every
control step and fires once, when its moment comes. A strength may be a span,
``[low, high]``: each episode draws its own from its fault stream.

- ``slip``: the object's surface turns slippery just after it is lifted, so it slides out of the fingers;
- ``target_moved``: someone moves the object to another spot while the robot drives towards it;
- ``obstacle_dropped``: a box lands on the floor in front of the robot while it drives;
- ``way_closed``: a box lands in the narrowest gap on the robot's way ahead, closing it: the way round is longer;
- ``push``: someone shoves the robot sideways while it drives;
- ``arm_bump``: someone walking past knocks the arm that carries something, while the robot drives;
- ``off_centre``: the object is nudged a few centimetres just before the open fingers reach it, so the hand
  closes off its centre (what a perception error of as much, or a knock to the table, does);
- ``blind``: the head camera delivers no frames (colour and depth) for some seconds;
- ``new_command``: a new command arrives mid-mission; the robot stops and does that instead.

Injectors are evaluation code: they read the simulator's ground truth to
pick their moment and act on the world the way the world would (forces,
friction, a box arriving, an object put elsewhere). The robot learns of a
fault only through its sensors.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Annotated, Any

import mujoco
import numpy as np
from pydantic import AfterValidator, Field, model_validator

from bt_humanoid.navigation.navigator import OBSERVED_PADDING
from bt_humanoid.navigation.planner import PlanError, plan_route
from bt_humanoid.strict_model import StrictModel, exactly_one

if TYPE_CHECKING:
    from bt_humanoid.engine.runner import MissionRun

PLACE_CLEARANCE = 1.0  # m a dropped box keeps from goals, named places and people
DRIVING = 0.15  # m/s of base speed above which the robot counts as driving
LOOK_PERIOD = 0.5  # s between way_closed's looks for a gap on the route
CANDIDATES = 3  # narrowest points of the route ahead way_closed tries per look (a route planned for each)
SPARE_BOX = "parcel"  # the free box in a corner of the apartment that obstacle_dropped drops on the robot's way


Span = float | tuple[float, float]  # one value, or [low, high] to draw from per episode


def _span_within(most: float) -> Any:
    """A Span type whose values lie in (0, ``most``], low before high."""

    def check(span: Span) -> Span:
        low, high = span if isinstance(span, tuple) else (span, span)
        if not 0.0 < low <= high <= most:
            raise ValueError(f"must lie in (0, {most:g}], low before high: got {span}")
        return span

    return Annotated[Span, AfterValidator(check)]


SpanUpTo005, SpanUpTo60 = _span_within(0.05), _span_within(60.0)
SpanUpTo100, SpanUpTo1000 = _span_within(100.0), _span_within(1000.0)


def pick(span: Span, rng: np.random.Generator) -> float:
    """The value of ``span`` for one episode: itself, or drawn uniformly from [low, high]."""
    return float(rng.uniform(*span)) if isinstance(span, tuple) else float(span)


class SlipSettings(StrictModel):
    friction: float = Field(0.02, gt=0, le=1, description="the object's friction while slippery")
    seconds: float = Field(1.0, gt=0, le=10, description="how long it stays slippery (at most: until it is out)")
    lifted: float = Field(0.02, gt=0, le=0.2, description="m above where it rested when the slip starts")


class TargetMovedSettings(StrictModel):
    distance: float = Field(0.2, gt=0, le=1, description="m, the least distance it is moved")
    within: float = Field(2.5, gt=0, le=10, description="m between robot and object when it is moved")


class ObstacleDroppedSettings(StrictModel):
    ahead: float = Field(1.4, gt=0.6, le=4, description="m ahead of the base where the box lands")


class WayClosedSettings(StrictModel):
    nearest: float = Field(1.0, gt=0.6, le=4, description="m along the route ahead where the gap may be, from ...")
    farthest: float = Field(4.0, gt=0.6, le=10, description="... to")
    detour: float = Field(1.0, gt=0, le=20, description="m the way round is longer, at least")


class PushSettings(StrictModel):
    # a person's shove on a standing adult is 40-80 N·s (issue 26); MuJoCo's xfrc_applied acts on the base link
    impulse: SpanUpTo1000 = Field(60.0, description="N·s sideways on the base: a number, or [low, high]")
    seconds: float = Field(0.3, gt=0, le=2, description="how long the shove lasts (force = impulse / seconds)")


class ArmBumpSettings(StrictModel):
    impulse: SpanUpTo100 = Field(6.0, description="N·s on the carrying hand: a number, or [low, high]")
    seconds: float = Field(0.15, gt=0, le=1, description="how long the knock lasts (force = impulse / seconds)")


class OffCentreSettings(StrictModel):
    offset: SpanUpTo005 = Field(0.03, description="m it is nudged, across the floor: a number, or [low, high]")
    near: float = Field(0.12, gt=0, le=0.3, description="m between the grip point and the object when it is nudged")


class BlindSettings(StrictModel):
    seconds: SpanUpTo60 = Field(4.0, description="how long the camera delivers no frames: a number, or [low, high]")
    after: float = Field(1.0, ge=0, le=600, description="s into the mission when it starts")


class NewCommandSettings(StrictModel):
    command: str = Field(description="what the person says; {object} and {surface} are filled per episode")
    expect: list[dict[str, Any]] = Field(description="success conditions of the new command")
    after: float = Field(8.0, ge=0, le=600, description="s into the mission when it arrives")


FAULT_MODELS: dict[str, type[StrictModel]] = {
    "slip": SlipSettings,
    "target_moved": TargetMovedSettings,
    "obstacle_dropped": ObstacleDroppedSettings,
    "way_closed": WayClosedSettings,
    "push": PushSettings,
    "arm_bump": ArmBumpSettings,
    "off_centre": OffCentreSettings,
    "blind": BlindSettings,
    "new_command": NewCommandSettings,
}


class FaultConfig(StrictModel):
    """One fault, written as ``- KIND: {settings}``."""

    slip: SlipSettings | None = None
    target_moved: TargetMovedSettings | None = None
    obstacle_dropped: ObstacleDroppedSettings | None = None
    way_closed: WayClosedSettings | None = None
    push: PushSettings | None = None
    arm_bump: ArmBumpSettings | None = None
    off_centre: OffCentreSettings | None = None
    blind: BlindSettings | None = None
    new_command: NewCommandSettings | None = None

    @model_validator(mode="after")
    def _one_kind(self) -> FaultConfig:
        exactly_one(self, *FAULT_MODELS)
        return self

    @property
    def kind(self) -> str:
        return next(kind for kind in FAULT_MODELS if getattr(self, kind) is not None)

    @property
    def settings(self) -> StrictModel:
        return getattr(self, self.kind)


@dataclass
class Fired:
    time: float
    what: str


class Injector:
    """Watches a run after every control step; ``fire()``s once when its moment comes."""

    kind = "fault"

    def __init__(self, run: MissionRun) -> None:
        self.run = run
        self.fired: Fired | None = None
        run.executor.observers.append(self.step)

    def step(self) -> None:
        if self.fired is None:
            self.watch()
        else:
            self.after()

    def watch(self) -> None:
        """Check for the moment; call ``fire()`` when it comes."""

    def after(self) -> None:
        """Runs every step once fired (to end a shove, dry a surface)."""

    def fire(self, what: str) -> None:
        self.fired = Fired(self.run.sim.time, what)
        self.run.events.add(self.run.sim.time, "fault", kind=self.kind, what=what)

    def driving(self) -> bool:
        return float(np.hypot(*self.run.robot.base.speeds()[:2])) > DRIVING


def _object_geoms(run: MissionRun, name: str) -> list[int]:
    model = run.sim.model
    body = model.body(run.sim.object_bodies[name]).id
    return list(range(model.body_geomadr[body], model.body_geomadr[body] + model.body_geomnum[body]))


def move_free_body(run: MissionRun, body: str, position: np.ndarray) -> None:
    """Put a free body elsewhere, turned as it was, at rest: how fault injection makes the world change."""
    model, data = run.sim.model, run.sim.data
    joint = model.body_jntadr[model.body(body).id]
    address, dof = model.jnt_qposadr[joint], model.jnt_dofadr[joint]
    data.qpos[address : address + 3] = position
    data.qvel[dof : dof + 6] = 0.0
    mujoco.mj_forward(model, data)


class Slip(Injector):
    kind = "slip"

    def __init__(self, run: MissionRun, obj: str, settings: SlipSettings) -> None:
        super().__init__(run)
        self.obj, self.settings = obj, settings
        self.geoms = _object_geoms(run, obj)
        self.friction = run.sim.model.geom_friction[self.geoms].copy()
        self.priority = run.sim.model.geom_priority[self.geoms].copy()
        self.rest_height = float(run.truth.object_position(obj)[2])
        self.dried = False

    def watch(self) -> None:
        truth = self.run.truth
        lifted = truth.object_position(self.obj)[2] - self.rest_height
        if lifted > self.settings.lifted and truth.in_hand(self.obj) is not None:
            model = self.run.sim.model
            model.geom_friction[self.geoms, 0] = self.settings.friction
            model.geom_priority[self.geoms] = 100  # its friction wins over the pads' (else MuJoCo takes the larger)
            self.fire(f"the {self.obj} turned slippery {lifted * 100:.0f} cm above where it rested")

    def after(self) -> None:
        if self.dried:
            return
        out_of_hand = self.run.truth.in_hand(self.obj) is None  # slippery fingers, not a slippery table
        if out_of_hand or self.run.sim.time > self.fired.time + self.settings.seconds:
            self.run.sim.model.geom_friction[self.geoms] = self.friction
            self.run.sim.model.geom_priority[self.geoms] = self.priority
            self.dried = True


class TargetMoved(Injector):
    kind = "target_moved"

    def __init__(self, run: MissionRun, obj: str, settings: TargetMovedSettings, spots: list[np.ndarray]) -> None:
        super().__init__(run)
        self.obj, self.settings = obj, settings
        self.spots = spots  # reachable free (x, y) spots on the object's surface, from the episode's scene draw

    def watch(self) -> None:
        truth = self.run.truth
        position = truth.object_position(self.obj)
        robot = np.array(truth.robot_pose()[:2])
        near = np.hypot(*(position[:2] - robot)) < self.settings.within
        if not (near and self.driving() and truth.in_hand(self.obj) is None):
            return
        surface = self.run.context.world_model.surface_under(position + np.array([0, 0, 0.5]))
        if surface is None:
            return  # not on a surface now (fallen): nobody would put it back for us
        far_enough = [
            s for s in self.spots if np.hypot(*(s[:2] - position[:2])) >= self.settings.distance and surface.contains(s)
        ]
        if not far_enough:
            return
        spot = far_enough[0]
        body = self.run.sim.object_bodies[self.obj]
        move_free_body(self.run, body, np.array([spot[0], spot[1], position[2] + 0.002]))
        self.fire(f"the {self.obj} was moved {np.hypot(*(spot[:2] - position[:2])):.2f} m")


class ObstacleDropped(Injector):
    kind = "obstacle_dropped"

    def __init__(self, run: MissionRun, settings: ObstacleDroppedSettings) -> None:
        super().__init__(run)
        self.settings = settings
        model = run.sim.model
        self.box = model.body(SPARE_BOX).id  # KeyError: the world has no spare box
        size = model.geom_size[model.body_geomadr[self.box]]
        self.half, self.height = float(size[:2].max()), float(size[2])

    def watch(self) -> None:
        if not self.driving():
            return
        vx, vy, _ = self.run.robot.base.speeds()
        x, y, _ = self.run.truth.robot_pose()
        heading = np.array([vx, vy]) / max(float(np.hypot(vx, vy)), 1e-9)
        spot = np.array([x, y]) + self.settings.ahead * heading
        if not self._fair(spot):
            return
        move_free_body(self.run, SPARE_BOX, np.array([*spot, self.height + 0.01]))
        self.fire(f"a box landed {self.settings.ahead:.1f} m ahead, at ({spot[0]:.2f}, {spot[1]:.2f})")

    def _fair(self, spot: np.ndarray) -> bool:
        """Open floor with room to drive round the box, not on the robot's goal, a named place or a person."""
        run = self.run
        footprint = run.context.robot_config.base.footprint_radius
        if run.navigator.grid.clearance_at(spot[None, :])[0] < self.half + 2 * footprint:
            return False
        places = [np.array(p.pose[:2]) for p in run.context.world.places.values()]
        return self._clear_of(spot, places)

    def _clear_of(self, spot: np.ndarray, places: list[np.ndarray]) -> bool:
        """``PLACE_CLEARANCE`` from ``places``, the robot's goal and the people."""
        run = self.run
        keep_clear = list(places)
        keep_clear += [run.truth.person_position(name)[:2] for name in run.context.world.people]
        keep_clear += [run.truth.person_position(name)[:2] for name in run.context.world.walkers]
        if run.navigator.goal is not None:
            keep_clear.append(np.asarray(run.navigator.goal[:2]))
        return all(np.hypot(*(spot - other)) >= PLACE_CLEARANCE for other in keep_clear)


class WayClosed(ObstacleDropped):
    """The free box lands in a gap on the robot's route ahead that it closes: the robot cannot pass beside it,
    and the way round is at least ``detour`` longer (a box in a passage, not on open floor). Looked for twice a
    second while the robot drives, at the narrowest points of the route first; only where the map, with the box
    on it, still has a way round, and not within ``PLACE_CLEARANCE`` of the goal or a person."""

    kind = "way_closed"

    def __init__(self, run: MissionRun, settings: WayClosedSettings) -> None:
        super().__init__(run, ObstacleDroppedSettings())
        self.settings = settings
        self.floor_plan = run.navigator.grid.without_observed()  # furniture only: gaps are between furniture
        self.next_look = 0.0

    def watch(self) -> None:
        navigator, now = self.run.navigator, self.run.sim.time
        if now < self.next_look or not self.driving() or navigator.route is None or navigator.goal is None:
            return
        self.next_look = now + LOOK_PERIOD
        route, s = navigator.route, navigator.follower.progress
        ahead = np.flatnonzero(
            (route.arc_length >= s + self.settings.nearest) & (route.arc_length <= s + self.settings.farthest)
        )
        room = self.floor_plan.clearance_at(route.points[ahead])
        footprint = self.run.context.robot_config.base.footprint_radius
        # the box fits there (its corners clear the furniture) and leaves the robot no way past: it keeps its
        # footprint and the padding for what it sees (things that may move) from the box
        fits = (room >= self.half * math.sqrt(2) + 0.02) & (room < self.half + footprint + OBSERVED_PADDING)
        for index in ahead[fits][np.argsort(room[fits])][:CANDIDATES]:
            spot = route.points[index]
            if not self._clear_of(spot, []):
                continue
            longer = self._way_round(spot) - (route.length - s)
            if longer >= self.settings.detour:
                move_free_body(self.run, SPARE_BOX, np.array([*spot, self.height + 0.01]))
                self.fire(
                    f"a box closed the way {route.arc_length[index] - s:.1f} m ahead, at ({spot[0]:.2f}, "
                    f"{spot[1]:.2f}): the way round is {longer:.1f} m longer"
                )
                return

    def _way_round(self, spot: np.ndarray) -> float:
        """m of the shortest route to the goal on the floor plan with the box at ``spot`` (as the robot would see
        it); 0 where there is none."""
        navigator = self.run.navigator
        closed = self.floor_plan.without_observed()
        side = np.arange(-self.half, self.half + 1e-9, closed.resolution / 2)
        closed.mark(spot + np.stack(np.meshgrid(side, side), axis=-1).reshape(-1, 2))
        try:
            return plan_route(closed, navigator.robot.base.pose(), navigator.goal, navigator.clearance).length
        except PlanError:
            return 0.0


class _Shove(Injector):
    """A force on one of the robot's bodies, sideways to its heading, for ``seconds``: impulse / seconds."""

    def __init__(self, run: MissionRun, impulse: float, seconds: float, sign: float) -> None:
        super().__init__(run)
        self.impulse, self.seconds, self.sign = impulse, seconds, sign
        self.body: int | None = None
        self.released = False

    def shove(self, body: int, what: str) -> None:
        _, _, yaw = self.run.truth.robot_pose()
        sideways = self.sign * np.array([-math.sin(yaw), math.cos(yaw), 0.0])
        self.body = body
        self.run.sim.data.xfrc_applied[body, :3] = self.impulse / self.seconds * sideways
        side = "left" if self.sign > 0 else "right"
        self.fire(f"{what} {side}: {self.impulse:.0f} N·s over {self.seconds:.2f} s")

    def after(self) -> None:
        if not self.released and self.run.sim.time > self.fired.time + self.seconds:
            self.run.sim.data.xfrc_applied[self.body, :3] = 0.0
            self.released = True


class Push(_Shove):
    kind = "push"

    def __init__(self, run: MissionRun, settings: PushSettings, sign: float, rng: np.random.Generator) -> None:
        super().__init__(run, pick(settings.impulse, rng), settings.seconds, sign)

    def watch(self) -> None:
        if self.driving():
            self.shove(self.run.sim.model.body(self.run.sim.robot_root).id, "pushed")


class ArmBump(_Shove):
    """Someone walking past knocks the hand that carries the episode's object, while the robot drives."""

    kind = "arm_bump"

    def __init__(
        self, run: MissionRun, obj: str, settings: ArmBumpSettings, sign: float, rng: np.random.Generator
    ) -> None:
        super().__init__(run, pick(settings.impulse, rng), settings.seconds, sign)
        self.obj = obj

    def watch(self) -> None:
        side = self.run.truth.in_hand(self.obj)
        if side is None or not self.driving():
            return
        model = self.run.sim.model
        hand = int(model.site_bodyid[model.site(self.run.context.robot_config.grippers[side].grip_site).id])
        self.shove(hand, f"the {side} hand carrying the {self.obj} was knocked")


class OffCentre(Injector):
    """Nudges the object ``offset`` across the floor, in a direction drawn per episode, as a hand comes within
    ``near`` of it: the fingers then close off its centre, on a chord of a bottle or beside a box's middle.
    Fires only where the object, moved, touches nothing it did not touch before (no pad inside it)."""

    kind = "off_centre"

    def __init__(self, run: MissionRun, obj: str, settings: OffCentreSettings, rng: np.random.Generator) -> None:
        super().__init__(run)
        self.obj, self.settings = obj, settings
        angle = rng.uniform(0.0, 2.0 * math.pi)
        self.shift = pick(settings.offset, rng) * np.array([math.cos(angle), math.sin(angle)])
        self.body = run.sim.model.body(run.sim.object_bodies[obj]).id

    def watch(self) -> None:
        truth, model, data = self.run.truth, self.run.sim.model, self.run.sim.data
        if truth.in_hand(self.obj) is not None:
            return
        centre = truth.object_centre(self.obj)
        for side, gripper in self.run.context.robot_config.grippers.items():
            grip = data.site_xpos[model.site(gripper.grip_site).id]
            if np.linalg.norm(grip - centre) <= self.settings.near and self._nudge(self.shift):
                offset = float(np.linalg.norm(self.shift)) * 100
                self.fire(f"the {self.obj} was nudged {offset:.1f} cm as the {side} hand came to it")
                return

    def _nudge(self, shift: np.ndarray) -> bool:
        """Move the object by ``shift`` (x, y); undo it, and say False, where it then touches something new."""
        before = self.run.truth.geoms_in_contact(self.body)
        position = self.run.truth.object_position(self.obj)
        move_free_body(self.run, self.run.sim.object_bodies[self.obj], position + np.array([*shift, 0.0]))
        if self.run.truth.geoms_in_contact(self.body) <= before:
            return True
        move_free_body(self.run, self.run.sim.object_bodies[self.obj], position)
        return False


class Blind(Injector):
    kind = "blind"

    def __init__(self, run: MissionRun, settings: BlindSettings, rng: np.random.Generator) -> None:
        super().__init__(run)
        self.settings = settings
        self.seconds = pick(settings.seconds, rng)
        self.start = run.sim.time + settings.after

    def watch(self) -> None:
        if self.run.sim.time < self.start:
            return
        until = self.run.sim.time + self.seconds
        if self.run.perceiver is not None:
            self.run.perceiver.camera.dropped_until = until
        if self.run.navigator.camera is not None:
            self.run.navigator.camera.dropped_until = until
        self.fire(f"the head camera gave no frames for {self.seconds:.1f} s")


class NewCommand(Injector):
    """Asks the run to stop when the new command arrives; the episode runner then plans and runs it."""

    kind = "new_command"

    def __init__(self, run: MissionRun, command: str, settings: NewCommandSettings) -> None:
        super().__init__(run)
        self.command, self.settings = command, settings
        self.start = run.sim.time + settings.after

    def watch(self) -> None:
        if self.run.sim.time >= self.start:
            self.run.request_stop(f"a new command: {self.command}")
            self.fire(f'"{self.command}" arrived')
