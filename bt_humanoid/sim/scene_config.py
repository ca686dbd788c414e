"""Scenes: which of a world's objects stand where, where the robot starts and what it holds.

A scene file (``worlds/<world>/scenes/NAME.yaml``, or any path) places
objects that world.yaml describes by a ``model:`` — as many of each as it
likes ("three cokes on the table"). Placements name a surface and, if they
like, a spot on it (an offset from the surface's centre); a placement without
a spot gets a free one, drawn from the scene's seed so a scene always looks
the same. Checked against the world when loaded: every error names file:line.
"""

from __future__ import annotations

from pathlib import Path
from typing import Literal

from pydantic import Field, PrivateAttr

from bt_humanoid.errors import UserError, did_you_mean
from bt_humanoid.sim.world_config import Pose2D, WorldConfig, instance_name
from bt_humanoid.strict_model import StrictModel
from bt_humanoid.yaml_source import YamlSource, display_path, read_model


class Placement(StrictModel):
    object: str = Field(description="an object of world.yaml that has a model")
    on: str = Field(description="a surface of world.yaml")
    at: tuple[float, float] | None = Field(
        None, description="[dx, dy] from the surface's centre (m, world axes); left out: a free spot"
    )
    yaw: float | None = Field(None, description="deg about the vertical; left out: drawn from the scene's seed")


class Holding(StrictModel):
    object: str = Field(description="an object of world.yaml that has a model")
    hand: Literal["left", "right"] = "right"


class SceneConfig(StrictModel):
    description: str = ""
    robot_start: str | Pose2D | None = Field(None, description="a place of world.yaml, or [x, y, yaw_deg]")
    objects: list[Placement] = Field(default_factory=list)
    holding: Holding | None = Field(None, description="an object in the robot's hand at the start, held by friction")
    seed: int = Field(0, ge=0, description="draws the free spots and yaws the placements leave out")
    name: str = ""
    _source: YamlSource | None = PrivateAttr(None)  # the file it was read from: errors found later name its lines

    def where(self, *path: str | int) -> str | None:
        """file:line of a key of the scene file (``where("objects", 2)``); None for a scene made in code."""
        return self._source.where(path) if self._source is not None else None

    def instances(self) -> list[tuple[str, str]]:
        """Every object of the scene as (its name in a run, the world object it is one of): the one in hand
        first, then the placements in order, numbered per object: "coke", "coke 2", "coke 3"."""
        counts: dict[str, int] = {}
        named = []
        held = [self.holding.object] if self.holding is not None else []
        for obj in [*held, *(p.object for p in self.objects)]:
            counts[obj] = counts.get(obj, 0) + 1
            named.append((instance_name(obj, counts[obj]), obj))
        return named


def scene_names(world: WorldConfig) -> list[str]:
    """The scenes of ``world`` by name (its scenes/ folder)."""
    return sorted(p.stem for p in (world.folder / "scenes").glob("*.yaml"))


def scene_path(world: WorldConfig, scene: str, base: Path | None = None) -> Path:
    """A scene given by name (``scenes/NAME.yaml`` of the world) or by path (a .yaml file, relative to ``base``
    when given: the folder of the mission that names it)."""
    given = Path(scene)
    if given.suffix in (".yaml", ".yml"):
        path = given if base is None or given.is_absolute() else base / given
        if not path.is_file():
            raise UserError(f"scene file not found: {display_path(path)}")
        return path
    named = world.folder / "scenes" / f"{scene}.yaml"
    if not named.is_file():
        valid = scene_names(world)
        hint = (
            did_you_mean(scene, valid) + "; or a scene file (.yaml)"
            if valid
            else f"world '{world.name}' has no scenes: its objects are fixed bodies of its model"
        )
        raise UserError(f"unknown scene '{scene}' of world '{world.name}'", hint=hint)
    return named


def load_scene(world: WorldConfig, scene: str, base: Path | None = None, named_at: str | None = None) -> SceneConfig:
    """Read a scene (by name or path, see ``scene_path``) and check it against ``world``: every name in it, and
    that its objects fit where it puts them. ``named_at``: where the scene was named (``mission.yaml:3``,
    ``--scene``), for an unknown scene."""
    try:
        path = scene_path(world, scene, base)
    except UserError as error:
        raise UserError(error.message, where=named_at, hint=error.hint) from None
    config, source = read_model(path, SceneConfig, "a scene: a mapping with objects:, robot_start:, holding:")
    config._source = source
    check_scene(config, world, source)
    named = config.model_copy(update={"name": config.name or path.stem})
    named._source = source
    return named


def check_scene(scene: SceneConfig, world: WorldConfig, source: YamlSource | None = None) -> None:
    """Every object, surface and place the scene names exists in ``world``; errors name file:line."""

    def where(*path: str | int) -> str | None:
        return source.where(path) if source is not None else None

    placeable = world.placeable
    if not placeable and (scene.objects or scene.holding is not None):
        first = ("objects", 0, "object") if scene.objects else ("holding", "object")
        raise UserError(
            f"world '{world.name}' has no objects a scene can place: its objects are fixed bodies of its model",
            where=where(*first),
            hint="scenes place the objects world.yaml gives by a model: (worlds/kitchen); "
            "here, leave out objects: and holding:",
        )
    for index, placement in enumerate(scene.objects):
        if placement.object not in placeable:
            raise UserError(
                f"objects[{index}]: '{placement.object}' is not an object scenes can place in world '{world.name}'",
                where=where("objects", index, "object"),
                hint=did_you_mean(placement.object, placeable),
            )
        if placement.on not in world.surfaces:
            raise UserError(
                f"objects[{index}]: unknown surface '{placement.on}'",
                where=where("objects", index, "on"),
                hint=did_you_mean(placement.on, world.surfaces),
            )
    if scene.holding is not None and scene.holding.object not in placeable:
        raise UserError(
            f"holding: '{scene.holding.object}' is not an object scenes can place in world '{world.name}'",
            where=where("holding", "object"),
            hint=did_you_mean(scene.holding.object, placeable),
        )
    if isinstance(scene.robot_start, str) and scene.robot_start not in world.places:
        raise UserError(
            f"robot_start: unknown place '{scene.robot_start}'",
            where=where("robot_start"),
            hint=did_you_mean(scene.robot_start, world.places),
        )
    if scene.robot_start is not None and not isinstance(scene.robot_start, str):
        outside = world.outside_map(*scene.robot_start[:2])
        if outside:
            raise UserError(f"robot_start: {outside}", where=where("robot_start"))
    _check_placements(scene, world, source)


def _check_placements(scene: SceneConfig, world: WorldConfig, source: YamlSource | None) -> None:
    """The objects fit where the scene puts them: on their surface, apart, with a free spot for each left out."""
    from bt_humanoid.sim.scene_objects import SceneError, place_scene, surface_tops

    try:
        place_scene(world, scene, surface_tops(world))
    except SceneError as error:
        raise UserError(error.message, where=source.where(error.path) if source is not None else None) from None


def start_pose(scene: SceneConfig | None, world: WorldConfig) -> Pose2D:
    """Where the robot starts: the scene's place or pose, else the world's start."""
    if scene is None or scene.robot_start is None:
        return world.robot_start
    if isinstance(scene.robot_start, str):
        return world.places[scene.robot_start].pose
    return scene.robot_start
