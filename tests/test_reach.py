"""A reach that falls short says why: out of reach (the commanded pose itself stopped short) or blocked."""

import numpy as np
import pinocchio as pin
import pytest

from bt_humanoid.control.whole_body import ReachHandle
from bt_humanoid.testing.scenario import build_run

FACING_THE_TABLE = (3.3, -1.0, 90.0)  # south of the dining table, facing it: its hand hangs short of the edge


def _reach_from_the_hand(run, offset: np.ndarray) -> ReachHandle:
    """The right hand's reach to where it is now, moved by ``offset`` (m, world), the base kept still."""
    whole_body = run.robot.whole_body
    hand = whole_body.frame_pose(whole_body.hand_frame("right"))
    target = pin.SE3(hand.rotation.copy(), hand.translation + offset)
    handle = whole_body.reach("right", target, move_base=False)
    assert isinstance(handle, ReachHandle)
    for _ in range(200):  # 10 s at most
        if handle.done:
            break
        run.executor.advance(0.05)
    return handle


@pytest.mark.sim
def test_a_target_beyond_the_arm_is_out_of_reach():
    run = build_run({"mission": "reach", "tree": {"wait": {"seconds": 0}}}, robot_start=FACING_THE_TABLE)
    try:
        handle = _reach_from_the_hand(run, np.array([1.2, 0.0, 0.0]))  # 1.2 m to the side, the base held still
        assert handle.done and not handle.result.startswith("arrived"), handle.result
        assert handle.out_of_reach, handle.result
        assert "out of reach" in handle.result
    finally:
        run.stack.close()


@pytest.mark.sim
def test_a_hand_that_meets_the_table_top_from_below_is_blocked_not_out_of_reach():
    run = build_run({"mission": "reach", "tree": {"wait": {"seconds": 0}}}, robot_start=FACING_THE_TABLE)
    try:
        # forwards and up: the straight line runs under the table's edge and into its top from below
        handle = _reach_from_the_hand(run, np.array([0.0, 0.2, 0.3]))
        assert handle.done and not handle.result.startswith("arrived"), handle.result
        assert any(other == "table_top" for _, other in run.truth.robot_contacts()), "the palm is on the table top"
        assert not handle.out_of_reach, handle.result
        assert "blocked" in handle.result
    finally:
        run.stack.close()
