"""Perception: the rendered RGB-D camera and the object detector, judged against the simulator."""

import numpy as np
import pytest

from bt_humanoid.perception.detector import colour_name, detect
from bt_humanoid.perception.rgbd_camera import RgbdCamera
from bt_humanoid.testing.scenario import build_run


def _look(robot_start: tuple[float, float, float]):
    run = build_run({"mission": "look", "tree": {"wait": {"seconds": 0}}}, robot_start=robot_start)
    camera = RgbdCamera(run.sim, "head_camera", 320, 240)
    frame = camera.capture()
    camera.close()
    return run, frame, detect(frame, list(run.context.world_model.surfaces.values()))


def test_depth_pixels_become_the_world_points_they_show():
    run, frame, _ = _look((2.0, 0.0, 0.0))
    red = (frame.rgb[..., 0] > 150) & (frame.rgb[..., 1] < 60) & (frame.rgb[..., 2] < 60)
    points = frame.points()[red]
    assert red.sum() > 50
    cube = run.truth.object_centre("red cube")
    assert np.all(np.abs(points[:, :2] - cube[:2]) <= 0.03)  # every red pixel lies on the 5 cm cube
    assert points[:, 2].max() == pytest.approx(cube[2] + 0.025, abs=0.003)  # its top


def test_the_table_objects_are_found_with_kind_colour_and_position():
    run, _, found = _look((2.0, 0.0, 0.0))
    expected = {"red cube": ("cube", "red"), "blue cube": ("cube", "blue"), "water bottle": ("bottle", "blue")}
    assert len(found) == len(expected)
    for name, (kind, colour) in expected.items():
        centre = run.truth.object_centre(name)
        match = min(found, key=lambda d: np.linalg.norm(d.position - centre))
        assert np.linalg.norm(match.position - centre) < 0.01, name
        assert (match.kind, match.colour, match.surface) == (kind, colour, "table"), name


def test_the_mug_on_the_counter_and_the_ball_on_the_shelf():
    run, _, found = _look((7.4, 2.0, 0.0))
    (mug,) = [d for d in found if d.surface == "counter"]
    assert (mug.kind, mug.colour) == ("mug", "white")
    assert np.linalg.norm(mug.position - run.truth.object_centre("coffee mug")) < 0.01
    run, _, found = _look((1.2, 3.2, 90.0))
    (ball,) = found
    assert (ball.kind, ball.colour, ball.surface) == ("ball", "yellow", "shelf")


@pytest.mark.parametrize(
    ("rgb", "name"),
    [
        ((217, 26, 26), "red"),
        ((26, 64, 217), "blue"),
        ((242, 217, 26), "yellow"),
        ((26, 166, 51), "green"),
        ((242, 128, 26), "orange"),
        ((140, 51, 191), "purple"),
        ((242, 242, 235), "white"),
        ((20, 20, 20), "black"),
        ((128, 128, 128), "grey"),
    ],
)
def test_colour_names(rgb, name):
    assert colour_name(np.array(rgb)) == name
