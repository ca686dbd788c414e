"""Testing helpers: run missions headless and assert on outcome, event log and ground truth."""

from bt_humanoid.testing.scenario import Scenario, run_scenario

__all__ = ["Scenario", "run_scenario"]
