"""Grasping every kitchen shape: the grasp chosen from the believed shape (unit), and picks, places and drops
on real physics judged in ground truth."""

import math

import numpy as np
import pytest

from bt_humanoid.control.grasping import (
    OPENING_MARGIN,
    PAD_HALF_HEIGHT,
    PALM_ABOVE_GRIP,
    GraspError,
    hand_yaws,
    plan_grasp,
)
from bt_humanoid.perception.world_model import TrackedObject
from bt_humanoid.sim.simulation import Simulation
from bt_humanoid.testing.told import told_objects

OPENING = 0.13  # m between the open pads of the wheeled humanoid's grippers
TABLE = 0.75  # m: the kitchen table's top


def _thing(kind: str, size: tuple[float, float, float], yaw: float = 0.0, name: str = "thing") -> TrackedObject:
    return TrackedObject(
        id=name,
        name=name,
        kind=kind,
        colour="red",
        position=np.array([1.0, 0.0, TABLE + size[2] / 2]),
        yaw=yaw,
        size=np.array(size),
    )


def _turn(a: float, b: float) -> float:
    return abs(math.remainder(a - b, math.tau))


@pytest.mark.parametrize("bag_yaw", [0.0, 0.4, 1.2, -2.0, math.pi / 2])
def test_a_bag_of_chips_is_taken_across_its_narrow_side_whichever_way_it_stands(bag_yaw):
    bag = _thing("bag", (0.12, 0.05, 0.16), yaw=bag_yaw)
    grasp = plan_grasp(bag, TABLE, 0.1, OPENING)
    assert grasp.width == pytest.approx(0.05)
    # the fingers close along the bag's narrow side (its y): the hand turned a right angle from the bag
    assert _turn(grasp.yaw, bag_yaw + math.pi / 2) < 1e-9 or _turn(grasp.yaw, bag_yaw - math.pi / 2) < 1e-9
    # and of the two such yaws, the one nearer the hand's
    other = grasp.yaw + math.pi
    assert _turn(grasp.yaw, 0.1) <= _turn(other, 0.1)


def test_of_the_yaws_that_fit_the_nearest_to_the_hand_wins():
    cube = _thing("cube", (0.05, 0.05, 0.05), yaw=0.3)
    assert plan_grasp(cube, TABLE, 0.0, OPENING).yaw == pytest.approx(0.3)
    assert plan_grasp(cube, TABLE, 1.2, OPENING).yaw == pytest.approx(0.3 + math.pi / 2)
    sponge = _thing("sponge", (0.095, 0.065, 0.03), yaw=0.0)  # both ways fit: the nearer yaw, not the narrower side
    assert plan_grasp(sponge, TABLE, 0.2, OPENING).width == pytest.approx(0.095)
    assert plan_grasp(sponge, TABLE, 1.3, OPENING).width == pytest.approx(0.065)


def test_a_width_fits_only_with_slack_on_both_sides():
    assert OPENING - OPENING_MARGIN < 0.12  # a bag's long side would leave a pad under a centimetre from its face
    box = _thing("box", (0.12, 0.12, 0.05))
    with pytest.raises(GraspError, match=r"12\.0 cm across at its narrowest; the gripper opens 13 cm"):
        plan_grasp(box, TABLE, 0.0, OPENING)


def test_round_things_are_closed_on_at_the_hands_own_yaw():
    for kind in ("can", "bottle", "ball", "fruit"):
        thing = _thing(kind, (0.066, 0.066, 0.122), yaw=1.0)
        grasp = plan_grasp(thing, TABLE, -0.4, OPENING)
        assert grasp.yaw == pytest.approx(-0.4) and grasp.width == pytest.approx(0.066), kind


def test_a_mug_is_closed_on_across_its_body_at_right_angles_to_the_handle():
    mug = _thing("mug", (0.11, 0.08, 0.09), yaw=0.0)  # the handle sticks out along x
    options = hand_yaws(mug, 0.0)
    assert all(_turn(yaw, math.pi / 2) < 1e-9 or _turn(yaw, -math.pi / 2) < 1e-9 for yaw, _ in options)
    assert plan_grasp(mug, TABLE, 0.0, OPENING).width == pytest.approx(0.08)


def test_an_unknown_kind_is_held_as_the_box_its_extents_describe():
    brick = _thing("brick", (0.2, 0.06, 0.05), yaw=0.0)
    grasp = plan_grasp(brick, TABLE, 0.1, OPENING)
    assert grasp.width == pytest.approx(0.06) and _turn(grasp.yaw, math.pi / 2) < 1e-9


@pytest.mark.parametrize("kind, size", [("bar", (0.13, 0.045, 0.022)), ("sponge", (0.095, 0.065, 0.03))])
def test_a_flat_thing_is_held_with_the_pads_just_above_the_surface(kind, size):
    flat = _thing(kind, size)
    grasp = plan_grasp(flat, TABLE, 0.0, OPENING)
    pads_bottom = grasp.position[2] - PAD_HALF_HEIGHT
    assert TABLE + 0.003 <= pads_bottom <= TABLE + 0.01  # close to the surface, never on it
    assert flat.top - pads_bottom >= 0.01  # the pads close on a centimetre of its sides at least
    assert grasp.position[2] > flat.top  # the grip site above the thing: it is lower than the pads are tall


def test_a_thing_too_flat_for_the_pads_is_refused():
    card = _thing("card", (0.09, 0.06, 0.004))
    with pytest.raises(GraspError, match="too flat"):
        plan_grasp(card, TABLE, 0.0, OPENING)


def test_tall_things_are_held_high_with_the_palm_clear_of_their_top():
    bag = _thing("bag", (0.12, 0.05, 0.16))
    grasp = plan_grasp(bag, TABLE, 0.0, OPENING)
    assert grasp.position[2] + PALM_ABOVE_GRIP > bag.top  # the palm stays above the bag
    assert grasp.position[2] > bag.position[2]  # held above its middle


def test_an_apple_is_held_at_its_widest():
    apple = _thing("fruit", (0.076, 0.076, 0.076))
    grasp = plan_grasp(apple, TABLE, 0.0, OPENING)
    assert abs(grasp.position[2] - apple.position[2]) < 0.005  # the pads close on the equator


def test_every_kitchen_object_has_a_grasp_from_the_natural_hand_yaw_at_any_turn():
    sim = Simulation.load("kitchen", "wheeled_humanoid")
    things = told_objects(sim)
    assert len(things) == 16
    for thing in things:
        for yaw in np.linspace(-math.pi, math.pi, 13):
            thing.yaw = float(yaw)
            grasp = plan_grasp(thing, thing.bottom, 0.0, OPENING)
            assert grasp.width <= OPENING - OPENING_MARGIN, thing.name
            assert grasp.position[2] - PAD_HALF_HEIGHT > thing.bottom, thing.name  # pads above the surface
