"""Grasping every kitchen shape: the grasp chosen from the believed shape (unit), and picks, places and drops
on real physics judged in ground truth."""

import math
from types import SimpleNamespace

import mujoco
import numpy as np
import pytest

from bt_humanoid.benchmarks.kitchen_manipulation import Kitchen, Outcome, Trial, mission_of, scene_of, summarize, table
from bt_humanoid.cli import validate_main
from bt_humanoid.control.grasping import (
    HOLD_DEPTH,
    OPENING_MARGIN,
    PAD_HALF_HEIGHT,
    PALM_ABOVE_GRIP,
    STOPPED_PAD_CLEARANCE,
    GraspError,
    hand_yaws,
    plan_grasp,
)
from bt_humanoid.control.wbc.limits import BaseBoundsLimit, JointRangeLimit
from bt_humanoid.engine.runner import MissionRun
from bt_humanoid.perception.world_model import TrackedObject
from bt_humanoid.sim.simulation import Simulation
from bt_humanoid.testing.scenario import Scenario, load_mission
from bt_humanoid.testing.told import told_objects, told_stack

OPENING = 0.13  # m between the open pads of the wheeled humanoid's grippers
TABLE = 0.75  # m: the kitchen table's top


def _thing(kind: str, size: tuple[float, float, float], yaw: float = 0.0, name: str = "thing") -> TrackedObject:
    return TrackedObject(
        id=name,
        name=name,
        kind=kind,
        colour="red",
        position=np.array([1.0, 0.0, TABLE + size[2] / 2]),
        yaw=yaw,
        size=np.array(size),
    )


def _turn(a: float, b: float) -> float:
    return abs(math.remainder(a - b, math.tau))


@pytest.mark.parametrize("bag_yaw", [0.0, 0.4, 1.2, -2.0, math.pi / 2])
def test_a_bag_of_chips_is_taken_across_its_narrow_side_whichever_way_it_stands(bag_yaw):
    bag = _thing("bag", (0.12, 0.05, 0.16), yaw=bag_yaw)
    grasp = plan_grasp(bag, TABLE, 0.1, OPENING)
    assert grasp.width == pytest.approx(0.05)
    # the fingers close along the bag's narrow side (its y): the hand turned a right angle from the bag
    assert _turn(grasp.yaw, bag_yaw + math.pi / 2) < 1e-9 or _turn(grasp.yaw, bag_yaw - math.pi / 2) < 1e-9
    # and of the two such yaws, the one nearer the hand's
    other = grasp.yaw + math.pi
    assert _turn(grasp.yaw, 0.1) <= _turn(other, 0.1)


def test_of_the_yaws_that_fit_the_nearest_to_the_hand_wins():
    cube = _thing("cube", (0.05, 0.05, 0.05), yaw=0.3)
    assert plan_grasp(cube, TABLE, 0.0, OPENING).yaw == pytest.approx(0.3)
    assert plan_grasp(cube, TABLE, 1.2, OPENING).yaw == pytest.approx(0.3 + math.pi / 2)
    # both ways fit the sponge, but its 9.5 cm leaves the pads little slack: its 6.5 cm, even at a yaw further off
    sponge = _thing("sponge", (0.095, 0.065, 0.03), yaw=0.0)
    assert plan_grasp(sponge, TABLE, 0.2, OPENING).width == pytest.approx(0.065)
    assert plan_grasp(sponge, TABLE, 1.3, OPENING).width == pytest.approx(0.065)
    wide = _thing("box", (0.095, 0.094, 0.05), yaw=0.0)  # no roomy way: the nearer yaw of the two that fit
    assert plan_grasp(wide, TABLE, 0.2, OPENING).width == pytest.approx(0.095)


def test_a_width_fits_only_with_slack_on_both_sides():
    assert OPENING - OPENING_MARGIN < 0.12  # a bag's long side would leave a pad under a centimetre from its face
    box = _thing("box", (0.12, 0.12, 0.05))
    with pytest.raises(GraspError, match=r"12\.0 cm across at its narrowest; the gripper opens 13 cm"):
        plan_grasp(box, TABLE, 0.0, OPENING)


def test_round_things_are_closed_on_at_the_hands_own_yaw():
    for kind in ("can", "bottle", "ball", "fruit"):
        thing = _thing(kind, (0.066, 0.066, 0.122), yaw=1.0)
        grasp = plan_grasp(thing, TABLE, -0.4, OPENING)
        assert grasp.yaw == pytest.approx(-0.4) and grasp.width == pytest.approx(0.066), kind


def test_a_mug_is_closed_on_across_its_body_at_right_angles_to_the_handle():
    mug = _thing("mug", (0.11, 0.08, 0.09), yaw=0.0)  # the handle sticks out along x
    options = hand_yaws(mug, 0.0)
    assert all(_turn(yaw, math.pi / 2) < 1e-9 or _turn(yaw, -math.pi / 2) < 1e-9 for yaw, _ in options)
    assert plan_grasp(mug, TABLE, 0.0, OPENING).width == pytest.approx(0.08)


def test_an_unknown_kind_is_held_as_the_box_its_extents_describe():
    brick = _thing("brick", (0.2, 0.06, 0.05), yaw=0.0)
    grasp = plan_grasp(brick, TABLE, 0.1, OPENING)
    assert grasp.width == pytest.approx(0.06) and _turn(grasp.yaw, math.pi / 2) < 1e-9


@pytest.mark.parametrize("kind, size", [("bar", (0.13, 0.045, 0.022)), ("sponge", (0.095, 0.065, 0.03))])
def test_a_flat_thing_is_held_with_the_pads_just_above_the_surface(kind, size):
    flat = _thing(kind, size)
    grasp = plan_grasp(flat, TABLE, 0.0, OPENING)
    pads_bottom = grasp.position[2] - PAD_HALF_HEIGHT
    assert TABLE + 0.003 <= pads_bottom <= TABLE + 0.01  # close to the surface, never on it
    assert flat.top - pads_bottom >= 0.01  # the pads close on a centimetre of its sides at least
    assert grasp.position[2] > flat.top  # the grip site above the thing: it is lower than the pads are tall


def test_a_thing_too_flat_for_the_pads_is_refused():
    card = _thing("card", (0.09, 0.06, 0.004))
    with pytest.raises(GraspError, match="too flat"):
        plan_grasp(card, TABLE, 0.0, OPENING)


def test_tall_things_are_held_high_with_the_palm_clear_of_their_top():
    bag = _thing("bag", (0.12, 0.05, 0.16))
    grasp = plan_grasp(bag, TABLE, 0.0, OPENING)
    assert grasp.position[2] + PALM_ABOVE_GRIP > bag.top  # the palm stays above the bag
    assert grasp.position[2] > bag.position[2]  # held above its middle


def test_an_apple_is_held_at_its_widest():
    apple = _thing("fruit", (0.076, 0.076, 0.076))
    grasp = plan_grasp(apple, TABLE, 0.0, OPENING)
    assert abs(grasp.position[2] - apple.position[2]) < 0.005  # the pads close on the equator


def test_every_kitchen_object_has_a_grasp_from_the_natural_hand_yaw_at_any_turn():
    sim = Simulation.load("kitchen", "wheeled_humanoid")
    things = told_objects(sim)
    assert len(things) == 16
    for thing in things:
        for yaw in np.linspace(-math.pi, math.pi, 13):
            thing.yaw = float(yaw)
            grasp = plan_grasp(thing, thing.bottom, 0.0, OPENING)
            assert grasp.width <= OPENING - OPENING_MARGIN, thing.name
            assert grasp.position[2] - PAD_HALF_HEIGHT > thing.bottom, thing.name  # pads above the surface


def _finger_touches_forearm(sim: Simulation, wrist_pitch: float, opening: float) -> bool:
    """Posed (no physics step): does a finger of the right hand, opened ``opening`` each, touch its forearm?"""
    model, data = sim.model, sim.data
    for joint, value in {"r_wrist_pitch": wrist_pitch, "r_finger_a": opening, "r_finger_b": opening}.items():
        data.qpos[model.joint(joint).qposadr[0]] = value
    mujoco.mj_forward(model, data)
    forearm = model.body("r_forearm").id
    fingers = {model.body("r_finger_a").id, model.body("r_finger_b").id}
    pairs = ({model.geom_bodyid[c.geom1], model.geom_bodyid[c.geom2]} for c in data.contact[: data.ncon])
    return any(forearm in pair and pair & fingers for pair in pairs)


def test_within_the_grippers_open_range_the_fingers_open_wide_clear_of_the_forearm():
    sim = Simulation.load("kitchen", "wheeled_humanoid")
    gripper = sim.robot.grippers["right"]
    low, high = gripper.open_range["r_wrist_pitch"]
    ready = sim.robot.postures["ready"]
    for joint in ("torso_lift", "r_shoulder_pitch", "r_shoulder_roll", "r_elbow", "r_wrist_roll", "r_wrist_yaw"):
        sim.data.qpos[sim.model.joint(joint).qposadr[0]] = ready[joint]
    assert low <= ready["r_wrist_pitch"] <= high  # grasps start inside it
    assert not _finger_touches_forearm(sim, high, gripper.open)
    assert _finger_touches_forearm(sim, high + 0.1, gripper.open)  # beyond it the fingers jam on the forearm


def test_a_joint_range_limit_holds_a_joint_inside_and_brings_one_outside_back():
    kinematics = SimpleNamespace(joints=["a", "r_wrist_pitch"], positions=np.array([0.0, 1.6]))
    limit = JointRangeLimit({"r_wrist_pitch": (-2.0, 1.7)}, gain=0.5)
    inside = limit.inequality(kinematics, 0.01)
    step_up = np.array([0.0, 0.06])  # to 1.66: more than half the 0.1 rad of slack
    assert np.all(inside.G @ np.array([0.0, 0.04]) >= inside.lower) and not np.all(inside.G @ step_up >= inside.lower)
    kinematics.positions = np.array([0.0, 1.8])  # started outside (the old ready posture)
    outside = limit.inequality(kinematics, 0.01)
    assert not np.all(outside.G @ np.zeros(2) >= outside.lower)  # holding still is not allowed
    assert np.all(outside.G @ np.array([0.0, -0.001]) >= outside.lower)  # coming back in is


def test_a_bounds_limit_keeps_the_base_off_the_walls():
    base = SimpleNamespace(translation=np.array([7.1, 0.0, 0.0]))
    jacobian = np.zeros((6, 3))
    jacobian[0, 0] = jacobian[1, 1] = 1.0  # the base's x and y joints move it straight
    kinematics = SimpleNamespace(
        joints=["x", "y", "yaw"],
        position=lambda _: base.translation,
        jacobian=lambda _: jacobian,
        parameter=lambda read, shape, moving=False: np.asarray(read()),  # numbers, as RobotKinematics gives them
    )
    limit = BaseBoundsLimit("base", np.array([[-1.5, -3.5], [7.5, 3.8]]), radius=0.35)
    near = limit.inequality(kinematics, 0.01)  # 0.4 m from the east wall: only it is near enough to count
    assert np.isfinite(near.lower).sum() == 1  # the other walls' rows hold no bound
    assert np.all(near.G @ np.array([0.02, 0.0, 0.0]) >= near.lower)  # half the 5 cm of slack may go
    assert not np.all(near.G @ np.array([0.03, 0.0, 0.0]) >= near.lower)
    base.translation = np.array([7.2, 0.0, 0.0])  # 0.3 m: too close, it must move away
    close = limit.inequality(kinematics, 0.01)
    assert not np.all(close.G @ np.zeros(3) >= close.lower)
    assert np.all(close.G @ np.array([-0.001, 0.0, 0.0]) >= close.lower)


# --------------------------------------------------------------------------- on real physics, told where things are

TILTED = math.radians(15.0)  # what counts as knocked over
FLUNG = math.sqrt(2 * 9.81 * 0.01)  # m/s: faster than a fall of 1 cm (put lets go 5 mm above the surface)


@pytest.fixture(scope="module")
def kitchen():
    return Kitchen.load()


def _run(kitchen, trial, success=()):
    """Run a benchmark trial's mission with the object alone in the kitchen; also the object's worst tilt (rad)
    and its fastest speed while out of the hand, sampled every control period."""
    stack = told_stack(kitchen.world, kitchen.robot, scene=scene_of(kitchen, trial))
    run = MissionRun(stack, load_mission({**mission_of(trial), "success": list(success)}))
    body = run.sim.model.body(run.sim.object_bodies[trial.object]).id
    worst = {"tilt": 0.0, "loose_speed": 0.0}

    def watch() -> None:
        up = run.sim.data.xmat[body].reshape(3, 3)[2, 2]
        worst["tilt"] = max(worst["tilt"], math.acos(float(np.clip(up, -1.0, 1.0))))
        if run.truth.in_hand(trial.object) is None:
            worst["loose_speed"] = max(worst["loose_speed"], run.truth.object_speed(trial.object))

    run.executor.observers.append(watch)
    try:
        return Scenario(run, run.execute()), worst
    finally:
        stack.close()


# one of each new shape, on each surface, turned away from the hand's natural yaw
PLACES = {
    # a bag of chips (40 g, 16 cm tall) turned 29° on the close counter: taken across its 5 cm, kept standing
    "kettle chips": ("close_counter", (2.40, 3.30), 0.5, (2.22, 2.43, 90.0), (2.70, 3.30)),
    # the energy bar lying flat (2.2 cm) on the far counter, turned 69°: the pads come down beside it
    "energy bar": ("far_counter", (7.05, 0.30), 1.2, (6.13, 0.48, 0.0), (7.05, -0.10)),
    # the sponge (15 g) on the table, turned -40°
    "sponge": ("table", (2.85, -1.20), -0.7, (1.93, -1.02, 0.0), (2.85, -1.45)),
    # the apple, a sphere: closed on at its widest, put down without rolling off the spot
    "apple": ("table", (2.90, -1.45), 0.0, (1.93, -1.27, 0.0), (2.90, -1.15)),
}


@pytest.mark.sim
@pytest.mark.parametrize("name", list(PLACES))
def test_each_new_shape_is_picked_and_placed_on_the_spot_without_being_knocked_over(kitchen, name):
    surface, spot, yaw, start, place = PLACES[name]
    trial = Trial(name, "place", surface, spot, yaw, start, place)
    scenario, worst = _run(kitchen, trial, success=[{"on": [name, surface]}])
    assert scenario.result.success, scenario.result.summary()
    assert scenario.statuses("sequence[0].pick")[-1] == "SUCCESS"
    x, y, _ = scenario.truth.object_position(name)
    assert np.hypot(x - place[0], y - place[1]) < 0.03
    assert scenario.truth.in_hand(name) is None
    if kitchen.world.objects[name].upright:  # stood upright all along: never pushed askew, never tipped
        assert worst["tilt"] < math.radians(5.0), f"tilted {math.degrees(worst['tilt']):.1f}°"
    else:  # lying things stay lying flat
        assert worst["tilt"] < TILTED, f"tilted {math.degrees(worst['tilt']):.1f}°"
    assert worst["loose_speed"] < FLUNG, f"out of the hand at {worst['loose_speed']:.2f} m/s: flung"


@pytest.mark.sim
@pytest.mark.parametrize(
    "name, bin_, surface, spot, start",
    [
        ("sponge", "trash_can", "close_counter", (2.90, 3.30), (2.72, 2.43, 90.0)),  # the lightest thing, 15 g
        ("apple", "compost_bin", "table", (2.85, -1.20), (1.93, -1.02, 0.0)),  # round: it could roll out
    ],
)
def test_throw_away_drops_the_object_into_the_bin_and_the_hand_is_empty(kitchen, name, bin_, surface, spot, start):
    trial = Trial(name, "throw", surface, spot, 0.3, start, into=bin_)
    scenario, _ = _run(kitchen, trial, success=[{"inside": [name, bin_]}])
    assert scenario.result.success, scenario.result.summary()
    assert scenario.truth.inside(name, bin_) and scenario.truth.in_hand(name) is None
    believed = scenario.run.context.world_model
    assert believed.held("right") is None  # the belief's hand is empty too, and the object in the bin
    (x0, y0), (x1, y1) = kitchen.world.containers[bin_].opening
    position = next(o for o in believed.objects.values() if o.name == name).position
    assert x0 <= position[0] <= x1 and y0 <= position[1] <= y1


# --------------------------------------------------------------------------- drop and inside: checked before running


def _validate(tmp_path, capsys, text: str) -> tuple[int, str]:
    path = tmp_path / "m.yaml"
    path.write_text(text)
    code = validate_main([str(path)])
    return code, capsys.readouterr().err.strip()


def test_a_drop_into_something_that_is_no_bin_is_refused_naming_the_bins(tmp_path, capsys):
    text = "mission: x\nworld: kitchen\ntree:\n  sequence:\n    - pick: {object: coke}\n    - drop: {into: fridge}\n"
    code, err = _validate(tmp_path, capsys, text)
    assert code == 2
    assert "m.yaml:6" in err and "unknown container 'fridge'" in err
    assert "trash_can" in err and "recycling_bin" in err and "compost_bin" in err


def test_an_inside_condition_names_an_object_of_the_run_and_a_bin(tmp_path, capsys):
    head = "mission: x\nworld: kitchen\ntree: {throw_away: {object: coke, into: trash_can}}\nsuccess:\n"
    assert _validate(tmp_path, capsys, head + "  - inside: [coke, trash_can]\n")[0] == 0
    code, err = _validate(tmp_path, capsys, head + "  - inside: [coke, table]\n")
    assert code == 2 and "m.yaml:5" in err and "unknown name 'table'" in err


def test_the_kitchen_table_says_what_each_rate_is_counted_over():
    place = Trial("coke", "place", "table", (2.9, -1.2), 0.0, (1.9, -1.0, 0.0), (2.9, -1.4))
    throw = Trial("coke", "throw", "table", (2.9, -1.2), 0.0, (1.9, -1.0, 0.0))

    def outcome(grasped: bool, done: bool) -> Outcome:
        return Outcome(grasped, done, 0.4 if done else None, None if done else "missed", 20.0)

    trials = [place] * 4 + [throw] * 2
    outcomes = [outcome(True, True)] * 2 + [outcome(True, False), outcome(False, False)]
    outcomes += [outcome(True, True), outcome(True, False)]
    header, row, total = table([summarize("coke", trials, outcomes)]).splitlines()
    assert "grasp | of all" in header and "place | of grasped" in header and "into bin | of all" in header
    assert "5/6 83%" in row and "2/3 67%" in row and "2/4 50%" in row and "1/2 50%" in row
    assert total.split()[0] == "all"


def test_a_grasp_that_stops_short_still_closes_a_little_high_or_off_along_the_closing_line_but_not_across_it():
    mug = _thing("mug", (0.11, 0.08, 0.09), yaw=0.0)  # closed on along y (across the handle)
    grasp = plan_grasp(mug, TABLE, math.pi / 2, OPENING)
    assert grasp.give == pytest.approx(mug.top - (grasp.position[2] - PAD_HALF_HEIGHT) - HOLD_DEPTH)
    assert grasp.sway == pytest.approx((OPENING - 0.08) / 2 - STOPPED_PAD_CLEARANCE)

    def closes(dx: float, dy: float, dz: float, dyaw: float = 0.0) -> bool:
        return grasp.closes_from(grasp.position + np.array([dx, dy, dz]), grasp.yaw + dyaw, (0.008, 0.1))

    assert closes(0.0, 0.0, 0.0)
    assert closes(0.0, -0.011, 0.004)  # a biped's hand 1.1 cm short along the closing line, 4 mm high
    assert closes(0.0, 0.0, grasp.give - 1e-4) and not closes(0.0, 0.0, grasp.give + 1e-4)
    assert closes(0.0, grasp.sway - 1e-4, 0.0) and not closes(0.0, grasp.sway + 1e-4, 0.0)
    assert closes(0.0, 0.008, -0.002)  # as low as a reach that arrived may end
    assert not closes(0.0, 0.0, -0.009)  # lower: nearer the table than a reach may go
    assert not closes(0.009, 0.0, 0.0)  # across the closing line: the pads would meet it off their middle
    assert not closes(0.0, 0.0, 0.0, dyaw=0.15)


def test_a_flat_thing_gives_no_room_to_close_higher():
    bar = _thing("bar", (0.1, 0.04, 0.022))
    assert plan_grasp(bar, TABLE, 0.0, OPENING).give == 0.0
