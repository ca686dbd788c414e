"""robot.yaml: what a robot is made of and what its controllers may do."""

from __future__ import annotations

from pathlib import Path

from pydantic import Field

from bt_humanoid.paths import robots_dir
from bt_humanoid.strict_model import StrictModel
from bt_humanoid.yaml_source import read_config


class RobotParts(StrictModel):
    lower_body: str
    upper_body: str
    mount_site: str = "mount"


class BaseLimits(StrictModel):
    max_speed: float = 0.8
    max_accel: float = 0.8
    max_jerk: float = 3.0
    max_yaw_rate: float = 1.2
    max_yaw_accel: float = 2.0
    max_yaw_jerk: float = 8.0


class BaseTolerance(StrictModel):
    position: float = 0.02
    yaw_deg: float = 2.0


class BaseConfig(StrictModel):
    joints: dict[str, str]
    actuators: dict[str, str]
    footprint_radius: float = 0.3
    limits: BaseLimits = BaseLimits()
    tolerance: BaseTolerance = BaseTolerance()


class GripperConfig(StrictModel):
    joints: list[str]
    open: float
    closed: float
    grip_site: str
    open_range: dict[str, tuple[float, float]] = Field(
        default_factory=dict,
        description="joint ranges (rad) within which the fingers open fully without meeting the arm; "
        "the whole-body controller keeps to them while the hand is open",
    )


class CameraConfig(StrictModel):
    width: int = 320
    height: int = 240
    depth: bool = True
    rate_hz: float = 10.0


class ScannerConfig(StrictModel):
    """A planar range scanner on the base (a safety laser scanner), for speed and separation monitoring."""

    height: float = Field(0.25, gt=0, description="m above the floor where the rays sweep")
    rays: int = Field(180, ge=8, le=2000, description="rays over the full circle")
    range: float = Field(4.0, gt=0, description="m beyond which nothing is seen")
    rate_hz: float = Field(50.0, gt=0, description="scans per second")


class MotionLimits(StrictModel):
    velocity: float
    acceleration: float
    jerk: float


class SafetyDefaults(StrictModel):
    max_base_speed: float = 0.8
    joint_limit_margin: float = 0.01
    time_budget: float = 600.0
    slow_distance: float = 1.0  # m between the robot and the nearest sensed thing below which it slows
    stop_distance: float = 0.2  # m below which nothing moves towards it (a protective stop)
    hold_limit: float = 10.0  # s a protective stop may hold a motion before the motion fails
    min_hand_height: float = 0.1  # m above the floor below which a hand trips the workspace monitor
    joint_speed_factor: float = 1.5  # a joint faster than this times its velocity limit trips the guard
    strain_time: float = 1.0  # s a joint may press at its torque limit before what it does is halted
    stuck_after: float = 20.0  # s a motion may make no progress (robot still, same feedback) before it fails


class RecoveryDefaults(StrictModel):
    retries: int = 0
    backoff: float = 0.5


class RobotConfig(StrictModel):
    name: str
    description: str = ""
    parts: RobotParts
    base: BaseConfig
    groups: dict[str, list[str]]
    grippers: dict[str, GripperConfig]
    frames: dict[str, tuple[str, str]]
    cameras: dict[str, CameraConfig] = Field(default_factory=dict)
    scanner: ScannerConfig | None = None
    joint_limits: dict[str, MotionLimits]
    postures: dict[str, dict[str, float]]
    safety: SafetyDefaults = SafetyDefaults()
    recovery: RecoveryDefaults = RecoveryDefaults()
    folder: Path = Path()

    def motion_limits(self, joint: str) -> MotionLimits:
        """Velocity/acceleration/jerk limits of one joint: its own, its group's, or the default."""
        if joint in self.joint_limits:
            return self.joint_limits[joint]
        for group, joints in self.groups.items():
            if joint in joints and group in self.joint_limits:
                return self.joint_limits[group]
        if any(joint in g.joints for g in self.grippers.values()) and "grippers" in self.joint_limits:
            return self.joint_limits["grippers"]
        return self.joint_limits["default"]

    @property
    def head_pan(self) -> str | None:
        """The head joint that turns the camera left and right (by name, in the head group), if any."""
        return next((j for j in self.groups.get("head", []) if "pan" in j), None)

    @property
    def head_tilt(self) -> str | None:
        """The head joint that tips the camera up and down (positive looks down), if any."""
        return next((j for j in self.groups.get("head", []) if "tilt" in j), None)

    @property
    def finger_joints(self) -> list[str]:
        """The grippers' finger joints (they press on what they hold by design)."""
        return [j for g in self.grippers.values() for j in g.joints]

    @property
    def actuated_joints(self) -> list[str]:
        """Every position-controlled joint: groups first, then gripper fingers."""
        return [j for group in self.groups.values() for j in group] + self.finger_joints


def load_robot_config(name: str) -> RobotConfig:
    """Read robots/<name>/robot.yaml; unknown names get the list of valid ones."""
    return read_config("robot", robots_dir(), name, "robot.yaml", RobotConfig)  # type: ignore[return-value]
