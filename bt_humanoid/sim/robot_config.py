"""robot.yaml: what a robot is made of and what its controllers may do."""

from __future__ import annotations

from pathlib import Path
from typing import Literal

from pydantic import Field, model_validator

from bt_humanoid.paths import robots_dir
from bt_humanoid.sim.sensor_models import SensorModels
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
    #: rad of heading error beyond which the base turns towards its route before it moves along it; None: it
    #: turns while it moves (a wheeled base; a biped walks three times faster forwards than sideways)
    turn_first: float | None = None
    #: m/s the base moves sideways to its heading; None: as fast as forwards (a wheeled base)
    max_sideways_speed: float | None = Field(None, gt=0)

    @property
    def sideways_speed(self) -> float:
        """m/s the base makes sideways to its heading (its forward speed where it says none)."""
        return self.max_sideways_speed if self.max_sideways_speed is not None else self.max_speed


class BaseTolerance(StrictModel):
    position: float = 0.02
    yaw_deg: float = 2.0
    #: m a base may fall behind a streamed route before it counts as blocked (a walking base answers a step late)
    tracking: float = 0.25


PLANAR_AXES = ("x", "y", "yaw")


class WorkingStance(StrictModel):
    """Where the base stands to work on a spot of a surface (control/stance.py): facing the nearest edge, the spot
    in front of the working hand. The defaults are the wheeled robot's, whose base and lift help every reach."""

    standoff: float | None = Field(
        None,
        gt=0,
        description="m from the surface's edge to the base's centre; default: the footprint 5 cm clear of the edge "
        "(a walking robot's feet take less room than its footprint)",
    )
    reach_depth: float = Field(0.42, gt=0, description="m behind the edge the hand reaches from the stance")
    hand_lateral: float = Field(0.18, ge=0, description="m to its side of the base's centre line the spot lies")
    closest: float | None = Field(
        None,
        gt=0,
        description="m from the edge the base may come for a spot deeper than reach_depth (nearer by as much as "
        "the spot is deeper); None: it stands at standoff",
    )


class BaseConfig(StrictModel):
    """How the robot's base moves: planar joints driven by actuators (a wheeled base), or a floating base (a free
    joint nothing drives: the legs carry it)."""

    kind: Literal["planar", "floating"] = "planar"
    joints: dict[str, str] = Field(description="planar: {x, y, yaw: joint}; floating: {free: the free joint}")
    actuators: dict[str, str] = Field(description="planar: {x, y, yaw: actuator}; floating: none ({})")
    footprint_radius: float = 0.3
    working_stance: WorkingStance = WorkingStance()
    limits: BaseLimits = BaseLimits()
    tolerance: BaseTolerance = BaseTolerance()

    @model_validator(mode="after")
    def _joints_fit_the_kind(self) -> BaseConfig:
        if self.kind == "planar":
            for key in ("joints", "actuators"):
                if set(getattr(self, key)) != set(PLANAR_AXES):
                    raise ValueError(f"a planar base names {key} for x, y and yaw, not {sorted(getattr(self, key))}")
        else:
            if set(self.joints) != {"free"}:
                raise ValueError(f"a floating base names one free joint ({{free: NAME}}), not {sorted(self.joints)}")
            if self.actuators:
                raise ValueError("a floating base has no actuators (actuators: {}): the legs move it")
        return self

    @property
    def floating(self) -> bool:
        return self.kind == "floating"

    @property
    def planar_joints(self) -> list[str]:
        """The x, y and yaw joints of a planar base, in that order; none for a floating base."""
        return [self.joints[axis] for axis in PLANAR_AXES] if self.kind == "planar" else []

    @property
    def root_joint(self) -> str:
        """The joint nearest the world: the robot's bodies are the tree it moves."""
        return self.joints["free"] if self.floating else self.joints["x"]


class GripperConfig(StrictModel):
    joints: list[str]
    open: float
    closed: float
    grip_site: str
    wrist_force: str | None = Field(
        None,
        description="the wrist's force sensor (MJCF sensor name), measuring what the hand and its load weigh; "
        "a legged robot weighs what it lifts with it and balances with that mass",
    )
    open_range: dict[str, tuple[float, float]] = Field(
        default_factory=dict,
        description="joint ranges (rad) within which the fingers open fully without meeting the arm; "
        "the whole-body controller keeps to them while the hand is open",
    )
    tactile_pads: list[str] = Field(
        default_factory=list,
        description="finger pads that feel where a held thing presses: each has touch sensors named PAD_taxel0, "
        "PAD_taxel1, … across its width (MJCF sites and sensors)",
    )
    taking_pull: float = Field(
        4.0,
        gt=0,
        le=50,
        description="N of pull and lift at the wrist, felt for 0.15 s, that is a person taking what the hand holds "
        "out (give): a stiff arm holds against their pull and feels it whole; an arm that yields to it feels less",
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
    mounts: list[tuple[float, float]] = Field(
        [(0.0, 0.0)],
        min_length=1,
        description="where each scanning head sits (m ahead of the base's centre, m to its left); each sweeps all "
        "round with `rays` rays, and one scan is all of their hits",
    )


LEG_ROLES = ("hip_yaw", "hip_roll", "hip_pitch", "knee", "ankle_pitch", "ankle_roll")


class LegConfig(StrictModel):
    """One leg: its joints from the hip down, its foot and the sensors on it (MJCF names)."""

    joints: list[str] = Field(description="hip yaw, hip roll, hip pitch, knee, ankle pitch, ankle roll: in that order")
    foot: str = Field(description="the foot's body")
    sole: str = Field(description="site at the centre of the sole's contact rectangle, on the sole plane, x forward")
    force_sensor: str = Field(description="3-axis force the ankle exerts on the foot, in the sensor site's frame")
    torque_sensor: str = Field(description="3-axis torque the ankle exerts on the foot, in the sensor site's frame")
    touch_sensor: str = Field(description="normal force of the ground on the sole")

    @model_validator(mode="after")
    def _six_joints(self) -> LegConfig:
        if len(self.joints) != len(LEG_ROLES):
            raise ValueError(f"a leg has {len(LEG_ROLES)} joints ({', '.join(LEG_ROLES)}), not {len(self.joints)}")
        return self


class SoleConfig(StrictModel):
    """The rectangle each foot stands on, centred on its sole site: where its contacts are."""

    length: float = Field(gt=0, description="m along the foot (x)")
    width: float = Field(gt=0, description="m across the foot (y)")
    friction: float = Field(0.7, gt=0, description="friction coefficient a controller may count on (below the floor's)")


class StanceConfig(StrictModel):
    """The neutral standing posture (bt_humanoid.sim.standing): feet flat and parallel, knees slightly bent."""

    pelvis_height: float = Field(gt=0, description="m from the floor to the pelvis origin")
    width: float = Field(gt=0, description="m between the sole centres")


class GaitConfig(StrictModel):
    """How the robot walks (bt_humanoid.control.walking): the timing of its steps and where its feet go."""

    single_support: float = Field(0.6, gt=0, description="s with one foot in the air")
    double_support: float = Field(0.1, gt=0, description="s passing the weight from one foot to the other")
    width: float = Field(0.22, gt=0, description="m between the sole centres while walking")
    step_height: float = Field(0.05, gt=0, description="m the swinging foot clears the floor")
    shortest_swing: float = Field(0.25, gt=0, description="s: the soonest a pushed robot may land a swinging foot")


class LegsConfig(StrictModel):
    """Two torque-controlled legs under a floating base: what a walking controller needs beyond the MJCF."""

    left: LegConfig
    right: LegConfig
    sole: SoleConfig
    stance: StanceConfig
    gait: GaitConfig = GaitConfig()
    torque_limits: dict[str, float] = Field(description="N·m per joint role (the motors' ctrlrange in the MJCF)")
    speed_limits: dict[str, float] = Field(description="rad/s per joint role: the motors' no-load speed")

    @model_validator(mode="after")
    def _every_role(self) -> LegsConfig:
        for key in ("torque_limits", "speed_limits"):
            given = getattr(self, key)
            if set(given) != set(LEG_ROLES):
                raise ValueError(f"{key}: one value for each of {', '.join(LEG_ROLES)}; got {', '.join(given)}")
            if any(value <= 0 for value in given.values()):
                raise ValueError(f"{key}: limits are positive")
        return self

    @property
    def joints(self) -> list[str]:
        """Every leg joint: the left leg's from the hip down, then the right's."""
        return self.left.joints + self.right.joints

    def role(self, joint: str) -> str:
        """hip_yaw, …, ankle_roll: which joint of its leg ``joint`` is."""
        for leg in (self.left, self.right):
            if joint in leg.joints:
                return LEG_ROLES[leg.joints.index(joint)]
        raise KeyError(f"{joint!r} is not a leg joint")

    def torque_limit(self, joint: str) -> float:
        return self.torque_limits[self.role(joint)]

    def speed_limit(self, joint: str) -> float:
        return self.speed_limits[self.role(joint)]


class ImuConfig(StrictModel):
    """An inertial measurement unit: its site and sensors (MJCF names)."""

    site: str
    gyro: str = Field(description="angular velocity, rad/s, in the site's frame")
    accelerometer: str = Field(description="specific force, m/s², in the site's frame (+g upwards at rest)")
    orientation: str | None = Field(None, description="the site's attitude (w, x, y, z), as a filter would give")


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
    legs: LegsConfig | None = Field(None, description="torque-controlled legs under a floating base")
    imu: ImuConfig | None = None
    sensors: SensorModels = Field(SensorModels(), description="how far the sensors are from the truth (noise)")
    safety: SafetyDefaults = SafetyDefaults()
    recovery: RecoveryDefaults = RecoveryDefaults()
    folder: Path = Path()

    @model_validator(mode="after")
    def _legs_carry_a_floating_base(self) -> RobotConfig:
        if self.base.floating and self.legs is None:
            raise ValueError("a floating base needs legs: (nothing else carries it)")
        if self.legs is not None and not self.base.floating:
            raise ValueError("legs: go with a floating base (base: kind: floating)")
        if self.legs is not None:
            grouped = {joint for joints in self.groups.values() for joint in joints}
            if both := grouped & set(self.legs.joints):
                raise ValueError(f"leg joints are torque-controlled, not in groups: {', '.join(sorted(both))}")
        return self

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
