"""Drive the base along a planned route, jerk-limited, facing the way it goes.

Progress along the route (arc length s) and the heading are two degrees of
freedom of an online Ruckig generator, updated every control step: s heads
for the end of the route under the speed, acceleration and jerk limits, its
speed capped ahead of every bend so the sideways acceleration stays small;
the heading turns towards the direction of travel (and to the goal's yaw for
the last stretch). The base tracks the route point at s through
``BaseMotion.track``. A base held back by contact falls behind its
reference and the motion fails as blocked.
"""

from __future__ import annotations

import math

import numpy as np
from ruckig import InputParameter, OutputParameter, Result, Ruckig, Synchronization

from bt_humanoid.control.base_driver import wrap_angle
from bt_humanoid.control.base_motion import BaseMotion
from bt_humanoid.control.motion import MotionHandle
from bt_humanoid.navigation.planner import Route
from bt_humanoid.sim.robot_config import BaseConfig

LATERAL_ACCEL = 0.4  # m/s^2 allowed sideways in a bend: v ≤ sqrt(a / curvature)
FINAL_STRETCH = 0.4  # m before the goal from which the base turns to the goal's yaw
SETTLE_TIMEOUT = 3.0  # s at the end of the route to come within tolerance
END_EPSILON = 1e-3  # m of the route's end that counts as reached
STOP_SHORT = 0.3  # m the base stops short of where its route is blocked
HORIZON = 60.0  # s of travel at the allowed speed that the route timing looks ahead (a crawl: a few cm)


class RouteFollower:
    """One route at a time; ``step()`` every control period while it runs."""

    def __init__(self, base: BaseMotion, config: BaseConfig, dt: float) -> None:
        self.base = base
        self.config = config
        self.dt = dt
        self.route: Route | None = None
        self.handle: MotionHandle | None = None
        self.stop_at: float | None = None  # arc length where the route is blocked: stop short of it
        self.speed_limit = math.inf  # m/s, set by the navigator near obstacles the camera saw
        self._otg = Ruckig(2, dt)
        self._input = InputParameter(2)
        self._output = OutputParameter(2)

    @property
    def progress(self) -> float:
        """Arc length reached along the current route (m)."""
        return float(self._input.current_position[0]) if self.route is not None else 0.0

    def follow(self, route: Route, max_speed: float) -> MotionHandle:
        """Start along ``route`` from the base's current state; returns the handle to poll."""
        if self.handle is not None:
            self.handle.fail("pre-empted by a new route")
        limits = self.config.limits
        pose, speeds = self.base.pose(), self.base.speeds()
        heading = route.heading(0)
        along = float(speeds[:2] @ np.array([math.cos(heading), math.sin(heading)]))
        inp = self._input
        inp.current_position = [0.0, pose[2]]
        inp.current_velocity = [max(along, 0.0), speeds[2]]
        inp.current_acceleration = [0.0, 0.0]
        inp.max_velocity = [min(max_speed, limits.max_speed), limits.max_yaw_rate]
        inp.max_acceleration = [limits.max_accel, limits.max_yaw_accel]
        inp.max_jerk = [limits.max_jerk, limits.max_yaw_jerk]
        inp.synchronization = Synchronization.No  # progress and heading each as fast as they can
        self.max_speed = inp.max_velocity[0]
        self.route = route
        self.started_settling: float | None = None
        self.settle_time = SETTLE_TIMEOUT  # s from then the base has to come within tolerance
        self.stop_at = None
        self.speed_limit = math.inf
        self.base.reset_hold()
        self.handle = MotionHandle(f"following a {route.length:.1f} m route", on_cancel=lambda _: self.stop())
        return self.handle

    def stop(self) -> None:
        """Abandon the route; the base brakes to rest."""
        if self.route is not None:
            self.route = None
            self.base.brake()
        if self.handle is not None:
            self.handle.fail("halted: braking")
            self.handle = None

    def step(self) -> None:
        route, handle = self.route, self.handle
        if route is None or handle is None:
            return
        inp = self._input
        s = float(inp.current_position[0])
        index = int(np.searchsorted(route.arc_length, s))
        limits = self.config.limits
        # speed and separation: the share of full speed along the route (and of the turn) allowed now
        share = self.base.allowed_share(
            np.array([*(self.max_speed * self._point(route, s)[1]), inp.current_velocity[1]])
        )
        held = self.base.held_too_long(share, self.base.time)
        if held is not None:
            handle.fail(held)
            self.handle = None
            self.stop()
            return
        speed = float(inp.current_velocity[0])
        speed_cap = min(self._speed_cap(route, s, speed, float(inp.current_position[1])), share * self.max_speed)
        yaw = self._heading_target(route, s, index)
        if limits.turn_first is not None and abs(wrap_angle(yaw - self.base.pose()[2])) > limits.turn_first:
            speed_cap = 0.0  # face the way first: the route's reference waits while the base turns
        inp.max_velocity = [max(speed_cap, 1e-3), max(share * limits.max_yaw_rate, 1e-3)]
        end = route.length if self.stop_at is None else min(route.length, max(s, self.stop_at - STOP_SHORT))
        # while held to a crawl (someone close), a far end would take longer than a trajectory can last: aim no
        # further than the crawl covers in HORIZON seconds, beyond the braking distance (re-aimed every step)
        end = min(end, s + speed**2 / (2 * limits.max_accel) + HORIZON * inp.max_velocity[0])
        inp.target_position = [end, float(inp.current_position[1]) + wrap_angle(yaw - inp.current_position[1])]
        inp.target_velocity = [0.0, 0.0]
        try:
            result = self._otg.update(inp, self._output)
        except ValueError as error:  # a code the binding's Result enum lacks (an error all the same)
            result = str(error)
        if result not in (Result.Working, Result.Finished):
            handle.fail(f"route timing failed ({result})")
            self.stop()
            return
        self._output.pass_to_input(inp)
        s, speed = float(inp.current_position[0]), float(inp.current_velocity[0])
        point, direction = self._point(route, s)
        reference = np.array([point[0], point[1], inp.current_position[1]])
        velocity = np.array([*(speed * direction), inp.current_velocity[1]])
        self.base.track(reference, velocity)
        self._check(route, handle, reference, s, speed)

    # ------------------------------------------------------------------ internals

    def _speed_cap(self, route: Route, s: float, speed: float, yaw: float) -> float:
        """The fastest speed from which every bend within braking distance can still be taken (and, for a base
        that turns before it walks, the last turn finished by the end of the route)."""
        limits = self.config.limits
        horizon = s + speed**2 / (2 * limits.max_accel) + 0.3
        window = (route.arc_length >= s) & (route.arc_length <= horizon)
        kappa = float(route.curvature[window].max()) if np.any(window) else 0.0
        cap = math.sqrt(LATERAL_ACCEL / kappa) if kappa > 1e-6 else self.max_speed
        if limits.turn_first is not None:
            cap = min(cap, self._final_turn_cap(route, s, yaw))
        if limits.max_sideways_speed is not None:  # at the heading the base has, not the one it is turning to
            cap = min(cap, self._sideways_cap(route, s, float(self.base.pose()[2])))
        if self.stop_at is not None:  # something ahead: slow so the base can stop short of it
            room = max(self.stop_at - STOP_SHORT - s, 0.0)
            cap = min(cap, math.sqrt(2 * limits.max_accel * room))
        return max(min(cap, self.max_speed, self.speed_limit), 0.05)

    def _final_turn_cap(self, route: Route, s: float, yaw: float) -> float:
        """A walking base takes up a streamed velocity a step late: arriving fast and still turning to the goal's
        yaw, its pelvis ran on 18 cm past the end (into a table). The speed at which the rest of the route takes
        as long as the turn still to make (at the base's yaw rate) lets the turn end as the route does."""
        to_go = route.length - s
        heading = yaw if to_go < FINAL_STRETCH else route.heading(len(route.points) - 1)
        turn = abs(wrap_angle(route.goal_yaw - heading))
        return to_go * self.config.limits.max_yaw_rate / turn if turn > 1e-6 else math.inf

    def _sideways_cap(self, route: Route, s: float, yaw: float) -> float:
        """The speed a base slower sideways than forwards makes along the route facing ``yaw``: on the ellipse of
        its forward and sideways speeds. Turning to the goal's yaw on the last stretch, a walking base was asked
        to go sideways at the route's speed, fell 0.3 m behind, and ran out of time side-stepping to the goal."""
        along = self._point(route, s)[1]
        if not np.any(along):
            return math.inf
        angle = math.atan2(along[1], along[0]) - yaw
        forward, sideways = math.cos(angle) / self.max_speed, math.sin(angle) / self.config.limits.sideways_speed
        return 1.0 / math.hypot(forward, sideways)

    def _heading_target(self, route: Route, s: float, index: int) -> float:
        if route.length - s < FINAL_STRETCH or route.length < 1e-6:
            return route.goal_yaw
        return route.heading(min(index, len(route.points) - 1))

    def _point(self, route: Route, s: float) -> tuple[np.ndarray, np.ndarray]:
        """Route point at arc length s and the unit direction of travel there."""
        arc = route.arc_length
        i = int(np.clip(np.searchsorted(arc, s) - 1, 0, max(len(arc) - 2, 0)))
        if len(arc) < 2:
            return route.points[0], np.zeros(2)
        a, b = route.points[i], route.points[i + 1]
        span = arc[i + 1] - arc[i]
        t = float(np.clip((s - arc[i]) / span, 0.0, 1.0)) if span > 0 else 1.0
        return a + t * (b - a), (b - a) / span if span > 0 else np.zeros(2)

    def _check(self, route: Route, handle: MotionHandle, reference: np.ndarray, s: float, speed: float) -> None:
        pose = self.base.pose()
        lag = float(np.hypot(*(reference[:2] - pose[:2])))
        if lag > self.config.tolerance.tracking:  # something holds the base back
            handle.fail(f"base blocked near ({pose[0]:.2f}, {pose[1]:.2f}): {lag:.2f} m behind its route")
            self.handle = None
            self.stop()
            return
        goal = route.points[-1]
        remaining = float(np.hypot(*(goal - pose[:2])))
        yaw_error = abs(wrap_angle(route.goal_yaw - pose[2]))
        handle.feedback = f"{max(route.length - s, 0.0):.1f} m of {route.length:.1f} m to go at {speed:.2f} m/s"
        if route.length - s > END_EPSILON or abs(speed) > 1e-3:
            return
        tolerance = self.config.tolerance
        arrived = remaining < tolerance.position and math.degrees(yaw_error) < tolerance.yaw_deg
        # a walking base is there once it stands: arriving mid-step, its swaying pelvis ended up to 13 cm off
        if arrived and self.base.settled():
            handle.succeed(f"arrived within {remaining * 100:.1f} cm, {math.degrees(yaw_error):.1f}°")
            self.handle = None
            self.route = None
            self.base.track(np.array([*goal, route.goal_yaw]), np.zeros(3))  # hold the goal
            return
        now = self.base.time
        if self.started_settling is None:
            self.started_settling = now
            # a slow base (a biped turning at 0.3 rad/s, side-stepping at 0.08 m/s, a step at a time) gets the
            # time its last turn and its last steps take as well, at its slowest
            limits = self.config.limits
            slowest = min(limits.max_speed, limits.sideways_speed)
            self.settle_time = SETTLE_TIMEOUT + yaw_error / limits.max_yaw_rate + remaining / slowest
        settle = self.settle_time
        if arrived:  # within tolerance and coming to rest: as long again for its last steps
            settle *= 2
        if now - self.started_settling > settle:
            handle.fail(f"stopped {remaining:.2f} m and {math.degrees(yaw_error):.0f}° from the goal")
            self.handle = None
            self.stop()
