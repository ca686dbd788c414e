"""Plan a collision-free route for the base: OMPL in SE(2), then shortcut and round the corners.

The base is a disc, so a pose is valid when the clearance field of the
occupancy grid says the disc (plus a margin) fits there; yaw is free and the
follower turns the robot along the route. A straight line is used when it is
free. Otherwise BIT* (optimising length) finds a route, RRT-Connect standing
by if it finds none in its budget; the route is pulled taut (shortcuts
between its points) and every remaining corner becomes a circular arc
(smaller where an arc would come too close to an obstacle), so the follower
can keep moving through it.
"""

from __future__ import annotations

import itertools
import math
import time
from dataclasses import dataclass

import numpy as np
from ompl import base as ob
from ompl import geometric as og
from ompl import util as ou

from bt_humanoid.navigation.occupancy import OccupancyGrid

LOG_LEVEL = ou.LogLevel.LOG_WARN
ou.setLogLevel(LOG_LEVEL)

SAMPLE_SPACING = 0.05  # m between points of a planned route
CORNER_RADIUS = 0.5  # m: the largest arc a corner is rounded with
NEAR_ENDS = 0.5  # m around the start and goal where the smaller clearance applies
OPTIMISE_ITERATIONS = 3000  # BIT* iterations spent shortening a route (about 0.1 s here); a count, not a
# duration, so a mission plans the same routes on any machine


class PlanError(RuntimeError):
    """No route: the goal is inside an obstacle, walled off, or the planner ran out of time."""


@dataclass(frozen=True)
class Clearance:
    """How far the base centre keeps from obstacles: ``preferred`` on the way, ``minimum`` near start and goal.

    The robot may have to stand close to furniture (at a table to pick), so
    the ends of a route may be tighter than its middle.
    """

    minimum: float
    preferred: float

    def required(self, points: np.ndarray, start: np.ndarray, goal: np.ndarray) -> np.ndarray:
        """Clearance needed at each of ``points`` (N, 2)."""
        to_start = np.hypot(*(points - start).T)
        to_goal = np.hypot(*(points - goal).T)
        return np.where(np.minimum(to_start, to_goal) < NEAR_ENDS, self.minimum, self.preferred)


@dataclass
class Route:
    """A planned route: points every SAMPLE_SPACING metres, with arc length and curvature at each."""

    points: np.ndarray  # (N, 2) world x, y
    arc_length: np.ndarray  # (N,) m from the start
    curvature: np.ndarray  # (N,) 1/m, 0 on straight parts
    goal_yaw: float
    planning_time: float  # s of wall time

    @property
    def length(self) -> float:
        return float(self.arc_length[-1])

    def heading(self, index: int) -> float:
        """Direction of travel at a point (rad)."""
        a = self.points[max(index - 1, 0)]
        b = self.points[min(index + 1, len(self.points) - 1)]
        return math.atan2(b[1] - a[1], b[0] - a[0]) if np.any(b != a) else self.goal_yaw


def pose_check(grid: OccupancyGrid, start_xy: np.ndarray, goal_xy: np.ndarray, clearance: Clearance):
    """``valid_xy(x, y)``: whether the base centre may stand at (x, y) on a route from ``start_xy`` to ``goal_xy``
    (``clearance.required`` there, point by point: OMPL's callback takes plain floats and runs thousands of
    times per plan)."""
    field = grid.clearance
    x0, y0, resolution = float(grid.origin[0]), float(grid.origin[1]), grid.resolution
    rows, cols = field.shape
    # per cell, bit 1: clear by the preferred margin (valid on the way), bit 0: by the minimum (valid near the
    # route's ends); a flat bytes object, because indexing it from Python is ten times cheaper than numpy's
    cells = (2 * (field >= clearance.preferred).astype(np.uint8) + (field >= clearance.minimum)).tobytes()
    (sx, sy), (gx, gy) = start_xy.tolist(), goal_xy.tolist()

    def valid_xy(x: float, y: float) -> bool:
        """One pose (OMPL's callback: plain floats, no arrays, it runs thousands of times)."""
        col, row = int((x - x0) / resolution), int((y - y0) / resolution)
        if not (0 <= row < rows and 0 <= col < cols):
            return False
        clear = cells[row * cols + col]
        if clear == 0 or clear == 3:  # neither, or both: where on the route does not matter
            return clear == 3
        near = min(math.hypot(x - sx, y - sy), math.hypot(x - gx, y - gy)) < NEAR_ENDS
        return near == (clear == 1)

    return valid_xy


def plan_route(
    grid: OccupancyGrid,
    start: np.ndarray,
    goal: np.ndarray,
    clearance: Clearance,
    time_limit: float = 1.0,
    seed: int = 0,
) -> Route:
    """A route from ``start`` (x, y, yaw) to ``goal`` (x, y, yaw) that keeps ``clearance`` from obstacles.

    The route depends on the query and ``seed`` only (the run's seed): not on what the process planned before.
    """
    started = time.perf_counter()
    start_xy, goal_xy = np.asarray(start[:2], dtype=float), np.asarray(goal[:2], dtype=float)
    valid_xy = pose_check(grid, start_xy, goal_xy, clearance)

    def valid_points(points: np.ndarray) -> bool:
        """Every point of an (N, 2) array."""
        return bool(np.all(grid.clearance_at(points) >= clearance.required(points, start_xy, goal_xy)))

    if not valid_xy(*goal_xy):
        free = float(grid.clearance_at(goal_xy[None, :])[0])
        raise PlanError(
            f"goal ({goal_xy[0]:.2f}, {goal_xy[1]:.2f}) is {'inside an obstacle' if free == 0 else 'too close to one'}"
            f" (clearance {free:.2f} m, the base needs {clearance.minimum:.2f} m)"
        )
    if not valid_xy(*start_xy):
        raise PlanError(
            f"the robot at ({start_xy[0]:.2f}, {start_xy[1]:.2f}) is too close to an obstacle to plan from "
            f"(clearance {float(grid.clearance_at(start_xy[None, :])[0]):.2f} m)"
        )
    if _segment_valid(start_xy, goal_xy, valid_points):
        corners = np.array([start_xy, goal_xy])  # straight line: no sampling needed
    else:
        # BIT* (optimising path length) finds the short way round within a small budget; RRT-Connect is the
        # fallback that keeps looking (a goal it cannot reach in time_limit is walled off)
        state_valid = lambda state: valid_xy(state.getX(), state.getY())  # noqa: E731
        _seed_ompl(seed)
        solution = _ompl_route(grid, start, goal, state_valid, og.BITstar, _iterations(OPTIMISE_ITERATIONS), True)
        if solution is None:
            solution = _ompl_route(grid, start, goal, state_valid, og.RRTConnect, _seconds(time_limit))
        if solution is None:
            where = f"({goal[0]:.2f}, {goal[1]:.2f})"
            raise PlanError(f"no route to {where} within {time_limit:.1f} s of planning: it may be walled off")
        corners = _shortcut(_densify(solution, 0.25), valid_points)
    points, curvature = _round_corners(corners, valid_points)
    steps = np.hypot(*np.diff(points, axis=0).T)
    arc = np.concatenate([[0.0], np.cumsum(steps)])
    return Route(points, arc, curvature, float(goal[2]), time.perf_counter() - started)


def _seed_ompl(seed: int) -> None:
    """Reseed the process-wide generator OMPL draws every sampler's seed from, before a query.

    OMPL seeds each sampler from one generator per process, so without this a query's route would depend on how
    many routes the process planned before (the same query gave 8.32, 8.28 and 8.39 m in one process).
    Reseeding after sampling has started works, but OMPL logs an error saying it might not: silenced here.
    """
    ou.setLogLevel(ou.LogLevel.LOG_NONE)
    ou.RNG.setSeed(seed % (2**31 - 1) + 1)  # 0 would mean "seed from the clock"
    ou.setLogLevel(LOG_LEVEL)


def _iterations(count: int) -> ob.PlannerTerminationCondition:
    """Stop after ``count`` planner iterations: the same work, so the same route, on any machine."""
    done = [0]

    def finished() -> bool:
        done[0] += 1
        return done[0] > count

    return ob.PlannerTerminationCondition(finished)


def _seconds(limit: float) -> ob.PlannerTerminationCondition:
    deadline = time.perf_counter() + limit
    return ob.PlannerTerminationCondition(lambda: time.perf_counter() > deadline)


def _ompl_route(
    grid: OccupancyGrid,
    start: np.ndarray,
    goal: np.ndarray,
    valid,
    planner,
    until: ob.PlannerTerminationCondition,
    optimise: bool = False,
) -> np.ndarray | None:
    """Corner points of an OMPL solution in SE(2), or None if there is none when ``until`` says stop."""
    space = ob.SE2StateSpace()
    bounds = ob.RealVectorBounds(2)
    high = grid.origin + np.array(grid.shape[::-1]) * grid.resolution
    for axis in range(2):
        bounds.setLow(axis, float(grid.origin[axis]))
        bounds.setHigh(axis, float(high[axis]))
    space.setBounds(bounds)
    setup = og.SimpleSetup(space)
    setup.setStateValidityChecker(valid)
    information = setup.getSpaceInformation()
    # check motions every half cell: no thin wall is skipped between two valid states
    information.setStateValidityCheckingResolution(0.5 * grid.resolution / space.getMaximumExtent())
    states = []
    for pose in (start, goal):
        state = space.allocState()
        state.setX(float(pose[0]))
        state.setY(float(pose[1]))
        state.setYaw((float(pose[2]) + math.pi) % (2 * math.pi) - math.pi)  # SO(2) states live in [-π, π)
        states.append(state)
    setup.setStartAndGoalStates(states[0], states[1])
    if optimise:
        setup.setOptimizationObjective(ob.PathLengthOptimizationObjective(information))
    setup.setPlanner(planner(information))
    setup.solve(until)
    if not setup.haveExactSolutionPath():
        return None
    path = setup.getSolutionPath()  # every motion of it was checked; _shortcut simplifies it
    return np.array([[path.getState(i).getX(), path.getState(i).getY()] for i in range(path.getStateCount())])


def _segment_valid(a: np.ndarray, b: np.ndarray, valid_points, step: float = SAMPLE_SPACING / 2) -> bool:
    count = max(2, math.ceil(np.hypot(*(b - a)) / step) + 1)
    return valid_points(np.linspace(a, b, count))


def _densify(corners: np.ndarray, spacing: float) -> np.ndarray:
    """The polyline with points at most ``spacing`` apart (so shortcuts may start between corners)."""
    return np.concatenate([*(_line(a, b, spacing) for a, b in itertools.pairwise(corners)), corners[-1:]])


def _shortcut(corners: np.ndarray, valid_points) -> np.ndarray:
    """Drop every corner that a straight segment can skip (greedy, from the start)."""
    kept = [corners[0]]
    i = 0
    while i < len(corners) - 1:
        j = len(corners) - 1
        while j > i + 1 and not _segment_valid(corners[i], corners[j], valid_points):
            j -= 1
        kept.append(corners[j])
        i = j
    return np.array(kept)


def _round_corners(corners: np.ndarray, valid_points) -> tuple[np.ndarray, np.ndarray]:
    """Dense points along the polyline with each interior corner replaced by a tangent arc."""
    pieces: list[np.ndarray] = [corners[:1]]
    curvature: list[np.ndarray] = [np.zeros(1)]
    entry = corners[0]
    for k in range(1, len(corners) - 1):
        before, corner, after = corners[k - 1], corners[k], corners[k + 1]
        arc = None
        radius = CORNER_RADIUS
        while radius >= 0.05:
            arc = _fillet(before, corner, after, radius, entry, np.hypot(*(after - corner)) / 2)
            if arc is not None and valid_points(arc[0]):
                break
            arc, radius = None, radius / 2
        if arc is None:  # no arc fits: a sharp corner (the follower slows right down for it)
            points, kappa, leave = corner[None, :], np.array([1.0 / 0.05]), corner
        else:
            points, kappa, leave = arc
        pieces += [_line(entry, points[0]), points]
        curvature += [np.zeros(len(pieces[-2])), kappa]
        entry = leave
    pieces.append(_line(entry, corners[-1]))
    curvature.append(np.zeros(len(pieces[-1])))
    pieces.append(corners[-1:])
    curvature.append(np.zeros(1))
    points = np.concatenate(pieces)
    kappa = np.concatenate(curvature)
    keep = np.concatenate([[True], np.hypot(*np.diff(points, axis=0).T) > 1e-6])
    return points[keep], kappa[keep]


def _line(a: np.ndarray, b: np.ndarray, spacing: float = SAMPLE_SPACING) -> np.ndarray:
    """Points from a towards b (a included, b excluded) at most ``spacing`` apart."""
    length = float(np.hypot(*(b - a)))
    count = max(1, math.ceil(length / spacing))
    return a + np.outer(np.arange(count) / count, b - a)


def _fillet(before, corner, after, radius, entry, half_next):
    """Arc of ``radius`` tangent to both legs at ``corner``: (points, curvature, exit point), or None if too big."""
    u = (before - corner) / np.hypot(*(before - corner))
    v = (after - corner) / np.hypot(*(after - corner))
    angle = math.acos(float(np.clip(u @ v, -1.0, 1.0)))  # between the legs
    if angle > math.pi - 1e-3:
        return (corner[None, :], np.zeros(1), corner)  # straight on
    setback = radius / math.tan(angle / 2)
    if setback > np.hypot(*(corner - entry)) or setback > half_next:
        return None
    start, end = corner + u * setback, corner + v * setback
    bisector = (u + v) / np.hypot(*(u + v))
    centre = corner + bisector * radius / math.sin(angle / 2)
    a0 = math.atan2(*(start - centre)[::-1])
    a1 = math.atan2(*(end - centre)[::-1])
    sweep = (a1 - a0 + math.pi) % (2 * math.pi) - math.pi
    count = max(2, math.ceil(abs(sweep) * radius / SAMPLE_SPACING) + 1)
    angles = a0 + np.linspace(0.0, sweep, count)
    points = centre + radius * np.stack([np.cos(angles), np.sin(angles)], axis=1)
    return points, np.full(count, 1.0 / radius), end
