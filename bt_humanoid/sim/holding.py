"""A scene's object in the robot's hand at the start: where it sits between the pads, and putting it there.

Initial conditions only, set before the first step: the arm in its carrying
posture (robot.yaml's ``carry``), the object between the finger pads as a
top-down grasp would hold it (control/grasping.py: the palm just clear of its
top; a flat thing between the pads' middles, as nothing lies below it), the
fingers touching it and their actuators commanded shut. From the
first step it is held by friction alone, like anything the robot picked up:
no weld, no constraint.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from bt_humanoid.sim.world_config import ObjectModel

CARRY_POSTURE = "carry"  # robot.yaml posture: a hand in front of the body at carrying height, pointing down
PALM_ABOVE_GRIP = 0.06  # m: the palm's underside above the grip site (as control/grasping.py)
TOP_CLEARANCE = 0.008  # m: the palm stays this far above the object's top (as control/grasping.py)
SQUEEZE = 0.0002  # m each pad starts pressed into the object: in contact from the first step


@dataclass(frozen=True)
class Hold:
    """How a top-down grasp holds one object: in the object's frame (origin at its body's centre)."""

    grip_height: float  # m the grip site sits above the object's origin
    width: float  # m between the pads: the object's extent across them
    turn: float  # rad about the vertical from the hand's frame to the object's (a box is held across its narrow side)
    centre_height: float  # m the centre of its bounding box (cap included) sits above its origin


def hold_for(model: ObjectModel) -> Hold:
    """Where the pads close on an object standing upright in the hand."""
    half = model.size[2] / 2
    top = half + (model.cap.height if model.cap is not None else 0.0)
    grip = max(top + TOP_CLEARANCE - PALM_ABOVE_GRIP, 0.0)  # no lower than its middle: a flat thing is not missed
    if model.shape == "box" and model.size[1] < model.size[0]:
        width, turn = model.size[1], math.pi / 2  # the pads close along the hand's x: the object's y goes there
    else:
        width, turn = model.size[0], 0.0
    return Hold(grip, width, turn, (top - half) / 2)
