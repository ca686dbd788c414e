"""The navigation stack of one robot: map, depth updates, planning, following and replanning.

``go_to(goal)`` plans a route on the occupancy grid and starts following it.
Every control step the navigator updates the map from the head depth camera
(at the camera's rate) and checks the route ahead against it: when something
now blocks it, the robot replans from where it is and carries on, or stops
with the reason if no route is left. Skills talk to the navigator through
the motion handles it returns; recovery (clear the map, spin, back up, wait)
is tree structure in behaviors/navigate.yaml.
"""

from __future__ import annotations

import math

import numpy as np

from bt_humanoid.control.motion import MotionHandle
from bt_humanoid.control.robot import RobotController
from bt_humanoid.navigation.follower import RouteFollower
from bt_humanoid.navigation.occupancy import OccupancyGrid
from bt_humanoid.navigation.planner import Clearance, PlanError, Route, plan_route
from bt_humanoid.navigation.static_map import ROBOT_HEIGHT, static_map
from bt_humanoid.perception.depth_camera import DepthCamera, DepthScan
from bt_humanoid.sim.simulation import Simulation

RESOLUTION = 0.05  # m per map cell
CLEARANCE_MARGIN = 0.1  # m the base keeps from obstacles on the way, beyond its footprint
END_MARGIN = 0.0  # m near the start and goal: stances at furniture are close to it (the grid errs on the safe side)
OBSTACLE_MIN_HEIGHT = 0.06  # m: depth points lower than this are floor
FREE_BELOW = 0.1  # m: a ray passing a cell lower than this shows nothing taller stands there
OWN_SPACE = 0.6  # m around the base centre where depth points are the robot or what it carries
LOOKAHEAD = 2.5  # m of route ahead checked against the map at every update
MAX_REPLANS = 5  # per goal, before the goal fails as blocked
FREE_SAMPLES = 12  # points along the low end of each ray that mark free cells


class Navigator:
    """Plans and follows routes for the base; ``step()`` runs it (registered with the RobotController)."""

    def __init__(self, sim: Simulation, robot: RobotController, bounds: np.ndarray) -> None:
        self.robot = robot
        config = robot.config
        footprint = config.base.footprint_radius
        self.clearance = Clearance(footprint + END_MARGIN, footprint + CLEARANCE_MARGIN)
        self.grid: OccupancyGrid = static_map(sim.model, sim.data, bounds, RESOLUTION)
        camera = next(iter(config.cameras), None)
        self.camera = DepthCamera(sim.model, sim.data, camera, "base") if camera else None
        self.scan_period = 1.0 / config.cameras[camera].rate_hz if camera else math.inf
        self.last_scan = -math.inf
        self.follower = RouteFollower(robot.base, config.base, robot.control_period)
        self.goal: np.ndarray | None = None
        self.max_speed = config.base.limits.max_speed
        self.replans = 0
        self.handle: MotionHandle | None = None
        self.planning_times: list[float] = []  # s of wall time per plan, for benchmarks
        self.route_lengths: list[float] = []  # m, per route planned
        self.route: Route | None = None
        self.motion: MotionHandle | None = None  # the follower's handle for the current route

    # ------------------------------------------------------------------ goals

    def go_to(self, goal: np.ndarray, max_speed: float) -> MotionHandle:
        """Plan to ``goal`` (x, y, yaw) and follow the route; the handle fails with the reason if there is none."""
        self._finish_goal("pre-empted by a new goal")
        if self.follower.dt != self.robot.control_period:  # the executor chose the control rate after we were built
            self.follower = RouteFollower(self.robot.base, self.robot.config.base, self.robot.control_period)
        self.goal, self.max_speed, self.replans = np.asarray(goal, dtype=float), max_speed, 0
        handle = MotionHandle(f"navigating to ({goal[0]:.2f}, {goal[1]:.2f})", on_cancel=lambda _: self.halt())
        self.handle = handle
        self._update_map()
        self._plan_and_follow()  # fails the handle at once if there is no route
        return handle

    def halt(self) -> None:
        """Stop following; the base brakes to rest."""
        self.follower.stop()
        self.goal = None
        if self.handle is not None:
            self.handle.fail("halted: braking")
            self.handle = None

    def clear_map(self) -> None:
        """Forget every obstacle the camera added; the next scans add back what is still there."""
        self.grid.clear_observed()

    # ------------------------------------------------------------------ control step

    def step(self) -> None:
        if self.handle is None:
            return  # the map is updated while navigating (scans cost time, and nothing reads it otherwise)
        now = self.robot.base.io.time
        if self.camera is not None and now - self.last_scan >= self.scan_period - 1e-9:
            self.last_scan = now
            if self._update_map() and self.handle is not None and self._route_ahead_blocked():
                self.replans += 1
                if self.replans > MAX_REPLANS:
                    self._finish_goal(f"the way stayed blocked after {MAX_REPLANS} replans", brake=True)
                else:
                    self._plan_and_follow()
        if self.handle is None:
            return
        self.follower.step()
        motion = self.motion
        if motion is None or motion.done:
            self._settle(motion)
        else:
            self.handle.feedback = motion.feedback

    # ------------------------------------------------------------------ internals

    def _plan_and_follow(self) -> None:
        start = self.robot.base.pose()
        try:
            route = plan_route(self.grid, start, self.goal, self.clearance)
        except PlanError as error:
            self.planning_times.append(0.0)
            self._finish_goal(str(error), brake=True)
            return
        self.planning_times.append(route.planning_time)
        self.route_lengths.append(route.length)
        self.route = route
        self.motion = self.follower.follow(route, self.max_speed)

    def _settle(self, motion: MotionHandle | None) -> None:
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

    def _route_ahead_blocked(self) -> bool:
        route = self.route
        if route is None or self.follower.route is None:
            return False
        s = self.follower.progress
        ahead = (route.arc_length >= s) & (route.arc_length <= s + LOOKAHEAD)
        points = route.points[ahead]
        if len(points) == 0:
            return False
        needed = self.clearance.required(points, route.points[0], route.points[-1])
        # the part the base stands in now may be tight (it started there): judge the rest
        return bool(np.any(self.grid.clearance_at(points) < np.minimum(needed, self.clearance.minimum)))

    def _update_map(self) -> bool:
        """Add what the depth camera sees, clear what it sees free; True if the map changed."""
        if self.camera is None:
            return False
        scan = self.camera.scan()
        base = self.robot.base.pose()[:2]
        hits = scan.hits
        away = np.hypot(*(hits[:, :2] - base).T) > OWN_SPACE
        solid = hits[away & (hits[:, 2] > OBSTACLE_MIN_HEIGHT) & (hits[:, 2] < ROBOT_HEIGHT)]
        changed = self.grid.mark(solid[:, :2])
        rows, cols = self._cells_seen_free(scan)
        return self.grid.clear(rows, cols) or changed

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
