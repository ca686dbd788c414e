"""What a household instruction asks for, judged the same way on a plan and on a finished run.

An instruction's ``expect:`` says what must be true at the end: "bring me
three drinks" is ``{delivered: drink, count: 3}``. An object is chosen by a
*selector*: a name (any instance of it: "coke" also means a scene's
"coke 2"), an instance name, a kind or a category from world.yaml, or a list
of those meaning any of them.

Both sides are reduced to a ``Situation`` — where each thing is (on a
surface, in a bin, in the hand, handed over), where the robot ends and which
places it visited:

- the plan's, by carrying its steps out symbolically (``plan_situation``):
  planning accuracy is whether the plan would do what was asked, and nothing
  else (a plan that also moves something nobody mentioned is wrong);
- the run's, from the simulator's ground truth (``truth_situation``):
  execution success.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Literal

from pydantic import Field, model_validator

from bt_humanoid.sim.ground_truth import GroundTruth
from bt_humanoid.sim.scene_config import SceneConfig
from bt_humanoid.sim.world_config import WorldConfig
from bt_humanoid.strict_model import StrictModel

GoalKind = Literal["delivered", "on", "inside", "in_hand", "at", "visited", "cleared"]
ANY_SURFACE = "any"
PERSON = "person"
PLACE_REACHED = 0.35  # m from a place's pose: the robot is there
PERSON_REACHED = 1.5  # m from a person: the robot came to them

# where a thing is: ("on", surface), ("inside", bin), ("hand", side), ("delivered", person), ("tipped", surface),
# ("floor", "")
Where = tuple[str, str]


class Goal(StrictModel):
    """One expected condition: exactly one of the kinds, and how many things must meet it."""

    delivered: str | list[str] | None = Field(None, description="handed to the person")
    on: tuple[str | list[str], str] | None = Field(None, description="[selector, surface or 'any']")
    inside: tuple[str | list[str], str] | None = Field(None, description="[selector, bin]")
    in_hand: str | list[str] | None = Field(None, description="the robot holds it at the end")
    at: str | None = Field(None, description="a place, or 'person': where the robot ends")
    visited: list[str] | None = Field(None, description="places the robot went to on the way")
    cleared: str | None = Field(None, description="a surface: nothing that stood on it at the start still does")
    count: int | Literal["all"] = Field(1, description="how many distinct things, or all that match in the scene")

    @model_validator(mode="after")
    def _one_kind(self) -> Goal:
        given = [kind for kind in GoalKind.__args__ if getattr(self, kind) is not None]  # type: ignore[attr-defined]
        if len(given) != 1:
            raise ValueError(f"give exactly one of {', '.join(GoalKind.__args__)}, not {given or 'none'}")  # type: ignore[attr-defined]
        if isinstance(self.count, int) and self.count < 1:
            raise ValueError(f"count: {self.count}: give 1 or more, or 'all'")
        return self

    @property
    def kind(self) -> str:
        return next(k for k in GoalKind.__args__ if getattr(self, k) is not None)  # type: ignore[attr-defined]

    @property
    def selector(self) -> list[str]:
        """The things the goal is about (empty for the robot's own goals)."""
        value = {"delivered": self.delivered, "in_hand": self.in_hand}.get(self.kind)
        if self.on is not None:
            value = self.on[0]
        if self.inside is not None:
            value = self.inside[0]
        if value is None:
            return []
        return [value] if isinstance(value, str) else list(value)

    def wants(self, where: Where) -> bool:
        """Whether a thing standing ``where`` meets this goal."""
        if self.delivered is not None:
            return where[0] == "delivered"
        if self.on is not None:
            return where[0] == "on" and self.on[1] in (ANY_SURFACE, where[1])
        if self.inside is not None:
            return where == ("inside", self.inside[1])
        if self.in_hand is not None:
            return where[0] == "hand"
        return False

    def describe(self) -> str:
        what = " or ".join(self.selector)
        many = "" if self.count == 1 else f" ({self.count})"
        if self.on is not None:
            return f"{what} on {self.on[1]}{many}"
        if self.inside is not None:
            return f"{what} in {self.inside[1]}{many}"
        if self.at is not None:
            return f"robot at {self.at}"
        if self.visited is not None:
            return f"visited {', '.join(self.visited)}"
        if self.cleared is not None:
            return f"{self.cleared} cleared"
        return f"{what} {self.kind.replace('_', ' ')}{many}"


@dataclass
class Situation:
    """Where every thing of a scene is, where the robot is and which places it has been to."""

    things: dict[str, Where]
    robot_at: str | None = None
    visited: set[str] = field(default_factory=set)


class Catalogue:
    """What a scene's things are called: each instance's names, kind and categories, for selectors."""

    def __init__(self, world: WorldConfig, instances: list[tuple[str, str]]) -> None:
        self.world = world
        self.instances = dict(instances)  # instance name → world object
        self.words: dict[str, set[str]] = {}
        for name, obj in instances:
            declared = world.objects[obj]
            self.words[name] = {name, obj, declared.kind, *declared.aliases, *declared.categories}

    @classmethod
    def of_scene(cls, world: WorldConfig, scene: SceneConfig) -> Catalogue:
        return cls(world, scene.instances())

    def matching(self, selector: list[str]) -> list[str]:
        """The scene's things a selector picks, in scene order."""
        wanted = set(selector)
        return [name for name, words in self.words.items() if words & wanted]

    def known(self, word: str) -> bool:
        """Whether a selector word names anything the world knows (in this scene or not)."""
        every = {w for o, d in self.world.objects.items() for w in (o, d.kind, *d.aliases, *d.categories)}
        return word in every or word in self.instances


def unmet(goals: list[Goal], start: Situation, end: Situation, catalogue: Catalogue) -> list[str]:
    """The goals a situation fails, each as a line saying what was wanted and what there is."""
    failures = []
    for goal in goals:
        if goal.at is not None:
            if end.robot_at != goal.at:
                failures.append(f"robot at {goal.at} (it is at {end.robot_at or 'no named place'})")
            continue
        if goal.visited is not None:
            missing = [p for p in goal.visited if p not in end.visited]
            if missing:
                failures.append(f"visited {', '.join(missing)} (went to {', '.join(sorted(end.visited)) or 'none'})")
            continue
        if goal.cleared is not None:
            left = [n for n, w in start.things.items() if w == ("on", goal.cleared) and end.things[n][0] == "on"]
            left = [n for n in left if end.things[n] == ("on", goal.cleared)]
            if left:
                failures.append(f"{goal.cleared} cleared ({', '.join(left)} still on it)")
            continue
        candidates = catalogue.matching(goal.selector)
        needed = len(candidates) if goal.count == "all" else goal.count
        meeting = [n for n in candidates if goal.wants(end.things[n])]
        if len(meeting) < max(needed, 1):
            failures.append(f"{goal.describe()}: {len(meeting)} of {needed} ({_places(candidates, end)})")
    return failures


def overreach(goals: list[Goal], start: Situation, end: Situation, catalogue: Catalogue) -> list[str]:
    """What a plan does beyond what was asked: a thing moved that no goal covers, or more than a count asked. A
    thing held at the start may be set down on a surface: the hand is needed for what was asked."""
    moved = [n for n, w in end.things.items() if w != start.things[n]]
    problems = []
    for name in moved:
        covering = [g for g in goals if name in catalogue.matching(g.selector) and g.wants(end.things[name])]
        cleared = [g for g in goals if g.cleared is not None and start.things[name] == ("on", g.cleared)]
        set_down = start.things[name][0] == "hand" and end.things[name][0] == "on"  # to free the hand: fine
        if not covering and not cleared and not set_down:
            problems.append(f"{name} moved to {_say(end.things[name])}, which was not asked")
    for goal in goals:
        if isinstance(goal.count, int) and goal.selector:
            into = [n for n in moved if n in catalogue.matching(goal.selector) and goal.wants(end.things[n])]
            if len(into) > goal.count:
                problems.append(f"{goal.describe()}: {len(into)} moved, {goal.count} asked")
    return problems


def _places(names: list[str], situation: Situation) -> str:
    shown = [f"{n}: {_say(situation.things[n])}" for n in names[:6]]
    return "; ".join(shown) + ("; …" if len(names) > 6 else "") if names else "none in the scene"


def _say(where: Where) -> str:
    kind, at = where
    return {"on": f"on {at}", "inside": f"in {at}", "hand": "in hand", "delivered": "handed over"}.get(
        kind, f"{kind} {at}".strip()
    )


# --- the start, a plan's end and a run's end ---------------------------------------------------------------------


def scene_situation(scene: SceneConfig, world: WorldConfig) -> Situation:
    """Where things stand at the start: as the scene places them, the held one in hand, the robot at the place
    it starts at or beside."""
    things: dict[str, Where] = {}
    for (name, _), placement in zip(scene.instances()[1 if scene.holding else 0 :], scene.objects, strict=True):
        things[name] = ("on", placement.on)
    if scene.holding is not None:
        things[scene.instances()[0][0]] = ("hand", scene.holding.hand)
    start = scene.robot_start or world.robot_start
    if isinstance(start, str):
        return Situation(things, robot_at=start)
    x, y = start[0], start[1]
    near = [p for p, place in world.places.items() if math.dist((x, y), place.pose[:2]) <= PLACE_REACHED]
    return Situation(things, robot_at=near[0] if near else None)


class PlanInvalid(Exception):
    """A step the plan cannot carry out in the situation it reaches (taking with a full hand, an unknown thing)."""


def plan_situation(
    tree: dict[str, Any], start: Situation, world: WorldConfig, instances: dict[str, str] | None = None
) -> Situation:
    """Where things end if every step of a plan does what it says (a symbolic run of the mission tree).
    ``instances``: the scene instance each robot id a plan may use stands for."""
    state = Situation(dict(start.things), start.robot_at, set(start.visited))
    _carry_out(tree, state, world, instances or {})
    return state


def _carry_out(node: dict[str, Any], state: Situation, world: WorldConfig, instances: dict[str, str]) -> None:
    kind, params = next(iter(node.items()))
    if kind in ("name", "description"):  # a node's label sits beside its kind
        kind, params = next((k, v) for k, v in node.items() if k not in ("name", "description"))
    if kind in ("sequence", "fallback", "parallel"):
        children = params if isinstance(params, list) else params["children"]
        for child in children if kind != "fallback" else children[:1]:  # a fallback does its first choice
            _carry_out(child, state, world, instances)
        return
    params = params or {}
    if kind in ("take", "fetch", "throw_away", "pick"):
        name = str(params["object"])
        _take(instances.get(name, name), state)
    if kind in ("fetch", "place"):
        surface = str(params.get("to") or params.get("surface"))
        state.things[_held(state, kind)] = ("on", surface)
        state.robot_at = world.surfaces[surface].place if surface in world.surfaces else None
    elif kind in ("throw_away", "drop"):
        container = str(params["into"])
        state.things[_held(state, kind)] = ("inside", container)
        state.robot_at = world.containers[container].place if container in world.containers else None
    elif kind in ("give", "hand_over"):  # judged as meant: in the person's hand
        state.things[_held(state, kind)] = ("delivered", str(params.get("to", PERSON)))
        state.robot_at = PERSON
    elif kind == "navigate":
        if params.get("person"):
            state.robot_at = PERSON
        elif params.get("place"):
            state.robot_at = str(params["place"])
            state.visited.add(state.robot_at)
        else:
            state.robot_at = None
    elif kind in ("take", "pick"):
        state.robot_at = None


def _take(name: str, state: Situation) -> None:
    if name.startswith("$"):
        raise PlanInvalid(f"takes '{name}', a thing found at run time, which a plan cannot be judged on")
    if name not in state.things:
        raise PlanInvalid(f"takes '{name}', which is not in the scene")
    held = [n for n, w in state.things.items() if w[0] == "hand"]
    if held == [name]:
        raise PlanInvalid(f"takes the {name}, which it already holds")
    if held:
        raise PlanInvalid(f"takes the {name} while holding the {held[0]}")
    state.things[name] = ("hand", "right")


def _held(state: Situation, kind: str) -> str:
    held = [n for n, w in state.things.items() if w[0] == "hand"]
    if not held:
        raise PlanInvalid(f"{kind} with an empty hand")
    return held[0]


def truth_situation(truth: GroundTruth, visited: set[str]) -> Situation:
    """Where things are in the simulator now, where the robot is, and the places it was seen at."""
    world = truth.sim.world
    things: dict[str, Where] = {}
    for name, obj in truth.sim.object_kinds.items():
        things[name] = _where(truth, name, world.objects[obj].upright)
    x, y, _ = truth.robot_pose()
    at = next(iter(places_reached(truth)), None)
    if at is None and any(math.dist((x, y), truth.person_position(p)[:2]) <= PERSON_REACHED for p in world.people):
        at = PERSON
    return Situation(things, robot_at=at, visited=set(visited))


def _where(truth: GroundTruth, name: str, keeps_upright: bool) -> Where:
    world = truth.sim.world
    side = truth.in_hand(name)
    if side is not None:
        return ("hand", side)
    for container in world.containers:
        if truth.inside(name, container):
            return ("inside", container)
    for surface in world.surfaces:
        if truth.rests_on(name, surface):
            return ("on", surface) if truth.upright(name) or not keeps_upright else ("tipped", surface)
    person = truth.held_by_person(name)
    return ("delivered", person) if person is not None else ("floor", "")


def places_reached(truth: GroundTruth) -> list[str]:
    """The places the robot stands at now (called while a run steps, to collect ``visited``)."""
    x, y, _ = truth.robot_pose()
    return [p for p, place in truth.sim.world.places.items() if math.dist((x, y), place.pose[:2]) <= PLACE_REACHED]
