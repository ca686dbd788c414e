"""Same mission, same seed → the same event log, whatever the process did before."""

from pathlib import Path

import numpy as np
import pytest

from bt_humanoid.engine.stack import RobotStack
from bt_humanoid.evaluation.episode import run_episode
from bt_humanoid.navigation.planner import plan_route
from bt_humanoid.testing.scenario import run_scenario

FETCH = str(Path(__file__).resolve().parents[1] / "missions" / "benchmarks" / "fetch.yaml")


@pytest.mark.sim
def test_same_seed_gives_identical_event_logs(project_root):
    mission = project_root / "missions" / "demo.yaml"
    first = run_scenario(mission, seed=7).result.events.lines()
    second = run_scenario(mission, seed=7).result.events.lines()
    assert len(first) > 20
    assert first == second


def test_a_route_query_repeated_in_one_process_plans_the_same_route():
    stack = RobotStack.load("apartment", "wheeled_humanoid")
    stack.close()
    navigator = stack.navigator
    places = {name: np.array(place.pose) for name, place in stack.world.places.items()}
    start, goal = places["start"], places["table"]  # round the chair to the far side of the table
    routes = []
    for other in ("kitchen", "living_room", "counter"):
        routes.append(plan_route(navigator.grid, start, goal, navigator.clearance, seed=3))
        plan_route(navigator.grid, start, places[other], navigator.clearance, seed=3)  # moves OMPL's generator on
    assert routes[0].length > 1.05 * np.hypot(*(goal - start)[:2]), "not a straight line: OMPL planned it"
    for route in routes[1:]:
        np.testing.assert_array_equal(route.points, routes[0].points)
    other_seed = plan_route(navigator.grid, start, goal, navigator.clearance, seed=4)
    assert not np.array_equal(other_seed.points, routes[0].points), "the run's seed is what the route depends on"


@pytest.mark.sim
@pytest.mark.slow
def test_a_fetch_episode_run_twice_in_one_process_gives_identical_event_logs():
    logs = []
    for _ in range(2):
        events: list[dict] = []
        record = run_episode(FETCH, 2, events=events)
        logs.append(events)
    assert any(e["event"] == "status" and "navigate" in e["node"] for e in logs[0]), "the episode drives somewhere"
    assert record["sim_time"] > 10
    assert logs[0] == logs[1]


def test_opencv_works_on_one_thread_whatever_the_cores_so_runs_repeat_on_any_machine():
    import cv2

    stack = RobotStack.load("apartment", "wheeled_humanoid")
    stack.close()
    assert cv2.getNumThreads() == 1


@pytest.mark.sim
def test_a_run_leaves_the_garbage_collector_as_it_found_it(project_root, monkeypatch):
    import gc

    from bt_humanoid.engine.runner import GC_THRESHOLD

    before = gc.get_threshold()
    set_to: list[tuple[int, ...]] = []
    original = gc.set_threshold
    monkeypatch.setattr(gc, "set_threshold", lambda *values: (set_to.append(values), original(*values)))
    run_scenario(project_root / "missions" / "demo.yaml", seed=7)
    assert set_to[0][0] == GC_THRESHOLD > before[0], "the collector passes less often while the mission runs"
    assert gc.get_threshold() == before and gc.get_freeze_count() == 0
