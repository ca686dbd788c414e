"""Footsteps, the DCM plan and the swing path of the walking controller: pure functions, no physics."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from bt_humanoid.control.walking.dcm_plan import DcmPlan
from bt_humanoid.control.walking.footsteps import LEFT, RIGHT, Footstep, FootstepPlanner, StepLimits
from bt_humanoid.control.walking.swing import PRESS, SwingTrajectory

WIDTH, PERIOD = 0.18, 0.7
OMEGA = math.sqrt(9.81 / 0.72)


@pytest.fixture
def planner() -> FootstepPlanner:
    return FootstepPlanner(WIDTH, PERIOD, StepLimits())


def walk(planner: FootstepPlanner, velocity: tuple[float, float, float], count: int) -> list[Footstep]:
    stance = Footstep(LEFT, 0.0, WIDTH / 2, 0.0)
    return [stance, *planner.plan(stance, np.array(velocity), count)]


def body_of(planner: FootstepPlanner, steps: list[Footstep]) -> Footstep:
    return planner.body(steps[-1])


@pytest.mark.parametrize(
    ("velocity", "expected"),
    [
        ((0.3, 0.0, 0.0), (0.3 * PERIOD * 10, 0.0)),  # forward: 0.21 m a step
        ((-0.15, 0.0, 0.0), (-0.15 * PERIOD * 10, 0.0)),  # backwards
        ((0.0, 0.08, 0.0), (0.0, 0.08 * PERIOD * 10)),  # sideways: the leading foot opens, the other closes
    ],
)
def test_a_velocity_gives_alternating_steps_that_cover_its_distance(planner, velocity, expected):
    steps = walk(planner, velocity, 10)
    assert [s.side for s in steps] == [LEFT, RIGHT] * 5 + [LEFT]
    assert all(StepLimits().contains(b, a) for a, b in itertools.pairwise(steps))
    body = body_of(planner, steps)
    assert (body.x, body.y) == pytest.approx(expected, abs=1e-6)


def test_a_command_beyond_the_legs_reach_gives_the_largest_steps(planner):
    steps = walk(planner, (2.0, 0.0, 0.0), 4)
    forward = [b.relative_to(a)[0] for a, b in itertools.pairwise(steps)]
    assert forward == pytest.approx([StepLimits().forward[1]] * 4)


def test_turning_in_place_360_degrees_opens_and_closes_the_feet_without_crossing(planner):
    stance = Footstep(RIGHT, 0.0, -WIDTH / 2, 0.0)
    steps, turned = [stance], 0.0
    while turned < 2 * math.pi - 1e-9 or steps[-1].side != RIGHT:  # a full turn, the feet side by side
        step = planner.next_step(steps[-1], np.array([0.0, 0.0, 0.3]))
        turned += step.relative_to(steps[-1])[2]  # the feet's heading, unwrapped
        steps.append(step)
        assert len(steps) < 40
    assert len(steps) - 1 <= 34  # 0.4 rad per pair: 16 pairs, and the last
    for a, b in itertools.pairwise(steps):
        assert StepLimits().contains(b, a)
        assert math.hypot(b.x - a.x, b.y - a.y) < 0.25  # in place: the feet stay round the same spot


def test_the_closing_step_puts_the_feet_side_by_side(planner):
    left = Footstep(LEFT, 0.1, 0.12, 0.2)
    right = planner.closing_step(left)
    assert right.side == RIGHT
    assert planner.together(left, right)
    assert not planner.together(left, Footstep(RIGHT, 0.0, -0.1, 0.2))


@settings(max_examples=200, deadline=None)
@given(
    vx=st.floats(-1.0, 1.0),
    vy=st.floats(-1.0, 1.0),
    wz=st.floats(-1.5, 1.5),
    yaw=st.floats(-math.pi, math.pi),
)
def test_no_command_ever_plans_a_step_outside_the_box(vx, vy, wz, yaw):
    planner = FootstepPlanner(WIDTH, PERIOD, StepLimits())
    stance = Footstep(LEFT, 1.0, 2.0, yaw)
    previous = stance
    for step in planner.plan(stance, np.array([vx, vy, wz]), 6):
        assert step.side != previous.side
        assert StepLimits().contains(step, previous)
        previous = step


# --- the DCM plan -----------------------------------------------------------------------------------------------


def test_the_dcm_plan_obeys_the_pendulum_and_ends_standing_over_the_last_zmp():
    feet = [np.array([0.0, 0.09]), np.array([0.2, -0.09]), np.array([0.4, 0.09])]
    times, zmps = [0.0], [np.array([0.0, 0.0])]
    t = 0.4
    for foot in feet:
        times += [t, t + 0.6]
        zmps += [foot, foot]
        t += 0.7
    times.append(t + 0.3)
    zmps.append(np.array([0.4, 0.0]))
    plan = DcmPlan(times, zmps, OMEGA)
    samples = np.arange(0.0, t + 2.0, 1e-3)
    dcm = np.array([plan.at(s)[1] for s in samples])
    for s in samples[::97]:  # ξ̇ = ω (ξ − p), checked by finite differences away from the knots
        zmp, xi, rate = plan.at(s)
        assert rate == pytest.approx(OMEGA * (xi - zmp), abs=1e-12)
        ahead = plan.at(s + 1e-6)[1]
        if not any(s < k < s + 1e-6 for k in times):
            assert (ahead - xi) / 1e-6 == pytest.approx(rate, abs=1e-4)
    assert np.max(np.linalg.norm(np.diff(dcm, axis=0), axis=1)) < 1e-3  # continuous: no jump at any knot
    assert plan.at(times[-1] + 1.0)[1] == pytest.approx([0.4, 0.0])
    # the DCM passes over each stance foot's side before the next step: it never runs away from the feet
    assert np.all(np.abs(dcm[:, 1]) < 0.09)


def test_a_dcm_plan_needs_matching_knots():
    with pytest.raises(ValueError, match="one ZMP per knot"):
        DcmPlan([0.0, 1.0], [np.zeros(2)], OMEGA)
    with pytest.raises(ValueError, match="must not decrease"):
        DcmPlan([1.0, 0.0], [np.zeros(2), np.zeros(2)], OMEGA)


# --- the swing path ---------------------------------------------------------------------------------------------


def test_the_swing_lifts_clears_and_lands_at_rest_on_its_footstep():
    start, end = np.array([0.0, 0.1, 0.0, 0.0]), np.array([0.25, 0.12, 0.0, 0.3])
    swing = SwingTrajectory(start, end, 0.6, height=0.05)
    pose, velocity, _acceleration = swing.at(0.0)
    assert pose == pytest.approx(start) and velocity == pytest.approx(np.zeros(4))
    pose, velocity, _ = swing.at(0.6)
    assert pose == pytest.approx([0.25, 0.12, -PRESS, 0.3]) and velocity == pytest.approx(np.zeros(4), abs=1e-9)
    heights = [swing.at(t)[0][2] for t in np.linspace(0.0, 0.6, 61)]
    assert max(heights) == pytest.approx(0.05, abs=0.005)
    # nothing moves across the floor while the sole is still near it
    assert swing.at(0.05)[0][:2] == pytest.approx(start[:2])


def test_retargeting_mid_swing_keeps_the_path_smooth_and_lands_sooner_where_asked():
    swing = SwingTrajectory(np.zeros(4), np.array([0.2, 0.0, 0.0, 0.0]), 0.6)
    before = swing.at(0.25)
    swing.retarget(0.25, np.array([0.3, 0.1, 0.2]), 0.45)
    after = swing.at(0.25)
    for a, b in zip(before, after, strict=True):  # position, velocity, acceleration carry on
        assert b == pytest.approx(a, abs=1e-9)
    pose, velocity, _ = swing.at(0.45)
    assert pose == pytest.approx([0.3, 0.1, -PRESS, 0.2]) and velocity == pytest.approx(np.zeros(4), abs=1e-9)


def test_a_swing_retimed_just_after_lift_off_still_rises_to_the_step_height_before_it_lands():
    """A push at lift-off asks the foot to land sooner; a path straight down from there dragged the sole across
    the floor and the recovery step fell 17 cm short."""
    swing = SwingTrajectory(np.zeros(4), np.array([0.0, -0.3, 0.0, 0.0]), 0.6, height=0.05)
    before = swing.at(0.01)
    swing.retarget(0.01, np.array([0.0, -0.45, 0.0]), 0.25)
    after = swing.at(0.01)
    for a, b in zip(before, after, strict=True):  # position, velocity, acceleration carry on
        assert b == pytest.approx(a, abs=1e-9)
    heights = [swing.at(t)[0][2] for t in np.linspace(0.01, 0.25, 49)]
    assert max(heights) == pytest.approx(0.05, abs=0.002)
    assert swing.at(0.125)[0][2] == pytest.approx(0.05, abs=1e-6)  # at the top half-way through the new swing
    pose, velocity, _ = swing.at(0.25)
    assert pose == pytest.approx([0.0, -0.45, -PRESS, 0.0]) and velocity == pytest.approx(np.zeros(4), abs=1e-9)
