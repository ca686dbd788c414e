"""What skills, the navigator and the whole-body controller may ask of a mobile base, whatever moves it.

The wheeled humanoid's ``BaseDriver`` drives planar joints through velocity actuators; a walking base (a
footstep planner and a balance controller under the same upper body) answers the same calls. Nothing above
the control layer looks past this interface at joints.
"""

from __future__ import annotations

from typing import Protocol, runtime_checkable

import numpy as np

from bt_humanoid.control.motion import MotionHandle


@runtime_checkable
class BaseMotion(Protocol):
    speed_cap: float  # m/s: the mission's cap, set once per run; every motion plans under it
    held_since: float | None  # when a protective stop began holding the motion now running; None while free

    @property
    def time(self) -> float:
        """The base's clock (simulation seconds)."""
        ...

    def pose(self) -> np.ndarray:
        """Odometry: (x, y, yaw) in the world frame."""
        ...

    def speeds(self) -> np.ndarray:
        """(vx, vy, yaw rate) in the world frame."""
        ...

    def settled(self) -> bool:
        """Whether the pose read now is where the base stays if it stops: a wheeled base's always is; a walking
        base's only once it stands, its pelvis no longer swaying over each stance foot."""
        ...

    def capped(self, requested: float | None = None) -> float:
        """The speed a motion may plan for: what it asks under the mission's cap and the base's limit."""
        ...

    def move_to(
        self,
        x: float,
        y: float,
        yaw: float,
        max_speed: float | None = None,
        shortest_turn: bool = True,
        tolerance: float | None = None,
    ) -> MotionHandle:
        """A pose goal: drive there and stop, arrived within ``tolerance`` m (default: robot.yaml
        ``base.tolerance.position``)."""
        ...

    def track(self, reference: np.ndarray, velocity: np.ndarray) -> None:
        """Follow a streamed pose and velocity (one control step's worth); pre-empts any goal."""
        ...

    def brake(self) -> None:
        """Cancel the goal and come to rest."""
        ...

    def allowed_share(self, velocity: np.ndarray) -> float:
        """The share (0 to 1) of ``velocity`` that speed and separation monitoring allows now."""
        ...

    def reset_hold(self) -> None:
        """A new motion: a protective stop holding it starts counting afresh."""
        ...

    def held_too_long(self, share: float, now: float) -> str | None:
        """Why to give up once a protective stop has held a motion too long; None until then."""
        ...


HELD_SHARE = 0.05  # a motion allowed less than this share of its speed is held (a protective stop)


class SpeedLimiter(Protocol):
    """Says how much of a planned base velocity may run now (speed and separation monitoring does)."""

    hold_limit: float  # s a motion may be held before it fails

    def share(self, velocity: np.ndarray) -> float: ...

    def describe(self) -> str: ...


class SpeedMonitoring:
    """The part of ``BaseMotion`` every base answers alike: the share of a velocity that speed and separation
    monitoring allows, and how long a protective stop has held a motion."""

    limiter: SpeedLimiter | None = None  # slows planned motions near people and things sensed
    held_since: float | None = None  # when the limiter stopped the motion

    def allowed_share(self, velocity: np.ndarray) -> float:
        """The share (0 to 1) of ``velocity`` (vx, vy, yaw rate; world frame) the base may run at now."""
        return self.limiter.share(velocity) if self.limiter is not None else 1.0

    def reset_hold(self) -> None:
        """A new motion: a protective stop holding it starts counting afresh."""
        self.held_since = None

    def held_too_long(self, share: float, now: float) -> str | None:
        """Track a protective stop; the reason to give up once it has held a motion for the limiter's hold limit."""
        if share >= HELD_SHARE or self.limiter is None:
            self.held_since = None
            return None
        self.held_since = now if self.held_since is None else self.held_since
        if now - self.held_since <= self.limiter.hold_limit:
            return None
        return f"held {now - self.held_since:.0f} s by a protective stop: {self.limiter.describe()}"
