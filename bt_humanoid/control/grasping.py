"""Grasps from an object's believed geometry: where the grip site goes and how the hand is turned.

Every grasp here is top-down with the fingers closing horizontally: it keeps
bottles and mugs upright, and it works for boxes, cylinders, mugs and balls.
The hand's yaw is chosen among the object's symmetric options (boxes every
90°, mugs every 180° across the body away from the handle, cylinders and
balls any) as the one nearest the hand's current yaw.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from bt_humanoid.control.base_driver import wrap_angle
from bt_humanoid.perception.world_model import TrackedObject

PAD_HALF_HEIGHT = 0.03  # m: finger pads reach this far below and above the grip site
PALM_ABOVE_GRIP = 0.06  # m: the palm's underside sits this far above the grip site
SURFACE_CLEARANCE = 0.006  # m: pads stay this far above the support surface
TOP_CLEARANCE = 0.008  # m: palm stays this far above the object's top
PRE_GRASP_HEIGHT = 0.1  # m above the grasp: the hand comes down from here
LIFT_HEIGHT = 0.1  # m the object is lifted before it counts as picked
OPENING_MARGIN = 0.01  # m the open pads must clear the object by, in total

# hand yaw relative to the base heading that suits either arm best for top-down grasps: the fingers close
# along the heading, the forearm points forward and the wrist pitches the hand down (see the "ready"
# posture in robot.yaml), which leaves every wrist joint mid-range
NATURAL_YAW = 0.0

SYMMETRY = {"cube": math.pi / 2, "box": math.pi / 2, "mug": math.pi, "bottle": 0.0, "can": 0.0, "ball": 0.0}


@dataclass(frozen=True)
class Grasp:
    position: np.ndarray  # grip-site position at the grasp (world)
    yaw: float  # hand yaw (rad); the fingers close along the hand's x axis at this yaw
    width: float  # expected distance between the pads when closed on the object (m)

    @property
    def pre_grasp(self) -> np.ndarray:
        return self.position + np.array([0.0, 0.0, PRE_GRASP_HEIGHT])

    @property
    def lifted(self) -> np.ndarray:
        return self.position + np.array([0.0, 0.0, LIFT_HEIGHT])


class GraspError(ValueError):
    """The object cannot be grasped by this hand (too wide, unknown shape)."""


def natural_hand_yaw(base_yaw: float) -> float:
    """The hand yaw (world) that suits either arm when the base faces ``base_yaw``."""
    return float(wrap_angle(base_yaw + NATURAL_YAW))


def plan_grasp(obj: TrackedObject, support_height: float, hand_yaw: float, max_opening: float) -> Grasp:
    """A top-down grasp of ``obj`` standing on a surface at ``support_height``, hand yaw nearest ``hand_yaw``.

    ``max_opening`` is the gap between the pads of the open gripper (m).
    """
    if obj.kind not in SYMMETRY:
        raise GraspError(f"no grasp for objects of kind {obj.kind!r}; graspable kinds: {', '.join(SYMMETRY)}")
    # mugs: close across the body, at right angles to the handle (which points along the mug's x)
    base_yaw = obj.yaw + (math.pi / 2 if obj.kind == "mug" else 0.0)
    period = SYMMETRY[obj.kind]
    yaw = hand_yaw if period == 0.0 else base_yaw + period * round(wrap_angle(hand_yaw - base_yaw) / period)
    # the object's extent along the closing direction (the hand's x axis)
    turn = yaw - obj.yaw
    if period == 0.0:  # round: the diameter whichever way the pads close
        width = float(obj.size[0])
    else:
        width = float(abs(math.cos(turn)) * obj.size[0] + abs(math.sin(turn)) * obj.size[1])
    if width > max_opening - OPENING_MARGIN:
        raise GraspError(f"{obj.name} is {width * 100:.0f} cm wide; the gripper opens {max_opening * 100:.0f} cm")
    # as high as the palm allows (keeps tall things steady), never so low that the pads touch the surface
    height = max(obj.top + TOP_CLEARANCE - PALM_ABOVE_GRIP, support_height + PAD_HALF_HEIGHT + SURFACE_CLEARANCE)
    height = min(height, obj.top - 0.01)
    position = np.array([obj.position[0], obj.position[1], height])
    return Grasp(position, float(wrap_angle(yaw)), width)
