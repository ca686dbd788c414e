"""The hand keeps clear of the other things on a surface (control/keep_clear.py), and a put finds room
(perception/free_space.nearest_free): geometry from the belief, no physics."""

import numpy as np
import pytest

from bt_humanoid.control.keep_clear import (
    CLOSED_HAND_RADIUS,
    OPEN_HAND_RADIUS,
    THING_MARGIN,
    clearance_limits,
    hand_radius,
    things_on,
    transit_height,
)
from bt_humanoid.perception.free_space import nearest_free
from bt_humanoid.perception.world_model import SupportSurface, TrackedObject, WorldModel

COUNTER = SupportSurface("counter", np.array([[0.0, 0.0], [1.0, 0.5]]), 0.9)


def _thing(name: str, x: float, y: float, height: float, width: float = 0.06) -> TrackedObject:
    centre = np.array([x, y, COUNTER.height + height / 2])
    return TrackedObject(name, name, "bottle", "blue", centre, 0.0, np.array([width, width, height]))


@pytest.fixture
def belief() -> WorldModel:
    model = WorldModel(surfaces={"counter": COUNTER})
    for thing in (_thing("bottle", 0.5, 0.25, 0.22), _thing("sponge", 0.3, 0.25, 0.03, 0.09)):
        model.update(thing)
    return model


def test_only_things_standing_on_the_surface_count(belief):
    held = _thing("can", 0.6, 0.1, 0.12)
    held.held_by = "right"
    belief.update(held)
    names = {t.name for t in things_on(belief, COUNTER)}
    assert names == {"bottle", "sponge"}
    assert {t.name for t in things_on(belief, COUNTER, exclude=("bottle",))} == {"sponge"}


def test_a_move_past_a_tall_thing_must_pass_over_it(belief):
    things = things_on(belief, COUNTER)
    # straight across the bottle: over its top, with the pads (3 cm) below the grip site and a margin
    over = transit_height(np.array([0.5, -0.2]), np.array([0.5, 0.45]), things, below_hand=0.03)
    assert over == pytest.approx(0.9 + 0.22 + 0.03 + THING_MARGIN)
    # a move that passes 20 cm to its side needs nothing
    assert transit_height(np.array([0.8, -0.2]), np.array([0.8, 0.45]), things, 0.03) == -np.inf
    # a held object hanging 15 cm below the hand needs more than an empty hand
    assert transit_height(np.array([0.5, -0.2]), np.array([0.5, 0.2]), things, 0.15) > over


def test_an_open_hand_is_wider_than_a_closed_one():
    assert hand_radius(None, is_open=True) == OPEN_HAND_RADIUS > CLOSED_HAND_RADIUS == hand_radius(None, False)
    big = _thing("bag", 0, 0, 0.16, width=0.2)
    assert hand_radius(big, is_open=False) > CLOSED_HAND_RADIUS  # what it holds is wider than the palm


def test_the_limits_skip_a_neighbour_over_the_goal(belief):
    things = things_on(belief, COUNTER)
    limits = clearance_limits("r_grip", things, 0.03, except_at=np.array([0.3, 0.25]))
    assert len(limits) == 1 and limits[0].height == pytest.approx(0.9 + 0.22 + 0.03 + THING_MARGIN)
    assert np.all(limits[0].region[0] < [0.5, 0.25]) and np.all(limits[0].region[1] > [0.5, 0.25])


def test_a_spot_taken_moves_to_the_nearest_free_one(belief):
    spot = nearest_free(COUNTER, belief, np.array([0.52, 0.25]), radius=0.035)
    assert spot is not None
    assert 0.05 < np.hypot(*(spot - [0.52, 0.25])) < 0.15
    assert np.hypot(*(spot - [0.5, 0.25])) >= 0.035 + np.hypot(0.06, 0.06) / 2
    free = np.array([0.8, 0.25])
    assert np.array_equal(nearest_free(COUNTER, belief, free, radius=0.035), free)  # free already: kept


def test_no_free_spot_near_a_crowded_one_is_none():
    model = WorldModel(surfaces={"counter": COUNTER})
    for i, x in enumerate(np.arange(0.05, 1.0, 0.09)):
        for j, y in enumerate(np.arange(0.05, 0.5, 0.09)):
            model.update(_thing(f"can {i} {j}", x, y, 0.12))
    assert nearest_free(COUNTER, model, np.array([0.5, 0.25]), radius=0.035) is None
