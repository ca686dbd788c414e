"""Same mission, same seed → the same event log."""

from bt_humanoid.testing.scenario import run_scenario


def test_same_seed_gives_identical_event_logs(project_root):
    mission = project_root / "missions" / "demo.yaml"
    first = run_scenario(mission, seed=7).result.events.lines()
    second = run_scenario(mission, seed=7).result.events.lines()
    assert len(first) > 20
    assert first == second
