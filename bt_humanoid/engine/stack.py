"""One robot in one world: the simulation, the robot's controllers, navigator and perceiver, and what it believes.

A stack lives as long as the robot does. Missions come and go on it (``MissionRun(stack, spec)``): a typed
command is planned from the stack's belief and run on the same stack, an interactive session and a benchmark
episode run mission after mission on one. Skills see the stack through its SkillContext: the base's motion
interface, the arm and joint controllers, the navigator, the perceiver and the WorldModel, never the simulator.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from bt_humanoid.control.robot import RobotController
from bt_humanoid.engine.events import EventLog
from bt_humanoid.language.plan import PlanningContext
from bt_humanoid.navigation.navigator import Navigator
from bt_humanoid.perception.map_knowledge import map_world_model
from bt_humanoid.perception.perceiver import Perceiver
from bt_humanoid.perception.safety_scanner import SafetyScanner
from bt_humanoid.perception.world_model import TrackedObject
from bt_humanoid.safety.separation import SpeedAndSeparation
from bt_humanoid.sim.assembly import joint_ranges
from bt_humanoid.sim.ground_truth import GroundTruth
from bt_humanoid.sim.robot_config import RobotConfig, load_robot_config
from bt_humanoid.sim.scene_config import SceneConfig, load_scene
from bt_humanoid.sim.scene_objects import body_name
from bt_humanoid.sim.sensor_models import scanner_ranges
from bt_humanoid.sim.simulation import Simulation
from bt_humanoid.sim.world_config import WorldConfig, load_world_config
from bt_humanoid.skills.context import SkillContext


class RobotStack:
    """Builds and holds one robot in one world; ``close()`` when done (the cameras' off-screen contexts).

    ``scene``: the objects, start and held object a run starts from (none: the world's own scene, if any).
    """

    def __init__(
        self,
        world: WorldConfig,
        robot: RobotConfig,
        seed: int = 0,
        speak: Callable[[str], None] | None = None,
        scene: SceneConfig | None = None,
    ) -> None:
        self.sim = Simulation(world, robot, scene)
        self.sim.reset(seed)
        self.robot = RobotController(self.sim)
        self.navigator = Navigator(self.sim, self.robot, np.array(world.bounds))
        self.robot.planners.append(self.navigator)
        self.truth = GroundTruth(self.sim)  # for tests, evaluation and fault injection only: skills never see it
        self.events = EventLog()  # what the robot did, mission after mission
        self.said: list[str] = []
        self.speak = speak
        #: called after every control period, whichever mission runs (recorders, pacing, fault injection)
        self.observers: list[Callable[[], None]] = []
        self.context = SkillContext(
            robot_config=robot,
            world=world,
            joint_ranges=joint_ranges(robot),
            robot=self.robot,
            clock=lambda: self.sim.time,
            speak=self.say,
            world_model=map_world_model(world, self.sim.model),  # its map, and no objects until the camera sees them
            navigator=self.navigator,
        )
        self.perceiver: Perceiver | None = None
        if robot.cameras:  # objects are known only once the head camera has seen them
            camera = next(iter(robot.cameras))
            self.perceiver = Perceiver(self.sim, lambda: self.context.world_model, camera)
            self.robot.planners.append(self.perceiver)
            self.context.perceiver = self.perceiver
        self.separation = self._separation()
        if self.sim.held is not None:
            self._handed_over()

    @classmethod
    def load(
        cls,
        world: str,
        robot: str,
        seed: int = 0,
        robot_start: tuple[float, float, float] | None = None,
        speak: Callable[[str], None] | None = None,
        scene: str | SceneConfig | None = None,
    ) -> RobotStack:
        """A stack of the named world (worlds/) and robot (robots/); ``scene`` by name (the world's scenes/), path
        or config (none: the world's own); ``robot_start`` [x, y, yaw_deg] replaces the start pose of the world
        and its scene (test and benchmark set-up)."""
        world_config = load_world_config(world)
        if isinstance(scene, str):
            scene = load_scene(world_config, scene, named_at="--scene")
        elif scene is None and world_config.scene is not None:
            scene = load_scene(world_config, world_config.scene, named_at=f"{world_config.folder.name}/world.yaml")
        if robot_start is not None:
            world_config = world_config.model_copy(update={"robot_start": tuple(robot_start)})
            if scene is not None:
                scene = scene.model_copy(update={"robot_start": tuple(robot_start)})
        return cls(world_config, load_robot_config(robot), seed, speak, scene)

    @property
    def world(self) -> WorldConfig:
        return self.context.world

    @property
    def robot_config(self) -> RobotConfig:
        return self.context.robot_config

    def say(self, text: str) -> None:
        """The robot says something: logged, kept, and spoken when the stack has a voice."""
        self.said.append(text)
        self.events.add(self.sim.time, "say", text=text)
        if self.speak is not None:
            self.speak(text)

    def look(self) -> None:
        """One look with the head camera, fused into the belief (robots without a camera know only their map)."""
        if self.perceiver is not None:
            self.perceiver.look()

    def planning_context(self) -> PlanningContext:
        """What a planner may read: the world's names, the robot's belief and where it believes it stands."""
        return PlanningContext(self.world, self.context.world_model, self.robot.base.pose(), self.robot_config.name)

    def close(self) -> None:
        if self.perceiver is not None:
            self.perceiver.close()

    def _handed_over(self) -> None:
        """The scene put an object in the robot's hand before the first step: its fingers stay shut on it, and it
        believes what it holds. Told, not seen: whoever handed it over said what it is, so its identity is known
        (a camera's sighting of a red can could be any red can); where it is comes from the robot's own arm."""
        held, hold = self.sim.held, self.sim.hold
        assert held is not None and held.hand is not None and hold is not None
        self.robot.grippers.start_closed(held.hand)
        declared = self.world.objects[held.object]
        model = declared.model
        assert model is not None
        hand = self.robot.whole_body.frame_pose(self.robot.whole_body.hand_frame(held.hand))
        grip_offset = hold.grip_height - hold.centre_height  # the grip site above the object's centre
        top = model.size[2] + (model.cap.height if model.cap is not None else 0.0)
        yaw = math.atan2(hand.rotation[1, 0], hand.rotation[0, 0]) + hold.turn
        self.context.world_model.update(
            TrackedObject(
                id=body_name(held.name),
                name=held.name,
                kind=declared.kind,
                colour=declared.colour,
                position=hand.translation - np.array([0.0, 0.0, grip_offset]),
                yaw=math.atan2(math.sin(yaw), math.cos(yaw)),
                size=np.array([model.size[0], model.size[1], top]),
                keep_upright=declared.upright,
                held_by=held.hand,
                grip_offset=grip_offset,
                identity=held.object,
            )
        )

    def _separation(self) -> SpeedAndSeparation | None:
        """Speed and separation monitoring from the base scanner, when the robot has one."""
        config = self.robot_config
        if config.scanner is None:
            return None
        model = self.sim.model
        base_body = model.body(self.sim.robot_root).id  # the scanner rides the body the base joints move
        robot = self.robot

        def hands() -> list[np.ndarray]:
            return [robot.hand_position(side) for side in config.grippers]

        def noise(ranges: np.ndarray) -> tuple[np.ndarray, np.ndarray]:  # the robot's range model, its own stream
            return scanner_ranges(self.sim.sensors.scanner, ranges, self.sim.random_stream("scanner"))

        def zone(name: str, distance: float) -> None:
            self.events.add(self.sim.time, "separation", zone=name, distance=round(distance, 3))

        scanner = SafetyScanner(model, self.sim.data, base_body, config.scanner, own=self.sim.robot_bodies, noise=noise)
        localisation = robot.localisation
        if localisation is not None:  # the same scans place the robot on its map
            scanner.listeners.append(localisation.scan)

            def localised(kind: str, text: str) -> None:
                self.events.add(self.sim.time, "localisation", status=kind, text=text)

            localisation.localiser.on_event = localised
        separation = SpeedAndSeparation(
            scanner,
            config.safety,
            config.base.footprint_radius,
            config.base.limits.max_speed,
            furniture=self.navigator.is_furniture,
            people=lambda: list(self.context.world_model.people.values()),
            hands=hands,
            on_zone=zone,
        )
        self.robot.monitor_separation(separation)
        return separation
