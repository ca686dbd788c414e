"""Localisation: odometry drifts, the scan matcher lays scans onto the map, the filter keeps the belief close and
notices when the robot was moved or no longer knows where it is."""

import math
import statistics

import numpy as np
import pytest

from bt_humanoid.benchmarks.navigation import run_one
from bt_humanoid.engine.stack import RobotStack
from bt_humanoid.localisation.frames import place_on_map
from bt_humanoid.localisation.localiser import LOST_AFTER, Localiser, search_map
from bt_humanoid.localisation.odometry import WheelOdometry, apply_increment, body_increment
from bt_humanoid.localisation.scan_map import ScanMap
from bt_humanoid.localisation.scan_matcher import match_scan, transform
from bt_humanoid.safety.monitors import LostMonitor
from bt_humanoid.sim.sensor_models import IDEAL_SENSORS_VARIABLE, OdometryModel

RESOLUTION = 0.01
ROOM = (6.0, 4.0)  # m: walls round it, a cupboard in one corner and a pillar: no two places look alike


def room() -> ScanMap:
    cols, rows = round(ROOM[0] / RESOLUTION), round(ROOM[1] / RESOLUTION)
    pad = 20
    occupied = np.ones((rows + 2 * pad, cols + 2 * pad), dtype=bool)
    occupied[pad:-pad, pad:-pad] = False

    def solid(x0: float, y0: float, x1: float, y1: float) -> None:
        occupied[
            pad + round(y0 / RESOLUTION) : pad + round(y1 / RESOLUTION),
            pad + round(x0 / RESOLUTION) : pad + round(x1 / RESOLUTION),
        ] = True

    solid(4.8, 2.9, 6.0, 4.0)  # cupboard
    solid(1.5, 1.0, 1.7, 1.2)  # pillar
    return ScanMap(occupied, np.array([-pad * RESOLUTION] * 2), RESOLUTION)


def scan_from(scan_map: ScanMap, pose: np.ndarray, rays: int = 180, reach: float = 4.0) -> np.ndarray:
    """The scanner-frame points a scanner at ``pose`` sees of the map's solid cells (ray-marched)."""
    angles = np.linspace(0.0, 2 * math.pi, rays, endpoint=False)
    steps = np.arange(0.05, reach, RESOLUTION / 2)
    local = np.stack([np.cos(angles)[:, None] * steps, np.sin(angles)[:, None] * steps], axis=-1)
    world = transform(local.reshape(-1, 2), pose).reshape(rays, len(steps), 2)
    cells = np.floor((world - scan_map.origin) / scan_map.resolution).astype(int)
    solid = scan_map.occupied[
        np.clip(cells[..., 1], 0, scan_map.occupied.shape[0] - 1),
        np.clip(cells[..., 0], 0, scan_map.occupied.shape[1] - 1),
    ]
    hit = solid.any(axis=1)
    first = solid.argmax(axis=1)
    return local[np.arange(rays)[hit], first[hit]]


def test_the_scan_matcher_finds_the_pose_from_a_guess_off_by_decimetres():
    scan_map = room()
    truth = np.array([2.5, 2.0, 0.3])
    points = scan_from(scan_map, truth)
    rng = np.random.default_rng(1)
    for _ in range(10):
        guess = truth + np.array([*rng.normal(0, 0.12, 2), rng.normal(0, math.radians(4))])
        match = match_scan(scan_map, points + rng.normal(0, 0.015, points.shape), guess)
        assert np.hypot(*(match.pose[:2] - truth[:2])) < 0.01
        assert abs(match.pose[2] - truth[2]) < math.radians(0.5)
        assert match.fraction > 0.95


def test_points_not_on_the_map_do_not_pull_the_match():
    scan_map = room()
    truth = np.array([3.0, 1.5, -0.4])
    points = scan_from(scan_map, truth)
    person = np.array([[0.6 + 0.1 * math.cos(a), 0.2 + 0.1 * math.sin(a)] for a in np.linspace(0, math.pi, 30)])
    match = match_scan(scan_map, np.vstack([points, person]), truth + np.array([0.08, -0.05, 0.03]))
    assert np.hypot(*(match.pose[:2] - truth[:2])) < 0.01
    assert match.inliers <= len(points) + 2  # the person's points are not counted as on the map


def test_a_corridor_leaves_the_match_uncertain_along_it():
    cols, rows, pad = 600, 100, 20  # 6 m by 1 m, nothing along it
    occupied = np.ones((rows + 2 * pad, cols + 2 * pad), dtype=bool)
    occupied[pad:-pad, pad:-pad] = False
    corridor = ScanMap(occupied, np.array([-pad * RESOLUTION] * 2), RESOLUTION)
    truth = np.array([3.0, 0.5, 0.0])
    match = match_scan(corridor, scan_from(corridor, truth, reach=1.5), truth)
    along, across = match.covariance[0, 0], match.covariance[1, 1]
    assert along > 100 * across  # the walls say where across the corridor, nothing says where along it


def test_odometry_reports_the_motion_with_a_scale_error_drawn_per_run():
    truth = body_increment(np.array([0.0, 0.0, 0.0]), np.array([0.01, 0.0, 0.0]))
    assert truth == pytest.approx([0.01, 0.0, 0.0])
    exact = WheelOdometry(OdometryModel(enabled=False), np.random.default_rng(0))
    assert exact.measure(truth) == pytest.approx(truth)
    worn = WheelOdometry(OdometryModel(scale=0.05, noise=0.0, yaw_noise=0.0), np.random.default_rng(0))
    assert worn.measure(truth)[0] == pytest.approx(0.01 * worn.scale[0])
    assert abs(worn.scale[0] - 1.0) > 1e-4
    # increments compose back into the path
    pose = np.array([1.0, 2.0, 0.5])
    moved = apply_increment(pose, body_increment(pose, np.array([1.3, 2.1, 0.7])))
    assert moved == pytest.approx([1.3, 2.1, 0.7])


def drive(localiser: Localiser, odometry: WheelOdometry, scan_map: ScanMap, path: np.ndarray, scans: bool) -> float:
    """Drive ``path`` (poses, one per 10 ms); the worst belief error (m)."""
    worst = 0.0
    for k in range(1, len(path)):
        localiser.predict(odometry.measure(body_increment(path[k - 1], path[k])))
        if scans and k % 10 == 0:
            localiser.correct(scan_from(scan_map, path[k]), k * 0.01)
        worst = max(worst, float(np.hypot(*(localiser.pose[:2] - path[k][:2]))))
    return worst


def test_the_filter_keeps_the_belief_where_odometry_alone_drifts_off():
    scan_map = room()
    t = np.linspace(0.0, 1.0, 1500)  # 15 s round a loop
    path = np.stack(
        [3.0 + 1.5 * np.cos(2 * math.pi * t), 2.0 + 0.9 * np.sin(2 * math.pi * t), 2 * math.pi * t + 0.5], axis=1
    )
    model = OdometryModel()  # scale errors of σ 2 %: this draw's are 4.1 %, 5.1 % and 0.8 %

    def fresh() -> tuple[Localiser, WheelOdometry]:
        return Localiser(scan_map, path[0]), WheelOdometry(model, np.random.default_rng(3))

    dead_reckoning = drive(*fresh(), scan_map, path, scans=False)
    localised = drive(*fresh(), scan_map, path, scans=True)
    assert dead_reckoning > 0.1
    assert localised < 0.03


def test_a_robot_carried_elsewhere_finds_its_place_again():
    scan_map = room()
    events: list[str] = []
    localiser = Localiser(scan_map, np.array([1.0, 3.0, 0.0]), on_event=lambda kind, _: events.append(kind))
    elsewhere = np.array([4.0, 1.0, 2.0])  # picked up and put down: the wheels felt nothing
    points = scan_from(scan_map, elsewhere)
    for k in range(round((LOST_AFTER + 1.0) / 0.1)):
        localiser.correct(points, 0.1 * k)
    assert np.hypot(*(localiser.pose[:2] - elsewhere[:2])) < 0.02
    assert abs(math.remainder(localiser.pose[2] - elsewhere[2], 2 * math.pi)) < math.radians(1)
    assert "relocalised" in events and not localiser.lost


def test_a_scan_that_fits_nowhere_leaves_the_robot_lost():
    scan_map = room()
    events: list[str] = []
    localiser = Localiser(scan_map, np.array([2.0, 2.0, 0.0]), on_event=lambda kind, _: events.append(kind))
    angles = np.linspace(0, 2 * math.pi, 120, endpoint=False)
    circle = np.stack([0.4 * np.cos(angles), 0.4 * np.sin(angles)], axis=1)  # boxed in by people: no map in sight
    for k in range(round((LOST_AFTER + 0.5) / 0.1)):
        localiser.correct(circle, 0.1 * k)
    assert localiser.lost and events == ["lost"]
    assert search_map(scan_map, circle) is None


def test_a_sensor_pose_is_placed_on_the_map_relative_to_the_believed_base():
    truth, belief = np.array([2.0, 1.0, 0.0]), np.array([2.1, 0.9, math.pi / 2])
    ahead = np.array([3.0, 1.0, 1.2])  # a camera 1 m ahead of the base, 1.2 m up, looking along x
    position, rotation = place_on_map(ahead, np.eye(3), truth, belief)
    assert position == pytest.approx([2.1, 1.9, 1.2])  # 1 m ahead of where the robot believes it is, facing +y
    assert rotation @ np.array([1.0, 0.0, 0.0]) == pytest.approx([0.0, 1.0, 0.0])


def test_exact_sensors_leave_the_base_pose_exact(monkeypatch):
    monkeypatch.setenv(IDEAL_SENSORS_VARIABLE, "1")
    for robot in ("wheeled_humanoid", "biped_humanoid"):
        stack = RobotStack.load("apartment", robot)
        stack.close()
        assert stack.robot.localisation is None


@pytest.mark.sim
def test_the_wheeled_base_drives_on_its_belief_and_keeps_it_within_centimetres():
    outcome = run_one((4.67, 2.06, 16.0), "shelf")  # across the apartment
    assert outcome.success, outcome.failure
    assert max(outcome.localisation_errors) < 0.06
    assert statistics.median(outcome.localisation_errors) < 0.02


def test_a_lost_robot_stops_its_mission_and_says_what_would_help():
    stack = RobotStack.load("apartment", "wheeled_humanoid")
    stack.close()
    localisation = stack.robot.localisation
    assert localisation is not None
    monitor = LostMonitor(localisation)
    assert monitor.check(0.0) is None
    localisation.localiser.lost = True
    assert "do not know where I am" in (monitor.check(0.0) or "")
