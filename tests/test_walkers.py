"""The walking person: they see the robot with their own eyes, act a reaction time late, and may not yield."""

import math

import numpy as np
import pytest

from bt_humanoid.sim.walkers import Sighting, WalkerDriver
from bt_humanoid.testing.scenario import Scenario, build_run

WAIT = {"mission": "in the way", "world": "apartment_busy", "tree": {"wait": {"seconds": 12}}}
CROSS = {"mission": "cross", "world": "apartment_busy", "tree": {"navigate": {"place": "kitchen"}}}


def _walker(run, **changes) -> WalkerDriver:
    """The run's walker, with ``changes`` to how they walk (the world's file gives them a share of each)."""
    walker = run.sim.walkers[0]
    walker.walker = walker.walker.model_copy(update=changes)
    return walker


def _watch(run, walker: WalkerDriver) -> tuple[list, list[np.ndarray]]:
    """Every contact of the robot with the walker, and the walker's trail, at each control step."""
    contacts: list = []
    trail: list[np.ndarray] = []
    run.executor.observers.append(
        lambda: (
            contacts.extend(c for c in run.truth.robot_contacts() if "walker" in c[1]),
            trail.append(walker.position().copy()),
        )
    )
    return contacts, trail


def test_a_walker_sees_the_robot_ahead_but_not_behind_them_or_behind_a_wall():
    """They start at (4.7, -2.2) heading north, and see about 100 degrees to each side of that."""
    seen = {}
    for name, start in {"ahead": (4.7, -0.6, 90.0), "behind": (4.7, -3.6, 0.0), "walled": (9.6, -2.2, 0.0)}.items():
        run = build_run(WAIT, robot_start=start)
        walker = run.sim.walkers[0]
        seen[name] = walker.look(walker.position(), np.array([0.0, 1.0]))
        run.stack.close()
    assert len(seen["ahead"].parts) > 5 and np.allclose(seen["ahead"].parts[0], [4.7, -0.6], atol=0.01)
    assert len(seen["behind"].parts) == 0, "out of their field of view"
    assert len(seen["walled"].parts) == 0, "east of the apartment's wall"


def test_a_walker_acts_on_what_they_saw_one_reaction_time_ago():
    run = build_run(WAIT)
    walker = _walker(run, reaction_time=0.7)
    robot = Sighting(0.0, np.array([[4.7, -1.0]]), np.array([0.3]))
    walker.sightings.extend([robot, *(Sighting(t, np.zeros((0, 2)), np.zeros(0)) for t in (0.1, 0.2, 0.3))])
    assert len(walker.picture(0.5).parts) == 0, "not yet: nothing seen so long ago"
    assert walker.picture(0.75) is robot
    assert len(walker.picture(0.85).parts) == 0, "the next look saw nothing"
    run.stack.close()


@pytest.mark.sim
def test_a_walker_who_yields_waits_for_a_robot_in_the_way_then_turns_back():
    run = build_run(WAIT, robot_start=(4.7, -0.6, 90.0))  # on the loop's west leg, which they walk north
    walker = _walker(run, yields=1.0)
    contacts, trail = _watch(run, walker)
    run.execute()
    apart = np.hypot(*(np.array(trail) - [4.7, -0.6]).T)
    assert apart.min() > 0.32 + 0.2 + 0.1, "stopped short of the robot's base"
    assert walker.direction == -1 and trail[-1][0] > 5.3, "turned back, and went round the other way"
    assert not contacts


@pytest.mark.sim
def test_a_walker_who_does_not_yield_walks_round_the_robot_and_goes_on():
    run = build_run(WAIT, robot_start=(4.7, -0.6, 90.0))
    walker = _walker(run, yields=0.0)
    contacts, trail = _watch(run, walker)
    run.execute()
    apart = np.hypot(*(np.array(trail) - [4.7, -0.6]).T)
    assert apart.min() > 0.32 + 0.2, "passed the robot's base"
    assert apart.min() < 1.0, "close by: they did not stop for it"
    assert walker.direction == 1 and max(y for _, y in trail) > 0.4, "and went on north, the way they were going"
    assert not contacts


@pytest.mark.sim
@pytest.mark.parametrize("yields", [0.0, 1.0])
def test_crossing_the_walking_persons_loop_never_touches_them(yields: float):
    """The robot keeps apart on its own: the walker may not stop for it (and reacts a reaction time late)."""
    run = build_run(CROSS, robot_start=(3.6, -1.5, 0.0))  # south of the table, the person's loop ahead
    walker = _walker(run, yields=yields)
    contacts, trail = _watch(run, walker)
    robot: list[np.ndarray] = []
    run.executor.observers.append(lambda: robot.append(run.truth.robot_pose()[:2]))
    scenario = Scenario(run, run.execute())
    assert scenario.result.tree_status == "SUCCESS", scenario.result.summary()
    apart = np.hypot(*(np.array(robot) - np.array(trail)).T)
    assert apart.min() < 1.5, "their ways crossed (the person is 0.2 m in radius, the robot 0.32 m)"
    assert not contacts
    x, y, _ = scenario.truth.robot_pose()
    assert math.hypot(x - 7.0, y - 2.4) <= 0.05


def test_a_walker_expects_what_they_saw_moving_to_go_on_moving():
    seen = Sighting(1.0, np.array([[5.0, 0.0]]), np.array([0.1]), np.array([[-0.5, 0.0]]))
    assert np.allclose(seen.predicted(1.7).parts, [[4.65, 0.0]]), "0.7 s on at 0.5 m/s"
    assert seen.predicted(1.7).radii is seen.radii
