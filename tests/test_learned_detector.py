"""The kitchen's learned detector: training runs, the committed weights recognise, the robot sees with them."""

from __future__ import annotations

import json

import numpy as np
import pytest

from bt_humanoid.errors import UserError
from bt_humanoid.perception.crops import CHANNELS, CROP, region_crop
from bt_humanoid.perception.learned_detector import LearnedDetector, candidates
from bt_humanoid.perception.recogniser import NONE, Recogniser
from bt_humanoid.sim.world_config import load_world_config
from bt_humanoid.training import detector as training
from bt_humanoid.training.views import ViewMaker


@pytest.fixture(scope="module")
def views() -> ViewMaker:
    maker = ViewMaker("kitchen")
    yield maker
    maker.close()


def test_retraining_on_a_tiny_budget_runs_and_writes_a_loadable_detector(tmp_path) -> None:
    code = training.main(["--views", "12", "--validation-views", "4", "--epochs", "1", "--out", str(tmp_path)])
    assert code == 0
    recipe = json.loads((tmp_path / "recipe.json").read_text())
    assert recipe["seed"] == 0 and recipe["views"] == 12 and recipe["training_regions"] > 12
    assert 0.0 <= recipe["validation"]["accuracy"] <= 1.0
    recogniser = Recogniser.load(tmp_path)
    assert recogniser.classes[-1] == NONE and len(recogniser.classes) == 17


def test_a_folder_without_weights_is_a_clear_error(tmp_path) -> None:
    with pytest.raises(UserError, match="no trained detector") as error:
        Recogniser.load(tmp_path)
    assert "bt_humanoid.training.detector" in str(error.value)


def test_the_committed_weights_say_how_they_were_made() -> None:
    folder = load_world_config("kitchen").detector_path
    recipe = json.loads((folder / "recipe.json").read_text())
    assert recipe["command"].startswith("python -m bt_humanoid.training.detector")
    assert recipe["validation"]["object_accuracy"] >= 0.97
    assert (folder / "weights.pt").stat().st_size < 5_000_000  # small enough to commit


def test_crops_are_centred_on_their_region(views: ViewMaker) -> None:
    views.arrange(training.view_rng(7, training.BENCHMARK_STREAM, 0))
    frame, _ = views.capture()
    regions = candidates(frame, views.surfaces)
    assert regions
    crop = region_crop(frame, regions[0])
    assert crop.shape == (CHANNELS, CROP, CROP) and crop.dtype == np.float32
    mask, middle = crop[3], slice(CROP // 2 - 4, CROP // 2 + 4)
    assert mask[middle, middle].mean() > 0.5  # the region fills the middle
    assert mask[0, :].max() < 0.5 and mask[:, 0].max() < 0.5  # with a margin round it
    assert np.all((crop[:3] >= 0.0) & (crop[:3] <= 1.0)) and np.all(np.abs(crop[4]) <= 1.0)


def test_views_hold_clutter_the_recogniser_learns_to_call_none(views: ViewMaker) -> None:
    labels = []
    for index in range(10):
        views.arrange(training.view_rng(3, training.TRAIN_STREAM, index))
        frame, shown = views.capture()
        labels += [training.region_label(region, shown, views) for region in candidates(frame, views.surfaces)]
    assert labels.count(NONE) >= 3  # clutter, labelled none
    assert len(set(labels) - {NONE}) >= 8  # and many of the sixteen


def test_the_committed_detector_names_objects_in_views_it_was_not_trained_on(views: ViewMaker) -> None:
    detector = LearnedDetector.for_world(views.sim.world)
    names = list(views.sim.object_bodies)
    found = right = 0
    for index in range(12):  # the benchmark's stream, under another seed than the benchmark's default
        used = views.arrange(training.view_rng(99, training.BENCHMARK_STREAM, index))
        frame, shown = views.capture()
        for detection in detector.detect(frame, views.surfaces):
            centres = {i: views.sim.data.xpos[views.instances[i].body] for i in used}
            nearest = min(centres, key=lambda i: np.linalg.norm(centres[i][:2] - detection.position[:2]))
            if np.linalg.norm(centres[nearest][:2] - detection.position[:2]) < 0.03:
                found += 1
                right += detection.identity == views.instances[nearest].name
        assert np.all(shown[shown >= 0] < len(names))
    assert found >= 30
    assert right / found >= 0.9


def test_the_kitchen_robot_recognises_the_coke_among_other_cans() -> None:
    from bt_humanoid.engine.stack import RobotStack

    stack = RobotStack.load("kitchen", "wheeled_humanoid", robot_start=(2.2, -1.3, 0.0))
    try:
        sim, belief = stack.sim, stack.context.world_model
        assert stack.perceiver is not None and stack.perceiver.learned is not None
        head_tilt = sim.model.joint("head_tilt").qposadr[0]
        sim.data.qpos[head_tilt] = 0.8  # looking down at the table (set-up, before any step)
        import mujoco

        mujoco.mj_forward(sim.model, sim.data)
        stack.look()
        coke = belief.object("coke")
        assert coke.identity == "coke" and coke.kind == "can"
        truth = stack.truth.object_centre("coke")
        assert np.linalg.norm(coke.position - truth) < 0.02
        seen = {o.identity for o in belief.present()}
        assert {"pepsi", "7up"} <= seen
    finally:
        stack.close()


def test_a_frame_says_which_points_project_into_it(views: ViewMaker) -> None:
    views.arrange(training.view_rng(7, training.BENCHMARK_STREAM, 1))
    frame, _ = views.capture()
    ahead = frame.position - frame.rotation[:, 2]  # one metre along the line of sight (the camera looks along -z)
    assert frame.in_image(ahead)
    assert not frame.in_image(frame.position + frame.rotation[:, 2])  # behind the camera
    assert not frame.in_image(ahead + 5.0 * frame.rotation[:, 0])  # far off to the right
