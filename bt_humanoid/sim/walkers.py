"""People who walk loops through the scene: each drives their own velocity actuators along a route.

A walker heads for the next corner of their loop at their walking speed and reacts to the robot as they see it:

- they see the parts of the robot that are in their field of view and not hidden behind something (a ray from
  their eyes to each part, ten looks a second), and act on what they saw one reaction time ago, carried forward
  at the speed they saw it move (people expect a moving thing to go on moving);
- when they meet the robot, they either yield (stop while it is close in front of them, and turn back if it stays)
  or walk round it at a small gap and go on: drawn once per meeting from the run's seed (``Walker.yields``);
- a robot they have not seen yet, they do not avoid: keeping apart from them is then the robot's job (its speed and
  separation monitoring).

This is the scene's script, so it reads the robot's parts from the simulation, but only what the person could see;
the robot itself knows walkers only through its sensors.
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass

import mujoco
import numpy as np

from bt_humanoid.sim.world_config import Walker

CORNER_REACHED = 0.1  # m from a corner before heading for the next
LOOK_PERIOD = 0.1  # s between looks
EYE_HEIGHT = 1.6  # m
SIGHT_RANGE = 10.0  # m: the apartment's longest view
MEETING = 2.0  # m: the robot seen this near, ahead, is a meeting (whether to yield is drawn once per meeting)
MEETING_OVER = 3.0  # s without seeing the robot that near ends the meeting
PASSING_GAP = 0.15  # m a walker leaves between themselves and each part of the robot they saw
YIELD_AHEAD = 0.6  # m of their way that must pass the robot at that gap, or one who yields stops (their reaction
#                    time at walking pace, 0.35 m, still leaves room)
LOOK_AHEAD = 1.0  # m of their way that must pass it at that gap for one who walks round it
SWERVES = np.radians([0, -10, 10, -20, 20, -30, 30, -45, 45, -60, 60, -75, 75, -90, 90])  # keep right, like people
PART_RADIUS = (0.05, 0.4)  # m: the smallest and largest disc a part of the robot is seen as
PATIENCE = 3.0  # s a walker waits for the robot before turning back
MAX_SPEED = 2.0  # m/s: no part of the robot is expected to move faster


@dataclass
class Sighting:
    """What a walker saw of the robot at one look: its parts as discs on the floor (none: not seen), and how fast
    each moved since the look before."""

    time: float
    parts: np.ndarray  # (n, 2) centres, m
    radii: np.ndarray  # (n,) m
    velocities: np.ndarray | None = None  # (n, 2) m/s; none: not seen moving
    bodies: np.ndarray | None = None  # (n,) which of the robot's bodies each part is

    def predicted(self, now: float) -> Sighting:
        """Where what they saw will be ``now``, had it gone on as it moved: people expect a moving thing to move."""
        if self.velocities is None:
            return self
        return Sighting(now, self.parts + self.velocities * (now - self.time), self.radii)


class WalkerDriver:
    """Commands one walker's actuators every control step, from what they have seen of the robot."""

    def __init__(
        self,
        model: mujoco.MjModel,
        data: mujoco.MjData,
        name: str,
        walker: Walker,
        robot: set[int],
    ) -> None:
        self.model, self.data = model, data
        self.name = name
        self.walker = walker
        self.route = np.array(walker.route, dtype=float)
        self.joints = [model.joint(f"{name}_{axis}").qposadr[0] for axis in ("x", "y")]
        self.actuators = [model.actuator(f"{name}_{axis}").id for axis in ("x", "y")]
        self.body = model.body(name).id
        self.robot_parts = np.array(sorted(robot))  # every body of the robot
        self._is_robot = np.zeros(model.nbody, dtype=bool)
        self._is_robot[self.robot_parts] = True
        self.part_radii = np.array([_part_radius(model, body) for body in self.robot_parts])
        self.start = self.route[0]
        self._geoms = np.zeros(len(self.robot_parts), dtype=np.int32)
        self._distances = np.zeros(len(self.robot_parts))
        self.reset(np.random.default_rng(0))

    def reset(self, rng: np.random.Generator) -> None:
        """Back at the route's start, having seen nothing, drawing their choices from ``rng`` (the run's)."""
        self.target = 1 % len(self.route)
        self.direction = 1  # along the route's corners, or -1 the other way round
        self.waiting_since: float | None = None
        self.sightings: deque[Sighting] = deque()
        self.next_look = 0.0
        self.yielding = True  # in the current meeting (none yet: as if they would)
        self.last_met = -math.inf  # s: when they last saw the robot near ahead
        self.rng = rng

    def position(self) -> np.ndarray:
        # slide joints measure from where the body was built: the route's first corner
        return self.start + self.data.qpos[self.joints]

    def control(self) -> None:
        now, here = float(self.data.time), self.position()
        if np.hypot(*(self.route[self.target] - here)) < CORNER_REACHED:
            self.target = (self.target + self.direction) % len(self.route)
        heading = self._heading(here)
        if now >= self.next_look:
            self.sightings.append(self.look(here, heading))
            self.next_look = now + LOOK_PERIOD
        seen = self.picture(now).predicted(now)
        self._meet(now, here, heading, seen)
        if self.yielding:
            way = heading if self._clear(here, heading[None, :], seen, YIELD_AHEAD)[0] else None
        else:
            way = self._way_round(here, heading, seen)
        if way is not None:
            self.waiting_since = None
            self.data.ctrl[self.actuators] = self.walker.speed * way
            return
        self.data.ctrl[self.actuators] = 0.0
        self.waiting_since = now if self.waiting_since is None else self.waiting_since
        if now - self.waiting_since > PATIENCE:  # the robot stays in the way: walk the loop the other way
            self.direction = -self.direction
            self.target = (self.target + self.direction) % len(self.route)
            self.waiting_since = None

    def look(self, here: np.ndarray, heading: np.ndarray) -> Sighting:
        """The robot's parts this walker sees now: within their field of view and first along the ray to them."""
        eye = np.array([here[0], here[1], EYE_HEIGHT])
        offsets = self.data.xpos[self.robot_parts] - eye
        distances = np.linalg.norm(offsets, axis=1)
        directions = offsets / np.maximum(distances, 1e-9)[:, None]
        flat = offsets[:, :2] / np.maximum(np.hypot(*offsets[:, :2].T), 1e-9)[:, None]
        in_view = flat @ heading >= math.cos(math.radians(self.walker.view_angle))
        mujoco.mj_multiRay(
            self.model, self.data, eye, directions.ravel(), None, 1, self.body, self._geoms, self._distances, None,
            len(directions), SIGHT_RANGE,
        )  # fmt: skip
        hit = self._geoms >= 0
        seen = in_view & hit & self._is_robot[self.model.geom_bodyid[np.where(hit, self._geoms, 0)]]
        now, parts = float(self.data.time), self.data.xpos[self.robot_parts[seen], :2].copy()
        velocities = np.zeros_like(parts)
        last = self.sightings[-1] if self.sightings else None
        if last is not None and last.bodies is not None and now - last.time <= 2 * LOOK_PERIOD:
            before = dict(zip(last.bodies.tolist(), last.parts, strict=True))
            for i, body in enumerate(self.robot_parts[seen].tolist()):
                if body in before:
                    velocities[i] = (parts[i] - before[body]) / max(now - last.time, 1e-9)
        return Sighting(
            now, parts, self.part_radii[seen], np.clip(velocities, -MAX_SPEED, MAX_SPEED), self.robot_parts[seen]
        )

    def picture(self, now: float) -> Sighting:
        """What they act on now: the last look at least one reaction time old (before any: nothing seen)."""
        due = now - self.walker.reaction_time
        while len(self.sightings) > 1 and self.sightings[1].time <= due + 1e-9:
            self.sightings.popleft()
        if self.sightings and self.sightings[0].time <= due + 1e-9:
            return self.sightings[0]
        return Sighting(now, np.zeros((0, 2)), np.zeros(0))

    def _meet(self, now: float, here: np.ndarray, heading: np.ndarray, seen: Sighting) -> None:
        """A robot seen near ahead after a while unseen is a new meeting: draw whether to yield in it."""
        to_parts = seen.parts - here
        near = np.hypot(*to_parts.T) < MEETING
        if not np.any(near & (to_parts @ heading > 0)):
            return
        if now - self.last_met > MEETING_OVER:
            self.yielding = bool(self.rng.random() < self.walker.yields)
        self.last_met = now

    def _way_round(self, here: np.ndarray, heading: np.ndarray, seen: Sighting) -> np.ndarray | None:
        """Their way, turned as little as passes every part they saw at the gap (right first); none: no way by."""
        cos, sin = np.cos(SWERVES), np.sin(SWERVES)
        ways = np.stack([cos * heading[0] - sin * heading[1], sin * heading[0] + cos * heading[1]], axis=1)
        clear = self._clear(here, ways, seen, LOOK_AHEAD)
        return ways[int(np.argmax(clear))] if np.any(clear) else None

    def _clear(self, here: np.ndarray, ways: np.ndarray, seen: Sighting, length: float) -> np.ndarray:
        """Per unit way (m, 2): do its first ``length`` m pass every part seen at the gap? One already nearer than
        the gap (the robot came to them) need only not come nearer."""
        if len(seen.parts) == 0:
            return np.ones(len(ways), dtype=bool)
        offsets = seen.parts - here  # (n, 2)
        along = np.clip(ways @ offsets.T, 0.0, length)  # (m, n): the nearest point of each way to each part
        apart = np.hypot(offsets[None, :, 0] - along * ways[:, :1], offsets[None, :, 1] - along * ways[:, 1:])
        needed = np.minimum(self.walker.radius + seen.radii + PASSING_GAP, np.hypot(*offsets.T) - 1e-3)
        return np.all(apart >= needed, axis=1)

    def _heading(self, here: np.ndarray) -> np.ndarray:
        offset = self.route[self.target] - here
        return offset / max(float(np.hypot(*offset)), 1e-6)


def _part_radius(model: mujoco.MjModel, body: int) -> float:
    """The disc on the floor a part of the robot is seen as: round its geoms' bounding spheres."""
    geoms = np.flatnonzero(model.geom_bodyid == body)
    reach = max((float(np.hypot(*model.geom_pos[g][:2]) + model.geom_rbound[g]) for g in geoms), default=0.0)
    return float(np.clip(reach, *PART_RADIUS))
