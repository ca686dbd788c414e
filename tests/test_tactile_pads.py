"""Tactile pads: where between the fingers a held thing presses, and a close that stops at the pads' edge."""

import mujoco
import numpy as np
import pytest

from bt_humanoid.control.gripper import MIN_PRESSURE, GripperController
from bt_humanoid.control.motion import MotionHandle, MotionStatus
from bt_humanoid.paths import project_root
from bt_humanoid.sim.robot_config import GripperConfig, load_robot_config

ACROSS = [-0.0196, -0.0088, 0.0, 0.0088, 0.0196]  # m: the taxels' middles across a pad (upper_body.xml)


class FakeIO:
    """Five taxels on each of two pads, with forces the test sets; fingers standing 3 cm open each."""

    def __init__(self) -> None:
        self.forces: dict[str, float] = {}
        self.time = 0.0

    def sensors_named(self, prefix: str) -> list[str]:
        return [f"{prefix}{i}" for i in range(len(ACROSS))]

    def sensor_offset(self, name: str) -> np.ndarray:
        return np.array([0.008, ACROSS[int(name[-1])], -0.06])

    def sensor(self, name: str) -> np.ndarray:
        return np.array([self.forces.get(name, 0.0)])

    def positions(self) -> np.ndarray:
        return np.array([0.03, 0.03])

    def velocities(self) -> np.ndarray:
        return np.array([-0.05, -0.05])  # still closing


class FakeJoints:
    def __init__(self) -> None:
        self.io = FakeIO()
        self.moves: list[dict[str, float]] = []

    def indices(self, joints: list[str]) -> np.ndarray:
        return np.arange(len(joints))

    def move(self, targets: dict[str, float], settle_check: bool = True) -> MotionHandle:
        self.moves.append(targets)
        return MotionHandle("moving the fingers")


@pytest.fixture
def hand() -> tuple[GripperController, FakeJoints]:
    joints = FakeJoints()
    config = GripperConfig(
        joints=["finger_a", "finger_b"], open=0.065, closed=0.0, grip_site="grip", tactile_pads=["pad_a", "pad_b"]
    )
    return GripperController(joints, {"right": config}), joints  # type: ignore[arg-type]


def test_the_pressure_centre_is_where_the_taxels_feel_the_force_weighted_by_it(hand):
    gripper, joints = hand
    joints.io.forces = {"pad_a_taxel4": 6.0, "pad_b_taxel3": 2.0}
    assert gripper.pressure_centre("right") == pytest.approx((6.0 * 0.0196 + 2.0 * 0.0088) / 8.0)
    joints.io.forces = {"pad_a_taxel4": 5.0, "pad_b_taxel0": 5.0}  # a box held across: one corner on each side
    assert gripper.pressure_centre("right") == pytest.approx(0.0)


def test_pads_that_feel_next_to_nothing_say_nothing_of_where_a_thing_sits(hand):
    gripper, joints = hand
    assert gripper.pressure_centre("right") is None
    joints.io.forces = {"pad_a_taxel4": MIN_PRESSURE / 2}
    assert gripper.pressure_centre("right") is None


def test_a_close_told_the_pads_edge_stops_where_the_fingers_are_and_fails_when_felt_beyond_it(hand):
    gripper, joints = hand
    handle = gripper.grasp("right", edge=0.012)
    joints.io.forces = {"pad_a_taxel2": 1.0}  # at the middle: closing goes on
    gripper.step()
    assert not handle.done
    joints.io.forces = {"pad_a_taxel0": 1.0}
    gripper.step()
    assert handle.status is MotionStatus.FAILED and "2.0 cm off their middle" in handle.result
    assert joints.moves[-1] == {"finger_a": 0.03, "finger_b": 0.03}, "held where they stood, not squeezed on"


def test_a_close_without_an_edge_goes_on_whatever_the_pads_feel(hand):
    gripper, joints = hand
    handle = gripper.grasp("right")
    joints.io.forces = {"pad_a_taxel0": 1.0}
    gripper.step()
    assert not handle.done


@pytest.mark.parametrize("robot", ["wheeled_humanoid", "biped_humanoid"])
def test_each_pad_s_taxels_lie_in_order_across_its_whole_width_without_gaps(robot: str):
    model = mujoco.MjModel.from_xml_path(str(project_root() / "robots" / robot / "scene.xml"))
    for gripper in load_robot_config(robot).grippers.values():
        assert len(gripper.tactile_pads) == 2
        for pad in gripper.tactile_pads:
            geom = model.geom(pad)
            sites = [model.site(f"{pad}_taxel{i}") for i in range(5)]
            assert all(model.site_bodyid[site.id] == geom.bodyid for site in sites), "on the pad's finger"
            low = [float(s.pos[1] - s.size[1]) for s in sites]
            high = [float(s.pos[1] + s.size[1]) for s in sites]
            assert low == sorted(low) and all(np.isclose(high[i], low[i + 1]) for i in range(4)), "no gaps"
            assert low[0] <= geom.pos[1] - geom.size[1] and high[-1] >= geom.pos[1] + geom.size[1]
            for site in sites:  # deep and tall enough to take in the pad's face
                assert abs(site.pos[0] - geom.pos[0]) + geom.size[0] <= site.size[0] + 1e-9
                assert site.size[2] >= geom.size[2]
            touch = [model.sensor(f"{pad}_taxel{i}") for i in range(5)]
            assert all(s.type == mujoco.mjtSensor.mjSENS_TOUCH for s in touch)
