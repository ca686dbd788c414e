"""Joint speed (latching), torque strain, dropped object and no-progress monitors (branch faults).

A branch fault halts the running leaf it concerns; the leaf fails with the monitor's reason and its recovery
policy takes over. Outside forces here are test set-up (a hand pushing on a joint), applied as forces.
"""

from types import SimpleNamespace

import pytest

from bt_humanoid.safety.monitors import StuckMonitor
from bt_humanoid.testing.scenario import build_run


def events(result, kind):
    return [e for e in result.events.events if e["event"] == kind]


def push_joint(run, joint, torque, start=0.3, until=lambda: float("inf")):
    """From ``start`` s to ``until()``, an outside torque on one joint (a number, or a function of its angle)."""
    model = run.sim.model
    joint_id = model.joint(joint).id
    dof, qpos = int(model.jnt_dofadr[joint_id]), int(model.jnt_qposadr[joint_id])

    def apply() -> None:
        on = start <= run.sim.time < until()
        value = torque(run.sim.data.qpos[qpos]) if callable(torque) else torque
        run.sim.data.qfrc_applied[dof] = value if on else 0.0

    run.executor.observers.append(apply)


@pytest.mark.sim
def test_a_joint_driven_past_its_speed_limit_trips_the_guard():
    run = build_run({"mission": "fast", "tree": {"wait": {"seconds": 4}}})
    push_joint(run, "waist_yaw", 260.0)  # more than the waist actuator's 200 N m: it turns away, ever faster
    result = run.execute()
    assert result.tree_status == "FAILURE"
    assert result.safety.startswith("joint_limits: joint waist_yaw moving at"), result.safety


@pytest.mark.sim
def test_a_knock_shorter_than_the_overspeed_time_does_not_trip():
    run = build_run({"mission": "knock", "tree": {"wait": {"seconds": 2}}})
    push_joint(run, "waist_yaw", 260.0, start=0.3, until=lambda: 0.4)
    result = run.execute()
    assert result.tree_status == "SUCCESS", result.safety


@pytest.mark.sim
def test_a_joint_straining_at_its_torque_limit_halts_its_skill_and_recovery_retries():
    mission = {
        "mission": "strain",
        "tree": {"move_joints": {"joints": {"r_elbow": -2.0}}, "recovery": {"retries": 1, "backoff": 0.5}},
    }
    run = build_run(mission)
    strained = []
    # a stiff obstacle holds the elbow where it starts, until the strain monitor has fired once
    start = run.robot.body_io.positions()[run.robot.body_io.index("r_elbow")]
    wall = lambda q: -1000.0 * (q - start)  # noqa: E731  N m per rad: the 80 N m drive bends it 0.08 rad
    push_joint(run, "r_elbow", wall, start=0.0, until=lambda: float("inf") if not strained else 0.0)
    run.executor.tick_listeners.append(lambda ex: strained.extend(run.supervisor.faults))
    result = run.execute()
    fault = events(result, "monitor")[0]
    assert fault["monitor"] == "strain" and fault["message"].startswith("r_elbow pressed at its torque limit")
    assert fault["t"] >= 1.0, "only after strain_time at the limit"
    feedback = [e.get("feedback", "") for e in events(result, "status") if e["node"] == "move_joints"]
    assert any(f.startswith("strain: r_elbow") for f in feedback)
    assert len(events(result, "retry")) == 1 and result.tree_status == "SUCCESS", "recovered once the push ended"
    assert run.robot.at_rest()


@pytest.mark.sim
def test_a_branch_fault_fails_only_the_running_leaf_and_recovery_takes_over():
    run = build_run({"mission": "f", "tree": {"wait": {"seconds": 1.0}, "recovery": {"retries": 1, "backoff": 0.5}}})
    fired = []

    class OnceMonitor:
        name = "test"

        def faults(self, now):
            if now >= 0.3 and not fired:
                fired.append(now)
                return [(None, "boom")]
            return []

    run.supervisor.branch_monitors.append(OnceMonitor())
    result = run.execute()
    assert result.tree_status == "SUCCESS" and result.safety is None
    assert [e["message"] for e in events(result, "monitor")] == ["boom"]
    assert result.summary()["halted_by"] == ["test: boom"], "the summary says which monitor halted what"
    assert "test: boom" in [e.get("feedback") for e in events(result, "status") if e["new"] == "FAILURE"]
    assert result.sim_time == pytest.approx(0.3 + 0.5 + 1.0, abs=0.11)


class FakeLeaf:
    def __init__(self, feedback: str) -> None:
        self.feedback_message = feedback
        self.motion = SimpleNamespace(done=False)


def test_a_motion_without_progress_is_stuck_after_the_limit():
    robot = SimpleNamespace(max_speed=lambda: 0.0)
    still, counting = FakeLeaf("waiting for the way"), FakeLeaf("3 s left")
    monitor = StuckMonitor(robot, lambda: [still, counting], stuck_after=5.0)
    for t in range(5):
        counting.feedback_message = f"{5 - t} s left"
        assert monitor.faults(float(t)) == []
    counting.feedback_message = "0 s left"
    found = monitor.faults(5.0)
    assert found == [(still, "no progress for 5 s (waiting for the way)")]


def test_a_moving_robot_is_never_stuck():
    robot = SimpleNamespace(max_speed=lambda: 0.2)
    monitor = StuckMonitor(robot, lambda: [FakeLeaf("driving")], stuck_after=1.0)
    assert all(monitor.faults(float(t)) == [] for t in range(5))
