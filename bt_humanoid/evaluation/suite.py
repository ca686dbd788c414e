"""Benchmark suites: what ``bt-eval SUITE`` runs, as a validated YAML file (missions/benchmarks/*.yaml).

A suite says which tasks to run (typed commands with ``{object}`` and
``{surface}`` slots, or mission files), over which objects and surfaces,
how scenes are randomized (object spots, the robot's start, obstacle
nudges), how many episodes from which seed, and which share of episodes get
an injected fault. Episodes are drawn from the seed alone, so the same suite
and seed give the same episodes on any machine and with any worker count.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Literal

from pydantic import Field, model_validator

from bt_humanoid.errors import UserError, did_you_mean
from bt_humanoid.evaluation.faults import FAULT_MODELS, FaultConfig
from bt_humanoid.mission.loader import MissionLoader
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


class Randomize(StrictModel):
    """How each episode's scene differs from the world file."""

    start: Literal["world", "random"] = Field("random", description="robot start: the world's, or a random free pose")
    object_on: list[str] = Field(
        default_factory=list, description="surfaces the episode's object starts on, at a random reachable spot"
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
    episodes: int = Field(20, ge=1, le=100_000, description="how many episodes")
    seed: int = Field(0, ge=0, description="draws every episode's scene, task and fault")
    objects: list[str] = Field(default_factory=list, description="objects for {object}, one drawn per episode")
    surfaces: list[str] = Field(default_factory=list, description="surfaces for {surface}, one drawn per episode")
    tasks: list[Task] = Field(min_length=1)
    randomize: Randomize = Randomize()
    faults: FaultPlan = FaultPlan()
    time_budget: float = Field(300.0, gt=0, le=86400, description="simulation seconds per episode")


def load_suite(file: Path) -> tuple[Suite, WorldConfig]:
    """A validated suite and its world; a UserError at file:line for anything wrong."""
    suite, source = read_model(file, Suite, "a suite is a mapping (suite:, tasks:, ...)")
    world = _world(suite, source)
    _check_names(suite, world, source)
    _check_tasks(suite, source)
    return suite, world


def _world(suite: Suite, source: YamlSource) -> WorldConfig:
    try:
        return load_world_config(suite.world)
    except UserError as error:
        raise UserError(error.message, where=source.where(("world",)), hint=error.hint) from None


def _check_names(suite: Suite, world: WorldConfig, source: YamlSource) -> None:
    checks = [
        (("objects",), suite.objects, world.objects),
        (("surfaces",), suite.surfaces, world.surfaces),
        (("randomize", "object_on"), suite.randomize.object_on, world.surfaces),
        (("randomize", "obstacles"), suite.randomize.obstacles, world.obstacles),
    ]
    for path, names, known in checks:
        for index, name in enumerate(names):
            if name not in known:
                hint = did_you_mean(name, known)
                raise UserError(f"unknown name '{name}'", where=source.where((*path, index)), hint=hint)


def _check_tasks(suite: Suite, source: YamlSource) -> None:
    """Every task fills its slots, and its expectations (and a new command's) are valid conditions on the world."""
    for index, task in enumerate(suite.tasks):
        text = task.command or ""
        for slot, names in (("object", suite.objects), ("surface", suite.surfaces)):
            if "{" + slot + "}" in text + str(task.expect) and not names:
                raise UserError(
                    f"the task uses {{{slot}}} but the suite lists no {slot}s", where=source.where(("tasks", index))
                )
        _check_expect(task.expect, ("tasks", index, "expect"), suite, source)
        if task.mission is not None and not (source.file.parent / task.mission).is_file():
            raise UserError(f"mission file not found: {task.mission}", where=source.where(("tasks", index, "mission")))
    for index, fault in enumerate(suite.faults.kinds):
        if fault.new_command is not None:
            _check_expect(fault.new_command.expect, ("faults", "kinds", index, "new_command", "expect"), suite, source)


def _check_expect(expect: list[dict[str, Any]], path: tuple, suite: Suite, source: YamlSource) -> None:
    """Success conditions checked the way a mission's are (kinds, fields, names), with the first names drawn."""
    slots = {"object": (suite.objects or [""])[0], "surface": (suite.surfaces or [""])[0]}
    probe = {"mission": "check", "world": suite.world, "robot": suite.robot, "tree": {"wait": {"seconds": 0}}}
    try:
        MissionLoader().load_data({**probe, "success": fill(expect, slots)}, name="<expect>")
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
