"""world.yaml: named places, surfaces, objects and people of a scene."""

from __future__ import annotations

from pathlib import Path
from typing import Literal

from pydantic import Field

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


class WorldObject(StrictModel):
    body: str
    kind: str
    colour: str
    upright: bool = False
    aliases: list[str] = Field(default_factory=list, description=ALIASES)


class Person(StrictModel):
    body: str
    aliases: list[str] = Field(default_factory=list)


class Walker(StrictModel):
    """A person who walks a loop through the scene, on their own legs (actuators), pausing for the robot."""

    route: list[tuple[float, float]] = Field(min_length=2, description="[x, y] corners of the loop (m)")
    speed: float = Field(0.5, gt=0, le=2.0, description="walking speed (m/s)")
    radius: float = Field(0.2, gt=0, le=0.5, description="body radius (m)")


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
    folder: Path = Path()

    @property
    def model_path(self) -> Path:
        return self.folder / self.model

    def outside_map(self, x: float, y: float) -> str | None:
        """Why (x, y) is not a place on this world's map, or None when it is."""
        (x0, y0), (x1, y1) = self.bounds
        if x0 <= x <= x1 and y0 <= y <= y1:
            return None
        return f"({x}, {y}) is outside the map: x {x0:g} to {x1:g}, y {y0:g} to {y1:g}"

    @property
    def person_names(self) -> list[str]:
        """Every name a person answers to: their own and their aliases ("me", "user")."""
        return [n for name, person in self.people.items() for n in (name, *person.aliases)]

    def place(self, name: str) -> Place:
        if name not in self.places:
            raise UserError(f"unknown place '{name}' in world '{self.name}'", hint=did_you_mean(name, self.places))
        return self.places[name]


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
