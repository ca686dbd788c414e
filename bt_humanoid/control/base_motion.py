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

    def capped(self, requested: float | None = None) -> float:
        """The speed a motion may plan for: what it asks under the mission's cap and the base's limit."""
        ...

    def move_to(
        self, x: float, y: float, yaw: float, max_speed: float | None = None, shortest_turn: bool = True
    ) -> MotionHandle:
        """A pose goal: drive there and stop."""
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
