"""Status semantics of the mission language's composites and decorators, on cheap leaves."""

import pytest

from bt_humanoid.testing.scenario import run_scenario


def run(tree, **header):
    return run_scenario({"mission": "t", "tree": tree, **header})


def leaf(scenario, kind):
    return [e for e in scenario.events if e["event"] == "status" and e["node"].endswith(kind)]


def test_sequence_stops_at_the_first_failure():
    s = run({"sequence": [{"check": {"key": "x", "op": "exists"}}, {"say": {"text": "never"}}]})
    assert s.result.tree_status == "FAILURE" and s.result.said == []


def test_fallback_takes_the_first_success():
    s = run({"fallback": [{"check": {"key": "x", "op": "exists"}}, {"say": {"text": "b"}}, {"say": {"text": "c"}}]})
    assert s.result.tree_status == "SUCCESS" and s.result.said == ["b"]


@pytest.mark.sim
def test_retry_runs_the_child_again():
    s = run({"retry": {"attempts": 3, "child": {"sequence": [{"say": {"text": "try"}}, {"check": {"key": "x"}}]}}})
    assert s.result.tree_status == "FAILURE" and s.result.said == ["try"] * 3


@pytest.mark.sim
def test_repeat_and_blackboard_references():
    s = run(
        {"repeat": {"times": 2, "child": {"say": {"text": "$word"}}}},
        blackboard={"word": "again"},
    )
    assert s.result.tree_status == "SUCCESS" and s.result.said == ["again", "again"]


def test_missing_blackboard_value_fails_with_the_plan_step():
    s = run({"sequence": [{"say": {"text": "$nothing"}}]})
    assert s.result.tree_status == "FAILURE"
    failure = next(e for e in s.events if e["event"] == "status" and e["new"] == "FAILURE")
    assert "sequence[0].say" in failure["feedback"] and "nothing" in failure["feedback"]


@pytest.mark.parametrize(
    ("kind", "child_ok", "expected"),
    [
        ("invert", True, "FAILURE"),
        ("invert", False, "SUCCESS"),
        ("force_success", False, "SUCCESS"),
        ("force_failure", True, "FAILURE"),
    ],
)
def test_status_flipping_decorators(kind, child_ok, expected):
    child = {"check": {"key": "flag", "op": "equals", "value": True}}
    s = run({kind: {"child": child}}, blackboard={"flag": child_ok})
    assert s.result.tree_status == expected


@pytest.mark.sim
def test_timeout_halts_on_simulation_time():
    s = run({"timeout": {"seconds": 0.5, "child": {"wait": {"seconds": 3}}}})
    assert s.result.tree_status == "FAILURE"
    assert 0.45 <= s.result.sim_time <= 0.7


@pytest.mark.sim
def test_parallel_policies():
    one = run({"parallel": {"policy": "one", "children": [{"wait": {"seconds": 0.2}}, {"wait": {"seconds": 5}}]}})
    assert one.result.tree_status == "SUCCESS" and one.result.sim_time < 0.5
    both = run({"parallel": {"policy": "all", "children": [{"wait": {"seconds": 0.2}}, {"wait": {"seconds": 1}}]}})
    assert both.result.tree_status == "SUCCESS" and both.result.sim_time >= 1.0


@pytest.mark.sim
def test_guard_halts_the_child_when_its_condition_stops_holding():
    tree = {
        "parallel": {
            "policy": "all",
            "children": [
                {"sequence": [{"wait": {"seconds": 0.5}}, {"set": {"key": "go", "value": False}}]},
                {"guard": {"condition": {"check": {"key": "go", "value": True}}, "child": {"wait": {"seconds": 5}}}},
            ],
        }
    }
    s = run(tree, blackboard={"go": True})
    assert s.result.tree_status == "FAILURE" and s.result.sim_time < 1.0
    assert [e["new"] for e in leaf(s, "guard.wait")] == ["RUNNING", "INVALID"]


@pytest.mark.sim
def test_reactive_sequence_rechecks_earlier_children():
    tree = {
        "parallel": {
            "policy": "all",
            "children": [
                {"sequence": [{"wait": {"seconds": 0.3}}, {"set": {"key": "ok", "value": False}}]},
                {"reactive_sequence": [{"check": {"key": "ok", "value": True}}, {"wait": {"seconds": 5}}]},
            ],
        }
    }
    assert run(tree, blackboard={"ok": True}).result.sim_time < 1.0
    memory = {
        "parallel": {
            "policy": "all",
            "children": [
                {"sequence": [{"wait": {"seconds": 0.3}}, {"set": {"key": "ok", "value": False}}]},
                {"sequence": [{"check": {"key": "ok", "value": True}}, {"wait": {"seconds": 1.5}}]},
            ],
        }
    }
    assert run(memory, blackboard={"ok": True}).result.sim_time >= 1.5


@pytest.mark.sim
def test_recovery_policy_retries_leaves_with_backoff():
    tree = {"sequence": [{"check": {"key": "never", "op": "exists"}, "recovery": {"retries": 2, "backoff": 0.5}}]}
    s = run(tree)
    assert s.result.tree_status == "FAILURE"
    retries = [e for e in s.events if e["event"] == "retry"]
    assert [e["node"] for e in retries] == ["sequence[0].check"] * 2
    assert retries[1]["t"] - retries[0]["t"] == pytest.approx(0.5, abs=0.06)
    assert s.result.sim_time >= 1.0
