"""Random views of a world's objects from the robot's head camera: training data and benchmark scenes.

One simulation holds a few of each of the world's objects, and some clutter:
plain boxes, cylinders and balls that are none of them. Each view puts three
to eight objects on one surface (sometimes a few more on another) and up to
two pieces of clutter, in random sizes and colours, close enough to hide one
another partly, at random spots and yaws; stands the robot at a random
distance and angle from that surface, arms in one of its postures, looking at
a random point on it; and scales and turns the light. Nothing is stepped: a
view is an initial state, rendered as it is.

``capture()`` gives the frame as the robot sees it (its own body masked out)
and, for training and judging only, which object each pixel shows.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco
import numpy as np

from bt_humanoid.perception.depth_filter import cleaned_depth
from bt_humanoid.perception.map_knowledge import map_world_model
from bt_humanoid.perception.rgbd_camera import RgbdCamera, RgbdFrame
from bt_humanoid.sim.robot_config import load_robot_config
from bt_humanoid.sim.scene_config import Placement, SceneConfig
from bt_humanoid.sim.scene_objects import footprint_radius, surface_tops
from bt_humanoid.sim.simulation import Simulation
from bt_humanoid.sim.world_config import ObjectModel, WorldConfig, WorldObject, load_world_config

COPIES = 2  # of each object in the simulation: a view may show two of a kind
OBJECTS = (3, 8)  # objects on the viewed surface
EDGE = 0.03  # m between an object and its surface's edge
GAP = (0.003, 0.06)  # m between neighbouring footprints: close enough to hide one another
BACK_OFF = (0.0, 1.3)  # m behind the surface's stance
SIDEWAYS = 0.5  # m either side of it
TURN = 0.35  # rad either side of facing the surface
POSTURES = ("home", "ready", "tucked")
CLUTTER = (  # shape and size (m) of each piece of clutter; every view scales and paints them anew
    ("box", (0.06, 0.06, 0.06)),
    ("box", (0.1, 0.04, 0.08)),
    ("cylinder", (0.06, 0.06, 0.1)),
    ("cylinder", (0.08, 0.08, 0.06)),
    ("sphere", (0.06, 0.06, 0.06)),
)
CLUTTER_SCALE = (0.6, 1.6)  # of each extent
CLUTTER_COUNT = 2  # at most, per view
PARKED = 60.0  # m: objects not in the view wait high above the room, apart (specks too small to render)


@dataclass
class Instance:
    name: str  # the world's object it is one of
    body: int
    qpos: int  # address of its free joint
    radius: float  # m: its footprint's circle
    half_height: float  # m: its centre above the surface it stands on
    clutter: bool = False  # none of the world's objects


def _pool(world: WorldConfig, objects: list[str]) -> list[Placement]:
    """Every object of the pool on a grid over the largest surface: a valid scene, rearranged before any view."""
    tops = surface_tops(world)
    surface = max(tops, key=lambda name: float(np.prod(tops[name][0][1] - tops[name][0][0])))
    half = (tops[surface][0][1] - tops[surface][0][0]) / 2
    radius = max(footprint_radius(world.objects[name].model) for name in objects)  # type: ignore[arg-type]
    step = 2 * radius + 0.005
    spots = [
        (x, y)
        for x in np.arange(-half[0] + radius, half[0] - radius, step)
        for y in np.arange(-half[1] + radius, half[1] - radius, step)
    ]
    if len(spots) < len(objects):
        raise ValueError(f"{len(objects)} objects do not fit on the {surface} to start from")
    return [Placement(object=name, on=surface, at=spot, yaw=0.0) for name, spot in zip(objects, spots, strict=False)]


class ViewMaker:
    """A world with ``COPIES`` of each object and the robot, rearranged into random views."""

    def __init__(self, world: str = "kitchen", robot: str = "wheeled_humanoid") -> None:
        config = load_world_config(world)
        self.objects = [name for name, o in config.objects.items() if o.model is not None]
        if not self.objects:
            raise ValueError(f"world '{world}' has no object models to draw views of")
        clutter = {
            f"clutter {i}": WorldObject(
                kind="clutter", colour="grey", model=ObjectModel(shape=shape, size=size, mass=0.1)
            )
            for i, (shape, size) in enumerate(CLUTTER)
        }
        config = config.model_copy(update={"objects": {**config.objects, **clutter}})
        scene = SceneConfig(objects=_pool(config, [n for n in self.objects for _ in range(COPIES)] + list(clutter)))
        self.sim = sim = Simulation(config, load_robot_config(robot), scene)
        model = sim.model
        model.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONTACT  # views are rendered, never stepped
        self.surfaces = list(map_world_model(config, model).surfaces.values())
        self.places = {name: config.places[s.place].pose for name, s in config.surfaces.items()}
        self.instances = []
        for name, body_name in sim.object_bodies.items():
            kind = sim.object_kinds[name]
            obj = config.objects[kind].model
            assert obj is not None
            body = model.body(body_name).id
            address = int(model.jnt_qposadr[model.body_jntadr[body]])
            radius, half_height = footprint_radius(obj), obj.size[2] / 2
            self.instances.append(Instance(kind, body, address, radius, half_height, clutter=kind in clutter))
        self._clutter_sizes = {i: model.geom_size[model.body_geomadr[c.body]].copy() for i, c in self._clutter()}
        camera = next(iter(sim.robot.cameras))
        config_camera = sim.robot.cameras[camera]
        self.camera = RgbdCamera(sim, camera, config_camera.width, config_camera.height)
        #: per geom: the index of the instance it belongs to, -1 for anything else
        self._instance_of_geom = np.full(model.ngeom, -1)
        for index, instance in enumerate(self.instances):
            self._instance_of_geom[model.geom_bodyid == instance.body] = index
        self._light = (model.light_diffuse.copy(), np.array(model.vis.headlight.diffuse))

    def close(self) -> None:
        self.camera.close()

    def arrange(self, rng: np.random.Generator) -> list[int]:
        """A new random view; returns the instances standing on surfaces in it."""
        sim, data = self.sim, self.sim.data
        for number, instance in enumerate(self.instances):
            data.qpos[instance.qpos : instance.qpos + 3] = (0.5 * number, 0.0, PARKED)
        free = [int(i) for i in rng.permutation(len(self.instances)) if not self.instances[i].clutter]
        surface = self.surfaces[int(rng.integers(len(self.surfaces)))]
        used = self._fill(surface, free, int(rng.integers(OBJECTS[0], OBJECTS[1] + 1)), rng)
        clutter = [index for index, _ in self._clutter()]
        for index in clutter:
            self._reshape(index, rng)
        used += self._fill(surface, list(rng.permutation(clutter)), int(rng.integers(CLUTTER_COUNT + 1)), rng)
        if rng.random() < 0.5:  # something on another surface too, seen from afar
            other = self.surfaces[int(rng.integers(len(self.surfaces)))]
            if other is not surface:
                used += self._fill(other, free, int(rng.integers(1, 4)), rng)
        self._pose_robot(surface, rng)
        self._light_up(rng)
        mujoco.mj_forward(sim.model, data)
        self._look_at(surface, rng)
        return used

    def capture(self) -> tuple[RgbdFrame, np.ndarray]:
        """The frame as the robot sees it, and per pixel the index of the instance it shows (-1: none)."""
        frame = self.camera.capture()
        assert frame is not None
        frame.depth = cleaned_depth(frame.depth)  # as the robot's perceiver does
        if frame.own_body is not None:
            frame.hide(frame.own_body)
        geoms = self.camera.geoms  # ground truth: the labels
        shown = np.where(geoms >= 0, self._instance_of_geom[np.maximum(geoms, 0)], -1)
        return frame, shown

    def _clutter(self) -> list[tuple[int, Instance]]:
        return [(index, instance) for index, instance in enumerate(self.instances) if instance.clutter]

    def _reshape(self, index: int, rng: np.random.Generator) -> None:
        """A piece of clutter in a new size and colour (for rendering: views are never stepped)."""
        model, instance = self.sim.model, self.instances[index]
        geom = model.body_geomadr[instance.body]
        size = self._clutter_sizes[index] * rng.uniform(*CLUTTER_SCALE, size=3)
        kind = model.geom_type[geom]
        if kind == mujoco.mjtGeom.mjGEOM_SPHERE:
            size[:] = size[0]
            instance.radius, instance.half_height = float(size[0]), float(size[0])
        elif kind == mujoco.mjtGeom.mjGEOM_CYLINDER:
            instance.radius, instance.half_height = float(size[0]), float(size[1])
        else:
            instance.radius, instance.half_height = float(np.hypot(size[0], size[1])), float(size[2])
        model.geom_size[geom] = size
        model.geom_rgba[geom] = (*rng.uniform(0.05, 0.95, size=3), 1.0)
        model.geom_matid[geom] = -1  # its own colour, not a material's

    def _fill(self, surface, free: list[int], count: int, rng: np.random.Generator) -> list[int]:
        """Stand up to ``count`` of the free instances on ``surface`` at random spots; returns those placed."""
        placed: list[int] = []
        spots: list[tuple[np.ndarray, float]] = []
        data = self.sim.data
        for index in list(free):
            if len(placed) == count:
                break
            instance = self.instances[index]
            spot = self._spot(surface, instance.radius, spots, rng)
            if spot is None:
                continue
            free.remove(index)
            placed.append(index)
            spots.append((spot, instance.radius))
            yaw = rng.uniform(-math.pi, math.pi)
            data.qpos[instance.qpos : instance.qpos + 3] = (*spot, surface.height + instance.half_height + 0.0005)
            if self.sim.world.objects[instance.name].model.shape == "sphere":  # an apple lies any way up
                quat = rng.normal(size=4)
                data.qpos[instance.qpos + 3 : instance.qpos + 7] = quat / np.linalg.norm(quat)
            else:
                data.qpos[instance.qpos + 3 : instance.qpos + 7] = (math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2))
        return placed

    @staticmethod
    def _spot(surface, radius: float, spots: list, rng: np.random.Generator) -> np.ndarray | None:
        low, high = surface.region[0] + EDGE + radius, surface.region[1] - EDGE - radius
        for _ in range(100):
            spot = rng.uniform(low, high)
            if all(np.hypot(*(spot - xy)) >= radius + r + rng.uniform(*GAP) for xy, r in spots):
                return spot
        return None

    def _pose_robot(self, surface, rng: np.random.Generator) -> None:
        sim = self.sim
        x, y, yaw_deg = self.places[surface.name]
        heading = math.radians(yaw_deg)
        back, side = rng.uniform(*BACK_OFF), rng.uniform(-SIDEWAYS, SIDEWAYS)
        x += -back * math.cos(heading) - side * math.sin(heading)
        y += -back * math.sin(heading) + side * math.cos(heading)
        joints = sim.robot.base.joints
        for axis, value in (("x", x), ("y", y), ("yaw", heading + rng.uniform(-TURN, TURN))):
            sim.set_initial_joint(joints[axis], value)
        posture = POSTURES[int(rng.integers(len(POSTURES)))]
        for joint, value in sim.robot.postures[posture].items():
            sim.set_initial_joint(joint, value)

    def _look_at(self, surface, rng: np.random.Generator) -> None:
        """Point the head at a random point of ``surface`` (the robot's pose must be forwarded first)."""
        sim = self.sim
        target = np.array([*rng.uniform(surface.region[0], surface.region[1]), surface.height])
        pan, tilt = sim.head_angles_towards(target)
        sim.set_initial_joint("head_pan", float(np.clip(pan + rng.normal(0, 0.1), -1.5, 1.5)))
        sim.set_initial_joint("head_tilt", float(np.clip(tilt + rng.normal(0, 0.08), -0.6, 1.1)))
        mujoco.mj_forward(sim.model, sim.data)

    def _light_up(self, rng: np.random.Generator) -> None:
        """Brighter or dimmer, the sun from another angle."""
        model = self.sim.model
        diffuse, headlight = self._light
        model.light_diffuse[:] = diffuse * rng.uniform(0.5, 1.4)
        model.vis.headlight.diffuse[:] = headlight * rng.uniform(0.5, 1.4)
        tilt = rng.uniform(-0.6, 0.6, size=2)
        turned = np.array([tilt[0], tilt[1], -1.0])
        model.light_dir[:] = turned / np.linalg.norm(turned)
