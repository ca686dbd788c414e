"""Build a scene's objects into a world's model: bodies from world.yaml's models, where the scene puts them.

Each placement becomes a free body on its surface, named after its object
("coke"; a second coke is "coke 2", body ``coke_2``). Its first geom is the
object's body (grasps close on it), a bottle's cap a second one. Spots a scene
leaves out are drawn from its seed: inside the surface's edge and clear of the
other objects. All of this is set-up, before the first simulation step.
"""

from __future__ import annotations

import math
import unicodedata
from dataclasses import dataclass

import mujoco
import numpy as np

from bt_humanoid.sim.scene_config import SceneConfig
from bt_humanoid.sim.world_config import ObjectModel, WorldConfig

EDGE_MARGIN = 0.08  # m between a drawn spot and the surface's edge
GAP = 0.03  # m between the footprints of drawn spots
DROP = 0.001  # m above the surface: the object settles onto it in the first steps
ATTEMPTS = 500


@dataclass(frozen=True)
class PlacedObject:
    """One object of a scene, placed: its name in the run, its model's name, its body, where and how turned."""

    name: str  # "coke", "coke 2"
    object: str  # the world's object it is one of ("coke")
    body: str  # MJCF body name ("coke_2")
    position: np.ndarray  # centre of its main geom (world, m)
    yaw: float  # rad
    hand: str | None = None  # "left" or "right": in the robot's hand at the start (put there when it resets)


class SceneError(ValueError):
    """A scene's objects do not fit where it puts them; ``path`` is the scene file's key concerned."""

    def __init__(self, message: str, path: tuple[str | int, ...]) -> None:
        super().__init__(message)
        self.message, self.path = message, path


def body_name(name: str) -> str:
    """An ASCII MJCF name for an object's name: "jalapeño chips 2" → "jalapeno_chips_2"."""
    folded = unicodedata.normalize("NFKD", name).encode("ascii", "ignore").decode()
    return "".join(c if c.isalnum() else "_" for c in folded)


def footprint_radius(model: ObjectModel) -> float:
    """Half the diagonal of the object's footprint: the circle it may sweep when turned."""
    return 0.5 * math.hypot(model.size[0], model.size[1]) if model.shape == "box" else 0.5 * model.size[0]


def place_scene(
    world: WorldConfig, scene: SceneConfig, surface_tops: dict[str, tuple[np.ndarray, float]]
) -> list[PlacedObject]:
    """Where each of the scene's objects stands. ``surface_tops``: surface → ([[x0, y0], [x1, y1]], top z).

    The object in hand comes first (named first, see ``SceneConfig.instances``); it is built above the floor and
    put in the hand when the simulation resets. A SceneError says which placement does not fit: a given spot
    off its surface or on another object, or no free spot left for one without.
    """
    rng = np.random.default_rng(scene.seed)
    names = scene.instances()
    placed: list[PlacedObject] = []
    if scene.holding is not None:
        name, obj = names.pop(0)
        placed.append(PlacedObject(name, obj, body_name(name), np.array([0.0, 0.0, 1.0]), 0.0, scene.holding.hand))
    standing: list[tuple[np.ndarray, float, int]] = []  # (x, y), footprint radius, placement index
    for index, (placement, (name, obj)) in enumerate(zip(scene.objects, names, strict=True)):
        model = world.objects[obj].model
        assert model is not None  # checked when the scene was loaded
        region, top = surface_tops[placement.on]
        radius = footprint_radius(model)
        if placement.at is not None:
            xy = (region[0] + region[1]) / 2 + np.array(placement.at)
            _check_spot(xy, radius, region, standing, placement.on, index)
        else:
            xy = _free_spot(region, radius, [(xy, r) for xy, r, _ in standing], rng)
            if xy is None:
                raise SceneError(
                    f"objects[{index}]: no free spot left on the {placement.on} for the {obj} "
                    f"({len([i for _, _, i in standing if scene.objects[i].on == placement.on])} objects on it "
                    "already): too many objects for it; give spots (at:) or use another surface",
                    ("objects", index),
                )
        yaw = math.radians(placement.yaw) if placement.yaw is not None else float(rng.uniform(-math.pi, math.pi))
        position = np.array([xy[0], xy[1], top + model.size[2] / 2 + DROP])
        placed.append(PlacedObject(name, obj, body_name(name), position, yaw))
        standing.append((xy, radius, index))
    return placed


def _check_spot(
    xy: np.ndarray,
    radius: float,
    region: np.ndarray,
    standing: list[tuple[np.ndarray, float, int]],
    surface: str,
    index: int,
) -> None:
    """A given spot keeps the object's footprint on its surface and off the objects placed before it."""
    centre, half = (region[0] + region[1]) / 2, (region[1] - region[0]) / 2
    room = half - radius
    offset = xy - centre
    if np.any(np.abs(offset) > room + 1e-9):
        raise SceneError(
            f"objects[{index}]: at [{offset[0]:g}, {offset[1]:g}] is off the {surface} for this object "
            f"(its footprint reaches {radius * 100:.1f} cm out): dx within ±{room[0]:.3f}, dy within ±{room[1]:.3f}",
            ("objects", index, "at"),
        )
    for other, other_radius, other_index in standing:
        gap = float(np.hypot(*(xy - other))) - radius - other_radius
        if gap < 0.0:
            raise SceneError(
                f"objects[{index}]: at [{offset[0]:g}, {offset[1]:g}] overlaps objects[{other_index}] "
                f"(by {-gap * 100:.1f} cm, footprints as circles)",
                ("objects", index, "at"),
            )


def _free_spot(
    region: np.ndarray, radius: float, others: list[tuple[np.ndarray, float]], rng: np.random.Generator
) -> np.ndarray | None:
    """A random spot inside the surface's edge and clear of ``others``; None when none is found."""
    low, high = region[0] + EDGE_MARGIN + radius, region[1] - EDGE_MARGIN - radius
    if np.any(low > high):
        return None
    for _ in range(ATTEMPTS):
        spot = rng.uniform(low, high)
        if all(np.hypot(*(spot - xy)) >= radius + r + GAP for xy, r in others):
            return spot
    return None


ROLLING_RESISTANCE = 0.003  # m: a round thing's rolling friction (an apple's lumps and flattened bottom)


def add_objects(spec: mujoco.MjSpec, world: WorldConfig, objects: list[PlacedObject]) -> None:
    """Add each placed object as a free body, with its model's textured material."""
    materials: dict[str, str] = {}
    for placed in objects:
        model = world.objects[placed.object].model
        assert model is not None
        if placed.object not in materials:
            materials[placed.object] = _material(spec, world, placed.object, model)
        yaw = placed.yaw
        body = spec.worldbody.add_body(
            name=placed.body, pos=placed.position, quat=[math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2)]
        )
        body.add_freejoint(name=placed.body)
        geom = dict(
            contype=1,
            conaffinity=1,
            condim=4,
            friction=[model.friction, 0.01, 0.001],
            solref=[0.004, 1.0],
            material=materials[placed.object],
        )
        if model.shape == "sphere":
            # a fruit is lumpy, not a ball: its shape resists rolling (rolling friction, metres of lever arm);
            # a perfect sphere set down with a millimetre a second of speed rolls on off the table's edge
            geom.update(condim=6, friction=[model.friction, 0.01, ROLLING_RESISTANCE])
        half = np.array(model.size) / 2
        if model.shape == "cylinder":
            shape, size = mujoco.mjtGeom.mjGEOM_CYLINDER, [half[0], half[2], 0.0]
        elif model.shape == "box":
            shape, size = mujoco.mjtGeom.mjGEOM_BOX, list(half)
        else:
            shape, size = mujoco.mjtGeom.mjGEOM_SPHERE, [half[0], 0.0, 0.0]
        cap = model.cap
        body_mass = model.mass * (0.97 if cap else 1.0)
        body.add_geom(name=placed.body, type=shape, size=size, mass=body_mass, **geom)
        if cap is not None:
            body.add_geom(
                name=f"{placed.body}_cap",
                type=mujoco.mjtGeom.mjGEOM_CYLINDER,
                size=[cap.diameter / 2, cap.height / 2, 0.0],
                pos=[0.0, 0.0, half[2] + cap.height / 2],
                mass=model.mass * 0.03,
                rgba=list(cap.rgba),
                **{k: v for k, v in geom.items() if k != "material"},
            )


def _material(spec: mujoco.MjSpec, world: WorldConfig, name: str, model: ObjectModel) -> str:
    material = spec.add_material(name=f"{body_name(name)}_look", rgba=list(model.rgba))
    if model.texture is not None:
        texture = spec.add_texture(
            name=f"{body_name(name)}_label",
            type=mujoco.mjtTexture.mjTEXTURE_2D,
            file=str(world.folder / "textures" / model.texture),
        )
        material.textures[mujoco.mjtTextureRole.mjTEXROLE_RGB] = texture.name
    return material.name


def surface_tops(world: WorldConfig) -> dict[str, tuple[np.ndarray, float]]:
    """Each surface's rectangle ([[x0, y0], [x1, y1]]) and top height, from the world's model (furniture only)."""
    model = mujoco.MjModel.from_xml_path(str(world.model_path))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    tops = {}
    for name, surface in world.surfaces.items():
        geom = model.geom(surface.geom).id
        centre, half = data.geom_xpos[geom], model.geom_size[geom]  # furniture tops are unrotated boxes
        tops[name] = (np.array([centre[:2] - half[:2], centre[:2] + half[:2]]), float(centre[2] + half[2]))
    return tops
