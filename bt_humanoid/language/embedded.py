"""The embedded planner: English commands to missions, offline and deterministic.

A command is split into clauses ("go to the kitchen, pick up the mug and
bring it to me" has three), and each clause is matched against the phrasings
of what the robot can do, verb first. Objects are grounded in the robot's
WorldModel (``perception/grounding.py``): a phrase that fits two things
becomes a question, one that fits nothing a refusal. "it" and "them" are the
objects of an earlier clause. The result is a mission in the mission
language, made of the library's behaviours:

=========================  ======================================================
"pick up the red cube"     take (find it, go to it, pick it up)
"put the mug on the shelf" fetch (take it, carry it, place it on a free spot)
"bring me the bottle"      take, navigate to the person, give
"go to the kitchen"        navigate
"walk forward 2 meters"    move_base, relative
"turn left 90 degrees"     move_base, relative yaw
"find the ball"            find, then say where it is
"wave", "say hello"        wave, say
"stop"                     a stop, not a mission
=========================  ======================================================
"""

from __future__ import annotations

import re
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from bt_humanoid.language.plan import Choice, Plan, PlanningContext
from bt_humanoid.language.vocabulary import BIN_VERBS, INTENTS, WorldVocabulary, every_verb
from bt_humanoid.language.words import normalise
from bt_humanoid.perception.free_space import free_spot
from bt_humanoid.perception.grounding import COLOURS, KIND_WORDS, describes_an_object, ground
from bt_humanoid.perception.world_model import TrackedObject


def abilities(context: PlanningContext) -> str:
    """What the robot can be asked to do, in this world's words: said when a command is not understood."""
    named = [f"the {_spoken(s)}" for s in context.world.surfaces] or ["a surface"]
    surfaces = named[0] if len(named) == 1 else ", ".join(named[:-1]) + " or " + named[-1]
    return (
        f"go to a place, pick things up, put them on {surfaces}, bring them to you, "
        "find them, walk forward or back, turn, wave, say something, and stop"
    )


DEFAULT_TURN = 90.0  # degrees for "turn left" without a number
DEFAULT_STEP = 1.0  # m for "walk forward" without a number
MAX_STEP = 5.0  # m: a longer relative move is a job for "go to"
PERSON_WORDS = {"me", "us", "the user", "user", "the person", "person", "here"}
CLAUSE_BREAK = re.compile(r"\s*(?:,\s*)?(?:\band then\b|\bthen\b|\bafter that\b|\band\b|,)\s*")
ARTICLE = re.compile(r"^(?:the|a|an|some|my|your|that|this)\s+")

VERB = "(?:" + "|".join(re.escape(verb) for verb in every_verb()) + r")\b"
STARTS_WITH_VERB = re.compile(rf"^{VERB}")


def _verbs(*intents: str) -> str:
    """The verbs of some intents (vocabulary.py) as one alternation, longest first."""
    verbs = sorted({verb for intent in intents for verb in INTENTS[intent].verbs}, key=len, reverse=True)
    return "(?:" + "|".join(re.escape(verb) for verb in verbs) + ")"


STOP = re.compile(rf"^{_verbs('stop')}\b")
# Each kind of step, by its verbs (the one vocabulary, shared with the speech grammar) and what follows them
PATTERNS: list[tuple[str, re.Pattern[str]]] = [
    ("stop", STOP),
    ("say", re.compile(rf"^{_verbs('say')}\s+(?P<text>.+)$")),
    ("wave", re.compile(rf"^{_verbs('wave')}\b(?:.*?\b(?P<times>\d+)\s+times)?")),
    (
        "step",
        re.compile(
            rf"^{_verbs('step')}\s+(?P<dir>forwards?|ahead|straight|back|backwards?)"
            r"(?:\s+(?:by\s+)?(?P<n>[\d.]+)\s*(?P<unit>meters?|metres?|m|centimeters?|centimetres?|cm|steps?))?$"
        ),
    ),
    ("back_up", re.compile(rf"^{_verbs('back_up')}(?:\s+(?:by\s+)?(?P<n>[\d.]+)\s*(?P<unit>meters?|metres?|m|cm))?$")),
    (
        "turn",
        re.compile(
            rf"^{_verbs('turn')}\s+(?:to (?:the|your)\s+)?(?P<dir>left|right|around)"
            r"(?:\s+(?:by\s+)?(?P<n>[\d.]+)\s*(?:degrees?|deg))?$"
        ),
    ),
    ("face", re.compile(rf"^{_verbs('face')}\s+(?P<where>.+)$")),
    ("bring_me", re.compile(rf"^{_verbs('bring_me')}\s+(?:me|us)\s+(?P<what>.+)$")),
    (
        "bring_to",
        re.compile(
            rf"^{_verbs('carry_to_surface', 'carry_to_person')}\s+(?P<what>.+?)\s+"
            r"(?:over\s+)?(?:to|onto|over to|into|back to)\s+(?P<where>.+)$"  # "on the table" says where it is
        ),
    ),
    ("bring_me", re.compile(rf"^{_verbs('bring_here')}\s+(?P<what>.+?)\s+(?:here|over here|back)$")),
    ("throw_away", re.compile(r"^(?:throw|toss|chuck)\s+(?P<what>.+?)\s+(?:away|out)$")),  # "throw the can away"
    ("throw_away", re.compile(rf"^(?P<verb>{_verbs('throw_away')})\s+(?P<what>.+)$")),
    (
        "put",
        re.compile(
            rf"^{_verbs('put')}\s+(?:down\s+)?(?P<what>.+?)\s+(?:down\s+)?"
            r"(?:on top of|onto|on|into|in)\s+(?P<where>.+)$"
        ),
    ),
    ("put_down", re.compile(rf"^{_verbs('put')}\s+(?:down\s+)?(?P<what>.+?)(?:\s+down)?$")),
    ("come", re.compile(rf"^{_verbs('come')}$")),
    (
        "go",
        re.compile(
            rf"^{_verbs('go')}\s+(?:back\s+)?(?:over\s+)?"
            r"(?:to|into|in|towards?|inside)\s+(?P<where>.+)$"
        ),
    ),
    ("go_home", re.compile(rf"^{_verbs('go_home')}$")),
    ("find", re.compile(rf"^{_verbs('find')}\s+(?P<what>.+?)$")),
    ("pick", re.compile(rf"^{_verbs('take')}\s+(?P<what>.+?)(?:\s+up)?$")),
]


class PlanRefused(Exception):
    """A clause the robot cannot do: the message says why, and what it can do instead."""


class Question(Exception):
    def __init__(self, choice: Choice, text: str) -> None:
        super().__init__(text)
        self.choice = choice


@dataclass
class _State:
    """What the plan so far implies: what the robot will hold, what "it" means, spots already promised."""

    held: str | None = None
    last: list[str] = field(default_factory=list)
    spots: list[np.ndarray] = field(default_factory=list)
    steps: list[dict[str, Any]] = field(default_factory=list)
    lines: list[str] = field(default_factory=list)


class EmbeddedPlanner:
    """Commands to missions by phrasing rules and grounding; asks when a phrase fits two things."""

    name = "embedded"

    def plan(self, text: str, context: PlanningContext) -> Plan:
        started = time.perf_counter()
        command = normalise(text)
        if not command:
            return Plan("refusal", "I did not hear a command.")
        state = _State()
        try:
            for clause in split_clauses(command):
                kind = self._clause(clause, state, context)
                if kind == "stop":
                    return Plan("stop", "Stopping.")
        except Question as question:
            question.choice.command = text
            return Plan("question", str(question), choice=question.choice, planning_time=time.perf_counter() - started)
        except PlanRefused as refusal:
            return Plan("refusal", str(refusal), planning_time=time.perf_counter() - started)
        tree = state.steps[0] if len(state.steps) == 1 else {"sequence": state.steps}
        mission = {
            "mission": text.strip()[:120] or command,
            "world": context.world.name,
            "robot": context.robot,
            "tree": tree,
        }
        summary = "I will " + _join(state.lines) + "."
        return Plan("mission", summary, mission=mission, planning_time=time.perf_counter() - started)

    def answer(self, choice: Choice, reply: str, context: PlanningContext) -> Plan:
        """Continue a command after a question: the reply picks one of the choice's options."""
        picked = pick_option(choice, reply, context)
        if picked is None:
            options = " or the ".join(choice.options)
            return Plan("question", f"Sorry, which one: the {options}?", choice=choice)
        command = normalise(choice.command)
        return self.plan(_replace_phrase(command, choice.phrase, picked), context)

    # --- clauses -----------------------------------------------------------------

    def _clause(self, clause: str, state: _State, context: PlanningContext) -> str:
        for kind, pattern in PATTERNS:
            match = pattern.match(clause)
            if match is None:
                continue
            handler = getattr(self, f"_{kind}")
            handler(match, state, context)
            return kind
        raise PlanRefused(f"I can't {clause}. I can {abilities(context)}.")

    def _stop(self, match: re.Match, state: _State, context: PlanningContext) -> None:
        pass

    def _say(self, match: re.Match, state: _State, context: PlanningContext) -> None:
        text = match["text"].strip().strip("'\"")
        text = re.sub(r"^(?:that|to)\s+", "", text)
        state.steps.append({"say": {"text": text[:1].upper() + text[1:]}})
        state.lines.append(f'say "{text}"')

    def _wave(self, match: re.Match, state: _State, context: PlanningContext) -> None:
        times = int(match["times"]) if match["times"] else 2
        if not 1 <= times <= 10:
            raise PlanRefused(f"I can wave 1 to 10 times, not {times}.")
        state.steps.append({"wave": {"times": times}})
        state.lines.append("wave")

    def _step(self, match: re.Match, state: _State, context: PlanningContext) -> None:
        distance = _distance(match["n"], match["unit"])
        if match["dir"].startswith("back"):
            distance = -distance
        _relative_move(state, x=distance)

    def _back_up(self, match: re.Match, state: _State, context: PlanningContext) -> None:
        _relative_move(state, x=-_distance(match["n"], match["unit"], default=0.5))

    def _turn(self, match: re.Match, state: _State, context: PlanningContext) -> None:
        if match["dir"] == "around":
            angle = float(match["n"]) if match["n"] else 180.0
        else:
            angle = float(match["n"]) if match["n"] else DEFAULT_TURN
            if match["dir"] == "right":
                angle = -angle
        if not -360.0 <= angle <= 360.0:
            raise PlanRefused(f"I turn at most a full circle at a time, not {abs(angle):.0f} degrees.")
        state.steps.append({"move_base": {"relative": True, "yaw": angle}})
        state.lines.append(f"turn {'left' if angle > 0 else 'right'} {abs(angle):.0f} degrees")

    def _face(self, match: re.Match, state: _State, context: PlanningContext) -> None:
        where = _bare(match["where"])
        place = _place_name(where, context)
        if place is not None:
            state.steps.append({"turn": {"place": place}})
            state.lines.append(f"turn to face the {_spoken(place)}")
            return
        target = self._one_object(match["where"], state, context)
        state.steps.append({"turn": {"object": target}})
        state.lines.append(f"turn to face the {target}")

    def _bring_me(self, match: re.Match, state: _State, context: PlanningContext) -> None:
        for target in self._objects(match["what"], state, context):
            self._take(target, state)
            self._give(state, context)

    def _bring_to(self, match: re.Match, state: _State, context: PlanningContext) -> None:
        where = _bare(match["where"])
        if where in PERSON_WORDS or where in context.world.person_names:
            self._bring_me(match, state, context)
            return
        self._put_on(match["what"], match["where"], state, context)

    def _put(self, match: re.Match, state: _State, context: PlanningContext) -> None:
        self._put_on(match["what"], match["where"], state, context)

    def _throw_away(self, match: re.Match, state: _State, context: PlanningContext) -> None:
        takes = BIN_VERBS.get(match.groupdict().get("verb") or "")  # "recycle": a bin for recyclable things
        for target in self._objects(match["what"], state, context):
            self._into(target, _bin_for(target, takes, context), state, context)

    def _put_down(self, match: re.Match, state: _State, context: PlanningContext) -> None:
        surfaces = ", the ".join(context.world.surfaces)
        raise PlanRefused(f"Where should I put it? Say, for example, 'put it on the {surfaces}'.")

    def _come(self, match: re.Match, state: _State, context: PlanningContext) -> None:
        self._go_to_person(state, context)

    def _go(self, match: re.Match, state: _State, context: PlanningContext) -> None:
        where = _bare(match["where"])
        if where in PERSON_WORDS or where in context.world.person_names:
            self._go_to_person(state, context)
            return
        place = _place_name(where, context)
        if place is not None:
            state.steps.append({"navigate": {"place": place}})
            state.lines.append(f"go to the {_spoken(place)}")
            return
        if describes_an_object(where, list(WorldVocabulary.of(context.world).objects)):
            target = self._one_object(match["where"], state, context)
            key = _key(target)
            state.steps.append({"find": {"object": target, "remember_as": key}})
            state.steps.append({"navigate": {"object": f"${key}"}})
            state.lines.append(f"go to the {target}")
            return
        places = ", the ".join(_spoken(p) for p in context.world.places)
        raise PlanRefused(f"I don't know a place called '{where}'. I know the {places}.")

    def _go_home(self, match: re.Match, state: _State, context: PlanningContext) -> None:
        home = "start" if "start" in context.world.places else next(iter(context.world.places))
        state.steps.append({"navigate": {"place": home}})
        state.lines.append(f"go back to the {_spoken(home)}")

    def _find(self, match: re.Match, state: _State, context: PlanningContext) -> None:
        for target in self._objects(match["what"], state, context):
            state.steps.append({"find": {"object": target, "remember_as": _key(target)}})
            state.steps.append({"say": {"text": f"I found the {target}."}})
            state.lines.append(f"find the {target}")

    def _pick(self, match: re.Match, state: _State, context: PlanningContext) -> None:
        targets = self._objects(match["what"], state, context)
        if len(targets) > 1:
            raise PlanRefused(f"I can hold one thing at a time; tell me where to put the {_join(targets)}.")
        self._take(targets[0], state)

    # --- shared steps --------------------------------------------------------------

    def _take(self, target: str, state: _State) -> None:
        if state.held == target:
            return  # already in hand from an earlier clause
        if state.held is not None:
            raise PlanRefused(f"I will be holding the {state.held}; tell me where to put it before the {target}.")
        state.steps.append({"take": {"object": target}})
        state.lines.append(f"pick up the {target}")
        state.held = target

    def _give(self, state: _State, context: PlanningContext) -> None:
        person = next(iter(context.world.people), None)
        if person is None:
            raise PlanRefused("There is nobody here to give it to.")
        state.steps.append({"navigate": {"person": person}})
        state.steps.append({"give": {"to": person}})
        state.lines.append("bring it to you")
        state.held = None

    def _go_to_person(self, state: _State, context: PlanningContext) -> None:
        person = next(iter(context.world.people), None)
        if person is None:
            raise PlanRefused("I don't know where you are.")
        state.steps.append({"navigate": {"person": person}})
        state.lines.append("come to you")

    def _into(self, target: str, container: str, state: _State, context: PlanningContext) -> None:
        """Drop ``target`` into an open bin: carry it there if it is in hand, else take it first."""
        if state.held == target:
            state.steps.append({"navigate": {"place": context.world.containers[container].place}})
            state.steps.append({"drop": {"into": container}})
        else:
            if state.held is not None:
                raise PlanRefused(f"I will be holding the {state.held}; I can carry one thing at a time.")
            state.steps.append({"throw_away": {"object": target, "into": container}})
        state.lines.append(f"put the {target} in the {_spoken(container)}")
        state.held = None
        state.last = [target]

    def _put_on(self, what: str, where: str, state: _State, context: PlanningContext) -> None:
        words = _bare(where)
        container = WorldVocabulary.of(context.world).container(words)
        if container is not None:  # "put the apple in the compost"
            for target in self._objects(what, state, context):
                self._into(target, container, state, context)
            return
        surface_name = WorldVocabulary.of(context.world).surface(words) or words
        if surface_name not in context.world.surfaces:
            surfaces = ", the ".join(context.world.surfaces)
            raise PlanRefused(f"I can't put things on '{surface_name}'. I can put them on the {surfaces}.")
        surface = context.belief.surface(surface_name)
        approach = np.array(context.world.places[context.world.surfaces[surface_name].place].pose[:2])
        for target in self._objects(what, state, context):
            spot = free_spot(surface, context.belief, approach, also_taken=state.spots)
            if spot is None:
                raise PlanRefused(f"There is no free spot left on the {surface_name}.")
            state.spots.append(spot)
            x, y = round(float(spot[0]), 3), round(float(spot[1]), 3)
            if state.held == target:
                state.steps.append({"navigate": {"place": context.world.surfaces[surface_name].place}})
                state.steps.append({"place": {"surface": surface_name, "x": x, "y": y}})
                state.lines.append(f"put it on the {surface_name}")
            else:
                if state.held is not None:
                    raise PlanRefused(f"I will be holding the {state.held}; I can carry one thing at a time.")
                state.steps.append({"fetch": {"object": target, "to": surface_name, "x": x, "y": y}})
                state.lines.append(f"put the {target} on the {surface_name}")
            state.held = None
            state.last = [target]

    # --- objects ------------------------------------------------------------------

    def _objects(self, phrase: str, state: _State, context: PlanningContext) -> list[str]:
        """The objects a phrase names: one, or several for "all the cubes" and "them"."""
        words = phrase.strip()
        if re.fullmatch(r"(?:it|that|this|that one|this one)", words):
            if not state.last:
                raise PlanRefused("I don't know what 'it' is; name the object, for example 'the red cube'.")
            return state.last[-1:]
        if re.fullmatch(r"(?:them|those|these|both|all of them)", words):
            if not state.last:
                raise PlanRefused("I don't know what 'them' are; name the objects.")
            return list(state.last)
        group = re.match(r"^(?:all(?: of)?(?: the)?|every|each|both(?: the)?|the two)\s+(?P<rest>.+)$", words)
        targets = self._all(group["rest"], context) if group else [self._one_object(words, state, context)]
        state.last = targets
        return targets

    def _one_object(self, phrase: str, state: _State, context: PlanningContext) -> str:
        bare = _bare(phrase)
        canonical = WorldVocabulary.of(context.world).object(bare)
        if canonical is not None:  # a name the world gives it, or an alias ("tea caddy" for the tea tin)
            phrase = bare = canonical
        if bare in ("it", "that", "this"):
            return self._objects(bare, state, context)[0]
        if bare in PERSON_WORDS or bare in context.world.person_names:
            raise PlanRefused("I can't pick up people.")
        if bare in context.world.surfaces or _place_name(bare, context) is not None:
            examples = ", the ".join(list(context.world.objects)[:3])
            raise PlanRefused(f"The {bare} is too big for me to carry; I can pick up things like the {examples}.")
        belief = context.belief
        grounding = ground(phrase, belief, viewer=context.robot_pose)
        if grounding.verdict == "found" and grounding.best is not None:
            name = _name_of(grounding.best, context)
            state.last = [name]
            return name
        if grounding.verdict == "ambiguous":
            options = [_name_of(o, context) for o in grounding.tied]
            if len(set(options)) == 1:  # three cokes alike: "a coke" is any of them, find takes the surest
                state.last = options[:1]
                return options[0]
            raise Question(Choice(command="", phrase=phrase, options=options), _which(options))
        named = _by_vocabulary(bare, context)
        if len(named) == 1:  # known by name, not seen yet: find will look for it
            state.last = named
            return named[0]
        if len(named) > 1:
            raise Question(Choice(command="", phrase=phrase, options=named), _which(named))
        raise PlanRefused(_not_seen(bare, context))

    def _all(self, phrase: str, context: PlanningContext) -> list[str]:
        words = re.findall(r"[a-z]+", phrase)
        kinds = {KIND_WORDS[w] for w in words if w in KIND_WORDS}
        colours = {w for w in words if w in COLOURS}  # "all the purple cubes" are none, not every cube
        present = context.belief.present()
        chosen = [
            o
            for o in present
            if (not kinds or o.kind in kinds) and (not colours or o.colour in colours) and (kinds or colours)
        ]
        if not chosen:
            raise PlanRefused(f"I don't see any {phrase}.")
        here = np.asarray(context.robot_pose[:2])
        chosen.sort(key=lambda o: float(np.hypot(*(o.position[:2] - here))))
        return [_name_of(o, context) for o in chosen]


# --- helpers -------------------------------------------------------------------------


def is_stop(text: str) -> bool:
    """Whether a command asks the robot to stop (its first clause does): cheap enough for every typed line."""
    clauses = split_clauses(normalise(text))
    return bool(clauses) and STOP.match(clauses[0]) is not None


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
        if STARTS_WITH_VERB.match(after) and current.strip():
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


UNJOINED = re.compile(r"\s(?=(?:put|place|bring|go|turn|walk|pick up|grab|find|wave|give me|hand me|come)\b)")


def _split_unjoined(clause: str) -> list[str]:
    """A clause broken before a second command verb (not in what a clause says aloud)."""
    if re.match(r"^(?:say|tell|announce)\b", clause):
        return [clause]
    parts = [p.strip() for p in UNJOINED.split(clause) if p.strip()]
    if any(len(p.split()) < 2 for p in parts):  # "go back", "turn around": a verb needs an object or a direction
        return [clause]
    return parts


def pick_option(choice: Choice, reply: str, context: PlanningContext) -> str | None:
    """Which of a question's options a reply means: by name, by its words, or by order ("the first one")."""
    text = normalise(reply)
    ordinals = {"first": 0, "1st": 0, "second": 1, "2nd": 1, "third": 2, "3rd": 2, "last": len(choice.options) - 1}
    for word, index in ordinals.items():
        if re.search(rf"\b{word}\b", text) and index < len(choice.options):
            return choice.options[index]
    for option in choice.options:
        if option in text:
            return option
    candidates = [o for o in context.belief.objects.values() if _name_of(o, context) in choice.options]
    if candidates:
        subset = type(context.belief)(
            objects={o.id: o for o in candidates},
            surfaces=context.belief.surfaces,
            rooms=context.belief.rooms,
            vocabulary=context.belief.vocabulary,
        )
        grounding = ground(text, subset, viewer=context.robot_pose)
        if grounding.verdict == "found" and grounding.best is not None:
            return _name_of(grounding.best, context)
    words = set(re.findall(r"[a-z]+", text)) - {"the", "one", "a", "please"}
    fitting = [o for o in choice.options if words & set(o.split())]
    return fitting[0] if len(fitting) == 1 else None


def _replace_phrase(command: str, phrase: str, name: str) -> str:
    """The command with the ambiguous phrase replaced by the chosen name."""
    if phrase and phrase in command:
        return command.replace(phrase, f"the {name}", 1)
    return command


def _relative_move(state: _State, x: float) -> None:
    if not 0.0 < abs(x) <= MAX_STEP:
        raise PlanRefused(f"I step at most {MAX_STEP:.0f} meters at a time; say where to go instead.")
    state.steps.append({"move_base": {"relative": True, "x": x}})
    state.lines.append(f"move {'forward' if x > 0 else 'back'} {abs(x):g} meters")


def _distance(number: str | None, unit: str | None, default: float = DEFAULT_STEP) -> float:
    if number is None:
        return default
    value = float(number)
    if unit and unit.startswith(("cm", "centi")):
        value /= 100.0
    elif unit and unit.startswith("step"):
        value *= 0.5  # a step is about half a metre
    return value


def _bare(phrase: str) -> str:
    """A phrase without its article and trailing filler: "the kitchen please" → "kitchen"."""
    phrase = ARTICLE.sub("", phrase.strip())
    return re.sub(r"\s+(?:please|now|for me|again)$", "", phrase).strip()


def _place_name(words: str, context: PlanningContext) -> str | None:
    """A named place from spoken words: "living room" is living_room, "dining table" (an alias) the table."""
    return WorldVocabulary.of(context.world).place(words)


def _spoken(name: str) -> str:
    return name.replace("_", " ")


def _name_of(tracked: TrackedObject, context: PlanningContext) -> str:
    """What to call an object in a mission: the world's name for it, else the robot's own id."""
    if context.world.object_of(tracked.name) is not None:  # the world's name, or a scene's ("coke 2")
        return tracked.name
    named = [
        name
        for name, declared in context.world.objects.items()
        if (declared.kind, declared.colour) == (tracked.kind, tracked.colour)
    ]
    return named[0] if len(named) == 1 else tracked.id


def _by_vocabulary(words: str, context: PlanningContext) -> list[str]:
    """World names a phrase fits by its words alone (objects not seen yet, but known to exist)."""
    tokens = set(re.findall(r"[a-z]+", words))
    kinds = {KIND_WORDS[w] for w in tokens if w in KIND_WORDS}
    fitting = []
    for name, declared in context.world.objects.items():
        if name == words:
            return [name]
        if kinds and declared.kind not in kinds:
            continue
        if any(w in tokens for w in name.split()) or declared.kind in kinds:
            colour_words = tokens & COLOURS
            if colour_words and declared.colour not in colour_words:
                continue
            fitting.append(name)
    return fitting


def _bin_for(target: str, takes: str | None, context: PlanningContext) -> str:
    """The bin for ``target``: one for ``takes`` things (recycle, compost), else the most particular bin its
    categories suit (a can is recyclable), else one that takes anything (the trash)."""
    containers = context.world.containers
    if not containers:
        raise PlanRefused("There is no bin here to put things in.")
    kind = context.world.object_of(target)
    categories = set(context.world.objects[kind].categories) if kind is not None else set()
    if takes is not None:
        bins = [name for name, c in containers.items() if takes in c.takes]
        if not bins:
            raise PlanRefused(f"There is no bin for {takes} things here.")
        if kind is not None and takes not in categories:
            other = _bin_for(target, None, context)
            raise PlanRefused(f"The {target} is not {takes}; say 'throw away the {target}' for the {_spoken(other)}.")
        return bins[0]
    suited = [name for name, c in containers.items() if c.takes and categories & set(c.takes)]
    anything = [name for name, c in containers.items() if not c.takes]
    if not suited and not anything:
        raise PlanRefused(f"None of the bins here takes the {target}.")
    return (suited or anything)[0]


def _which(options: list[str]) -> str:
    return f"I see {_join([f'a {o}' for o in options])}. Which would you like?"


def _not_seen(phrase: str, context: PlanningContext) -> str:
    seen = sorted({_name_of(o, context) for o in context.belief.present()})
    article = "an" if phrase[:1] in "aeiou" else "a"
    what = f" I see the {_join(seen)}." if seen else " I have not seen anything yet."
    return f"I don't see {article} {phrase}.{what}"


def _key(name: str) -> str:
    return re.sub(r"[^a-z0-9]+", "_", name.lower()).strip("_") or "it"


def _join(items: list[str]) -> str:
    return items[0] if len(items) == 1 else ", ".join(items[:-1]) + " and " + items[-1]
