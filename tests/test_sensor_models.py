"""The sensor models: what each sensor adds to the truth, seeded, and off with --ideal-sensors."""

import math

import numpy as np
import pytest

from bt_humanoid.perception.depth_filter import cleaned_depth
from bt_humanoid.sim.sensor_models import (
    IDEAL_SENSORS_VARIABLE,
    ColourModel,
    DepthModel,
    EncoderModel,
    RangeModel,
    SensorModels,
    axial_sigma,
    colour_image,
    depth_image,
    depth_ranges,
    encoder_steps,
    quantise,
    scanner_ranges,
)
from bt_humanoid.sim.simulation import Simulation

FOCAL = 207.8  # pixels: the robots' 320 × 240 head camera
GREY = np.full((240, 320, 3), 128, np.uint8)


def two_walls(near: float = 1.0, far: float = 3.0) -> np.ndarray:
    """A depth image facing two walls square on: the left half at ``near`` m, the right half at ``far``."""
    depth = np.full((240, 320), near)
    depth[:, 160:] = far
    return depth


def test_depth_noise_grows_with_distance_as_the_model_says():
    model = DepthModel(dropout=0.0, edge_dropout=0.0)
    depth = depth_image(model, two_walls(), GREY, FOCAL, np.random.default_rng(1))
    near, far = depth[:, :150], depth[:, 170:]
    assert near.std() == pytest.approx(float(axial_sigma(model, np.array(1.0))), rel=0.05)
    assert far.std() == pytest.approx(float(axial_sigma(model, np.array(3.0))), rel=0.05)
    assert far.std() > 5 * near.std()  # a metre's millimetres, three metres' centimetres
    assert abs(near.mean() - 1.0) < 1e-3  # noise, not bias


def test_depth_is_lost_beside_edges_on_dark_things_and_at_grazing_angles():
    model = DepthModel(dropout=0.0)
    rgb = GREY.copy()
    rgb[:40] = 10  # a dark band
    depth = depth_image(model, two_walls(), rgb, FOCAL, np.random.default_rng(2))
    assert (depth[40:, 160] == 0).mean() == pytest.approx(0.5, abs=0.1)  # the far side of the edge
    assert (depth[40:, 159] == 0).mean() < 0.02  # the near side keeps its rim
    assert (depth[:40, :150] == 0).mean() == pytest.approx(0.5, abs=0.05)  # dark
    assert (depth[40:, :150] == 0).mean() == 0.0
    # a floor 1.2 m below a level camera: seen steeper than 80° from its normal where the ray dips below 10°
    rows = np.arange(240) + 0.5 - 120
    floor = np.where(rows > 0, 1.2 * FOCAL / np.maximum(rows, 1e-6), 50.0)[:, None] * np.ones((1, 320))
    depth = depth_image(model, floor, GREY, FOCAL, np.random.default_rng(3))
    dips = np.degrees(np.arctan(rows / FOCAL))
    assert (depth[(dips > 0) & (dips < 8)] == 0).all()
    assert (depth[dips > 20] == 0).mean() < 0.01


def test_depth_rays_keep_their_misses_and_lose_some_hits():
    model = DepthModel(dropout=0.1)
    ranges = np.r_[np.full(5000, 2.0), np.full(100, np.inf)]
    noisy = depth_ranges(model, ranges, np.random.default_rng(4))
    assert np.isinf(noisy[5000:]).all()
    assert np.isinf(noisy[:5000]).mean() == pytest.approx(0.1, abs=0.02)
    kept = noisy[:5000][np.isfinite(noisy[:5000])]
    assert kept.std() == pytest.approx(float(axial_sigma(model, np.array(2.0))), rel=0.1)


def test_colour_frames_have_an_exposure_and_pixel_noise():
    model = ColourModel(noise=2.0, exposure=0.05)
    rng = np.random.default_rng(5)
    frames = [colour_image(model, GREY, rng) for _ in range(20)]
    assert all(f.dtype == np.uint8 and f.shape == GREY.shape for f in frames)
    within = [float(f.astype(float).std()) for f in frames]
    assert np.median(within) == pytest.approx(2.0, abs=0.5)  # pixel noise around the frame's level
    levels = [float(f.mean()) for f in frames]
    assert np.std(levels) > 2.0  # the exposure moves the whole frame: 5 % of 128 is 6 levels
    assert np.array_equal(colour_image(ColourModel(enabled=False), GREY, rng), GREY)


def test_the_scanner_loses_rays_and_blurs_ranges():
    ranges, returned = scanner_ranges(
        RangeModel(noise=0.015, dropout=0.05), np.full(20000, 2.0), np.random.default_rng(6)
    )
    assert ranges.std() == pytest.approx(0.015, rel=0.05)
    assert (~returned).mean() == pytest.approx(0.05, abs=0.01)
    exact, all_back = scanner_ranges(RangeModel(enabled=False), np.full(10, 2.0), np.random.default_rng(6))
    assert np.array_equal(exact, np.full(10, 2.0)) and all_back.all()


def test_encoders_read_whole_counts():
    steps = encoder_steps(EncoderModel(bits=12, linear_resolution=1e-4), np.array([True, False]))
    assert steps == pytest.approx([2 * math.pi / 4096, 1e-4])
    read = quantise(np.array([0.1234567, 0.0123456]), steps)
    assert np.allclose(read / steps, np.rint(read / steps))
    assert np.all(np.abs(read - [0.1234567, 0.0123456]) <= steps / 2 + 1e-12)
    assert encoder_steps(EncoderModel(enabled=False), np.array([True])) is None


def test_the_depth_filter_fills_small_holes_from_the_background():
    model = DepthModel()
    noisy = depth_image(model, two_walls(), GREY, FOCAL, np.random.default_rng(7))
    assert (noisy == 0).any()
    cleaned = cleaned_depth(noisy)
    assert (cleaned[5:-5, 5:-5] > 0).all()  # the holes beside the edge and here and there are filled
    assert np.all(cleaned[:, 160:170] > 2.9)  # with the far wall's depth: the edge does not grow towards the camera
    assert np.all(cleaned[:, 150:159] < 1.1)
    assert (cleaned[:, 159] < 1.1).mean() > 0.95  # the near rim's own losses are taken for background
    beyond = two_walls(far=0.0)  # nothing returns from the right half (beyond the camera's range)
    assert np.all(cleaned_depth(beyond)[:, 160:] == 0)  # wide unknown stays unknown, not the near wall's


def sim_with(monkeypatch, ideal: bool) -> Simulation:
    if ideal:
        monkeypatch.setenv(IDEAL_SENSORS_VARIABLE, "1")
    else:
        monkeypatch.delenv(IDEAL_SENSORS_VARIABLE, raising=False)
    return Simulation.load("apartment", "wheeled_humanoid")


def test_a_simulation_takes_the_robots_models_unless_ideal_sensors_are_asked_for(monkeypatch):
    noisy = sim_with(monkeypatch, ideal=False)
    assert noisy.sensors == noisy.robot.sensors and noisy.sensors.depth.enabled
    ideal = sim_with(monkeypatch, ideal=True)
    assert ideal.sensors == SensorModels.ideal()


def test_each_sensor_has_its_own_stream_and_the_same_seed_gives_the_same_noise(monkeypatch):
    sim = sim_with(monkeypatch, ideal=False)
    sim.reset(3)
    first = sim.random_stream("head_camera.depth").random(4)
    other = sim.random_stream("scanner").random(4)
    sim.reset(3)
    assert np.array_equal(sim.random_stream("head_camera.depth").random(4), first)
    assert not np.array_equal(first, other)
    sim.reset(4)
    assert not np.array_equal(sim.random_stream("head_camera.depth").random(4), first)


def test_the_robots_encoders_count_steps_but_its_base_pose_is_not_an_encoder(monkeypatch):
    from bt_humanoid.sim.robot_io import MujocoRobotIO

    sim = sim_with(monkeypatch, ideal=False)
    sim.set_initial_joint("l_elbow", -0.7000123)
    io = MujocoRobotIO(sim, ["l_elbow", "base_x"])
    step = 2 * math.pi / 2**sim.sensors.encoders.bits
    elbow, base_x = io.positions()
    assert elbow / step == pytest.approx(round(elbow / step), abs=1e-9) and abs(elbow + 0.7000123) <= step / 2
    assert base_x == sim.data.qpos[sim.model.joint("base_x").qposadr[0]]  # localisation's job, not an encoder's


def test_the_imu_reads_with_white_noise(monkeypatch):
    from bt_humanoid.sim.robot_io import MujocoRobotIO

    monkeypatch.delenv(IDEAL_SENSORS_VARIABLE, raising=False)
    sim = Simulation.load("apartment", "biped_humanoid")
    imu = sim.robot.imu
    io = MujocoRobotIO(sim, [])
    gyro = np.array([io.sensor(imu.gyro) - sim.data.sensor(imu.gyro).data for _ in range(2000)])
    assert gyro.std(axis=0) == pytest.approx([sim.sensors.imu.gyro] * 3, rel=0.1)
    touch = sim.robot.legs.left.touch_sensor
    assert np.array_equal(io.sensor(touch), sim.data.sensor(touch).data)  # only the IMU's rates and force are noisy


@pytest.mark.parametrize(
    "block",
    [{"depth": {"axial": [-0.001, 0.0019, 0.4]}}, {"depth": {"enabled": 1}}, {"scanner": {"dropout": 1.5}}],
)
def test_a_sensors_block_with_an_impossible_figure_is_refused(block):
    from pydantic import ValidationError

    with pytest.raises(ValidationError):
        SensorModels.model_validate(block)
