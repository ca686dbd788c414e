"""The manipulation benchmark's set-up and judging, on a couple of trials (the figures come from running it)."""

import numpy as np
import pytest

from bt_humanoid.benchmarks.manipulation import OBJECTS, SURFACE, run_trial, sample_trial
from bt_humanoid.control.stance import stance_for
from bt_humanoid.engine.stack import RobotStack
from bt_humanoid.testing.scene import place_object
from bt_humanoid.testing.told import told_objects


def _table():
    stack = RobotStack.load("apartment", "wheeled_humanoid")
    return stack, stack.context.world_model.surface(SURFACE)


def test_place_object_moves_the_declared_and_the_simulated_pose_together():
    run, table = _table()
    place_object(run, "water bottle", 3.6, -0.2, 0.7)
    belief = next(o for o in told_objects(run.sim) if o.name == "water bottle")
    truth = run.truth.object_position("water bottle")
    assert np.allclose(belief.position[:2], [3.6, -0.2]) and np.allclose(truth[:2], [3.6, -0.2], atol=1e-6)
    assert abs(belief.bottom - table.height) < 0.002
    assert abs(belief.yaw - 0.7) < 1e-6


def test_sampled_trials_stand_on_the_edge_they_were_drawn_for():
    run, table = _table()
    rng = np.random.default_rng(3)
    bounds = np.array(run.context.world.bounds)
    footprint = run.context.robot_config.base.footprint_radius
    for kind in OBJECTS:
        trial = sample_trial(kind, table, bounds, footprint, rng)
        assert table.contains(np.array(trial.spot), margin=0.09) and table.contains(np.array(trial.place), margin=0.09)
        assert np.hypot(trial.spot[0] - trial.place[0], trial.spot[1] - trial.place[1]) >= 0.15
        for spot in (trial.spot, trial.place):
            _, _, yaw = stance_for(np.array(spot), table, "right", footprint, bounds, np.array(trial.start[:2]))
            assert abs(np.degrees(yaw) - trial.start[2]) < 1e-6


@pytest.mark.sim
def test_a_bottle_trial_is_picked_and_placed_upright_and_judged_so():
    run, table = _table()
    trial = sample_trial("bottle", table, np.array(run.context.world.bounds), 0.32, np.random.default_rng(7))
    outcome = run_trial(trial)
    assert outcome.grasped and outcome.placed, outcome.failure
    assert outcome.error_cm < 3.0
    assert len(outcome.qp_times) > 100  # the whole-body QP ran and was timed at every control step


def test_the_table_says_what_each_rate_is_counted_over():
    from bt_humanoid.benchmarks.manipulation import Outcome, Trial, summarize, table

    trial = Trial("mug", "west", (2.9, 0.1), 0.0, (2.9, -0.1), (2.2, 0.0, 0.0))

    def outcome(grasped: bool, placed: bool) -> Outcome:
        return Outcome(grasped, placed, 0.3 if placed else None, None if placed else "missed", 10.0, [], [])

    outcomes = [outcome(True, True)] * 3 + [outcome(True, False), outcome(False, False)]
    header, row = table([summarize("mug", [trial] * 5, outcomes)]).splitlines()
    assert "grasp | of all" in header and "place | of grasped" in header and "place | of all" in header
    assert "4/5 80%" in row and "3/4 75%" in row and "3/5 60%" in row
