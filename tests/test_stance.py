"""Where the robot stands to work at a surface (control/stance.py): facing the nearest edge, the spot in front of
the working hand, as near as each robot's ``base.working_stance`` says."""

from __future__ import annotations

import math

import numpy as np
import pytest

from bt_humanoid.control.stance import MAX_DEPTH, StanceError, deepest_reach, working_stance, working_stances
from bt_humanoid.perception.world_model import SupportSurface
from bt_humanoid.sim.robot_config import load_robot_config

TABLE = SupportSurface("table", np.array([[1.8, -0.45], [3.0, 0.45]]), 0.75)  # the apartment's
BOUNDS = np.array([[-2.0, -4.5], [9.0, 4.5]])
SOUTH = np.array([2.4, -3.0])  # the robot comes from the south: the south edge (y = -0.45) is nearest


def test_the_wheeled_robot_stands_its_footprint_clear_of_the_edge_with_the_spot_in_front_of_its_hand():
    base = load_robot_config("wheeled_humanoid").base
    x, y, yaw = working_stance(np.array([2.4, -0.2]), TABLE, "right", base, BOUNDS, SOUTH)
    assert yaw == pytest.approx(math.pi / 2)  # facing the table (north)
    assert y == pytest.approx(-0.45 - base.footprint_radius - 0.05)
    assert x == pytest.approx(2.4 - 0.18)  # the spot 0.18 m to the right of the base's centre line


def test_the_biped_comes_nearer_for_a_deeper_spot_down_to_its_closest():
    base = load_robot_config("biped_humanoid").base
    stance = base.working_stance
    edge = -0.45

    def distance_from_edge(depth: float) -> float:
        return edge - working_stance(np.array([2.4, edge + depth]), TABLE, "right", base, BOUNDS, SOUTH)[1]

    assert distance_from_edge(0.1) == pytest.approx(stance.standoff)
    assert distance_from_edge(stance.reach_depth) == pytest.approx(stance.standoff)
    assert distance_from_edge(stance.reach_depth + 0.04) == pytest.approx(stance.standoff - 0.04)
    deepest = stance.reach_depth + stance.standoff - stance.closest
    assert distance_from_edge(deepest) == pytest.approx(stance.closest)
    assert deepest_reach(base) == pytest.approx(deepest)  # what bt-eval's spots keep within
    assert deepest_reach(load_robot_config("wheeled_humanoid").base) == MAX_DEPTH
    # beyond, from no edge: the message names how far the arm reaches
    wide = SupportSurface("wide", np.array([[1.0, -1.0], [4.0, 1.0]]), 0.75)
    with pytest.raises(StanceError, match=f"the arm reaches {deepest:.2f} m"):
        working_stance(np.array([2.4, 0.0]), wide, "right", base, BOUNDS, SOUTH)


@pytest.mark.parametrize("closest", [None, 0.3])
def test_the_deepest_reach_is_where_the_working_stance_stops_reaching(closest):
    """With or without a closest stance, and with the standoff left to the footprint (the wheeled robot's)."""
    base = load_robot_config("wheeled_humanoid").base
    base = base.model_copy(update={"working_stance": base.working_stance.model_copy(update={"closest": closest})})
    deep = SupportSurface("deep", np.array([[1.0, -3.0], [4.0, 0.45]]), 0.75)  # reached from its north edge only
    deepest = deepest_reach(base)
    north = np.array([2.4, 3.0])
    working_stance(np.array([2.4, 0.45 - deepest + 0.005]), deep, "right", base, BOUNDS, north)
    with pytest.raises(StanceError):
        working_stance(np.array([2.4, 0.45 - deepest - 0.005]), deep, "right", base, BOUNDS, north)


def test_after_a_short_reach_the_biped_stands_nearer_by_as_much_but_not_past_its_closest():
    base = load_robot_config("biped_humanoid").base
    stance = base.working_stance
    spot = np.array([2.4, -0.45 + 0.1])  # shallow: the biped stands at its standoff

    def distance_from_edge(nearer: float, robot: str = "biped_humanoid") -> float:
        config = load_robot_config(robot).base
        return -0.45 - working_stance(spot, TABLE, "right", config, BOUNDS, SOUTH, shift=(nearer, 0.0))[1]

    assert distance_from_edge(0.0) == pytest.approx(stance.standoff)
    assert distance_from_edge(0.04) == pytest.approx(stance.standoff - 0.04)
    assert distance_from_edge(1.0) == pytest.approx(stance.closest)
    # the wheeled robot has no closest stance: it stands where it stood (its base helps the arm instead)
    assert distance_from_edge(0.04, "wheeled_humanoid") == pytest.approx(distance_from_edge(0.0, "wheeled_humanoid"))


def test_a_shift_to_the_left_moves_the_stance_along_the_edge_by_as_much():
    base = load_robot_config("biped_humanoid").base
    spot = np.array([2.4, -0.45 + 0.1])
    x0, y0, _ = working_stance(spot, TABLE, "right", base, BOUNDS, SOUTH)
    x1, y1, _ = working_stance(spot, TABLE, "right", base, BOUNDS, SOUTH, shift=(0.0, -0.04))
    assert (x1, y1) == pytest.approx((x0 + 0.04, y0))  # facing north, its left is west: 4 cm to its right is east


def test_every_edge_that_reaches_a_spot_gives_a_stance_nearest_the_robot_first():
    """A spot near the table's south-west corner is reached from the south and the west edges: the nearer to the
    robot comes first, the other is where to work from when something stands on the first."""
    base = load_robot_config("wheeled_humanoid").base
    spot = np.array([1.95, -0.3])
    from_south = working_stances(spot, TABLE, "right", base, BOUNDS, SOUTH)
    assert [round(yaw, 3) for _, _, yaw in from_south] == [round(math.pi / 2, 3), 0.0]
    assert working_stance(spot, TABLE, "right", base, BOUNDS, SOUTH) == from_south[0]
    from_west = working_stances(spot, TABLE, "right", base, BOUNDS, np.array([0.0, -0.3]))
    assert [yaw for _, _, yaw in from_west] == [0.0, pytest.approx(math.pi / 2)]
