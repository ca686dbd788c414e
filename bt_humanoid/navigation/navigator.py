"""The navigation stack of one robot: map, depth updates, planning, following and replanning.

``go_to(goal)`` plans a route on the occupancy grid and starts following it.
Every control step the navigator updates the map from the head depth camera
(at the camera's rate) and checks the route ahead against it: when something
now blocks it, the robot replans from where it is and carries on, or stops
with the reason if no route is left. Where something the camera saw stands on
the goal itself (a parcel on a stance, a person nearer than the stance by them
allows), a skill that passed ``choose_goal`` is asked for the goal afresh, on
the map as it is now. Skills talk to the navigator through
the motion handles it returns; recovery (clear the map, spin, back up, wait)
is tree structure in behaviors/navigate.yaml.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import cv2
import numpy as np

from bt_humanoid.control.motion import MotionHandle
from bt_humanoid.control.robot import RobotController
from bt_humanoid.navigation.follower import RouteFollower
from bt_humanoid.navigation.occupancy import OccupancyGrid
from bt_humanoid.navigation.planner import Clearance, PlanError, Route, plan_route
from bt_humanoid.navigation.static_map import ROBOT_HEIGHT, static_map
from bt_humanoid.perception.depth_camera import DepthCamera, DepthScan
from bt_humanoid.sim.sensor_models import depth_ranges
from bt_humanoid.sim.simulation import Simulation

RESOLUTION = 0.05  # m per map cell
CLEARANCE_MARGIN = 0.1  # m the base keeps from obstacles on the way, beyond its footprint
END_MARGIN = 0.0  # m near the start and goal: stances at furniture are close to it (the grid errs on the safe side)
OBSTACLE_MIN_HEIGHT = 0.06  # m: depth points lower than this are floor
FREE_BELOW = 0.1  # m: a ray passing a cell lower than this shows nothing taller stands there
OWN_MARGIN = 0.03  # m beyond the footprint where depth points are the robot's own bumper
HELD_RADIUS = 0.15  # m around a hand where points below it are what it holds
HELD_ABOVE = 0.15  # m above the grip what a hand holds may still rise (a mug or a bottle gripped below its top)
SEEN_DEPTH = 0.3  # m an obstacle is assumed to extend behind the face the camera sees (a person, a parcel)
OBSERVED_MEMORY = 6.0  # s an obstacle the camera saw is kept after it was last seen (out of view: it may move)
OBSERVED_PADDING = 0.2  # m more room given to what the camera saw than to the furniture: it may move
GAZE_AHEAD = 1.5  # m along the route where the head looks
CAUTION_DISTANCE = 1.0  # m between the footprint and something the camera saw, below which the base slows
CAUTION_SPEED = 0.5  # m/s allowed at CAUTION_DISTANCE, falling linearly to CREEP_SPEED
CREEP_SPEED = 0.1  # m/s
MAX_GAZE_PAN = 1.0  # rad the head turns from the heading at most
LOOKAHEAD = 2.5  # m of route ahead checked against the map at every update
MAX_REPLANS = 30  # per goal, before the goal fails as blocked
# s a protective stop holds the base before what the base scanner senses near it goes on the map: the head camera
# looks along the route and may never see a low thing beside the base (a box dropped there held the robot 10 s)
HELD_REMAP = 1.0
# new goals a goal may be swapped for when what the camera saw stands on it (a parcel on a stance, a person nearer
# than the stance by them allows): each is chosen afresh on the map as it is then
GOAL_RECHOICES = 5
WAIT_LIMIT = 15.0  # s to wait, stopped, for a blocked way to clear before the goal fails
# a new route longer than DETOUR times what was left of the blocked one, plus DETOUR_SLACK, is a way round: the
# robot first waits up to DETOUR_WAIT for the way to clear, as someone walking across it does (a biped took 30
# routes in 50 s to and fro beside a walker's loop, 7 m one way and 13 m round the other)
DETOUR = 1.5
DETOUR_SLACK = 1.0  # m
DETOUR_WAIT = 6.0  # s
FREE_SAMPLES = 12  # points along the low end of each ray that mark free cells
# m a robot standing nearer furniture than its footprint allows a route to start (a biped works 0.25 m from a
# table's edge, inside its 0.36 m footprint) steps straight back, at most, before it plans
STEP_OUT = 0.4


class Navigator:
    """Plans and follows routes for the base; ``step()`` runs it (registered with the RobotController)."""

    def __init__(self, sim: Simulation, robot: RobotController, bounds: np.ndarray) -> None:
        self.robot = robot
        config = robot.config
        footprint = config.base.footprint_radius
        self.clearance = Clearance(footprint + END_MARGIN, footprint + CLEARANCE_MARGIN)
        self.sim, self.bounds = sim, bounds
        self.remap()
        camera = next(iter(config.cameras), None)
        self.camera = None
        if camera:

            def noise(ranges: np.ndarray) -> np.ndarray:  # the robot's depth model, on the camera's own stream
                return depth_ranges(sim.sensors.depth, ranges, sim.random_stream(f"{camera}.mapping"))

            self.camera = DepthCamera(
                sim.model, sim.data, camera, sim.robot_root, noise=noise, on_map=lambda p, r: sim.on_map(p, r)
            )
        self.camera_frame = config.frames[camera][1] if camera in config.frames else None
        self.scan_period = 1.0 / config.cameras[camera].rate_hz if camera else math.inf
        self.last_scan = -math.inf
        self.follower = RouteFollower(robot.base, config.base, robot.control_period)
        self.head_pan = config.head_pan
        self.goal: np.ndarray | None = None
        self.max_speed = config.base.limits.max_speed
        self.replans = 0
        self.handle: MotionHandle | None = None
        self.planning_times: list[float] = []  # s of wall time per plan, for benchmarks
        self.route_lengths: list[float] = []  # m, per route planned
        self.route: Route | None = None
        self.motion: MotionHandle | None = None  # the follower's handle for the current route (or the step out)
        self.stepping_out = False  # backing straight out of a working stance before the first plan
        self.waiting_since: float | None = None  # stopped because no route is free now, or only a way round
        self.way_left: float | None = None  # m of the route that got blocked still to go, when it did
        self.resume_tilt: float | None = None  # the head's tilt before a wait (it looks down at the goal meanwhile)
        self.remapped_hold: float | None = None  # the protective stop whose sensed things went on the map
        self.choose_goal: Callable[[], np.ndarray] | None = None  # the goal chosen afresh, when seen things take it
        self.goals_chosen = 0  # of GOAL_RECHOICES

    def remap(self) -> None:
        """Build the floor plan from the furniture where it stands now (at start, or after it was rearranged)."""
        self.grid: OccupancyGrid = static_map(self.sim.model, self.sim.data, self.bounds, RESOLUTION)
        self.grid.observed_padding = OBSERVED_PADDING
        # a hit on a face of the furniture may fall in the cell just outside it, and the scanner's noise (3σ) may
        # carry it further: that is the furniture too
        scanner = self.sim.sensors.scanner
        reach = 1 + (math.ceil(3 * scanner.noise / RESOLUTION) if scanner.enabled else 0)
        square = np.ones((2 * reach + 1, 2 * reach + 1), np.uint8)
        self._near_static = cv2.dilate(self.grid.static.astype(np.uint8), square).astype(bool)

    # ------------------------------------------------------------------ goals

    def go_to(
        self,
        goal: np.ndarray,
        max_speed: float | None = None,
        choose_goal: Callable[[], np.ndarray] | None = None,
    ) -> MotionHandle:
        """Plan to ``goal`` (x, y, yaw) and follow the route at up to ``max_speed`` (None: as fast as the mission's
        cap allows); the handle fails with the reason if there is none. ``choose_goal``, when given, picks the
        goal again on the map as it is now: it is asked when something the camera saw stands where the goal is
        (the goal is kept if the answer has no more room)."""
        self._finish_goal("pre-empted by a new goal")
        if self.follower.dt != self.robot.control_period:  # the executor chose the control rate after we were built
            self.follower = RouteFollower(self.robot.base, self.robot.config.base, self.robot.control_period)
        self.goal, self.max_speed, self.replans = np.asarray(goal, dtype=float), self.robot.base.capped(max_speed), 0
        self.choose_goal, self.goals_chosen = choose_goal, 0
        self.waiting_since, self.way_left = None, None
        self.stepping_out = False
        handle = MotionHandle(f"navigating to ({goal[0]:.2f}, {goal[1]:.2f})", on_cancel=lambda _: self.halt())
        self.handle = handle
        self._update_map()
        self._plan_and_follow()  # fails the handle at once if there is no route
        return handle

    def halt(self) -> None:
        """Stop following; the base brakes to rest."""
        if self.stepping_out:
            self.stepping_out = False
            self.robot.base.brake()
        self.follower.stop()
        self.goal = None
        self.waiting_since = None
        if self.handle is not None:
            self.handle.fail("halted: braking")
            self.handle = None

    def room_behind(self, xy: np.ndarray, yaw: float, longest: float) -> np.ndarray | None:
        """The nearest point straight behind ``xy`` (facing ``yaw``), at most ``longest`` back, where a route may
        start or end (the footprint's clearance on the map); ``xy`` itself if it has room; None if none has."""
        back = -np.array([math.cos(yaw), math.sin(yaw)])
        steps = np.arange(0.0, longest + 1e-9, self.grid.resolution)
        points = np.asarray(xy, dtype=float)[:2] + steps[:, None] * back
        free = np.flatnonzero(self.has_room(points))
        return points[free[0]] if free.size else None

    def free_pose_near(self, goal: np.ndarray, within: float) -> np.ndarray:
        """The pose nearest ``goal`` (x, y, yaw), within ``within`` m and facing the same way, whose footprint has
        room on the map as it is now: ``goal`` itself if it has, or if none has."""
        rings = np.arange(0.0, within + 1e-9, self.grid.resolution * 2)
        angles = np.linspace(0.0, 2 * math.pi, 12, endpoint=False)
        offsets = np.concatenate(
            [[[0.0, 0.0]], *(r * np.column_stack([np.cos(angles), np.sin(angles)]) for r in rings[1:])]
        )
        points = np.asarray(goal, dtype=float)[:2] + offsets
        free = np.flatnonzero(self.has_room(points))
        return np.array([*points[free[0]], goal[2]]) if free.size else np.asarray(goal, dtype=float)

    def has_room(self, points: np.ndarray) -> np.ndarray:
        """Per floor point (x, y): whether the footprint standing there clears everything on the map as it is
        now (where a route may start or end)."""
        return self.grid.clearance_at(np.asarray(points, dtype=float)[:, :2]) >= self.clearance.minimum

    def is_furniture(self, points: np.ndarray) -> np.ndarray:
        """Per floor point (x, y): on or next to the map's furniture and walls (outside the map counts too)."""
        rows, cols = self.grid.cell(points)
        inside = self.grid.inside(rows, cols)
        result = np.ones(len(points), dtype=bool)
        result[inside] = self._near_static[rows[inside], cols[inside]]
        return result

    def clear_map(self) -> None:
        """Forget every obstacle the camera added; the next scans add back what is still there."""
        self.grid.clear_observed()

    # ------------------------------------------------------------------ control step

    def step(self) -> None:
        if self.handle is None:
            return  # the map is updated while navigating (scans cost time, and nothing reads it otherwise)
        now = self.robot.base.time
        if self.camera is not None and now - self.last_scan >= self.scan_period - 1e-9 and not self.stepping_out:
            self.last_scan = now
            self._update_map()
            blocked_at = self._blocked_at()
            if self.waiting_since is not None or blocked_at is not None:
                self._replan(now)
                blocked_at = self._blocked_at()  # on the new route, if there is one
            self.follower.stop_at = blocked_at
            self.follower.speed_limit = self._speed_near_obstacles()
            if self.waiting_since is not None and self.goal is not None:
                self._look_towards(self.goal[:2], at_floor=True)  # to see the way there clear when they walk on
            else:
                self._look_along_route()
        if self.handle is None:
            return
        if self._held_by_the_unseen(now):
            self.follower.stop()
            self._plan_and_follow()  # backing out first, when it stands too near what it now knows of to plan
            if self.handle is None:
                return
        if self.waiting_since is not None:
            self.handle.feedback = f"waiting for the way to clear ({now - self.waiting_since:.0f} s)"
            return
        if not self.stepping_out:
            self.follower.step()
        motion = self.motion
        if motion is None or motion.done:
            self._settle(motion)
        else:
            self.handle.feedback = motion.feedback

    # ------------------------------------------------------------------ internals

    def _plan(self) -> Route:
        try:
            route = plan_route(self.grid, self.robot.base.pose(), self.goal, self.clearance, seed=self.sim.seed)
        except PlanError:
            self.planning_times.append(0.0)
            raise
        self.planning_times.append(route.planning_time)
        self.route_lengths.append(route.length)
        return route

    def _plan_and_follow(self) -> None:
        """The first plan of a goal: no route fails the goal at once (the map says the goal cannot be reached).
        A robot nearer furniture than a route may start first steps straight back (``_step_out``)."""
        if self._step_out():
            return
        if self.stepping_out:  # planned again mid-step (a protective stop's hold): that step is over
            self.stepping_out = False
            self.robot.base.brake()
        try:
            route = self._plan_or_choose_again()
        except PlanError as error:
            if self._blocked_only_by_what_was_seen():  # a person on the way or at the goal may walk on: wait
                self._wait(self.robot.base.time)
                return
            self._finish_goal(str(error), brake=True)
            return
        self.route = route
        self.motion = self.follower.follow(route, self.max_speed)

    def _plan_or_choose_again(self) -> Route:
        """Plan; where something the camera saw stands on the goal itself, plan to a goal chosen afresh."""
        try:
            return self._plan()
        except PlanError:
            if not self._choose_goal_again():
                raise
            return self._plan()

    def _choose_goal_again(self) -> bool:
        """Swap the goal for ``choose_goal``'s answer where only what the camera saw leaves the goal too little
        room and the answer has enough; False (keep it: wait for the way to clear) otherwise."""
        if self.choose_goal is None or self.goal is None or self.goals_chosen >= GOAL_RECHOICES:
            return False
        if self.has_room(self.goal[None])[0]:
            return False  # the goal has room: the way to it is what is blocked
        if self.grid.without_observed().clearance_at(self.goal[None, :2])[0] < self.clearance.minimum:
            return False  # furniture, not something seen: choosing again would not help
        goal = np.asarray(self.choose_goal(), dtype=float)
        if np.allclose(goal[:2], self.goal[:2], atol=1e-3) or not self.has_room(goal[None])[0]:
            return False
        self.goal = goal
        self.goals_chosen += 1
        return True

    def _blocked_only_by_what_was_seen(self) -> bool:
        """Whether the map alone, without what the camera added, has a route to the goal."""
        if not np.any(self.grid.observed):
            return False
        try:
            plan_route(
                self.grid.without_observed(), self.robot.base.pose(), self.goal, self.clearance, seed=self.sim.seed
            )
        except PlanError:
            return False
        return True

    def _wait(self, now: float) -> None:
        self.waiting_since = now
        self.motion = None
        self.follower.stop()
        tilt = self.robot.config.head_tilt
        self.resume_tilt = self.robot.joint_positions()[tilt] if tilt is not None else None

    def _stop_waiting(self) -> None:
        """Back on the way: the head looks ahead again as it did before the wait."""
        self.waiting_since = None
        tilt = self.robot.config.head_tilt
        if tilt is not None and self.resume_tilt is not None:
            self.robot.joints.move({tilt: self.resume_tilt})

    def _replan(self, now: float) -> None:
        """The way ahead got blocked: take a new route, or stop and wait for one (a person may walk on)."""
        if self.waiting_since is None:  # a new route for a blocked one; tries while waiting are not counted
            self.replans += 1
            if self.replans > MAX_REPLANS:
                self._finish_goal(f"the way kept getting blocked: {MAX_REPLANS} new routes taken", brake=True)
                return
            if self.route is not None:
                self.way_left = self.route.length - self.follower.progress
        try:
            route = self._plan_or_choose_again()
        except PlanError as error:
            if self.waiting_since is None:
                self._wait(now)
            elif now - self.waiting_since > WAIT_LIMIT:
                self._finish_goal(f"waited {WAIT_LIMIT:.0f} s for the way to clear: {error}", brake=True)
            return
        if self._wait_instead_of(route, now):
            if self.waiting_since is None:
                self._wait(now)
            return
        if self.waiting_since is not None:
            self._stop_waiting()
        self.route = route
        self.motion = self.follower.follow(route, self.max_speed)

    def _wait_instead_of(self, route: Route, now: float) -> bool:
        """Whether to wait for the blocked way to clear rather than take ``route``, a way round much longer than
        what was left of it, until the robot has waited DETOUR_WAIT."""
        if self.way_left is None or route.length <= DETOUR * self.way_left + DETOUR_SLACK:
            return False
        return self.waiting_since is None or now - self.waiting_since < DETOUR_WAIT

    def _speed_near_obstacles(self) -> float:
        """Slow down near what the camera saw: it may be a person who moves, or who has more to them than seen."""
        here = self.robot.base.pose()[None, :2]
        distance = float(self.grid.observed_distance_at(here)[0]) - self.robot.config.base.footprint_radius
        if distance >= CAUTION_DISTANCE:
            return math.inf
        return max(CAUTION_SPEED * distance / CAUTION_DISTANCE, CREEP_SPEED)

    def _look_along_route(self) -> None:
        """Turn the head towards where the route goes next: the camera sees a bend (and who is there) early."""
        route, pan = self.route, self.head_pan
        if route is None or pan is None or self.follower.route is None:
            return
        s = self.follower.progress
        self._look_towards(route.points[min(np.searchsorted(route.arc_length, s + GAZE_AHEAD), len(route.points) - 1)])

    def _look_towards(self, point: np.ndarray, at_floor: bool = False) -> None:
        """Turn the head towards a floor point; ``at_floor`` tips it down to see the floor there too."""
        if self.head_pan is None:
            return
        x, y, yaw = self.robot.base.pose()
        bearing = math.remainder(math.atan2(point[1] - y, point[0] - x) - yaw, 2 * math.pi)
        targets = {self.head_pan: float(np.clip(bearing, -MAX_GAZE_PAN, MAX_GAZE_PAN))}
        tilt = self.robot.config.head_tilt
        if at_floor and tilt is not None and self.camera_frame is not None:
            camera = self.robot.frame_position(self.camera_frame)
            targets[tilt] = math.atan2(camera[2], float(np.hypot(*(point[:2] - camera[:2]))))
        self.robot.joints.move(targets)

    def _blocked_at(self) -> float | None:
        """Arc length of the first point ahead on the route where the base would touch something, if any."""
        route = self.route
        if route is None or self.follower.route is None:
            return None
        s = self.follower.progress
        # ahead of where the base stands (it may have started close to something), up to LOOKAHEAD
        ahead = np.nonzero((route.arc_length > s + 0.1) & (route.arc_length <= s + LOOKAHEAD))[0]
        blocked = ahead[self.grid.clearance_at(route.points[ahead]) < self.clearance.minimum]
        return float(route.arc_length[blocked[0]]) if len(blocked) else None

    def _step_out(self) -> bool:
        """Back straight out, facing the same way, to where a route may start: the nearest point behind within
        ``STEP_OUT`` with the footprint's clearance. False (plan as it stands) where none is needed or found."""
        pose = self.robot.base.pose()
        out = self.room_behind(pose[:2], float(pose[2]), STEP_OUT)
        if out is None or np.allclose(out, pose[:2]):
            return False
        x, y = out
        if self.waiting_since is not None:  # moving now: a wait left standing would hold the step-out forever
            self._stop_waiting()
        self.stepping_out = True
        self.motion = self.robot.base.move_to(float(x), float(y), float(pose[2]), max_speed=self.max_speed)
        return True

    def _settle(self, motion: MotionHandle | None) -> None:
        if self.stepping_out:
            self.stepping_out = False
            if motion is not None and motion.status.name == "SUCCEEDED":
                self._plan_and_follow()
                return
        if motion is not None and motion.status.name == "SUCCEEDED":
            self.handle.succeed(motion.result)
            self.handle = None
            self.goal = None
        else:
            self._finish_goal(motion.result if motion is not None else "route abandoned")

    def _finish_goal(self, reason: str, brake: bool = False) -> None:
        if self.handle is not None:
            self.handle.fail(reason)
            self.handle = None
        if brake:
            self.follower.stop()
        self.goal = None

    def _held_by_the_unseen(self, now: float) -> bool:
        """Whether a protective stop has held the base for HELD_REMAP s; if so, what the base scanner senses near
        the robot goes on the map (once per hold), so that the next route goes round it."""
        held, separation = self.robot.base.held_since, self.robot.separation
        if held is None or separation is None or now - held < HELD_REMAP or self.remapped_hold == held:
            return False
        self.remapped_hold = held
        sensed = separation.near_points
        if not len(sensed):
            return False
        self._mark_seen(sensed, self.robot.base.pose()[:2], now)
        return True

    def _mark_seen(self, solid: np.ndarray, origin: np.ndarray, now: float) -> None:
        """Put floor points a sensor at ``origin`` hit on the map; it sees only the near face of a thing, so the
        thing is assumed SEEN_DEPTH deep along the ray."""
        away = solid - origin[:2]
        away /= np.maximum(np.hypot(*away.T), 1e-6)[:, None]
        depths = np.arange(0.0, SEEN_DEPTH + 1e-9, self.grid.resolution)
        behind = solid[:, None, :] + depths[None, :, None] * away[:, None, :]
        self.grid.mark(behind.reshape(-1, 2), now)

    def _update_map(self) -> None:
        """Add what the depth camera sees, clear what it sees free."""
        if self.camera is None:
            return
        scan = self.camera.scan()
        if scan is None:
            return  # no frame: the map keeps what it had
        base = self.robot.base.pose()[:2]
        hits = scan.hits
        mine = np.hypot(*(hits[:, :2] - base).T) < self.robot.config.base.footprint_radius + OWN_MARGIN
        for side in self.robot.config.grippers:  # what a hand holds, below it or rising above it: not an obstacle
            hand = self.robot.hand_position(side)
            mine |= (np.hypot(*(hits[:, :2] - hand[:2]).T) < HELD_RADIUS) & (hits[:, 2] < hand[2] + HELD_ABOVE)
        keep = ~mine & (hits[:, 2] > OBSTACLE_MIN_HEIGHT) & (hits[:, 2] < ROBOT_HEIGHT)
        rows, cols = self.grid.cell(hits[:, :2])
        inside = self.grid.inside(rows, cols)
        keep[inside] &= ~self._near_static[rows[inside], cols[inside]]  # the map already knows it
        now = self.robot.base.time
        self._mark_seen(hits[keep][:, :2], scan.origin, now)
        self.grid.forget_older_than(now - OBSERVED_MEMORY)
        rows, cols = self._cells_seen_free(scan)
        self.grid.clear(rows, cols)

    def _cells_seen_free(self, scan: DepthScan) -> tuple[np.ndarray, np.ndarray]:
        """Cells that rays crossed low over the floor (below FREE_BELOW) before they ended."""
        usable = np.isfinite(scan.ranges) & ~scan.own_body & (scan.directions[:, 2] < -1e-3)
        directions, ranges = scan.directions[usable], scan.ranges[usable]
        # a downward ray is below FREE_BELOW from t_low on; it saw free floor from there to its end
        t_low = np.maximum((scan.origin[2] - FREE_BELOW) / -directions[:, 2], 0.0)
        # stop 1.5 cells short of the hit, measured on the floor: the hit cell itself holds what was hit
        horizontal = np.maximum(np.hypot(directions[:, 0], directions[:, 1]), 1e-3)
        t_end = ranges - 1.5 * self.grid.resolution / horizontal
        fraction = np.linspace(0.0, 1.0, FREE_SAMPLES)
        t = t_low[:, None] + (t_end - t_low)[:, None] * fraction[None, :]
        keep = np.broadcast_to((t_end > t_low)[:, None], t.shape)
        points = scan.origin + directions[:, None, :] * t[..., None]
        return self.grid.cell(points[keep][:, :2])
