"""world.yaml: named places, surfaces, objects and people of a scene."""

from __future__ import annotations

from pathlib import Path
from typing import Literal

from pydantic import Field, model_validator

from bt_humanoid.errors import UserError, did_you_mean
from bt_humanoid.paths import worlds_dir
from bt_humanoid.strict_model import StrictModel
from bt_humanoid.yaml_source import read_config

Pose2D = tuple[float, float, float]  # x [m], y [m], yaw [deg]
Region = tuple[tuple[float, float], tuple[float, float]]


ALIASES = "other names people call it by, in commands typed or spoken (English words the recogniser knows)"


class Place(StrictModel):
    pose: Pose2D
    region: Region | None = None
    kind: Literal["room", "furniture", "spot"] = "spot"
    aliases: list[str] = Field(default_factory=list, description=ALIASES)


class Surface(StrictModel):
    geom: str
    place: str
    aliases: list[str] = Field(default_factory=list, description=ALIASES)


class Cap(StrictModel):
    """A bottle's cap: a small cylinder on top of its body."""

    diameter: float = Field(gt=0, le=0.1, description="m")
    height: float = Field(gt=0, le=0.1, description="m")
    rgba: tuple[float, float, float, float] = (0.9, 0.9, 0.9, 1.0)


class ObjectModel(StrictModel):
    """How to build one of an object: scenes place as many as they like (worlds/<world>/scenes/)."""

    shape: Literal["cylinder", "box", "sphere"]
    size: tuple[float, float, float] = Field(
        description="full extents along x, y and up (m); a cylinder's x is its diameter"
    )
    mass: float = Field(gt=0, le=5.0, description="kg")
    texture: str | None = Field(
        None, description="PNG in the world's textures/ folder: wrapped round a cylinder, on every face of a box"
    )
    rgba: tuple[float, float, float, float] = (1.0, 1.0, 1.0, 1.0)
    friction: float = Field(1.0, gt=0, le=2.0)
    cap: Cap | None = None


class WorldObject(StrictModel):
    """A thing people can ask for: either one body of the world's model, or a model that scenes place."""

    body: str | None = Field(None, description="the body in the world's MJCF (objects built by scenes have none)")
    model: ObjectModel | None = None
    kind: str = Field(description="its shape for grasping: cube, box, can, bottle, mug, ball, bag, bar, ...")
    colour: str
    upright: bool = False
    aliases: list[str] = Field(default_factory=list, description=ALIASES)
    categories: list[str] = Field(
        default_factory=list,
        description="what kind of thing it is and what it is good for, as people say it: drink, snack, recyclable, ...",
    )

    @model_validator(mode="after")
    def _body_or_model(self) -> WorldObject:
        if (self.body is None) == (self.model is None):
            raise ValueError("give either body (a body of the world's MJCF) or model (built by scenes), not both")
        return self


class Person(StrictModel):
    body: str
    aliases: list[str] = Field(default_factory=list)
    takes: bool = Field(
        True,
        description="reaches for what the robot holds out to them and takes it (an arm and hand are built onto "
        "their body, sim/people.py); false: busy, they never reach",
    )


class Walker(StrictModel):
    """A person who walks a loop through the scene, on their own legs (actuators), reacting to the robot as they
    see it (sim/walkers.py)."""

    route: list[tuple[float, float]] = Field(min_length=2, description="[x, y] corners of the loop (m)")
    speed: float = Field(0.5, gt=0, le=2.0, description="walking speed (m/s)")
    radius: float = Field(0.2, gt=0, le=0.5, description="body radius (m)")
    yields: float = Field(
        0.8, ge=0, le=1, description="share of meetings in which they stop for the robot; in the others they pass it"
    )
    # about 0.7 s for an expected event, longer for a surprise (Green 2000, "How long does it take to stop?")
    reaction_time: float = Field(0.7, ge=0, le=3.0, description="s from seeing the robot to acting on it")
    # the human field of view spans about 200 degrees across (Spector 1990, Clinical Methods, ch. 116)
    view_angle: float = Field(100.0, gt=0, le=180, description="half-angle they see round the way they walk (deg)")


class Container(StrictModel):
    """An open bin things are dropped into: the opening is a rectangle at the top of its walls."""

    body: str = Field(description="the bin's body in the world's MJCF")
    place: str = Field(description="the place the robot stands at to drop things in")
    opening: Region = Field(description="[[x_min, y_min], [x_max, y_max]] inside its walls (m, world)")
    height: float = Field(gt=0, le=1.5, description="m: the top of its walls")
    takes: list[str] = Field(
        default_factory=list, description="categories it is for (recyclable, compostable); none: anything"
    )
    aliases: list[str] = Field(default_factory=list, description=ALIASES)


class WorldConfig(StrictModel):
    name: str
    description: str = ""
    model: str
    robot_start: Pose2D = (0.0, 0.0, 0.0)
    bounds: Region
    places: dict[str, Place]
    surfaces: dict[str, Surface] = Field(default_factory=dict)
    objects: dict[str, WorldObject] = Field(default_factory=dict)
    people: dict[str, Person] = Field(default_factory=dict)
    obstacles: list[str] = Field(default_factory=list)
    walkers: dict[str, Walker] = Field(default_factory=dict)  # body name → how they walk
    containers: dict[str, Container] = Field(default_factory=dict)
    scene: str | None = Field(None, description="the scene (scenes/NAME.yaml) a run starts from unless told another")
    detector: str | None = Field(
        None, description="folder of the learned detector for this world's objects (weights, recipe); none: shape rules"
    )
    folder: Path = Path()

    @property
    def model_path(self) -> Path:
        return self.folder / self.model

    @property
    def detector_path(self) -> Path | None:
        return self.folder / self.detector if self.detector is not None else None

    def outside_map(self, x: float, y: float) -> str | None:
        """Why (x, y) is not a place on this world's map, or None when it is."""
        (x0, y0), (x1, y1) = self.bounds
        if x0 <= x <= x1 and y0 <= y <= y1:
            return None
        return f"({x}, {y}) is outside the map: x {x0:g} to {x1:g}, y {y0:g} to {y1:g}"

    @property
    def placeable(self) -> list[str]:
        """The objects scenes place (those given by a model), as many of each as a scene likes."""
        return [name for name, o in self.objects.items() if o.model is not None]

    def object_of(self, name: str) -> str | None:
        """The world object ``name`` is one of: itself for a world object, "coke" for "coke 2" (a scene's second
        coke, see ``instance_name``); None for a name that is neither."""
        if name in self.objects:
            return name
        base, _, number = name.rpartition(" ")
        placeable = base in self.objects and self.objects[base].model is not None
        return base if placeable and number.isdigit() and not number.startswith("0") and int(number) >= 2 else None

    @property
    def person_names(self) -> list[str]:
        """Every name a person answers to: their own and their aliases ("me", "user")."""
        return [n for name, person in self.people.items() for n in (name, *person.aliases)]

    def place(self, name: str) -> Place:
        if name not in self.places:
            raise UserError(f"unknown place '{name}' in world '{self.name}'", hint=did_you_mean(name, self.places))
        return self.places[name]


def instance_name(obj: str, number: int) -> str:
    """What the ``number``-th of a world object in a scene is called: "coke", "coke 2", "coke 3"."""
    return obj if number == 1 else f"{obj} {number}"


def load_world_config(name: str) -> WorldConfig:
    """Read worlds/<name>/world.yaml; unknown names get the list of valid ones.

    A world may start from another (``extends: apartment``): it takes every
    key of that world (its model file included) and overrides the ones it gives.
    """
    return read_config(  # type: ignore[return-value]
        "world", worlds_dir(), name, "world.yaml", WorldConfig, inherit=_inherit_world
    )


def _inherit_world(parent: WorldConfig) -> dict:
    inherited = parent.model_dump(exclude={"folder", "name", "description"})
    inherited["model"] = str(parent.model_path)  # the parent's model file, wherever the child lives
    return inherited
