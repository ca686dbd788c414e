"""Step adjustment: the footstep and landing time that capture a pushed DCM (no physics)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from bt_humanoid.control.walking.footsteps import LEFT, RIGHT, Footstep, StepLimits
from bt_humanoid.control.walking.stepping import Sole, capture_step, cop_room, crosses

OMEGA = math.sqrt(9.81 / 0.72)
SOLE = Sole(0.10, 0.04)
LIMITS = StepLimits(forward=(-0.25, 0.35), sideways=(0.14, 0.40))
STANCE = Footstep(RIGHT, 0.0, -0.11, 0.0)
NOMINAL = Footstep(LEFT, 0.21, 0.11, 0.0)  # a 0.21 m step forwards, 0.22 m apart
REMAINING, SHORTEST = 0.4, 0.1


def plan_dcm(t: float) -> np.ndarray:
    """A plan's DCM over the stance sole's centre's LIPM, landing on ``TOUCHDOWN`` after REMAINING."""
    return STANCE.position + (TOUCHDOWN - STANCE.position) * math.exp(-OMEGA * (REMAINING - t))


TOUCHDOWN = np.array([0.17, -0.03])  # where the plan has the DCM at touchdown: behind and inside the new foot


def adjust(dcm: np.ndarray, room: float | None = None):
    reference = plan_dcm(0.0)
    error = dcm - reference
    if room is None:
        room = cop_room(STANCE, error / max(np.linalg.norm(error), 1e-9), SOLE, 0.8)
    return capture_step(NOMINAL, STANCE, dcm, reference, TOUCHDOWN, OMEGA, REMAINING, SHORTEST, room, LIMITS), room


def test_the_centre_of_pressure_reaches_to_the_soles_edge_that_way():
    assert cop_room(STANCE, np.array([1.0, 0.0]), SOLE, 1.0) == pytest.approx(0.10)
    assert cop_room(STANCE, np.array([0.0, -1.0]), SOLE, 1.0) == pytest.approx(0.04)
    turned = Footstep(RIGHT, 0.0, 0.0, math.pi / 2)  # its length now along y
    assert cop_room(turned, np.array([0.0, 1.0]), SOLE, 0.8) == pytest.approx(0.08)


def test_no_disturbance_or_one_the_ankles_take_leaves_the_footstep():
    assert adjust(plan_dcm(0.0))[0] is None
    assert adjust(plan_dcm(0.0) + np.array([0.05, 0.0]))[0] is None  # 5 cm ahead: the toes take it


@pytest.mark.parametrize("push", [np.array([0.12, 0.0]), np.array([-0.12, 0.0]), np.array([0.03, 0.07])])
def test_a_push_moves_the_footstep_where_the_dcm_lands_as_planned_from_it(push):
    dcm = plan_dcm(0.0) + push
    adjusted, room = adjust(dcm)
    assert adjusted is not None
    footstep, duration = adjusted
    assert LIMITS.contains(footstep, STANCE)
    direction = push / np.linalg.norm(push)
    pivot = STANCE.position + room * direction
    landing = pivot + (dcm - pivot) * math.exp(OMEGA * duration)  # the DCM at touchdown, the sole at its edge
    # from the new footstep the DCM lies where the plan has it, give or take the room the new sole answers
    assert landing - footstep.position == pytest.approx(TOUCHDOWN - NOMINAL.position + room * direction, abs=0.011)
    assert np.dot(footstep.position - NOMINAL.position, direction) > 0  # moved the way of the push


def test_a_push_beyond_reach_lands_the_foot_as_soon_as_it_may_at_the_edge_of_reach():
    adjusted, _ = adjust(plan_dcm(0.0) + np.array([0.35, 0.0]))
    footstep, duration = adjusted
    assert duration == pytest.approx(SHORTEST)
    assert footstep.relative_to(STANCE)[0] == pytest.approx(LIMITS.forward[1])


@pytest.mark.parametrize("push", [0.06, 0.15])
def test_a_push_towards_the_stance_side_lands_the_swinging_foot_beside_it_as_soon_as_it_may(push):
    # to the right, over the right (stance) foot: only the right foot can catch it, once the left is down
    adjusted, _ = adjust(plan_dcm(0.0) + np.array([0.0, -push]))
    footstep, duration = adjusted
    assert footstep.relative_to(STANCE)[1] == pytest.approx(LIMITS.sideways[0])  # the feet do not cross
    assert duration == pytest.approx(SHORTEST)


def test_a_footstep_crosses_when_it_lies_nearer_the_other_side_than_the_feet_may_come():
    beside = STANCE.moved(0.1, LIMITS.sideways[0], 0.0, LEFT)
    assert not crosses(beside, STANCE, LIMITS)
    assert crosses(STANCE.moved(0.1, 0.05, 0.0, LEFT), STANCE, LIMITS)  # the soles would overlap
    assert crosses(STANCE.moved(0.0, -0.1, 0.0, LEFT), STANCE, LIMITS)  # the left foot right of the right
    assert not crosses(STANCE.moved(0.0, -0.2, 0.0, RIGHT), Footstep(LEFT, 0.0, 0.0, 0.0), LIMITS)
