"""The manipulation benchmark's set-up and judging, on a couple of trials (the figures come from running it)."""

import numpy as np
import pytest

from bt_humanoid.benchmarks.common import footing_removed, has_fallen
from bt_humanoid.benchmarks.manipulation import OBJECTS, SURFACE, run_trial, sample_trial
from bt_humanoid.control.stance import deepest_reach, working_stance
from bt_humanoid.engine.stack import RobotStack
from bt_humanoid.testing.scene import place_object
from bt_humanoid.testing.told import told_objects


def _table(robot: str = "wheeled_humanoid"):
    stack = RobotStack.load("apartment", robot)
    return stack, stack.context.world_model.surface(SURFACE)


def test_place_object_moves_the_declared_and_the_simulated_pose_together():
    run, table = _table()
    place_object(run, "water bottle", 3.6, -0.2, 0.7)
    belief = next(o for o in told_objects(run.sim) if o.name == "water bottle")
    truth = run.truth.object_position("water bottle")
    assert np.allclose(belief.position[:2], [3.6, -0.2]) and np.allclose(truth[:2], [3.6, -0.2], atol=1e-6)
    assert abs(belief.bottom - table.height) < 0.002
    assert abs(belief.yaw - 0.7) < 1e-6


@pytest.mark.parametrize("robot", ["wheeled_humanoid", "biped_humanoid"])
def test_sampled_trials_stand_on_the_edge_they_were_drawn_for_within_the_robots_reach(robot):
    run, table = _table(robot)
    rng = np.random.default_rng(3)
    bounds = np.array(run.context.world.bounds)
    base = run.context.robot_config.base
    (x0, y0), (x1, _) = table.region
    for kind in list(OBJECTS) * 4:
        trial = sample_trial(kind, table, bounds, base, rng)
        assert table.contains(np.array(trial.spot), margin=0.09) and table.contains(np.array(trial.place), margin=0.09)
        assert np.hypot(trial.spot[0] - trial.place[0], trial.spot[1] - trial.place[1]) >= 0.15
        for spot in (trial.spot, trial.place):
            _, _, yaw = working_stance(np.array(spot), table, "right", base, bounds, np.array(trial.start[:2]))
            assert abs(np.degrees(yaw) - trial.start[2]) < 1e-6
            x, y = spot
            behind_edge = {"west": x - x0, "east": x1 - x, "south": y - y0}[trial.edge]
            assert behind_edge <= deepest_reach(base) - 0.06 + 1e-3  # the biped reaches less deep than the wheels


def test_a_fall_is_the_pelvis_low_or_anything_but_a_sole_on_the_floor():
    standing = [("l_sole_0", "floor"), ("r_foot", "floor"), ("r_pad", "red cube")]
    assert footing_removed(standing) == [("r_pad", "red cube")]
    assert not has_fallen(0.62, footing_removed(standing))
    assert has_fallen(0.62, footing_removed([*standing, ("l_hand", "floor")]))  # a hand down
    assert has_fallen(0.3, [])  # sitting on the floor


@pytest.mark.sim
def test_a_bottle_trial_is_picked_and_placed_upright_and_judged_so():
    run, table = _table()
    base = run.context.robot_config.base
    trial = sample_trial("bottle", table, np.array(run.context.world.bounds), base, np.random.default_rng(7))
    outcome = run_trial(trial)
    assert outcome.grasped and outcome.placed, outcome.failure
    assert outcome.error_cm < 3.0
    assert len(outcome.qp_times) > 100  # the whole-body QP ran and was timed at every control step
    assert not outcome.fell


def test_the_table_says_what_each_rate_is_counted_over():
    from bt_humanoid.benchmarks.manipulation import Outcome, Trial, summarize, table

    trial = Trial("mug", "west", (2.9, 0.1), 0.0, (2.9, -0.1), (2.2, 0.0, 0.0))

    def outcome(grasped: bool, placed: bool) -> Outcome:
        failure = None if placed else "missed"
        return Outcome(grasped, placed, 0.3 if placed else None, failure, 10.0, fell=False, qp_times=[], conic_times=[])

    outcomes = [outcome(True, True)] * 3 + [outcome(True, False), outcome(False, False)]
    header, row = table([summarize("mug", [trial] * 5, outcomes)]).splitlines()
    assert "grasp | of all" in header and "place | of grasped" in header and "place | of all" in header
    assert "4/5 80%" in row and "3/4 75%" in row and "3/5 60%" in row
