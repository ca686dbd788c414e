"""The 3-D recording of a run (bt-run --rerun FILE.rrd): written, and read back with Rerun's own reader
(bt_humanoid/viz/rerun_recorder.py, rerun_scene.py, docs/rerun.md)."""

from __future__ import annotations

import json
import sys

import pytest

from bt_humanoid.cli import run_main

rerun = pytest.importorskip("rerun")

MISSION = """mission: look at the table and drive towards it
world: apartment
robot: wheeled_humanoid
tree:
  sequence:
    - say: {text: Off I go.}
    - navigate_to: {pose: [0.6, -0.9, 0]}
    - move_joints: {posture: ready}
"""


def _chunks(path):
    from rerun.chunk import RrdReader

    return list(RrdReader(path).stream().collect().stream())


@pytest.mark.sim
def test_a_run_is_recorded_on_the_simulation_clock(tmp_path):
    mission, rrd, summary = tmp_path / "m.yaml", tmp_path / "run.rrd", tmp_path / "s.json"
    mission.write_text(MISSION)
    assert run_main([str(mission), "--no-live", "--rerun", str(rrd), "--summary-json", str(summary)]) == 0
    chunks = _chunks(rrd)
    paths = {chunk.entity_path for chunk in chunks}
    wanted = {
        "/world/bodies/base",  # the robot's links and their geoms
        "/world/bodies/base/cylinders",
        "/world/bodies/table/boxes",  # the world's furniture
        "/world/head_camera/rgb",  # what the head camera saw
        "/world/head_camera/depth",
        "/world/perception/detections",
        "/world/belief/objects",  # what the robot believes, beside the truth
        "/world/truth/objects",
        "/world/map/furniture",
        "/world/navigation/route",
        "/tree/status",
        "/log/said",
    }
    assert wanted <= paths, sorted(wanted - paths)
    assert any(path.startswith("/tree/nodes/") and "navigate_to" in path for path in paths)
    times = []
    for chunk in chunks:
        if "sim_time" in chunk.timeline_names:
            column = chunk.to_record_batch().column("sim_time").cast("int64").to_pylist()
            times += [t / 1e9 for t in column]
    sim_time = json.loads(summary.read_text())["sim_time"]
    assert min(times) == pytest.approx(0.0, abs=0.01)
    assert max(times) == pytest.approx(sim_time, abs=0.06), "the timeline spans the run"
    base = next(c for c in chunks if c.entity_path == "/world/bodies/base" and not c.is_static)
    assert base.num_rows > 10 * sim_time, "the robot's pose at 20 Hz"


def test_an_unwritable_recording_is_one_message_and_exit_2(tmp_path, capsys):
    mission = tmp_path / "m.yaml"
    mission.write_text("mission: talk\ntree:\n  say: {text: hello}\n")
    (tmp_path / "file").write_text("")
    assert run_main([str(mission), "--no-live", "--rerun", str(tmp_path / "file" / "run.rrd")]) == 2
    assert run_main([str(mission), "--no-live", "--rerun", str(tmp_path / "run.mp4")]) == 2
    err = capsys.readouterr().err
    assert "cannot write it" in err and ".rrd file" in err and "Traceback" not in err


def test_without_rerun_sdk_it_says_how_to_install_it(tmp_path, capsys, monkeypatch):
    mission = tmp_path / "m.yaml"
    mission.write_text("mission: talk\ntree:\n  say: {text: hello}\n")
    monkeypatch.setitem(sys.modules, "rerun", None)  # import rerun fails
    assert run_main([str(mission), "--no-live", "--rerun", str(tmp_path / "run.rrd")]) == 2
    err = capsys.readouterr().err
    assert "rerun-sdk" in err and "bt-humanoid[rerun]" in err
