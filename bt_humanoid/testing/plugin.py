"""pytest plugin (registered as an entry point): fixtures for mission scenario tests.

def test_demo(run_mission):
    scenario = run_mission("missions/demo.yaml")
    assert scenario.result.success
    assert scenario.truth.robot_pose()[0] > 2.0
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest

from bt_humanoid.testing.scenario import Scenario, build_run, run_scenario


@pytest.fixture
def run_mission() -> Callable[..., Scenario]:
    """Run a mission (file path, YAML text or mapping) headless; returns a Scenario."""
    return run_scenario


@pytest.fixture
def mission_run() -> Callable[..., object]:
    """Build a MissionRun without executing it, to inject faults or stop requests first."""
    return build_run


@pytest.fixture
def project_root() -> Path:
    from bt_humanoid.paths import project_root

    return project_root()
