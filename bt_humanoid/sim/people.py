"""People who take what the robot hands them: an actuated arm and hand on a person's body, and its script.

The arm is built onto the person's body in the world's model (``add_arm``): a yaw at the body's axis (they turn
to what is offered), a shoulder, an elbow, a wrist that keeps the hand level and one that turns it square to the
thing, each a position servo with a person's strength; the hand is a palm with two fingers whose tips close
sideways on a thing. The arm's own weight is carried by gravity compensation (muscles hold an arm up without
thought); what it holds, it must lift.

The script (``PersonDriver``), every control step:

1. waits, arm down, until the robot holds something out to them, still, within their reach (the scene's script
   reads what the person would see: a thing touched by the robot alone, held out close to them, not moving);
2. reaches round it: the arm turns to it, low; the open hand comes level with the thing's middle from their side,
   then slides forward, fingertips either side of its middle (the robot's parallel fingers hold it on the faces
   towards and away from the person, so the sides are free);
3. closes the fingers on it, then draws it a little up and towards themselves: a pull the robot's wrist feels;
4. once the robot has let go and drawn its hand back, holds it close. A thing that falls out of their hand, they
   leave.

A person with ``takes: false`` (busy, on the phone) never reaches.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import mujoco
import numpy as np

from bt_humanoid.sim.geometry import geoms_touching

SHOULDER_HEIGHT = 1.35  # m above the floor
SHOULDER_OUT = 0.18  # m from the body's axis, towards where the arm points
UPPER_ARM, FOREARM = 0.3, 0.27  # m
PALM_DEPTH = 0.03  # m from the wrist to the palm's front
FINGER_LENGTH = 0.11  # m ahead of the palm
# m each fingertip's inner face stands from the hand's middle when open: wide enough to pass round a mug's handle
# (7.5 cm from its middle), as an open hand does
FINGER_OPEN = 0.09
# the fingertips, 3 cm long, stand proud of the fingers by 1.2 cm, this far ahead of the palm: they meet the thing
# at its middle, and the rest of the finger passes the robot's fingers on its near and far faces
TIP_AT, TIP_LENGTH, TIP_DEPTH = 0.08, 0.03, 0.012
# m from the body's axis, horizontally, where they reach for a thing: held out to them, not carried past (a robot
# that stops at arm's length, 0.6 m from its footprint, carries things 0.59 m from them and holds them out at 0.42)
REACH = (0.3, 0.5)
HEIGHTS = (0.6, 1.5)  # m above the floor
STILL = 0.03  # m/s: a thing offered is held still ...
STILL_FOR = 0.5  # s ... for this long before they reach
STANDS_OUT = 0.02  # m off a thing's middle, across the floor, where a part of it is a handle to close along
HAND_SPEED = 0.3  # m/s their hand moves at ...
TURN_RATE = 1.5  # rad/s ... and turns at
TURNED = 0.05  # rad: the arm turns to the thing first, low, to within this ...
APPROACH = 0.12  # m ... then the hand comes level with the thing this far back, then slides round it
CLOSE_TIME = 0.5  # s the fingers take to close before the pull
# m: (towards themselves, up) the hand draws a taken thing, slowly: less than the 3 cm the robot's loosened pads
# stand off (6 cm dragged the thing along the near pad as the robot's hand rose), and less than the 1.4 cm between a
# mug's rim and the palm of a robot that holds it from above (4 cm jammed it into that palm) ...
PULL = np.array([-0.02, 0.01])
PULL_SPEED = 0.05  # m/s
HOLD = np.array([0.2, 1.0])  # m: (wrist from the body's axis, height) where they hold what they took ...
WAIT_CLEAR = 1.5  # s ... once the robot's hand has had this long to withdraw (its finger is on their side)
ARM_GAINS = {
    "yaw": (150.0, 40.0),
    "shoulder": (300.0, 50.0),
    "elbow": (200.0, 40.0),
    "wrist": (60.0, 15.0),
    "wrist_yaw": (40.0, 8.0),
}
FINGER_GAIN, FINGER_FORCE = 400.0, 15.0  # N/m and N: a firm but human grip
# a finger pad on smooth glass: 0.78 ± 0.35 measured (docs/dependencies.md). Their two fingertips stand for a whole
# hand round the thing; at 0.8 a mug they held by its handle turned in them against the robot's withdrawing pad
# and fell (fetch_faults episode 60 at 4a6baae), so the upper part of that spread
SKIN_FRICTION = 1.0


def arm_joint_names(person: str) -> list[str]:
    return [f"{person}_{joint}" for joint in ("yaw", "shoulder", "elbow", "wrist", "wrist_yaw")]


def finger_names(person: str) -> list[str]:
    """Each finger's body, joint, actuator and fingertip geom (one name for all four)."""
    return [f"{person}_finger_{side}" for side in ("left", "right")]


def person_hand(person: str) -> list[str]:
    """The bodies of a person's hand."""
    return [f"{person}_hand", *finger_names(person)]


def add_arm(spec: mujoco.MjSpec, person: str) -> None:
    """Build an arm and a hand onto the body ``person`` of ``spec`` (the arm turns about the body's axis)."""
    body = spec.body(person)
    turn = body.add_body(name=f"{person}_turn", pos=[0, 0, SHOULDER_HEIGHT], gravcomp=1)
    turn.add_joint(name=f"{person}_yaw", type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0, 0, 1], damping=5)
    turn.add_geom(type=mujoco.mjtGeom.mjGEOM_SPHERE, size=[0.01, 0, 0], mass=0.1, contype=0, conaffinity=0)
    upper = turn.add_body(name=f"{person}_upper_arm", pos=[SHOULDER_OUT, 0, 0], gravcomp=1)
    upper.add_joint(name=f"{person}_shoulder", type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0, 1, 0], damping=5)
    _limb(upper, UPPER_ARM, 0.045, 2.0)
    fore = upper.add_body(name=f"{person}_forearm", pos=[UPPER_ARM, 0, 0], gravcomp=1)
    fore.add_joint(name=f"{person}_elbow", type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0, 1, 0], damping=3)
    _limb(fore, FOREARM, 0.04, 1.4)
    hand = fore.add_body(name=f"{person}_hand", pos=[FOREARM, 0, 0], gravcomp=1)
    hand.add_joint(name=f"{person}_wrist", type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0, 1, 0], damping=1)
    hand.add_joint(name=f"{person}_wrist_yaw", type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0, 0, 1], damping=1)
    skin = [0.55, 0.75, 0.6, 1.0]
    hand.add_geom(
        name=f"{person}_palm", type=mujoco.mjtGeom.mjGEOM_BOX, size=[PALM_DEPTH / 2, 0.05, 0.02],
        pos=[PALM_DEPTH / 2, 0, 0], mass=0.3, rgba=skin,
    )  # fmt: skip
    for side, sign in (("left", 1.0), ("right", -1.0)):
        finger = hand.add_body(name=f"{person}_finger_{side}", pos=[PALM_DEPTH, 0, 0], gravcomp=1)
        finger.add_joint(
            name=f"{person}_finger_{side}", type=mujoco.mjtJoint.mjJNT_SLIDE, axis=[0, -sign, 0],
            range=[0, FINGER_OPEN], damping=5,
        )  # fmt: skip
        finger.add_geom(
            name=f"{person}_finger_{side}", type=mujoco.mjtGeom.mjGEOM_BOX,
            size=[TIP_LENGTH / 2, TIP_DEPTH / 2, 0.015], pos=[TIP_AT, sign * (FINGER_OPEN + TIP_DEPTH / 2), 0],
            mass=0.01, rgba=skin, friction=[SKIN_FRICTION, 0.02, 0.001], condim=4, priority=1,
        )  # fmt: skip
        finger.add_geom(
            name=f"{person}_finger_{side}_bar", type=mujoco.mjtGeom.mjGEOM_BOX, size=[FINGER_LENGTH / 2, 0.003, 0.012],
            pos=[FINGER_LENGTH / 2, sign * (FINGER_OPEN + TIP_DEPTH + 0.003), 0], mass=0.04, rgba=skin,
        )  # fmt: skip
        actuator = spec.add_actuator(name=f"{person}_finger_{side}", target=f"{person}_finger_{side}")
        actuator.trntype = mujoco.mjtTrn.mjTRN_JOINT
        actuator.set_to_position(kp=FINGER_GAIN, kv=20.0)
        actuator.forcelimited, actuator.forcerange = True, [-FINGER_FORCE, FINGER_FORCE]
    for part in ("turn", "upper_arm", "forearm", "hand", "finger_left", "finger_right"):  # the arm passes the body
        spec.add_exclude(bodyname1=person, bodyname2=f"{person}_{part}")
    for joint, (kp, kv) in zip(arm_joint_names(person), ARM_GAINS.values(), strict=True):
        actuator = spec.add_actuator(name=joint, target=joint)
        actuator.trntype = mujoco.mjtTrn.mjTRN_JOINT
        actuator.set_to_position(kp=kp, kv=kv)
        actuator.forcelimited, actuator.forcerange = True, [-60.0, 60.0]


def _limb(body: mujoco.MjsBody, length: float, radius: float, mass: float) -> None:
    body.add_geom(
        type=mujoco.mjtGeom.mjGEOM_CAPSULE, fromto=[0.03, 0, 0, length - 0.03, 0, 0], size=[radius, 0, 0],
        mass=mass, rgba=[0.8, 0.3, 0.3, 1.0],
    )  # fmt: skip


class HandPose(NamedTuple):
    """Where a person's hand is told to be: the arm's turn about the body's axis (rad), the wrist's distance from
    that axis and height (m), and the hand's own turn at the wrist (rad)."""

    yaw: float
    reach: float
    height: float
    turn: float = 0.0


REST = HandPose(0.0, SHOULDER_OUT + 0.1, SHOULDER_HEIGHT - UPPER_ARM - FOREARM + 0.1)  # the arm down in front


def arm_angles(reach: float, height: float) -> tuple[float, float, float]:
    """Shoulder, elbow and wrist angles (rad, positive down) that put the wrist ``reach`` m from the body's axis
    and ``height`` m above the floor, the elbow below the line to it and the hand level."""
    forward, down = reach - SHOULDER_OUT, SHOULDER_HEIGHT - height
    distance = min(math.hypot(forward, down), UPPER_ARM + FOREARM - 1e-6)
    cos_elbow = (distance**2 - UPPER_ARM**2 - FOREARM**2) / (2 * UPPER_ARM * FOREARM)
    elbow = -math.acos(float(np.clip(cos_elbow, -1.0, 1.0)))
    shoulder = math.atan2(down, forward) - math.atan2(FOREARM * math.sin(elbow), UPPER_ARM + FOREARM * math.cos(elbow))
    return shoulder, elbow, -(shoulder + elbow)


class PersonDriver:
    """Drives one person's arm and hand every control step: wait, turn, approach, reach, close, pull, hold."""

    def __init__(
        self,
        model: mujoco.MjModel,
        data: mujoco.MjData,
        name: str,
        takes: bool,
        objects: dict[str, str],
        robot: set[int],
    ) -> None:
        """``name``: the person's body; ``objects``: the run's things by name → body name; ``robot``: its bodies."""
        self.model, self.data, self.name, self.takes = model, data, name, takes
        self.body = model.body(name).id
        self.hand_body = model.body(f"{name}_hand").id
        self.arm = [model.actuator(joint).id for joint in arm_joint_names(name)]
        self.arm_qpos = [model.joint(joint).qposadr[0] for joint in arm_joint_names(name)]
        self.fingers = [model.actuator(finger).id for finger in finger_names(name)]
        self.finger_geoms = {model.geom(finger).id for finger in finger_names(name)}
        self.objects = {thing: model.body(body).id for thing, body in objects.items()}
        self.robot_geoms = set(np.flatnonzero(np.isin(model.geom_bodyid, sorted(robot))).tolist())
        self.reset()

    def reset(self) -> None:
        self.state = "waiting"
        self.target: str | None = None  # the thing they reach for, or hold
        self.pull_to: HandPose | None = None  # where the hand draws what it closed on
        self.still_since: dict[str, float] = {}
        self.hand = REST  # where the hand is told to be now
        self.since = 0.0  # s: when this state began
        self.last_control, self.dt = float(self.data.time), 0.0  # s: the hand's set point moves by the time since
        self._command(open_hand=True)
        self.data.qpos[self.arm_qpos] = self.data.ctrl[self.arm]  # initial conditions: the arm starts at rest

    def holding(self, body: int) -> bool:
        """Are both their fingertips on ``body``? (Ground truth; what ``delivered`` means.)"""
        return self.finger_geoms <= self._touching(body)

    def control(self) -> None:
        if not self.takes:
            return
        now = float(self.data.time)
        self.dt, self.last_control = now - self.last_control, now
        if self.state == "waiting":
            self.target = self._offered(now)
            if self.target is not None:
                self._enter("turning", now)
        elif self.state in ("turning", "approaching", "reaching"):
            self._reach(now)
        elif self.state == "closing":
            if now - self.since > CLOSE_TIME:
                self.pull_to = self.hand._replace(reach=self.hand.reach + PULL[0], height=self.hand.height + PULL[1])
                self._enter("pulling", now)
        elif self.state == "pulling":
            if not self._robot_touches(self.target):
                self._enter("holding", now)
            elif self.pull_to is not None:
                self.hand = self._step(self.pull_to, PULL_SPEED)
        elif self.state == "holding":
            if now - self.since > WAIT_CLEAR:
                self._move_towards(self.hand._replace(reach=HOLD[0], height=HOLD[1]))
            if self.target is None or not self.holding(self.objects[self.target]):
                self._enter("waiting", now)  # it fell out of their hand: they leave it
        self._command(open_hand=self.state in ("waiting", "turning", "approaching", "reaching"))

    def _reach(self, now: float) -> None:
        """Turn the arm to the thing low, come level with it well back, then slide the open hand round it."""
        goal = self._grasp_pose(self.target)
        if goal is None:  # gone from their reach
            self._enter("waiting", now)
        elif self.state == "turning":
            self._move_towards(goal._replace(reach=min(REST.reach, goal.reach - APPROACH), height=REST.height))
            turned = math.remainder(float(self.data.qpos[self.arm_qpos[0]]) - goal.yaw, 2 * math.pi)
            if abs(turned) < TURNED:
                self._enter("approaching", now)
        elif self.state == "approaching":
            if self._move_towards(goal._replace(reach=goal.reach - APPROACH)):
                self._enter("reaching", now)
        elif self._move_towards(goal):
            self._enter("closing", now)

    # --------------------------------------------------------------------------- what they see

    def _offered(self, now: float) -> str | None:
        """A thing the robot holds out still within their reach: touched by the robot only (off every surface)."""
        for name, body in self.objects.items():
            offset = self.data.xpos[body] - self.data.xpos[self.body]
            reach, height = float(np.hypot(*offset[:2])), float(self.data.xpos[body][2])
            offered = REACH[0] <= reach <= REACH[1] and HEIGHTS[0] <= height <= HEIGHTS[1]
            if offered:
                touching = self._touching(body)
                still = float(np.linalg.norm(self.data.cvel[body][3:])) < STILL
                offered = still and bool(touching) and touching <= self.robot_geoms
            if not offered:
                self.still_since.pop(name, None)
            elif now - self.still_since.setdefault(name, now) >= STILL_FOR:
                return name
        return None

    def _robot_touches(self, name: str | None) -> bool:
        return name is not None and bool(self._touching(self.objects[name]) & self.robot_geoms)

    def _touching(self, body: int) -> set[int]:
        return geoms_touching(self.model, self.data, body)

    # --------------------------------------------------------------------------- where the hand goes

    def _grasp_pose(self, name: str | None) -> HandPose | None:
        """The hand square to the thing's face nearest them, fingers either side of it, level with its middle."""
        if name is None:
            return None
        body = self.objects[name]
        centre = self.data.xipos[body]
        offset = centre[:2] - self.data.xpos[self.body][:2]
        if not REACH[0] - 0.1 <= float(np.hypot(*offset)) <= REACH[1] + 0.1:
            return None
        inwards = self._face(body, offset / max(float(np.hypot(*offset)), 1e-9))
        wrist = centre[:2] - (TIP_AT + PALM_DEPTH) * inwards  # the fingertips either side of its middle
        from_axis = wrist - self.data.xpos[self.body][:2]
        yaw = math.atan2(from_axis[1], from_axis[0])
        turn = math.remainder(math.atan2(inwards[1], inwards[0]) - yaw, 2 * math.pi)
        return HandPose(yaw, float(np.hypot(*from_axis)), float(centre[2]), turn)

    def _face(self, body: int, towards: np.ndarray) -> np.ndarray:
        """The unit direction into the thing the hand squares up to: of a thing with a part standing out from it
        (a mug's handle), across that part, so that the fingers close along it, one on its end and one on the far
        side, and neither lands on its flank; of a box, its side most nearly facing them; of anything else round,
        the way they look at it."""
        geoms = np.flatnonzero(self.model.geom_bodyid == body)
        outwards = self.data.geom_xpos[geoms, :2] - self.data.xpos[body][:2]
        part = outwards[int(np.argmax(np.hypot(outwards[:, 0], outwards[:, 1])))]
        if float(np.hypot(*part)) > STANDS_OUT:  # (a bottle's cap, above its middle, stands out from nothing)
            across = np.array([-part[1], part[0]]) / float(np.hypot(*part))
            return across if float(across @ towards) >= 0.0 else -across
        if self.model.geom_type[geoms[0]] != mujoco.mjtGeom.mjGEOM_BOX:
            return towards
        axes = self.data.geom_xmat[geoms[0]].reshape(3, 3)[:2, :2].T  # the box's x and y axes, on the floor
        dots = axes @ towards
        best = int(np.argmax(np.abs(dots)))
        inwards = axes[best] * np.sign(dots[best])
        return inwards / max(float(np.hypot(*inwards)), 1e-9)

    def _move_towards(self, goal: HandPose) -> bool:
        """Step the hand's set point towards ``goal``: arrived, and the wrist with it?"""
        self.hand = self._step(goal, HAND_SPEED)
        return self.hand == goal and self._wrist_error() < 0.01

    def _step(self, goal: HandPose, speed: float) -> HandPose:
        """The hand's set point, one control period (``dt``) on towards ``goal``: at ``speed`` (m/s), turning at
        TURN_RATE."""
        dt, hand = self.dt, self.hand

        def turned(now: float, to: float) -> float:
            step = math.remainder(to - now, 2 * math.pi)
            return to if abs(step) <= TURN_RATE * dt else now + math.copysign(TURN_RATE * dt, step)

        move = np.array([goal.reach - hand.reach, goal.height - hand.height])
        length = float(np.hypot(*move))
        if length <= speed * dt:
            reach, height = goal.reach, goal.height
        else:
            reach, height = np.array([hand.reach, hand.height]) + move * speed * dt / length
        return HandPose(turned(hand.yaw, goal.yaw), float(reach), float(height), turned(hand.turn, goal.turn))

    def _wrist_error(self) -> float:
        """m between where the wrist is told to be and where it is."""
        yaw, reach, height, _ = self.hand
        told = self.data.xpos[self.body] + reach * np.array([math.cos(yaw), math.sin(yaw), 0.0])
        told[2] = height
        return float(np.linalg.norm(self.data.xpos[self.hand_body] - told))

    def _enter(self, state: str, now: float) -> None:
        self.state, self.since = state, now
        if state == "waiting":
            self.target = None
            self.hand = REST

    def _command(self, open_hand: bool) -> None:
        self.data.ctrl[self.arm] = [self.hand.yaw, *arm_angles(self.hand.reach, self.hand.height), self.hand.turn]
        self.data.ctrl[self.fingers] = 0.0 if open_hand else FINGER_OPEN
