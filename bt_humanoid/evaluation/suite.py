"""Benchmark suites: what ``bt-eval SUITE`` runs, as a validated YAML file (missions/benchmarks/*.yaml).

A suite says which tasks to run (typed commands with ``{object}`` and
``{surface}`` slots, or mission files), over which objects and surfaces,
the scene episodes start from (``scene:``, in a world with scenes), how
scenes are randomized (object spots, a random scene of the world's objects,
the robot's start, obstacle nudges), how many episodes from which seed, and
which share of episodes get an injected fault. Episodes are drawn from the seed alone, so the same suite
and seed give the same episodes on any machine and with any worker count.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Literal

from pydantic import Field, model_validator

from bt_humanoid.errors import UserError, did_you_mean
from bt_humanoid.evaluation.faults import FAULT_MODELS, FaultConfig
from bt_humanoid.evaluation.goals import Catalogue, Goal
from bt_humanoid.mission.loader import MissionLoader
from bt_humanoid.sim.robot_config import load_robot_config
from bt_humanoid.sim.scene_config import Placement, SceneConfig, load_scene
from bt_humanoid.sim.world_config import WorldConfig, load_world_config
from bt_humanoid.strict_model import StrictModel, exactly_one
from bt_humanoid.yaml_source import YamlSource, read_model


class Task(StrictModel):
    """One kind of episode: a command to plan and run, or a mission file to run as written."""

    command: str | None = Field(None, description="typed command; {object} and {surface} are filled per episode")
    mission: str | None = Field(None, description="mission file, relative to the suite file")
    expect: list[dict[str, Any]] = Field(
        default_factory=list,
        description="success conditions checked in ground truth (mission kinds, plus delivered); slots filled",
    )
    weight: float = Field(1.0, gt=0, le=1000, description="how often this task is drawn, relative to the others")

    @model_validator(mode="after")
    def _one_source(self) -> Task:
        exactly_one(self, "command", "mission")
        if self.command is not None and not self.expect:
            raise ValueError("a command task needs expect: (the conditions that mean it was done)")
        return self


FAMILIES = ("primitives", "verbs", "nouns", "structured", "embodiment", "crowd", "long_horizon")


class Instruction(StrictModel):
    """One household instruction: what a person says, in which scene, and what must be true when it is done."""

    say: str = Field(min_length=1, description="what the person types (or says)")
    family: Literal[FAMILIES] = Field(description="the family of instructions it belongs to (SayCan's)")  # type: ignore[valid-type]
    scene: str = Field(description="the scene it starts from: a name in the world's scenes/, or a file")
    expect: list[Goal] = Field(min_length=1, description="what must be true at the end (evaluation/goals.py)")


class SceneDraw(StrictModel):
    """A random scene for each episode: some of the world's objects (those scenes place) on some surfaces."""

    objects: tuple[int, int] = Field(
        description="[fewest, most] objects in an episode's scene, the episode's {object} among them"
    )
    surfaces: list[str] = Field(min_length=1, description="surfaces they stand on, at random spots the hand reaches")
    among: list[str] = Field(
        default_factory=list,
        description='objects to draw from, as many of each as drawn ("coke", "coke 2"), the episode\'s {object} '
        "once only; none: every one scenes place",
    )

    @model_validator(mode="after")
    def _range(self) -> SceneDraw:
        fewest, most = self.objects
        if not 1 <= fewest <= most <= 40:
            raise ValueError(f"objects: [{fewest}, {most}] is no range: give [fewest, most], 1 <= fewest <= most <= 40")
        return self


class Randomize(StrictModel):
    """How each episode's scene differs from the world file."""

    start: Literal["world", "random"] = Field("random", description="robot start: the world's, or a random free pose")
    object_on: list[str] = Field(
        default_factory=list, description="surfaces the episode's object starts on, at a random reachable spot"
    )
    scene: SceneDraw | None = Field(
        None, description="draw each episode's objects anew (the suite's scene keeps its start and what is held)"
    )
    obstacles: list[str] = Field(default_factory=list, description="obstacle bodies nudged by up to obstacle_shift")
    obstacle_shift: float = Field(0.25, ge=0, le=1.0, description="m, largest nudge of an obstacle")


class FaultPlan(StrictModel):
    share: float = Field(0.0, ge=0, le=1, description="fraction of episodes that get one injected fault")
    kinds: list[FaultConfig] = Field(default_factory=list, description="faults to draw from, one per faulted episode")
    order: Literal["random", "cycle"] = Field(
        "random", description="draw a kind at random, or take them in turn (episode i gets kind i mod N)"
    )

    @model_validator(mode="after")
    def _kinds_when_shared(self) -> FaultPlan:
        if self.share > 0 and not self.kinds:
            raise ValueError(f"share is {self.share} but no fault kinds are given; kinds: {', '.join(FAULT_MODELS)}")
        return self


class Suite(StrictModel):
    suite: str = Field(description="the suite's name")
    description: str = ""
    world: str = Field("apartment", description="a folder of worlds/")
    robot: str = Field("wheeled_humanoid", description="a folder of robots/")
    scene: str | None = Field(
        None,
        description="the scene episodes start from: a name in the world's scenes/, or a file relative to the suite; "
        "none: the world's own",
    )
    episodes: int = Field(20, ge=1, le=100_000, description="how many episodes")
    seed: int = Field(0, ge=0, description="draws every episode's scene, task and fault")
    objects: list[str] = Field(default_factory=list, description="objects for {object}, one drawn per episode")
    surfaces: list[str] = Field(default_factory=list, description="surfaces for {surface}, one drawn per episode")
    tasks: list[Task] = Field(default_factory=list, description="kinds of episode, drawn per episode")
    instructions: list[Instruction] = Field(
        default_factory=list, description="household instructions, one episode each, in order (instead of tasks)"
    )
    randomize: Randomize = Randomize()
    faults: FaultPlan = FaultPlan()
    time_budget: float | dict[str, float] = Field(
        300.0,
        description="simulation seconds per episode: one for every robot, or per robot ({wheeled_humanoid: 300, "
        "biped_humanoid: 900}: a walking robot takes longer over the same job)",
    )

    @property
    def episode_budget(self) -> float:
        """The simulation seconds each episode may take with the suite's robot."""
        if isinstance(self.time_budget, dict):
            return self.time_budget[self.robot]  # present: load_suite checked it
        return self.time_budget

    @model_validator(mode="after")
    def _budgets_in_range(self) -> Suite:
        budgets = self.time_budget.values() if isinstance(self.time_budget, dict) else [self.time_budget]
        if any(not 0 < budget <= 86400 for budget in budgets):
            raise ValueError("a time budget is simulation seconds, more than 0 and at most 86400")
        return self

    @model_validator(mode="after")
    def _tasks_or_instructions(self) -> Suite:
        if bool(self.tasks) == bool(self.instructions):
            raise ValueError("give tasks: (episodes drawn from them) or instructions: (one episode each), not both")
        if self.instructions and "episodes" not in self.model_fields_set:
            self.episodes = len(self.instructions)
        return self


def load_suite(file: Path, scene: str | None = None, robot: str | None = None) -> tuple[Suite, WorldConfig]:
    """A validated suite and its world; a UserError at file:line for anything wrong. ``scene`` (by name, or a
    file relative to the working directory) replaces the suite's, and ``robot`` (a folder of robots/) its robot;
    the suite returned names its scene so that it loads from anywhere (a file's path made absolute)."""
    suite, source = read_model(file, Suite, "a suite is a mapping (suite:, tasks:, ...)")
    if robot is not None:
        try:
            load_robot_config(robot)
        except UserError as error:
            raise UserError(f"--robot {robot}: {error.message}", hint=error.hint) from None
        suite = suite.model_copy(update={"robot": robot})
    world = _world(suite, source)
    if scene is not None:
        suite = suite.model_copy(update={"scene": _absolute(scene, Path.cwd())})
        start = load_scene(world, scene, named_at="--scene")
    elif suite.scene is not None:
        suite = suite.model_copy(update={"scene": _absolute(suite.scene, file.parent)})
        start = load_scene(world, suite.scene, named_at=source.where(("scene",)))
    else:
        start = (
            load_scene(world, world.scene, named_at=f"worlds/{world.folder.name}/world.yaml") if world.scene else None
        )
    _check_names(suite, world, source)
    _check_budget(suite, source)
    _check_scene_draw(suite, world, source)
    _check_objects_in_scene(suite, world, start, source)
    _check_tasks(suite, source, _names_scene(suite, world, start))
    _check_instructions(suite, world, source, file.parent)
    return suite, world


def suite_scene(suite: Suite, world: WorldConfig) -> SceneConfig | None:
    """The scene a suite's episodes start from (checked when the suite was loaded): its own, else the world's."""
    name = suite.scene or world.scene
    return load_scene(world, name) if name is not None else None


def _absolute(scene: str, base: Path) -> str:
    """A scene file's path made absolute (from ``base``); a scene's name as it is."""
    return str((base / scene).resolve()) if Path(scene).suffix in (".yaml", ".yml") else scene


def _world(suite: Suite, source: YamlSource) -> WorldConfig:
    try:
        return load_world_config(suite.world)
    except UserError as error:
        raise UserError(error.message, where=source.where(("world",)), hint=error.hint) from None


def _check_budget(suite: Suite, source: YamlSource) -> None:
    """A budget per robot names the robot the suite runs (its own, or --robot's)."""
    if isinstance(suite.time_budget, dict) and suite.robot not in suite.time_budget:
        given = ", ".join(suite.time_budget)
        raise UserError(
            f"time_budget gives no budget for robot '{suite.robot}' (it gives them for {given})",
            where=source.where(("time_budget",)),
            hint=f"add '{suite.robot}: SECONDS' to it, or give one number for every robot",
        )


def _check_names(suite: Suite, world: WorldConfig, source: YamlSource) -> None:
    for index, name in enumerate(suite.objects):  # a world object, or a scene's ("coke 2", a second coke)
        if world.object_of(name) is None:
            hint = did_you_mean(name, world.objects)
            raise UserError(f"unknown name '{name}'", where=source.where(("objects", index)), hint=hint)
    checks = [
        (("surfaces",), suite.surfaces, world.surfaces),
        (("randomize", "object_on"), suite.randomize.object_on, world.surfaces),
        (("randomize", "obstacles"), suite.randomize.obstacles, world.obstacles),
    ]
    for path, names, known in checks:
        for index, name in enumerate(names):
            if name not in known:
                hint = did_you_mean(name, known)
                raise UserError(f"unknown name '{name}'", where=source.where((*path, index)), hint=hint)


def _check_scene_draw(suite: Suite, world: WorldConfig, source: YamlSource) -> None:
    """A random scene draws objects scenes can place, on known surfaces; the episode's {object} is one of them."""
    draw = suite.randomize.scene
    if draw is None:
        return
    placeable = world.placeable
    if not placeable:
        raise UserError(
            f"world '{world.name}' has no objects a scene can place: its objects are fixed bodies of its model",
            where=source.where(("randomize", "scene")),
            hint="leave out randomize.scene, or use a world whose objects are models (kitchen)",
        )
    checks = [
        (("randomize", "scene", "surfaces"), draw.surfaces, world.surfaces),
        (("randomize", "scene", "among"), draw.among, placeable),
    ]
    for path, names, known in checks:
        for index, name in enumerate(names):
            if name not in known:
                raise UserError(
                    f"unknown name '{name}'", where=source.where((*path, index)), hint=did_you_mean(name, known)
                )
    for index, name in enumerate(suite.objects):
        if name not in placeable:
            raise UserError(
                f"'{name}' is not an object a random scene can place",
                where=source.where(("objects", index)),
                hint=did_you_mean(name, placeable),
            )


def _check_objects_in_scene(suite: Suite, world: WorldConfig, scene: SceneConfig | None, source: YamlSource) -> None:
    """Without a random scene, the episode's {object} must be an object of the run: the world's or its scene's."""
    if suite.randomize.scene is not None:
        return
    present = _run_objects(world, scene)
    for index, name in enumerate(suite.objects):
        if name not in present:
            where = f"scene '{scene.name}'" if scene is not None else f"world '{world.name}'"
            raise UserError(
                f"no '{name}' in {where}: an episode's object must be in the scene it starts from",
                where=source.where(("objects", index)),
                hint=did_you_mean(name, present) if present else "the scene places no objects",
            )


def _run_objects(world: WorldConfig, scene: SceneConfig | None) -> list[str]:
    """The names of a run's objects: the world's fixed bodies and the scene's instances."""
    fixed = [name for name, o in world.objects.items() if o.body is not None]
    return fixed + ([name for name, _ in scene.instances()] if scene is not None else [])


def _names_scene(suite: Suite, world: WorldConfig, scene: SceneConfig | None) -> SceneConfig | None:
    """The scene whose object names expectations may use: the one episodes start from, or, for random scenes,
    one with each object the draws may name (the episode's object is always the first of its kind)."""
    draw = suite.randomize.scene
    if draw is None:
        return scene
    names = list(dict.fromkeys([*suite.objects, *(draw.among or world.placeable)]))
    return SceneConfig(objects=[Placement(object=name, on=draw.surfaces[0]) for name in names], name="random")


def _check_tasks(suite: Suite, source: YamlSource, scene: SceneConfig | None = None) -> None:
    """Every task fills its slots, and its expectations (and a new command's) are valid conditions on the world."""
    for index, task in enumerate(suite.tasks):
        text = task.command or ""
        for slot, names in (("object", suite.objects), ("surface", suite.surfaces)):
            if "{" + slot + "}" in text + str(task.expect) and not names:
                raise UserError(
                    f"the task uses {{{slot}}} but the suite lists no {slot}s", where=source.where(("tasks", index))
                )
        _check_expect(task.expect, ("tasks", index, "expect"), suite, source, scene)
        if task.mission is not None and not (source.file.parent / task.mission).is_file():
            raise UserError(f"mission file not found: {task.mission}", where=source.where(("tasks", index, "mission")))
    for index, fault in enumerate(suite.faults.kinds):
        if fault.new_command is not None:
            path = ("faults", "kinds", index, "new_command", "expect")
            _check_expect(fault.new_command.expect, path, suite, source, scene)


def _check_expect(
    expect: list[dict[str, Any]], path: tuple, suite: Suite, source: YamlSource, scene: SceneConfig | None
) -> None:
    """Success conditions checked the way a mission's are (kinds, fields, names), with the first names drawn."""
    slots = {"object": (suite.objects or [""])[0], "surface": (suite.surfaces or [""])[0]}
    probe = {"mission": "check", "world": suite.world, "robot": suite.robot, "tree": {"wait": {"seconds": 0}}}
    try:
        MissionLoader(scene=scene).load_data({**probe, "success": fill(expect, slots)}, name="<expect>")
    except UserError as error:
        raise UserError(f"expect: {error.message}", where=source.where(path), hint=error.hint) from None


def fill(value: Any, slots: dict[str, str]) -> Any:
    """``value`` with every ``{slot}`` in its strings replaced."""
    if isinstance(value, str):
        for slot, name in slots.items():
            value = value.replace("{" + slot + "}", name)
        return value
    if isinstance(value, list):
        return [fill(item, slots) for item in value]
    if isinstance(value, dict):
        return {key: fill(item, slots) for key, item in value.items()}
    return value


def instruction_scene(suite: Suite, index: int, folder: Path, world: WorldConfig) -> SceneConfig:
    """The scene instruction ``index`` starts from (a name, or a file relative to the suite's ``folder``)."""
    scene = suite.instructions[index].scene
    return load_scene(world, str(folder / scene) if Path(scene).suffix in (".yaml", ".yml") else scene)


def _check_instructions(suite: Suite, world: WorldConfig, source: YamlSource, folder: Path) -> None:
    """Each instruction's scene loads, and its goals name things of that scene, in numbers it holds."""
    for index, instruction in enumerate(suite.instructions):
        at = ("instructions", index)
        try:
            scene = instruction_scene(suite, index, folder, world)
        except UserError as error:
            raise UserError(error.message, where=source.where((*at, "scene")), hint=error.hint) from None
        catalogue = Catalogue.of_scene(world, scene)
        for number, goal in enumerate(instruction.expect):
            where = source.where((*at, "expect", number))
            for word in goal.selector:
                if not catalogue.known(word):
                    raise UserError(f"'{word}' names nothing in world '{world.name}'", where=where)
            if goal.selector and not catalogue.matching(goal.selector):
                raise UserError(f"nothing in scene '{scene.name}' is a {' or '.join(goal.selector)}", where=where)
            needed = goal.count if isinstance(goal.count, int) else 1
            if goal.selector and len(catalogue.matching(goal.selector)) < needed:
                raise UserError(
                    f"count {needed}, but scene '{scene.name}' has {len(catalogue.matching(goal.selector))}",
                    where=where,
                )
            names = [
                (goal.on[1] if goal.on else None, [*world.surfaces, "any"]),
                (goal.cleared, list(world.surfaces)),
                (goal.inside[1] if goal.inside else None, list(world.containers)),
                (goal.at, [*world.places, "person"]),
                *((place, list(world.places)) for place in goal.visited or []),
            ]
            for name, known in names:
                if name is not None and name not in known:
                    raise UserError(f"unknown name '{name}'", where=where, hint=did_you_mean(name, known))
