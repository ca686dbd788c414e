"""bt-run exit codes and outputs: 0 success, 1 mission failure, 2 invalid input."""

import json

import pytest

from bt_humanoid.cli import run_main


@pytest.mark.sim
def test_success_writes_summary_and_events(tmp_path, project_root, capsys):
    summary, events = tmp_path / "s.json", tmp_path / "e.jsonl"
    code = run_main(
        [str(project_root / "missions/demo.yaml"), "--no-live", "--summary-json", str(summary), "--events", str(events)]
    )
    assert code == 0
    data = json.loads(summary.read_text())
    assert data["outcome"] == "success" and all(c["holds"] for c in data["conditions"])
    assert data["real_time_factor"] > 1
    lines = [json.loads(line) for line in events.read_text().splitlines()]
    assert lines[0]["event"] == "start" and lines[-1]["event"] == "end" and lines[-1]["status"] == "SUCCESS"
    assert lines[-1]["speed_at_finish"] < 0.01  # the demo's last step waits for its gripper: nothing moves then
    assert "SUCCESS" in capsys.readouterr().out


def test_tree_success_with_a_false_condition_exits_1(tmp_path):
    mission = tmp_path / "m.yaml"
    mission.write_text("mission: lie\ntree:\n  say: {text: done}\nsuccess:\n  - at: kitchen\n")
    assert run_main([str(mission), "--no-live"]) == 1


def test_tree_failure_exits_1(tmp_path):
    mission = tmp_path / "m.yaml"
    mission.write_text("mission: fail\ntree:\n  check: {key: nothing, op: exists}\n")
    assert run_main([str(mission), "--no-live"]) == 1


def test_invalid_input_exits_2(tmp_path, capsys):
    mission = tmp_path / "m.yaml"
    mission.write_text("mission: bad\ntree:\n  wait: {seconds: -1}\n")
    assert run_main([str(mission), "--no-live"]) == 2
    err = capsys.readouterr().err
    assert "m.yaml:3" in err and "seconds" in err
    assert run_main([str(mission), "--tick-hz", "0"]) == 2
    assert run_main([str(tmp_path / "absent.yaml")]) == 2


@pytest.mark.sim
def test_record_writes_a_video(tmp_path, project_root):
    import cv2

    mission = tmp_path / "m.yaml"
    mission.write_text("mission: short\ntree:\n  move_base: {relative: true, yaw: 30}\n")
    video = tmp_path / "run.mp4"
    assert run_main([str(mission), "--no-live", "--record", str(video)]) == 0
    capture = cv2.VideoCapture(str(video))
    assert capture.get(cv2.CAP_PROP_FRAME_COUNT) >= 30
