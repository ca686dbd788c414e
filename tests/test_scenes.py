"""Scenes as data: names of a scene's objects, where the robot starts, mistakes at file:line, and an object held
from the start (by friction alone) that the robot believes it holds and can put down or hand over.

Runs with a stack here have the head camera off: they test control from what the robot was told, not sight.
"""

from __future__ import annotations

import math
import textwrap

import numpy as np
import pytest

from bt_humanoid.engine.runner import MissionRun
from bt_humanoid.engine.stack import RobotStack
from bt_humanoid.errors import UserError
from bt_humanoid.evaluation import episode
from bt_humanoid.evaluation.episode import Draw, _random_scene
from bt_humanoid.evaluation.suite import load_suite
from bt_humanoid.mission.loader import MissionLoader
from bt_humanoid.sim.ground_truth import GroundTruth
from bt_humanoid.sim.robot_config import load_robot_config
from bt_humanoid.sim.scene_config import Holding, Placement, SceneConfig, load_scene
from bt_humanoid.sim.scene_objects import body_name
from bt_humanoid.sim.simulation import Simulation
from bt_humanoid.sim.world_config import load_world_config
from bt_humanoid.testing.spots import EDGE_MARGIN


@pytest.fixture(scope="module")
def kitchen():
    return load_world_config("kitchen")


@pytest.fixture(scope="module")
def robot():
    return load_robot_config("wheeled_humanoid")


@pytest.fixture(scope="module")
def blind(robot):
    """The robot with its head camera off: it acts on what it was told (here: what it was handed)."""
    return robot.model_copy(update={"cameras": {}})


def test_three_cokes_are_coke_coke_2_and_coke_3(kitchen, robot):
    sim = Simulation(kitchen, robot, load_scene(kitchen, "three_cokes"))
    assert {name: sim.object_bodies[name] for name in ("coke", "coke 2", "coke 3")} == {
        "coke": "coke",
        "coke 2": "coke_2",
        "coke 3": "coke_3",
    }
    assert set(sim.object_bodies) == {"coke", "coke 2", "coke 3", "pepsi", "7up"}
    assert {sim.object_kinds[name] for name in ("coke", "coke 2", "coke 3")} == {"coke"}


def test_a_scene_s_names_are_the_world_s_objects_numbered(kitchen):
    assert [kitchen.object_of(n) for n in ("coke", "coke 2", "coke 12", "pepsi 3")] == ["coke", "coke", "coke", "pepsi"]
    assert [kitchen.object_of(n) for n in ("coke 1", "coke 02", "coke two", "cola 2", "coke 2 2")] == [None] * 5
    apartment = load_world_config("apartment")
    assert apartment.object_of("red cube") == "red cube" and apartment.object_of("red cube 2") is None  # a body


def test_the_object_in_hand_is_named_first(kitchen):
    scene = load_scene(kitchen, "holding_coke")
    assert scene.instances() == [("coke", "coke"), ("pepsi", "pepsi"), ("coke 2", "coke")]


def test_robot_start_by_place_and_by_pose(kitchen, robot):
    x, y, yaw = kitchen.places["far_counter"].pose
    truth = GroundTruth(Simulation(kitchen, robot, SceneConfig(robot_start="far_counter")))
    assert truth.robot_pose() == pytest.approx((x, y, math.radians(yaw)))
    truth = GroundTruth(Simulation(kitchen, robot, SceneConfig(robot_start=(1.0, -2.0, 45.0))))
    assert truth.robot_pose() == pytest.approx((1.0, -2.0, math.radians(45.0)))
    truth = GroundTruth(Simulation(kitchen, robot, SceneConfig()))  # none: the world's start
    assert truth.robot_pose() == pytest.approx((0.0, 0.0, 0.0))


def test_free_spots_follow_from_the_scene_s_seed(kitchen, robot):
    def spots(seed: int) -> np.ndarray:
        scene = SceneConfig(objects=[Placement(object="coke", on="table")] * 6, seed=seed)
        sim = Simulation(kitchen, robot, scene)
        truth = GroundTruth(sim)
        return np.array([truth.object_position(name) for name in sim.object_bodies])

    first = spots(1)
    assert np.array_equal(first, spots(1)) and not np.allclose(first, spots(2))
    (x0, y0), (x1, y1) = (3.2 - 0.6, -1.3 - 0.4), (3.2 + 0.6, -1.3 + 0.4)  # the table's top
    assert np.all((first[:, 0] > x0) & (first[:, 0] < x1) & (first[:, 1] > y0) & (first[:, 1] < y1))
    gaps = [np.hypot(*(a[:2] - b[:2])) for i, a in enumerate(first) for b in first[i + 1 :]]
    assert min(gaps) >= 0.066  # apart: no two cans overlap


@pytest.mark.parametrize(
    ("text", "line", "message"),
    [
        ("objects:\n  - {object: coke, on: table}\n  - {object: banana, on: table}\n", 3, "'banana' is not an object"),
        ("objects:\n  - {object: coke, on: shelf}\n", 2, "unknown surface 'shelf'"),
        ("robot_start: garden\n", 1, "unknown place 'garden'"),
        ("holding: {object: mug}\n", 1, "'mug' is not an object scenes can place"),
        ("objects:\n  - {object: coke, on: table, at: [0, 0.39]}\n", 2, "is off the table"),
        ("objects: {coke: table}\n", 1, "objects: Input should be a valid list"),
        ("- coke\n", 1, "a scene: a mapping"),
    ],
)
def test_scene_errors_name_the_file_and_line(kitchen, tmp_path, text, line, message):
    file = tmp_path / "mine.yaml"
    file.write_text(text)
    with pytest.raises(UserError) as error:
        load_scene(kitchen, str(file))
    assert f"mine.yaml:{line}" in str(error.value) and message in str(error.value)


def test_a_scene_made_in_code_that_does_not_fit_is_a_user_error(kitchen, robot):
    crowded = SceneConfig(objects=[Placement(object="water bottle", on="table")] * 200)
    with pytest.raises(UserError, match=r"objects\[\d+\]: no free spot left on the table"):
        Simulation(kitchen, robot, crowded)


def test_a_mission_names_its_scene_and_the_command_line_overrides_it(tmp_path):
    mission = tmp_path / "m.yaml"
    mission.write_text("mission: m\nworld: kitchen\nscene: holding_coke\ntree:\n  wait: {seconds: 1}\n")
    assert MissionLoader().load_file(mission).scene.name == "holding_coke"
    assert MissionLoader(scene="three_cokes").load_file(mission).scene.name == "three_cokes"
    mission.write_text("mission: m\nworld: kitchen\ntree:\n  wait: {seconds: 1}\n")
    assert MissionLoader().load_file(mission).scene.name == "default"  # the world's own
    mission.write_text("mission: m\ntree:\n  wait: {seconds: 1}\n")
    assert MissionLoader().load_file(mission).scene is None  # the apartment has none


def test_a_mission_judged_on_an_object_its_robot_s_scene_lacks_is_refused_before_it_runs(kitchen, blind):
    spec = MissionLoader().load_text(  # checked against the default scene, which has an apple
        "mission: m\nworld: kitchen\ntree:\n  wait: {seconds: 1}\nsuccess:\n  - upright: apple\n", "m.yaml"
    )
    stack = RobotStack(kitchen, blind, scene=load_scene(kitchen, "three_cokes"))
    with pytest.raises(UserError, match=r"success: no 'apple' in this run \(scene 'three_cokes'\)"):
        MissionRun(stack, spec)


# --- held from the start -----------------------------------------------------------------------------------


@pytest.mark.sim
@pytest.mark.parametrize(
    ("obj", "hand"), [("coke", "right"), ("water bottle", "left"), ("jalapeno chips", "right"), ("energy bar", "left")]
)
def test_an_object_handed_over_at_the_start_stays_in_hand(kitchen, robot, obj, hand):
    sim = Simulation(kitchen, robot, SceneConfig(holding=Holding(object=obj, hand=hand)))
    truth = GroundTruth(sim)
    start = truth.object_position(obj)
    assert truth.in_hand(obj) == hand  # the pads touch it before the first step
    sim.step(round(3.0 / sim.timestep))
    assert truth.in_hand(obj) == hand and truth.upright(obj)
    assert np.linalg.norm(truth.object_position(obj) - start) < 0.005
    body = body_name(obj)
    assert {other for _, other in truth.robot_contacts()} <= {body, f"{body}_cap"}  # nothing else touches the robot
    assert sim.model.neq == 0  # no weld, no constraint: friction holds it


def test_the_robot_believes_what_it_was_handed(kitchen, blind):
    stack = RobotStack(kitchen, blind, scene=load_scene(kitchen, "holding_coke"))
    held = stack.context.world_model.held("right")
    assert held is not None and held.name == "coke" and held.identity == "coke"
    assert (held.kind, held.colour, held.keep_upright) == ("can", "red", True)
    assert held.size == pytest.approx([0.066, 0.066, 0.122])
    truth = GroundTruth(stack.sim)
    assert held.position == pytest.approx(truth.object_centre("coke"), abs=0.002)  # its arm's kinematics
    assert stack.robot.grippers.holding("right") and stack.context.world_model.held("left") is None
    assert stack.context.world_model.object("coke") is held


def _run(stack: RobotStack, text: str):
    spec = MissionLoader().load_text(textwrap.dedent(text), "m.yaml")
    return MissionRun(stack, spec).execute()


@pytest.mark.sim
def test_held_at_the_start_it_stays_in_hand_standing_and_driving(kitchen, blind):
    stack = RobotStack(kitchen, blind, scene=load_scene(kitchen, "holding_coke"))
    truth = GroundTruth(stack.sim)
    result = _run(stack, "mission: stand\nworld: kitchen\ntree:\n  wait: {seconds: 3}\n")
    assert result.success and stack.sim.time > 2.99
    assert truth.in_hand("coke") == "right" and truth.upright("coke")
    moves = """
        mission: drive
        world: kitchen
        tree:
          sequence:
            - move_base: {x: -0.6, relative: true}
            - move_base: {yaw: 90, relative: true}
        """
    result = _run(stack, moves)
    assert result.success and result.safety is None, result.summary()
    x, y, _ = truth.robot_pose()
    assert np.hypot(x - 1.4, y + 1.3) < 0.05
    assert truth.in_hand("coke") == "right" and truth.upright("coke")


@pytest.mark.sim
def test_a_coke_held_from_the_start_is_put_on_the_table(kitchen, blind):
    stack = RobotStack(kitchen, blind, scene=load_scene(kitchen, "holding_coke"))
    result = _run(
        stack,
        """
        mission: put the coke down
        world: kitchen
        scene: holding_coke
        tree:
          place: {surface: table, x: 2.8, y: -1.55}
        success:
          - on: [coke, table]
          - upright: coke
        """,
    )
    assert result.success, result.summary()
    assert stack.context.world_model.held("right") is None


@pytest.mark.sim
def test_a_coke_held_from_the_start_is_handed_to_the_person(kitchen, blind):
    stack = RobotStack(kitchen, blind, scene=load_scene(kitchen, "holding_coke"))
    result = _run(
        stack,
        """
        mission: hand it over
        world: kitchen
        tree:
          sequence:
            - navigate: {person: person}
            - give: {to: person}
        success:
          - delivered: coke
        """,
    )
    assert result.success, result.summary()


# --- random scenes for evaluation --------------------------------------------------------------------------


def test_a_suite_draws_random_scenes_the_hand_reaches(kitchen, blind, tmp_path, monkeypatch):
    suite_file = tmp_path / "suite.yaml"
    suite_file.write_text(
        "suite: s\nworld: kitchen\nscene: holding_coke\nobjects: [pepsi, 7up]\nrandomize:\n  object_on: [table]\n"
        "  scene: {objects: [3, 6], surfaces: [table, far_counter], among: [coke, tea, apple]}\n"
        "tasks:\n  - command: bring me the {object}\n    expect: [{delivered: '{object}'}]\n"
    )
    suite, _ = load_suite(suite_file)
    probe = RobotStack(kitchen, blind)
    monkeypatch.setattr(episode, "_probe", lambda world, robot: probe)
    base = load_scene(kitchen, "holding_coke")
    counts = []
    for index in range(6):
        draw = Draw(suite, index)
        scene = _random_scene(suite, draw, probe, base)
        again = _random_scene(suite, Draw(suite, index), probe, base)
        assert scene == again  # from the suite's seed and the index alone
        assert scene.holding == base.holding and scene.robot_start == base.robot_start
        first = scene.objects[0]
        assert (first.object, first.on) == (draw.obj, "table")  # the episode's object, on its start surface
        assert {p.object for p in scene.objects[1:]} <= {"coke", "tea", "apple"}
        counts.append(len(scene.objects))
        for placement in scene.objects:
            surface = probe.context.world_model.surface(placement.on)
            half = (surface.region[1] - surface.region[0]) / 2
            assert np.all(np.abs(placement.at) <= half - EDGE_MARGIN + 1e-9)
        sim = Simulation(kitchen, blind, scene)  # it builds: the held coke first, the drawn ones numbered after
        assert sim.held is not None and sim.held.name == "coke"
    assert min(counts) >= 3 and max(counts) <= 6 and len(set(counts)) > 1
