"""Grasps from an object's believed shape: where the grip site goes and how the hand is turned.

Every grasp here is top-down with the fingers closing horizontally: it keeps
upright things upright, and it suits every shape the robot meets. The shape
is the belief's: the object's extents and yaw, and whether its kind is round
(cans, bottles, balls, fruit: the pads close on the diameter at any yaw) or
has a handle (mugs: across the body, at right angles to the handle). Any
other kind is held as the box its extents describe (cubes, boxes, bags of
chips, bars, sponges), across one pair of its faces.

Of the hand yaws a shape allows, the one nearest the hand's natural yaw whose
width fits the open gripper with slack to spare wins: a bag of chips 12 cm
by 5 cm is taken across its 5 cm, whichever way it stands. A width that
leaves the pads under 2.5 cm of slack each side loses to one that leaves
more (a sponge 9.5 by 6.5 cm is taken across its 6.5 cm): a pad that lands on
the object's edge pushes it away.

The grip site goes as high as the palm allows (tall things stay steady),
never so low that the pads touch the surface, and low enough that the pads
reach down over the object's top: a flat thing (an energy bar 2.2 cm high)
is held with the pads just above the surface, the grip site above its top.
A grip may close a little off its plan when the hand cannot reach it (a
biped's arm at the far side of its reach): higher, as long as the pads still
reach ``HOLD_DEPTH`` down the object's sides, and off-centre along the line
the pads close on, as long as the open pads stay clear of the object's sides
(the nearer pad meets the object first and pushes it to the other).
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
MIN_PAD_OVERLAP = 0.01  # m: the pads reach at least this far down the object's sides from its top
PRE_GRASP_HEIGHT = 0.1  # m above the grasp: the hand comes down from here
LIFT_HEIGHT = 0.1  # m the object is lifted before it counts as picked
# m and rad a grasp's descent ends within, of its target and of its yaw
DESCEND_TOLERANCE = (0.008, 0.1)
# m the open pads must clear the object by, in total: within DESCEND_TOLERANCE of the grasp, a pad 1.5 cm from
# the object's side cannot land on its top
OPENING_MARGIN = 0.03
# m an open pad that stopped beside an object (the descent done, not blocked) must still clear its side by: the
# belief's error in where the object stands
STOPPED_PAD_CLEARANCE = 0.005
# m the pads' lower edge must reach below an object's top for a grip that closes higher than planned: half a
# mug's height, with the pads (6 cm tall) touching its side over 5 cm
HOLD_DEPTH = 0.05
COMFORTABLE_SLACK = 0.05  # m in total: a width with less slack is taken only when no other fits with more

# hand yaw relative to the base heading that suits either arm best for top-down grasps: the fingers close
# along the heading, the forearm points forward and the wrist pitches the hand down (see the "ready"
# posture in robot.yaml), which leaves every wrist joint mid-range
NATURAL_YAW = 0.0

ROUND_KINDS = frozenset({"can", "bottle", "ball", "fruit"})  # round in plan: closed on at any yaw
HANDLED_KINDS = frozenset({"mug"})  # a handle along the object's x: closed on across the body, at right angles to it


@dataclass(frozen=True)
class Grasp:
    position: np.ndarray  # grip-site position at the grasp (world)
    yaw: float  # hand yaw (rad); the fingers close along the hand's x axis at this yaw
    width: float  # expected distance between the pads when closed on the object (m)
    give: float = 0.0  # m above ``position`` the grip site may close and still hold (the pads reach HOLD_DEPTH down)
    sway: float = 0.0  # m off ``position`` along the closing line the grip site may close (the open pads clear it)

    @property
    def pre_grasp(self) -> np.ndarray:
        return self.position + np.array([0.0, 0.0, PRE_GRASP_HEIGHT])

    @property
    def lifted(self) -> np.ndarray:
        return self.position + np.array([0.0, 0.0, LIFT_HEIGHT])

    def closes_from(
        self, grip_site: np.ndarray, yaw: float, tolerance: tuple[float, float] = DESCEND_TOLERANCE
    ) -> bool:
        """Whether a hand whose grip site stopped at ``grip_site``, turned to ``yaw``, short of this grasp still
        closes on the object: within ``tolerance`` (m, rad) across the closing line, below the grasp and of its
        yaw (as a descent that arrived), off along the line by no more than the sway, and above by no more than
        the give."""
        off = np.asarray(grip_site, dtype=float) - self.position
        along = np.array([math.cos(self.yaw), math.sin(self.yaw)])  # the fingers close along the hand's x
        across = abs(float(off[0] * -along[1] + off[1] * along[0]))
        position_tolerance, yaw_tolerance = tolerance
        return (
            abs(wrap_angle(yaw - self.yaw)) <= yaw_tolerance
            and across <= position_tolerance
            and abs(float(off[:2] @ along)) <= self.sway
            and -position_tolerance <= float(off[2]) <= self.give
        )


class GraspError(ValueError):
    """The object cannot be grasped by this hand (too wide, too flat)."""


def natural_hand_yaw(base_yaw: float) -> float:
    """The hand yaw (world) that suits either arm when the base faces ``base_yaw``."""
    return float(wrap_angle(base_yaw + NATURAL_YAW))


def hand_yaws(obj: TrackedObject, hand_yaw: float) -> list[tuple[float, float]]:
    """The ways a top-down hand can close on ``obj``: (hand yaw, width between the pads), by its believed shape.

    A round object is closed on its diameter at ``hand_yaw`` itself; a mug across its body either way; any other
    shape across either pair of its box's side faces, from each side.
    """
    length, breadth = float(obj.size[0]), float(obj.size[1])
    if obj.kind in ROUND_KINDS:
        return [(float(wrap_angle(hand_yaw)), min(length, breadth))]
    if obj.kind in HANDLED_KINDS:
        across = obj.yaw + math.pi / 2  # the fingers close along the hand's x: at right angles to the handle
        return [(float(wrap_angle(across + k * math.pi)), breadth) for k in range(2)]
    return [(float(wrap_angle(obj.yaw + k * math.pi / 2)), length if k % 2 == 0 else breadth) for k in range(4)]


def grip_height(obj: TrackedObject, support_height: float) -> float:
    """Where the grip site goes (z): palm above the top, pads above the surface and down over the object's top."""
    highest = obj.top + PAD_HALF_HEIGHT - MIN_PAD_OVERLAP  # the pads' lower edge reaches down the object's sides
    lowest = support_height + PAD_HALF_HEIGHT + SURFACE_CLEARANCE  # the pads' lower edge clears the surface
    if lowest > highest:
        raise GraspError(
            f"the {obj.name} is {obj.size[2] * 100:.1f} cm high: too flat for the pads "
            f"to close on it {SURFACE_CLEARANCE * 100:.1f} cm above the surface"
        )
    under_the_palm = obj.top + TOP_CLEARANCE - PALM_ABOVE_GRIP  # as high as the palm allows: tall things stay steady
    return float(min(max(under_the_palm, lowest), highest))


def plan_grasp(obj: TrackedObject, support_height: float, hand_yaw: float, max_opening: float) -> Grasp:
    """A top-down grasp of ``obj`` standing on a surface at ``support_height``, hand yaw nearest ``hand_yaw``.

    ``max_opening`` is the gap between the pads of the open gripper (m).
    """
    options = hand_yaws(obj, hand_yaw)
    fitting = [(yaw, width) for yaw, width in options if width <= max_opening - OPENING_MARGIN]
    if not fitting:
        narrowest = min(width for _, width in options)
        raise GraspError(
            f"the {obj.name} is {narrowest * 100:.1f} cm across at its narrowest; the gripper opens "
            f"{max_opening * 100:.0f} cm and needs {OPENING_MARGIN * 100:.0f} cm to spare"
        )
    roomy = [(yaw, width) for yaw, width in fitting if width <= max_opening - COMFORTABLE_SLACK]
    yaw, width = min(roomy or fitting, key=lambda option: abs(wrap_angle(option[0] - hand_yaw)))
    height = grip_height(obj, support_height)
    depth = obj.top - (height - PAD_HALF_HEIGHT)  # how far below the top the pads' lower edge reaches
    position = np.array([obj.position[0], obj.position[1], height])
    sway = (max_opening - width) / 2 - STOPPED_PAD_CLEARANCE  # each open pad still clears the object's side
    return Grasp(position, yaw, width, give=max(0.0, depth - HOLD_DEPTH), sway=max(0.0, sway))
