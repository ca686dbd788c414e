"""The WorldModel: what the robot believes about objects and support surfaces.

Skills and planners read objects and surfaces from here, never from the
simulator. The map gives surfaces, people and the names of things
(``map_knowledge.py``); the head camera finds objects (``perceiver.py``);
and the robot's own actions move beliefs: an object it holds moves with its
hand, an object it put down is where it let go.
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, field

import numpy as np

from bt_humanoid.errors import did_you_mean


@dataclass
class TrackedObject:
    """One object as believed: pose of its centre, extents, and how sure we are."""

    id: str  # unique, stable (e.g. the body name)
    name: str  # what people call it ("red cube")
    kind: str  # cube, bottle, mug, ball, ...
    colour: str
    position: np.ndarray  # centre, world frame (m)
    yaw: float  # rad about world z
    size: np.ndarray  # full extents (x, y, z) in the object's frame (m)
    confidence: float = 1.0
    last_seen: float = 0.0  # s of simulation time
    first_seen: float = 0.0  # s of simulation time it was first seen (where it is now)
    keep_upright: bool = False
    held_by: str | None = None  # gripper side while the robot holds it
    grip_offset: float = 0.0  # m the grip site sits above the centre, while held
    weight: float | None = None  # kg, as the wrist weighed it once lifted (robots with a wrist sensor)
    # base (x, y) the next stance to work on it stands at: where the hand fell short of it from, moved by the miss
    step_to: np.ndarray | None = None
    yaw_known: bool = True  # false while a mug's handle has not been seen (its yaw is a guess)
    votes: Counter = field(default_factory=Counter)  # (kind, colour, identity) → sightings, near ones weighing more
    identity: str | None = None  # which of the world's objects it is ("coke"), where its look tells them apart
    seen_from: float = 0.0  # m from the camera of the nearest view its position comes from (0: not from a camera)
    seen_with: set[str] = field(default_factory=set)  # ids of objects one frame saw beside it: never the same thing

    @property
    def bottom(self) -> float:
        return float(self.position[2] - self.size[2] / 2)

    @property
    def top(self) -> float:
        return float(self.position[2] + self.size[2] / 2)

    @property
    def footprint_radius(self) -> float:
        """The radius of the circle round its extents in the plane (m)."""
        return float(np.hypot(self.size[0], self.size[1])) / 2


@dataclass
class SupportSurface:
    """A horizontal surface objects can stand on: a rectangle at a height (map knowledge)."""

    name: str
    region: np.ndarray  # [[x_min, y_min], [x_max, y_max]]
    height: float  # z of the top (m)

    def contains(self, xy: np.ndarray, margin: float = 0.0) -> bool:
        return bool(np.all(xy >= self.region[0] + margin) and np.all(xy <= self.region[1] - margin))


# kinds one view can confuse (a handle hidden behind a mug, a cube's top seen at a grazing angle)
LOOK_ALIKES = {"can": ("mug",), "mug": ("can", "cube"), "cube": ("box", "mug"), "box": ("cube",)}


@dataclass
class WorldModel:
    objects: dict[str, TrackedObject] = field(default_factory=dict)
    surfaces: dict[str, SupportSurface] = field(default_factory=dict)
    people: dict[str, np.ndarray] = field(default_factory=dict)  # name or alias → position (m)
    rooms: dict[str, np.ndarray] = field(default_factory=dict)  # name → [[x_min, y_min], [x_max, y_max]] (m)
    vocabulary: dict[str, tuple[str, str]] = field(default_factory=dict)  # what people call things → (kind, colour)
    merged: dict[str, str] = field(default_factory=dict)  # id of a sighting found to be a known object → its id

    def object(self, name: str) -> TrackedObject:
        """An object by id, by name, or by what people call it (the vocabulary: "water bottle" is a blue bottle).

        Objects believed gone (confidence 0) are only found by id.
        """
        name = self.merged.get(name, name)  # a plan may hold the id a sighting had before it was recognised
        if name in self.objects:
            return self.objects[name]
        present = self.present()
        named = [o for o in present if o.name == name]
        if not named and name in self.vocabulary:
            kind, colour = self.vocabulary[name]
            unnamed = [o for o in present if o.identity is None]  # a recognised coke is not "a red can" for a pepsi
            named = [o for o in unnamed if o.kind == kind and o.colour == colour]
            if not named:  # one view may take a mug for a can, or a cube for a box: the right colour and a look-alike
                named = [o for o in unnamed if o.colour == colour and kind in LOOK_ALIKES.get(o.kind, ())]
        if named:
            return max(named, key=lambda o: (o.held_by is not None, o.confidence, o.last_seen))
        if any(o.name == name for o in self.objects.values()):
            raise KeyError(f"I do not know where the {name} is now")  # believed gone: slipped, taken away
        if name in self.vocabulary:
            kind, colour = self.vocabulary[name]
            what = "" if name == f"{colour} {kind}" else f" (a {colour} {kind})"
            raise KeyError(f"I have not seen the {name}{what} yet")
        known = [o.name for o in present]
        raise KeyError(f"no object {name!r} in the world model; {did_you_mean(name, known)}")

    def present(self) -> list[TrackedObject]:
        """The objects believed to be there now: seen and not since missed, or in a hand."""
        return [o for o in self.objects.values() if o.confidence > 0.0 or o.held_by is not None]

    def surface(self, name: str) -> SupportSurface:
        if name not in self.surfaces:
            raise KeyError(f"no surface {name!r}; {did_you_mean(name, list(self.surfaces))}")
        return self.surfaces[name]

    def person(self, name: str) -> np.ndarray:
        if name not in self.people:
            raise KeyError(f"no person {name!r}; {did_you_mean(name, list(self.people))}")
        return self.people[name]

    def room_of(self, position: np.ndarray) -> str | None:
        """The room whose region holds ``position``, if any."""
        xy = np.asarray(position[:2])
        return next((name for name, r in self.rooms.items() if np.all(xy >= r[0]) and np.all(xy <= r[1])), None)

    def surface_under(self, position: np.ndarray) -> SupportSurface | None:
        """The highest surface below ``position`` whose rectangle contains it."""
        below = [s for s in self.surfaces.values() if s.contains(position[:2]) and s.height <= position[2] + 0.01]
        return max(below, key=lambda s: s.height) if below else None

    def update(self, tracked: TrackedObject) -> None:
        self.objects[tracked.id] = tracked

    def held(self, side: str) -> TrackedObject | None:
        return next((o for o in self.objects.values() if o.held_by == side), None)

    def held_any(self) -> bool:
        return any(o.held_by is not None for o in self.objects.values())
