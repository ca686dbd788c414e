"""Speed and separation monitoring: the base slows, then stops, as a person or a thing it senses gets close.

The base scanner's hits that are not the map's furniture (a person, a parcel,
a box that was moved) each set how fast the robot may close in on them: full
speed beyond ``slow_distance`` from the robot's outline, falling linearly to
nothing at ``stop_distance`` (a protective stop, in the sense of ISO/TS 15066).
Moving away or sideways is always allowed, so a robot that someone stands
close to can still make way. Turning counts as closing in when an arm reaches
out past the base: the hand sweeps round. Nothing latches: the motion goes
on when the way clears, and a motion held too long fails (``hold_limit``).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from bt_humanoid.perception.safety_scanner import SafetyScanner
from bt_humanoid.sim.robot_config import SafetyDefaults

PERSON_RADIUS = 0.4  # m around a known person's position where hits are them, though the map has them as fixed
HAND_RADIUS = 0.06  # m a hand (and what it holds) reaches past its grip point
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
        self.distance = np.inf  # m from the robot's outline to the nearest sensed thing
        self.outline = footprint  # m from the base centre that the robot reaches now (arms included)
        self._gaps = np.zeros(0)  # m per sensed thing within the slow zone, from the outline
        self._directions = np.zeros((0, 2))  # unit vectors from the base centre to them

    def update(self, base_xy: np.ndarray) -> None:
        """Scan, and find what is near the robot's outline."""
        points = self.scanner.scan()
        reach = [float(np.hypot(*(hand[:2] - base_xy))) + HAND_RADIUS for hand in self.hands()]
        self.outline = max([self.footprint, *reach])
        if len(points):
            near_person = np.zeros(len(points), dtype=bool)
            for person in self.people():
                near_person |= np.hypot(*(points - person[:2]).T) < PERSON_RADIUS
            points = points[near_person | ~self.furniture(points)]
        offsets = points - base_xy
        ranges = np.hypot(*offsets.T) if len(points) else np.zeros(0)
        gaps = ranges - self.outline
        close = gaps < self.slow
        self._gaps = gaps[close]
        self._directions = offsets[close] / np.maximum(ranges[close, None], 1e-6)
        self.distance = float(gaps.min()) if len(gaps) else np.inf
        self._update_zone()

    def share(self, velocity: np.ndarray) -> float:
        """The share (0 to 1) of a base velocity (vx, vy, yaw rate; world frame) that keeps the closing speeds."""
        if not len(self._gaps):
            return 1.0
        allowed = self.max_speed * np.clip((self._gaps - self.stop) / (self.slow - self.stop), 0.0, 1.0)
        sweep = abs(float(velocity[2])) * max(self.outline - self.footprint, 0.0)
        closing = np.maximum(self._directions @ np.asarray(velocity[:2], dtype=float), 0.0) + sweep
        limited = closing > allowed + 1e-9
        if not np.any(limited):
            return 1.0
        return float(np.min(allowed[limited] / closing[limited]))

    def describe(self) -> str:
        return f"something {max(self.distance, 0.0):.2f} m from the robot"

    def _update_zone(self) -> None:
        d, zone = self.distance, self.zone
        margin = {"clear": 0.0, "slow": HYSTERESIS, "stop": HYSTERESIS}[zone]
        if d < self.stop + (margin if zone == "stop" else 0.0):
            new = "stop"
        elif d < self.slow + (margin if zone != "clear" else 0.0):
            new = "slow"
        else:
            new = "clear"
        if new != zone:
            self.zone = new
            if self.on_zone is not None:
                self.on_zone(new, d)
