"""Speed and separation monitoring: the base slows, then stops, as a person or a thing it senses gets close.

The base scanner's hits that are not the map's furniture (a person, a parcel,
a box that was moved) each set how fast the robot may close in on them: full
speed beyond ``slow_distance``, falling linearly to nothing at
``stop_distance`` (a protective stop, in the sense of ISO/TS 15066). Moving
away or sideways is always allowed, so a robot that someone stands close to
can still make way. The robot's parts are the base and the hands: turning
moves a hand that reaches out, and that counts as closing in too. Nothing
latches: the motion goes on when the way clears, and a motion held too long
fails (``hold_limit``).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from bt_humanoid.localisation.scan_matcher import transform
from bt_humanoid.perception.safety_scanner import SafetyScanner
from bt_humanoid.sim.robot_config import SafetyDefaults

PERSON_RADIUS = 0.4  # m around a known person's position where hits are them, though the map has them as fixed
HAND_RADIUS = 0.06  # m a hand (and what it holds) reaches past its grip point
LOOK_AHEAD = 0.01  # s over which a part's closing speed is measured
HYSTERESIS = 0.05  # m a zone is left by, so a person at its edge does not flood the event log


class SpeedAndSeparation:
    """``update()`` every control step; ``share(velocity)`` says how much of a planned base velocity may run."""

    def __init__(
        self,
        scanner: SafetyScanner,
        settings: SafetyDefaults,
        footprint: float,
        max_speed: float,
        furniture: Callable[[np.ndarray], np.ndarray],
        people: Callable[[], list[np.ndarray]],
        hands: Callable[[], list[np.ndarray]],
        on_zone: Callable[[str, float], None] | None = None,
    ) -> None:
        self.scanner = scanner
        self.slow, self.stop = settings.slow_distance, settings.stop_distance
        self.hold_limit = settings.hold_limit
        self.footprint, self.max_speed = footprint, max_speed
        self.furniture, self.people, self.hands = furniture, people, hands
        self.on_zone = on_zone
        self.zone = "clear"
        self.distance = np.inf  # m from the nearest part of the robot to the nearest sensed thing
        self._points = np.zeros((0, 2))  # sensed things within the slow zone of a part
        self._parts = np.zeros((0, 2))  # the robot's parts as discs on the floor: the base, then each hand
        self._arms = np.zeros((0, 2))  # each part's centre from the base centre: it swings when the base turns
        self._radii = np.zeros(0)
        self._near_gaps = np.zeros(0)  # per part: m to the nearest of those

    def update(self, base_pose: np.ndarray) -> None:
        """On each fresh scan: what is near the base or a hand, as the robot stood when the scan was taken
        (``base_pose``: x, y, yaw on the map, where the robot believes it is)."""
        points = self.scanner.scan()
        if points is None:
            return  # between scans: keep the last picture (the points and the parts of one instant)
        points = transform(points, base_pose)
        base_xy = np.asarray(base_pose[:2], dtype=float)
        if len(points):
            near_person = np.zeros(len(points), dtype=bool)
            for person in self.people():
                near_person |= np.hypot(*(points - person[:2]).T) < PERSON_RADIUS
            points = points[near_person | ~self.furniture(points)]
        self._arms = np.array([np.zeros(2), *(hand[:2] - base_xy for hand in self.hands())])
        self._parts = base_xy + self._arms
        self._radii = np.array([self.footprint] + [HAND_RADIUS] * (len(self._arms) - 1))
        gaps = self._gaps_of(self._parts, points)  # (points, parts)
        near = np.any(gaps < self.slow, axis=1)
        self._points = points[near]
        self._near_gaps = gaps[near].min(axis=0) if np.any(near) else np.full(len(self._parts), np.inf)
        self.distance = float(gaps.min()) if gaps.size else np.inf
        self._update_zone()

    @property
    def near_points(self) -> np.ndarray:
        """(N, 2) what the scanner sensed within the slow zone of a part, not furniture (map frame, last scan)."""
        return self._points

    def share(self, velocity: np.ndarray) -> float:
        """The share (0 to 1) of a base velocity (vx, vy, yaw rate; world frame) that keeps the closing speeds.

        A part's closing speed is how fast its gap to the nearest sensed thing shrinks, over a short look ahead:
        sliding past the side of a person does not count, heading at them does.
        """
        if not len(self._points):
            return 1.0
        vx, vy, yaw_rate = (float(v) for v in velocity)
        # each part moves with the base and, when the base turns, at right angles to its arm
        moving = np.array([vx, vy]) + yaw_rate * np.stack([-self._arms[:, 1], self._arms[:, 0]], axis=1)
        ahead = self._gaps_of(self._parts + moving * LOOK_AHEAD, self._points).min(axis=0)
        now = self._near_gaps
        closing = np.maximum(now - ahead, 0.0) / LOOK_AHEAD
        allowed = self.max_speed * np.clip((now - self.stop) / (self.slow - self.stop), 0.0, 1.0)
        limited = closing > allowed + 1e-6
        if not np.any(limited):
            return 1.0
        return float(np.min(allowed[limited] / closing[limited]))

    def _gaps_of(self, parts: np.ndarray, points: np.ndarray) -> np.ndarray:
        """(points, parts): metres between each sensed point and each part's edge."""
        offsets = points[:, None, :] - parts[None, :, :]
        return np.hypot(offsets[..., 0], offsets[..., 1]) - self._radii[None, :]

    def describe(self) -> str:
        return f"something {max(self.distance, 0.0):.2f} m from the robot"

    def _update_zone(self) -> None:
        d, zone = self.distance, self.zone
        if d < self.stop + (HYSTERESIS if zone == "stop" else 0.0):
            new = "stop"
        elif d < self.slow + (HYSTERESIS if zone != "clear" else 0.0):
            new = "slow"
        else:
            new = "clear"
        if new != zone:
            self.zone = new
            if self.on_zone is not None:
                self.on_zone(new, d)
