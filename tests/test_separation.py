"""Speed and separation monitoring: the base slows, then stops, near people and things the scanner sees."""

import math

import numpy as np
import pytest

from bt_humanoid.safety.separation import HAND_RADIUS, SpeedAndSeparation
from bt_humanoid.sim.ground_truth import GroundTruth
from bt_humanoid.sim.robot_config import SafetyDefaults
from bt_humanoid.testing.scenario import build_run

SETTINGS = SafetyDefaults(slow_distance=1.0, stop_distance=0.2)
FOOTPRINT, MAX_SPEED = 0.3, 0.8


class FixedScanner:
    """A scanner that always sees the same points."""

    def __init__(self, points: list[tuple[float, float]]) -> None:
        self.points = np.array(points, dtype=float).reshape(-1, 2)

    def scan(self) -> np.ndarray:
        return self.points


def monitor(points, furniture=False, hands=(), people=()) -> SpeedAndSeparation:
    separation = SpeedAndSeparation(
        FixedScanner(points),
        SETTINGS,
        FOOTPRINT,
        MAX_SPEED,
        furniture=lambda p: np.full(len(p), furniture),
        people=lambda: [np.array(p) for p in people],
        hands=lambda: [np.array(h) for h in hands],
    )
    separation.update(np.zeros(3))
    return separation


def test_nothing_near_allows_full_speed():
    assert monitor([(3.0, 0.0)]).share(np.array([0.8, 0.0, 0.0])) == 1.0
    assert monitor([]).share(np.array([0.8, 0.0, 1.0])) == 1.0


def test_closing_speed_falls_with_distance_and_stops_in_the_stop_zone():
    gap = 0.6  # midway through the slow zone: half the top speed towards it
    separation = monitor([(FOOTPRINT + gap, 0.0)])
    assert separation.zone == "slow"
    assert separation.share(np.array([0.8, 0.0, 0.0])) == pytest.approx(0.5)
    assert separation.share(np.array([0.2, 0.0, 0.0])) == 1.0  # slow enough already
    stopped = monitor([(FOOTPRINT + 0.1, 0.0)])
    assert stopped.zone == "stop"
    assert stopped.share(np.array([0.3, 0.0, 0.0])) == 0.0


def test_moving_away_or_sideways_is_allowed_in_the_stop_zone():
    separation = monitor([(FOOTPRINT + 0.1, 0.0)])
    assert separation.share(np.array([-0.5, 0.0, 0.0])) == 1.0
    assert separation.share(np.array([0.0, 0.5, 0.0])) == 1.0
    assert separation.share(np.array([0.0, 0.0, 1.0])) == 1.0  # the round base turns in place, arms tucked


def test_a_hand_that_reaches_out_counts_and_turning_sweeps_it():
    separation = monitor([(0.6, 0.6)], hands=[(0.6, 0.0, 1.0)])  # 0.6 m beside the hand, far from the base
    assert separation.distance == pytest.approx(0.54)
    allowed = MAX_SPEED * (0.54 - 0.2) / (1.0 - 0.2)
    assert separation.share(np.array([0.0, 0.0, 1.0])) == pytest.approx(allowed / 0.6)  # the hand swings at it
    assert separation.share(np.array([0.0, 0.0, -1.0])) == 1.0  # away from it
    separation = monitor([(0.6, 0.2)], hands=[(0.6, 0.0, 1.0)])
    assert separation.zone == "stop"
    assert separation.share(np.array([0.0, 0.0, 1.0])) == 0.0
    assert separation.share(np.array([0.0, 0.0, -1.0])) == 1.0


def test_furniture_is_muted_but_people_on_the_map_are_not():
    near = [(FOOTPRINT + 0.1, 0.0)]
    assert monitor(near, furniture=True).distance == math.inf
    assert monitor(near, furniture=True, people=[(FOOTPRINT + 0.2, 0.0)]).zone == "stop"


# --- in the simulation --------------------------------------------------------------------------------------------

TOWARDS_PERSON = (0.5, -2.0, -90.0)  # 1.7 m north of the person standing in the living room, facing them


@pytest.mark.sim
def test_driving_at_a_person_stops_short_and_the_motion_fails_held():
    """A relative move does not steer round people: the separation monitor stops it before the person."""
    mission = {"mission": "at person", "tree": {"move_base": {"x": 2.5, "y": 0.0, "relative": True}}}
    run = build_run(mission, robot_start=TOWARDS_PERSON)
    truth = GroundTruth(run.sim)
    touched = []
    run.executor.observers.append(lambda: touched.extend(c for c in truth.robot_contacts() if "person" in c[1]))
    result = run.execute()
    assert result.tree_status == "FAILURE"
    assert "protective stop" in result.cause
    assert not touched
    # the nearest part of the robot (a hand, in the home posture) crept up to the stop zone's edge
    legs = truth.person_position("person")[:2]
    model, data = run.sim.model, run.sim.data
    hands = [data.site_xpos[model.site(g.grip_site).id][:2] for g in run.context.robot_config.grippers.values()]
    gap = min(float(np.hypot(*(hand - legs))) for hand in hands) - HAND_RADIUS - 0.14  # leg capsule radius
    assert SETTINGS.stop_distance - 0.03 < gap < SETTINGS.stop_distance + 0.05
    zones = [e["zone"] for e in result.events.events if e["event"] == "separation"]
    assert zones[0] == "slow"
    assert run.robot.at_rest()


@pytest.mark.sim
def test_a_robot_held_close_to_a_person_may_back_away():
    start = (0.5, -3.7 + 0.32 + 0.14 + 0.1, -90.0)  # 0.1 m from the person's legs, facing them
    mission = {"mission": "back off", "tree": {"move_base": {"x": -1.0, "y": 0.0, "relative": True}}}
    run = build_run(mission, robot_start=start)
    result = run.execute()
    assert result.success, result.cause
    assert GroundTruth(run.sim).robot_pose()[1] == pytest.approx(start[1] + 1.0, abs=0.05)
