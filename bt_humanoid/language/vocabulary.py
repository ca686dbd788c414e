"""One command vocabulary: the words that ask for each thing the robot can do, and the world's names for things.

The embedded planner's phrasings (``embedded.py``) and the recogniser's JSGF
grammar (``asr.py``) are both built from this module, so that what can be
typed and what can be said do not drift apart:

- ``INTENTS``: for each kind of step a command asks for (take, put, go, …), the
  verbs that ask for it and the behaviour or skill it plans. ``spoken`` verbs
  are in the speech grammar and understood when typed; ``typed`` ones only
  when typed (each alternative in a grammar is one more thing that noisy
  speech can be mistaken for, so the grammar holds the common ones).
- ``WorldVocabulary``: a world's objects, places, surfaces and people by every
  name its world.yaml gives them (``aliases`` included), and the colours and
  kinds that describe objects. A new object or place in a world.yaml is
  commandable by typing and by voice with no other edit.

What a step does with the words (grounding an object, finding a free spot)
is the planner's code; which behaviour or skill it plans is checked against
the skill registry and the behaviour library (``planned_kinds``).
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from bt_humanoid.perception.grounding import COLOURS, KIND_WORDS
from bt_humanoid.sim.world_config import WorldConfig


@dataclass(frozen=True)
class Intent:
    """The verbs that ask for one kind of step, and the mission node kinds that step plans."""

    spoken: tuple[str, ...]  # in the speech grammar, and understood when typed
    typed: tuple[str, ...] = ()  # understood when typed only
    plans: tuple[str, ...] = ()  # behaviours or skills a step of this kind is made of

    @property
    def verbs(self) -> tuple[str, ...]:
        return (*self.spoken, *self.typed)

    def pattern(self) -> str:
        """A regular expression alternation of every verb, longest first (so "pick up" wins over "pick")."""
        return "(?:" + "|".join(re.escape(v) for v in sorted(self.verbs, key=len, reverse=True)) + ")"

    def rule(self) -> str:
        """A JSGF alternation of the spoken verbs."""
        return self.spoken[0] if len(self.spoken) == 1 else "(" + " | ".join(self.spoken) + ")"


INTENTS: dict[str, Intent] = {
    "stop": Intent(("stop", "halt", "freeze"), ("stand still", "abort", "cancel")),
    "say": Intent(("say",), ("tell me", "tell us", "tell them", "tell everyone", "announce"), ("say",)),
    "wave": Intent(("wave",), (), ("wave",)),
    "step": Intent(("walk", "go", "move", "drive"), ("step", "roll", "back up", "head"), ("move_base",)),
    "back_up": Intent((), ("back up",), ("move_base",)),
    "turn": Intent(("turn", "rotate"), ("spin",), ("move_base",)),
    "face": Intent(
        ("face",), ("turn to face", "turn towards", "turn toward", "look towards", "look toward"), ("turn",)
    ),
    # "bring me X": take it and give it to the person (these verbs with no destination mean that too)
    "bring_me": Intent(
        ("bring", "fetch", "give", "hand", "get"),
        ("pass", "deliver", "send", "toss", "grab"),
        ("take", "navigate", "hand_over"),
    ),
    # "carry X to the counter" (put) and "carry X to me" (bring): the same verbs when typed
    "carry_to_surface": Intent(
        ("move", "take", "carry"),
        ("bring", "fetch", "get", "hand", "give", "pass", "deliver", "relocate", "shift", "transfer", "return", "run"),
        ("fetch", "navigate", "place"),
    ),
    "carry_to_person": Intent(
        ("bring", "take", "carry"),
        ("fetch", "get", "hand", "give", "pass", "move", "deliver", "run"),
        ("take", "navigate", "hand_over"),
    ),
    "bring_here": Intent((), ("bring", "fetch"), ("take", "navigate", "hand_over")),  # "bring the mug here"
    "put": Intent(
        ("put", "place", "set"),
        (
            *("drop", "leave", "stack", "stash", "store", "stick", "pop", "lay", "stand", "restock", "drop off"),
            *("return", "gather", "round up", "line up"),
        ),
        ("fetch", "navigate", "place"),
    ),
    # "put it down", "let go of the apple": set what is in hand down on the nearest surface with room
    "release": Intent(
        ("put down", "set down", "release"),
        ("lay down", "let go of", "let go", "drop", "unhand"),
        ("navigate", "place"),
    ),
    "come": Intent(("come here", "come to me"), ("come", "come over here", "come back", "return to me"), ("navigate",)),
    "go": Intent(
        ("go", "walk", "drive", "head", "navigate"),
        (
            *("move", "come", "return", "get", "park", "visit", "stop by", "swing by", "roll", "do a lap"),
            *("make your way", "approach", "check on", "check", "run", "pop over", "nip over"),
            *("scoot", "zip", "trundle", "wander", "mosey", "stay", "hang out"),
        ),
        ("navigate", "find"),
    ),
    "go_home": Intent(
        ("go home",), ("go back home", "come home", "come back home", "return home", "return back home"), ("navigate",)
    ),
    "find": Intent(
        ("find", "where is", "look for"),
        (
            "search for",
            "locate",
            "where's",
            "where are",
            "look at",
            "show me",
            "can you see",
            "do you see",
            "have you seen",
            "i am looking for",
            "where did i leave",
            "where did i put",
            "do you know where",
        ),
        ("find", "say"),
    ),
    "take": Intent(
        ("pick up", "grab", "take", "get", "lift", "collect"),
        ("pick", "grasp", "hold", "snag", "nab", "hold on to", "hang on to", "keep hold of", "take hold of", "keep"),
        ("take",),
    ),
    # "throw away the coke", "recycle the can", "compost the apple": into the bin that takes it
    "throw_away": Intent(
        ("throw away", "throw out", "recycle", "compost"),
        ("dispose of", "get rid of", "discard", "bin", "trash", "toss", "chuck", "throw", "dump", "ditch"),
        ("throw_away", "navigate", "drop"),
    ),
    # "clear the table", "tidy up the close counter": everything on it to another surface
    "clear": Intent(
        (),
        ("clear off", "clear up", "clear", "tidy up", "tidy", "empty", "clean up", "clean off", "declutter"),
        ("fetch",),
    ),
}
# the bin a verb of throw_away asks for, by what the bin takes (world.yaml containers' takes:)
BIN_VERBS = {"recycle": "recyclable", "compost": "compostable"}
SAY_PHRASES = ("hello", "hello everyone", "goodbye", "done", "thank you")  # what "say …" is heard as when spoken


def planned_kinds() -> set[str]:
    """Every mission node kind some command plans: each must be a skill or a behaviour (a test checks)."""
    return {kind for intent in INTENTS.values() for kind in intent.plans}


NOT_CLAUSE_STARTS = {"can", "do"}  # they start questions ("can you see …"), but "and can" is more often a can


def every_verb() -> list[str]:
    """Every verb of every intent, first words only: what starts a clause ("… and then put …")."""
    return sorted({verb.split()[0] for intent in INTENTS.values() for verb in intent.verbs} - NOT_CLAUSE_STARTS)


def spoken(name: str) -> str:
    """A world name as people say it: "living_room" is "living room"."""
    return name.replace("_", " ")


@dataclass
class WorldVocabulary:
    """A world's names for things, as people say them, and what each means in a mission."""

    objects: dict[str, str]  # words → object name ("tea caddy" → "tea tin"; a name is its own words)
    places: dict[str, str]  # words → place name ("living room" → "living_room", "dining table" → "table")
    surfaces: dict[str, str]  # words → surface name
    containers: dict[str, str]  # words → open bin ("trash" → "trash_can")
    people: list[str]  # every name a person answers to
    kinds: list[str]  # words for kinds of things (singular): cube, block, mug, …
    plurals: list[str]  # and their plurals: cubes, mugs, …
    colours: list[str]

    @classmethod
    def of(cls, world: WorldConfig) -> WorldVocabulary:
        objects = {n: n for n in world.objects} | {a: n for n, o in world.objects.items() for a in o.aliases}
        places = {spoken(n): n for n in world.places} | {a: n for n, p in world.places.items() for a in p.aliases}
        surfaces = {spoken(n): n for n in world.surfaces}
        surfaces |= {a: n for n, s in world.surfaces.items() for a in s.aliases}
        containers = {spoken(n): n for n in world.containers}
        containers |= {a: n for n, c in world.containers.items() for a in c.aliases}
        declared_kinds = {o.kind for o in world.objects.values()}
        kinds = {w for w in KIND_WORDS if not w.endswith("s")} | {k for k in declared_kinds if k not in KIND_WORDS}
        plurals = {w for w in KIND_WORDS if w.endswith("s") and w[:-1] in KIND_WORDS}
        colours = (COLOURS - {"gray"}) | {o.colour for o in world.objects.values()}
        people = world.person_names
        return cls(objects, places, surfaces, containers, people, sorted(kinds), sorted(plurals), sorted(colours))

    def place(self, words: str) -> str | None:
        """The place some words name ("the" already gone), or None."""
        return self.places.get(words) or self.places.get(spoken(words))

    def surface(self, words: str) -> str | None:
        return self.surfaces.get(words) or self.surfaces.get(spoken(words))

    def container(self, words: str) -> str | None:
        return self.containers.get(words) or self.containers.get(spoken(words))

    def object(self, words: str) -> str | None:
        """The object a name or an alias names exactly, or None (descriptions are for grounding)."""
        return self.objects.get(words)


CLAUSE_BREAK = re.compile(r"\s*(?:,\s*)?(?:\band then\b|\bthen\b|\bafter that\b|\band\b|,)\s*")
VERB_AT_START = re.compile("^(?:" + "|".join(re.escape(verb) for verb in every_verb()) + r")\b")
UNJOINED = re.compile(r"(?<!\bto)\s(?=(?:put|place|bring|go|turn|walk|pick up|grab|find|wave|give me|hand me|come)\b)")


def starts_clause(text: str) -> bool:
    """Whether ``text`` starts with a verb of some intent: what begins a new clause after "and" or a comma."""
    return VERB_AT_START.match(text) is not None


def split_clauses(command: str) -> list[str]:
    """Clauses of a normalised command: broken at commas, "and" and "then" only before a new verb.

    "put the red cube and the blue cube on the shelf" stays whole; "pick up the mug and bring it to me" splits.
    """
    pieces: list[str] = []
    position = 0
    current = ""
    for match in CLAUSE_BREAK.finditer(command):
        after = command[match.end() :]
        current += command[position : match.start()]
        if starts_clause(after) and current.strip():
            pieces.append(current.strip())
            current = ""
        else:
            current += command[match.start() : match.end()]
        position = match.end()
    current += command[position:]
    if current.strip(" ,"):
        pieces.append(current.strip(" ,"))
    # speech drops the little words: "pick up the red cube put it on the counter" is two clauses too
    return [part for piece in pieces if piece.strip(" ,") for part in _split_unjoined(piece.strip(" ,"))]


def _split_unjoined(clause: str) -> list[str]:
    """A clause broken before a second command verb (not in what a clause says aloud)."""
    if re.match(r"^(?:say|tell|announce)\b", clause):
        return [clause]
    parts = [p.strip() for p in UNJOINED.split(clause) if p.strip()]
    if any(len(p.split()) < 2 for p in parts):  # "go back", "turn around": a verb needs an object or a direction
        return [clause]
    return parts
