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

import itertools
import re
import time
from dataclasses import dataclass, field
from functools import lru_cache
from typing import Any

import numpy as np
from lemminflect import getAllLemmas, getLemma

from bt_humanoid.language.lexicon import CATEGORY_WORDS, OPPOSITES
from bt_humanoid.language.phrases import Item, Wanted, category_words, is_open, read_wanted
from bt_humanoid.language.plan import Choice, Plan, PlanningContext
from bt_humanoid.language.reading import is_context, lexicon_words, read
from bt_humanoid.language.vocabulary import BIN_VERBS, INTENTS, WorldVocabulary, split_clauses
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
PERSON_WORDS = {"me", "us", "the user", "user", "the person", "person", "here", "where i am", "where we are"}
ARTICLE = re.compile(r"^(?:the|a|an|some|my|your|that|this)\s+")


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
    ("come", re.compile(rf"^{_verbs('come')}$")),
    ("go_home", re.compile(rf"^{_verbs('go_home')}$")),
    ("find", re.compile(rf"^{_verbs('find')}\s+(?P<what>(?!me\b|us\b).+?)$")),  # "find me a coke" is a bring
]
# what the other clauses ask for is read as a frame (``_act``): a verb, the things, where they go
VERB_CLASSES = ("throw_away", "clear", "release", "bring_me", "take", "put", "carry_to_surface", "go", "come")
DESTINATION = re.compile(
    r"\s+(?:over\s+|back\s+|down\s+)?(?:onto|on to|on top of|on|into|in to|inside|in|to|towards?|at|by|beside|"
    r"next to|near|up to|round|around|over)\s+"
)
TOWARDS = re.compile(r"\s+(?:over\s+|back\s+)?(?:onto|on to|into|in to|to|towards?|over to|up to)\s+")
LOCATING = {"from", "off", "on", "in", "at", "by", "near", "beside", "inside", "under"}  # where a thing is now
FOR_SOMEONE = r"for (?:the kids?|him|her|them|us|me|my \w+|everyone|the team)"
HERE = re.compile(
    rf"\s+(?:(?:back\s+)?(?:over\s+)?(?:here|to me|to us|for me|with me|with us|back|over|to where i am)"
    rf"(?:\s+{FOR_SOMEONE})?|{FOR_SOMEONE})$"
)
BACK = re.compile(r"\s+back\b|^back\s+")
DOWN = re.compile(r"\s+down\b|^down\s+")
TAKE_ONLY = {"pick up", "pick", "grasp", "hold", "lift", "collect", "snag", "nab", "grab", "take", "get"}
TAKE_ONLY |= {"hold on to", "hang on to", "keep hold of", "take hold of", "keep"}
HELD_PHRASE = re.compile(
    r"^(?:(?:the )?(?:thing|one|object|stuff)? ?(?:in|from) your hand|(?:the )?(?:thing |one )?(?:that )?"
    r"(?:what )?you (?:are )?(?:holding|carrying|have)|what you have(?: got)?(?: in your hands?)?|"
    r"what is in your hand)$"
)
ONE_OF_A_KIND = re.compile(  # "they love the spicy crisps, put a bag on the table": a bag of those
    r"(?:a|an|one) (?:bag|can|bottle|packet|pack|piece|box|tin)(?: of (?:them|those|it|these))?(?:\s+(?:out|over))?"
    r"(?P<but>\s+(?:without|but not)\s.+)?"
)
SWAP = re.compile(
    r"^(?:swap|switch|exchange|trade|swap over|switch over|switch round|swap round)(?: round| around| over)?"
    r"(?: the places of| the spots of| the positions of| where)? (?P<a>.+?) (?:and|with|for) (?P<b>.+?)"
    r"(?: are| is)?(?: around| round| over| places| spots| positions)?$"
)
EVERYTHING_FROM_TO = re.compile(
    r"^(?:everything|all(?: the things| the stuff| of it)?|the lot|stuff) (?:off|from|on)(?: of)? (?P<source>.+?) "
    r"(?:over )?(?P<prep>to|onto|on to|into|in to|on) (?P<to>.+)$"
)
POINTED_AT = re.compile(r"^(it|them|that|this|those|these)\s+(?:off|from|out of|on|in)\s+.+$")
ONE_OF_THOSE = re.compile(  # "bring one over (without cola)": one of what an aside wanted
    r"(?:one|some|one of those|one of them|something like that|whichever(?: one)?(?: is)?(?: \w+){0,4})"
    r"(?:\s+(?:over|here|over here|back|out))?"
    r"(?P<but>\s+(?:without|but not)\s.+)?"
)
BRING_ONLY = {"bring", "fetch", "deliver", "hand", "give", "pass", "send", "toss"}


class PlanRefused(Exception):
    """A clause the robot cannot do: the message says why, and what it can do instead."""


class Question(Exception):
    def __init__(self, choice: Choice, text: str) -> None:
        super().__init__(text)
        self.choice = choice


@dataclass
class _State:
    """What the plan so far implies: what the robot will hold, where it will be, what "it" means, spots promised."""

    held: str | None = None
    last: list[str] = field(default_factory=list)
    spots: list[np.ndarray] = field(default_factory=list)
    steps: list[dict[str, Any]] = field(default_factory=list)
    lines: list[str] = field(default_factory=list)
    position: np.ndarray = field(default_factory=lambda: np.zeros(2))  # where the robot will be (x, y)
    surface: str | None = None  # the surface it was last sent to ("leave it there")
    place: str | None = None  # the place it last went to ("go to the bin and wait there")
    container: str | None = None  # the bin it was last sent to ("drop it in")
    used: set[str] = field(default_factory=set)  # things a step has already claimed ("a drink" twice: two drinks)
    mentioned: str = ""  # an aside that says what is wanted ("my kid wants something sweet"): for "one"
    mentioned_surface: str | None = None  # a surface an aside talks about ("the table's a mess"): for "clear it"
    pending: list[str] = field(default_factory=list)  # "grab every can (and bin them)": taken by the next clause
    done: dict[str, tuple[str, str]] = field(default_factory=dict)  # where this plan has already put things
    counted: bool = False  # a count or "every": the answer depends on everything there is
    clear_later: list[str] = field(default_factory=list)  # "clear the table: the cans to the recycling, …"
    swap_later: list[tuple[str, str]] = field(default_factory=list)  # "swap them: the coke onto the table, …"
    more_to_come: bool = False  # clauses follow the one being planned

    @classmethod
    def at_start(cls, context: PlanningContext) -> _State:
        """The robot as it is: where it stands and what it holds (it knows what is in its hand)."""
        held = next((o for o in context.belief.present() if o.held_by is not None), None)
        name = _name_of(held, context) if held is not None else None
        return cls(held=name, last=[name] if name else [], position=np.asarray(context.robot_pose[:2], dtype=float))


class NotUnderstood(PlanRefused):
    """A clause that asks for nothing the robot knows how to do (an aside, or something it cannot do)."""


class EmbeddedPlanner:
    """Requests to missions: clauses read as frames (verb, things, destination), things grounded in the belief."""

    name = "embedded"

    def plan(self, text: str, context: PlanningContext, replace: tuple[str, str] | None = None) -> Plan:
        started = time.perf_counter()
        clauses = read(text, known_words(context))
        if replace is not None:
            clauses = [_replace_phrase(clause, *replace) for clause in clauses]
        clauses = _telegraphic(_same_again(_fetched_to_put(clauses), context), context)
        if not clauses:
            return Plan("refusal", "I did not hear a command.")
        state = _State.at_start(context)
        asides: list[NotUnderstood] = []
        try:
            for i, clause in enumerate(clauses):
                state.more_to_come = i < len(clauses) - 1
                try:
                    kind = self._clause(clause, state, context)
                except NotUnderstood as aside:
                    asides.append(aside)  # "i knocked my drink over": kept only if nothing else is asked
                    self._mentioned(clause, state, context)  # "the apples are soft, compost them"
                    continue
                if kind == "stop":
                    return Plan("stop", "Stopping.")
            if len(asides) == len(clauses):
                raise asides[0]
            state.more_to_come = False
            for rest in state.clear_later:  # what the details after "clear the table" left there
                self._clear(rest, state, context)
            for a, b in state.swap_later:
                self._swap(a, b, state, context)
            if state.pending:
                raise PlanRefused(f"I can hold one thing at a time; tell me where to put the {_join(state.pending)}.")
        except Question as question:
            question.choice.command = text
            return Plan("question", str(question), choice=question.choice, planning_time=time.perf_counter() - started)
        except PlanRefused as refusal:
            understood = not isinstance(refusal, NotUnderstood)
            seconds = time.perf_counter() - started
            return Plan("refusal", str(refusal), planning_time=seconds, understood=understood, survey=state.counted)
        if not state.steps:  # asked for what is already so: say so, do nothing
            state.steps.append({"say": {"text": _sentence(_join(state.lines)) if state.lines else "Done."}})
        tree = state.steps[0] if len(state.steps) == 1 else {"sequence": state.steps}
        mission = {
            "mission": text.strip()[:120] or " ".join(clauses),
            "world": context.world.name,
            "robot": context.robot,
            "tree": tree,
        }
        would = re.search(r"\bhow (?:would|do|could|can|will|should) (?:you|i)\b", text.lower())
        summary = ("I would " if would else "I will ") + _join(state.lines) + "."
        seconds = time.perf_counter() - started
        return Plan("mission", summary, mission=mission, planning_time=seconds, survey=state.counted)

    def answer(self, choice: Choice, reply: str, context: PlanningContext) -> Plan:
        """Continue a command after a question: the reply picks one of the choice's options."""
        picked = pick_option(choice, reply, context)
        if picked is None:
            options = " or the ".join(choice.options)
            return Plan("question", f"Sorry, which one: the {options}?", choice=choice)
        return self.plan(choice.command, context, replace=(choice.phrase, picked))

    # --- clauses -----------------------------------------------------------------

    def _clause(self, clause: str, state: _State, context: PlanningContext) -> str:
        for kind, pattern in PATTERNS:
            match = pattern.match(clause)
            if match is None:
                continue
            handler = getattr(self, f"_{kind}")
            handler(match, state, context)
            return kind
        return self._act(clause, state, context)

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

    def _come(self, match: re.Match, state: _State, context: PlanningContext) -> None:
        self._go_to_person(state, context)

    def _go_home(self, match: re.Match, state: _State, context: PlanningContext) -> None:
        self._go_to_place(_home(context), state, context)

    def _find(self, match: re.Match, state: _State, context: PlanningContext) -> None:
        for target in self._objects(match["what"], state, context):
            state.steps.append({"find": {"object": target, "remember_as": _key(target)}})
            state.steps.append({"say": {"text": f"I found the {target}."}})
            state.lines.append(f"find the {target}")

    # --- frames: a verb, the things it acts on, where they go ----------------------------------------------------

    def _act(self, clause: str, state: _State, context: PlanningContext) -> str:
        """A clause read as a frame; NotUnderstood when it has neither a verb the robot knows nor a thing."""
        swap = SWAP.match(clause)
        if swap is not None:
            self._swap(swap["a"], swap["b"], state, context)
            return "transfer"
        verb, rest = _verb_of(clause)
        if verb is None:
            return self._verbless(clause, state, context)
        kinds = [kind for kind in VERB_CLASSES if verb in INTENTS[kind].verbs]
        if "go" in kinds or "come" in kinds:
            errand = re.sub(r"^(?:and|to)\s+", "", rest)
            second, _ = _verb_of(errand)
            errands = TAKE_ONLY | BRING_ONLY | set(INTENTS["put"].verbs) | set(INTENTS["throw_away"].verbs)
            if second is not None and second in errands:
                return self._clause(errand, state, context)  # "go get the sponge": the errand is the request
            if re.search(r"\s+with (?:it|them|that)$", rest) and state.held is not None:  # "come back with it"
                self._bring(state.held, state, context)
                return "transfer"
        if verb == "drop" and re.match(r"^(?:it|them|that|those)?\s*(?:in|into|inside)\b", rest):
            kinds.insert(0, "throw_away")  # "drop it in (the bin)"
        tossed_to_me = verb == "toss" and re.match(r"^(?:me|us)\b", rest)
        dropped_elsewhere = verb == "drop" and not (
            _is_bin_phrase(rest, context) or re.match(r"^(?:it|them)?\s*in", rest)
        )
        taking = {"bring_me", "take", "carry_to_surface"} & set(kinds)
        moved = EVERYTHING_FROM_TO.match(rest)
        if moved is not None and ({"put", "carry_to_surface"} & set(kinds) or taking):
            where = _destination(moved["to"], context)
            if where is not None and where[0] in ("surface", "container"):  # "move everything from A to B"
                self._transfer(
                    "put", f"all the things on {moved['source']} {moved['prep']} {moved['to']}", state, context
                )
                return "transfer"
        if taking and re.match(r"^(?:everything|all|all the things|the things|stuff) (?:off|from)\s", rest):
            self._clear(rest, state, context)  # "get everything off the table"
            return "clear"
        if "throw_away" in kinds and not tossed_to_me and not dropped_elsewhere:
            self._throw(verb, rest, state, context)
            return "throw_away"
        cleared = re.sub(r"^(?:off|up|(?:everything|all|things|stuff) (?:off|on|from))\s+", "", rest)
        said_before = re.fullmatch(r"(?:it|that|this)(?: up| off)?", rest) and state.mentioned_surface
        if "clear" in kinds and (not rest or _destination(cleared, context) or said_before):
            self._clear(rest, state, context)
            return "clear"
        if "clear" in kinds:  # "tidy the chips away (onto the counter)": put it away, or back where it belongs
            rest = re.sub(r"\s+(?:away|up)\b", "", rest)
            _what, where = _split_destination(rest, context, moving=True)
            self._transfer("put", rest if where else f"{rest} back", state, context)
            return "transfer"
        somewhere = not rest or re.match(
            r"^(?:back|over|round|around|to|into|towards?|by|next|up|at|home|here|in)\b", rest
        )
        if ("go" in kinds or "come" in kinds) and somewhere:
            self._go(verb, rest, state, context)
            return "go"
        if "release" in kinds and verb not in ("put", "set", "lay", "drop"):
            self._transfer(verb, rest, state, context, release=True)
            return "release"
        if any(k in kinds for k in ("bring_me", "take", "put", "carry_to_surface", "release")):
            self._transfer(verb, rest, state, context)
            return "transfer"
        if "go" in kinds:
            self._go(verb, rest, state, context)
            return "go"
        raise NotUnderstood(f"I can't {clause}. I can {abilities(context)}.")

    def _verbless(self, clause: str, state: _State, context: PlanningContext) -> str:
        """ "rice chips to the far counter", "to the table", "a coke", "with the apple you're holding"."""
        if is_context(clause):
            raise NotUnderstood(f"I can't {clause}. I can {abilities(context)}.")
        holding = re.match(r"^with\s+(?P<what>.+?)(?:\s+(?:you are|you're)\s+(?:holding|carrying))?$", clause)
        if holding is not None:
            state.mentioned = holding["what"]  # "do we have any sparkling water? i'd like one"
            state.last = self._objects(holding["what"], state, context)
            return "aside"
        stops = [_bare(p) for p in re.split(r"\s*(?:,|\band then\b|\bthen\b|\band\b)\s*", clause) if _bare(p)]
        if stops and all(
            _prefix_place(re.sub(r"^(?:back\s+)?to\s+", "", p), context)
            or re.sub(r"^(?:back\s+)?to\s+", "", p) in PERSON_WORDS
            for p in stops
        ):
            self._go("go", clause, state, context)  # "table, close counter, then back to me"
            return "go"
        if _unknown_verb(clause, context):
            raise NotUnderstood(f"I can't {clause}. I can {abilities(context)}.")
        parts = [p for p in re.split(r"\s*,\s*", clause) if p]
        first_where = _split_destination(parts[0], context, moving=True)
        bare_things = all(
            _names_a_thing(p, context) and not _split_destination(p, context, moving=True)[1] for p in parts[1:]
        )
        if len(parts) > 1 and first_where[1] and bare_things:
            destination = parts[0][len(first_where[0]) :]  # "coke to the far counter, pepsi, and the 7up": all there
            parts = [parts[0]] + [re.sub(r"^and\s+", "", p) + destination for p in parts[1:]]
        if len(parts) > 1 and all(_split_destination(p, context, moving=True)[1] for p in parts):
            for part in parts:  # "red bull onto the table, apple onto the far counter"
                self._verbless(part, state, context)
            return "transfer"
        what, where = _split_destination(clause, context, moving=True)
        if where is not None and not what:
            self._go("go", clause, state, context)
            return "go"
        if where is not None:
            self._transfer("put", clause, state, context)
            return "transfer"
        if _names_a_thing(clause, context):
            self._transfer("bring", f"me {clause}", state, context)
            return "transfer"
        raise NotUnderstood(f"I can't {clause}. I can {abilities(context)}.")

    def _transfer(self, verb: str, rest: str, state: _State, context: PlanningContext, release: bool = False) -> None:
        """Take things, and bring them to the person, put them on a surface or drop them in a bin."""
        pairs = [p for p in re.split(r"\s*(?:,\s*)?\band\s+|\s*,\s*", rest) if p]
        if len(pairs) > 1 and all(_split_destination(p, context, moving=True)[1] for p in pairs):
            for pair in pairs:  # "put the coke on the table and the pepsi on the far counter"
                self._transfer(verb, pair, state, context, release)
            return
        to_person = bool(re.match(r"^(?:me|us)\b", rest)) and verb not in ("put", "set", "place", "leave")
        rest = re.sub(r"^(?:me|us)\s+", "", rest) if to_person else rest
        restock = re.match(r"^(?P<where>.+?)\s+with\s+(?P<what>.+)$", rest)
        if restock is not None and _destination(restock["where"], context) is not None:
            rest = f"{restock['what']} on {restock['where']}"  # "restock the table with a water bottle"
        purpose = re.search(rf"\s+(?:{FOR_SOMEONE}|for (?:the|a|our|my|this|tonight's) \w+)$", rest)
        if purpose and _split_destination(rest[: purpose.start()], context, moving=True)[1] is not None:
            rest = rest[: purpose.start()]  # "put one on the table for her": the table, not her hands
        left_here = verb in ("leave", "drop") and re.search(r"\s+here$", rest) is not None
        if left_here:  # "leave the water here": set down where the robot is, not handed over
            rest, release = rest[: -len(" here")], True
        if HERE.search(rest) and not (rest.endswith(" back") and verb not in BRING_ONLY):  # "put it back": not me
            to_person, rest = True, HERE.sub("", rest)
        away = re.search(r"(?:^|\s+)away(?:\s+|$)", rest) is not None and verb not in INTENTS["throw_away"].verbs
        rest = re.sub(r"(?:^|\s+)away(?=\s+|$)", "", rest).strip() if away else rest  # "put (it) away"
        back = bool(_back(rest, context)) or verb in ("return", "restock") or away
        down = bool(DOWN.search(rest)) or release
        rest = DOWN.sub(" ", _back(rest, context) or rest).strip()
        moving = verb not in TAKE_ONLY  # "grab the cup on the counter" says where it is, "put it on …" where to
        what, where = (rest, None) if to_person else _split_destination(rest, context, moving=moving)
        beside = re.search(r"\s+(?:next to|beside|near|by)\s+(?P<other>.+)$", what)
        if where is None and beside is not None:  # "put the chips next to it": on the surface that stands on
            surface = self._surface_of(beside["other"], state, context)
            if surface is not None:
                what, where = what[: beside.start()].strip(), ("surface", surface)
        if where is None and re.search(r"\s+there$", what):  # "leave them there": where the last went, or the
            what = re.sub(r"\s+(?:over\s+)?there$", "", what)  # surface an aside spoke of ("the table is sticky")
            there = state.surface or state.mentioned_surface
            where = ("surface", there) if there else None
        if not what:
            what = "it"
        if where is not None and where[0] == "person":
            to_person = True
        if to_person:
            targets = self._objects(what, state, context)
            targets.sort(key=lambda t: t != state.held)  # what is in hand first: it is on its way already
            for target in targets:
                self._bring(target, state, context)
            return
        if where is None and (down or back or verb in ("put", "set", "place", "leave", "drop", "lay")):
            if not (down or back) and verb not in ("leave", "drop"):
                raise PlanRefused(f"Where should I put it? Say, for example, 'put it on the {_surfaces(context)}'.")
            targets = self._objects(what, state, context)
            for target in targets:
                surface = self._home_of(target, state, context) if back else self._nearest_surface(state, context)
                self._put_on_surface(target, surface, state, context)
            return
        if where is None:
            if verb in BRING_ONLY:
                for target in self._objects(what, state, context):
                    self._bring(target, state, context)
                return
            if verb not in TAKE_ONLY and verb not in INTENTS["take"].verbs:
                raise PlanRefused(
                    f"Where should I take it? Say, for example, 'to the {_surfaces(context)}' or 'to me'."
                )
            targets = self._objects(what, state, context)
            if len(targets) > 1:  # one hand: wait for where they go ("… and bin them"), else refused at the end
                state.pending = targets
                return
            self._take(targets[0], state, context, asked=True)
            return
        kind, name = where
        if kind == "container":
            for target in self._objects(what, state, context):
                self._into(target, name, state, context)
        elif kind == "surface":
            for target in self._objects(what, state, context):
                self._put_on_surface(target, name, state, context)
        else:
            raise PlanRefused(
                f"I can carry things to the {_surfaces(context)}, into a bin or to you, not to the {_spoken(name)}."
            )

    def _swap(self, first: str, second: str, state: _State, context: PlanningContext) -> None:
        """ "swap the energy bar and the apple": each goes to the surface the other stands on."""
        a, b = self._objects(first, state, context)[0], self._objects(second, state, context)[0]
        if state.more_to_come:  # "swap them: the red bull onto the table, …": the details first, then the rest
            state.swap_later.append((a, b))
            return
        if a in state.done or b in state.done:
            return
        where = {}
        for name in (a, b):
            tracked = _tracked(name, context)
            under = context.belief.surface_under(tracked.position) if tracked is not None else None
            if under is None:
                state.counted = True  # a look round may find where it stands
                raise PlanRefused(f"I can swap things standing on surfaces; I don't know where the {name} stands.")
            where[name] = under.name
        if where[a] == where[b]:
            state.lines.append(f"find the {a} and the {b} both on the {_spoken(where[a])} already")
            return
        self._put_on_surface(a, where[b], state, context)
        self._put_on_surface(b, where[a], state, context)

    def _throw(self, verb: str, rest: str, state: _State, context: PlanningContext) -> None:
        takes = BIN_VERBS.get(verb)  # "recycle": a bin for recyclable things
        rest = re.sub(r"\s+(?:away|out)$", "", rest)
        what, where = _split_destination(rest, context, moving=True)
        if where is not None and where[0] != "container":  # "compost the apple on the far counter": where it is
            what, where = rest, None
        container = where[1] if where is not None else None
        if not what.strip() or what.strip() in ("in", "it in", "them in"):
            what = "it" if what.strip() in ("", "in", "it in") else "them"
            container = container or state.container
        for target in self._objects(what, state, context):
            self._into(target, container or _bin_for(target, takes, context), state, context)

    def _clear(self, rest: str, state: _State, context: PlanningContext) -> None:
        """Everything believed on a surface moved off it, each to the nearest other surface with room."""
        rest = re.sub(
            r"\s*,?\s*(?:everything|all of it|the lot|all)(?: on it| of it)?$", "", rest
        )  # "…, everything on it"
        rest = re.sub(r"\s+(?:after|before) (?:lunch|dinner|breakfast|supper|the \w+|my \w+)$", "", rest)
        words = re.sub(r"^(?:everything|all|the things|things|stuff)\s+(?:off|from|on)\s+", "", rest)
        words = re.sub(r"^(?:off|up)\s+", "", words)
        if re.fullmatch(r"(?:it|that|this)(?: up| off)?", words) and state.mentioned_surface is not None:
            words = state.mentioned_surface  # "the table is a mess, clear it"
        surface = WorldVocabulary.of(context.world).surface(_bare(words))
        if surface is None:
            refusal = NotUnderstood if not _bare(words) else PlanRefused  # a bare "tidy up" before the details
            raise refusal(f"I can clear a surface: the {_surfaces(context)}.")
        state.counted = True  # everything on it: what was seen from afar may not be all
        state.mentioned_surface = surface  # "clear the table: the chips in the bin": the chips on the table
        if state.more_to_come and rest not in state.clear_later:
            state.clear_later.append(rest)  # the clauses after it may say where things go: they go first
            state.lines.append(f"clear the {_spoken(surface)}")
            return
        moved = set(state.done) | state.used
        on_it = [
            o
            for o in context.belief.present()
            if o.held_by is None
            and _on_surface(o, surface, context)
            and not {_name_of(o, context), _one_of(o, context)} & moved
        ]
        if not on_it:
            state.lines.append(f"find the {_spoken(surface)} already clear")
            return
        here = state.position
        on_it.sort(key=lambda o: float(np.hypot(*(o.position[:2] - here))))
        for tracked in on_it:
            target = _name_of(tracked, context)
            self._put_on_surface(target, self._nearest_surface(state, context, besides=surface), state, context)

    def _go(self, verb: str, rest: str, state: _State, context: PlanningContext) -> None:
        """To a place, a person or an object; to several in turn ("round every counter and back")."""
        second, after = _verb_of(rest)
        if second is not None and second in INTENTS["go"].verbs:  # "go park by the counter"
            rest = after
        rest = re.sub(
            r"^(?:and\s+)?(?:check(?: on)?|look at|have a look at|see|check out)\s+", "", rest
        )  # "go check …"
        rest = re.sub(
            r"^(?:back\s+)?(?:over\s+)?(?:round|around|to|into|towards?|by|next to|up to|at|in)?\s*", "", rest
        )
        if not rest and verb in ("do a lap", "visit", "park", "stop by", "swing by", "go", "head", "walk", "drive"):
            raise NotUnderstood(f"Where should I {verb}? I know the {_surfaces(context)}.")
        if not rest or rest in ("back", "here", "home"):
            if verb == "come" or rest in ("back", "here"):
                self._go_to_person(state, context)
            else:
                self._go_to_place(_home(context), state, context)
            return
        stops = [p for p in re.split(r"\s*(?:,|\band then\b|\bthen\b|\band\b)\s*", rest) if p.strip()]
        for words in stops:
            self._go_one(_bare(re.sub(r"^(?:back\s+)?(?:to|round|around|by|at)\s+", "", words)), state, context)

    def _go_one(self, where: str, state: _State, context: PlanningContext) -> None:
        if where == "there" and state.place is not None:
            where = state.place
        if where in ("back", "home", "back home", "where you started", "your start position", "start position"):
            self._go_to_place(_home(context), state, context)
            return
        if where in PERSON_WORDS or where in context.world.person_names or where in ("back to me", "me again"):
            self._go_to_person(state, context)
            return
        every = re.match(
            r"^(?:every|each|all(?: the)?(?: \d+| two| three| four| five| six)?|all of the|"
            r"(?:the )?(?:\d+|two|three|four|five|six)|both(?: the)?)\s+(?P<kind>.+?)s?$",
            where,
        )
        if every is not None:
            places = _places_like(every["kind"], context)
            if places:
                for place in places:
                    self._go_to_place(place, state, context)
                return
        place = _place_name(where, context) or _prefix_place(where, context)
        if place is None and where.endswith("s"):  # "head over to the bins": the nearest of them
            alike = _places_like(where, context)
            place = (
                min(
                    alike, key=lambda p: float(np.hypot(*(np.array(context.world.places[p].pose[:2]) - state.position)))
                )
                if alike
                else None
            )
        if place is not None:
            self._go_to_place(place, state, context)
            return
        if describes_an_object(where, list(WorldVocabulary.of(context.world).objects)):
            target = self._one_object(where, state, context)
            key = _key(target)
            state.steps.append({"find": {"object": target, "remember_as": key}})
            state.steps.append({"navigate": {"object": f"${key}"}})
            state.lines.append(f"go to the {target}")
            return
        places = ", the ".join(_spoken(p) for p in context.world.places)
        raise PlanRefused(f"I don't know a place called '{where}'. I know the {places}.")

    # --- shared steps --------------------------------------------------------------

    def _take(self, target: str, state: _State, context: PlanningContext, asked: bool = False) -> None:
        if state.held == target:
            if asked:
                state.lines.append(f"keep holding the {target}")
            return  # already in hand
        if state.held is not None:
            self._set_down(state, context)
        state.steps.append({"take": {"object": target}})
        state.lines.append(f"pick up the {target}")
        state.held = target
        state.position = self._where_is(target, state, context)

    def _set_down(self, state: _State, context: PlanningContext) -> None:
        """Free the hand: what it holds goes on the nearest surface with room."""
        assert state.held is not None
        last = state.last
        self._put_on_surface(state.held, self._nearest_surface(state, context), state, context)
        state.last = last

    def _bring(self, target: str, state: _State, context: PlanningContext) -> None:
        if state.done.get(target) == ("given", "person"):  # "… something to snack on? bring it over": once
            return
        self._take(target, state, context)
        person = next(iter(context.world.people), None)
        if person is None:
            raise PlanRefused("There is nobody here to give it to.")
        state.steps.append({"navigate": {"person": person}})
        state.position = np.asarray(context.belief.person(person)[:2], dtype=float)
        try:  # if they do not take it, it goes on the surface nearest them with room: never dropped, never kept
            surface = self._nearest_surface(state, context)
        except PlanRefused:  # nowhere to put it: a plain give, which keeps it if they do not take it
            state.steps.append({"give": {"to": person}})
        else:
            place, x, y = self._promise_spot(surface, state, context)
            state.steps.append({"hand_over": {"to": person, "surface": surface, "place": place, "x": x, "y": y}})
        state.lines.append("bring it to you")
        state.held = None
        state.last = [target]
        state.done[target] = ("given", "person")

    def _go_to_person(self, state: _State, context: PlanningContext) -> None:
        person = next(iter(context.world.people), None)
        if person is None:
            raise PlanRefused("I don't know where you are.")
        state.steps.append({"navigate": {"person": person}})
        state.lines.append("come to you")

    def _go_to_place(self, place: str, state: _State, context: PlanningContext) -> None:
        if state.place == place and state.steps and state.steps[-1] == {"navigate": {"place": place}}:
            return  # "go to the bin and wait there": there already
        state.place = place
        state.steps.append({"navigate": {"place": place}})
        state.lines.append(f"go to the {_spoken(place)}")
        state.position = np.array(context.world.places[place].pose[:2], dtype=float)

    def _into(self, target: str, container: str, state: _State, context: PlanningContext) -> None:
        """Drop ``target`` into an open bin: carry it there if it is in hand, else take it first."""
        bin_place = context.world.containers[container].place
        if state.done.get(target) == ("inside", container):  # "carry it to the bin and throw it in": once
            return
        if state.held == target:
            state.steps.append({"navigate": {"place": bin_place}})
            state.steps.append({"drop": {"into": container}})
        else:
            if state.held is not None:
                self._set_down(state, context)
            state.steps.append({"throw_away": {"object": target, "into": container}})
        state.lines.append(f"put the {target} in the {_spoken(container)}")
        state.held = None
        state.last = [target]
        state.done[target] = ("inside", container)
        state.container = container
        state.position = np.array(context.world.places[bin_place].pose[:2], dtype=float)

    def _put_on_surface(self, target: str, surface_name: str, state: _State, context: PlanningContext) -> None:
        if state.done.get(target) == ("on", surface_name):  # "take it to the table and leave it there": once
            return
        there = _tracked(target, context)
        alike = [o for o in context.belief.present() if _name_of(o, context) == target]
        if len(alike) > 1 or (there is not None and there.id != target and _one_of(there, context) != target):
            there = None  # "apple" when there are two: not necessarily the one already there
        if target not in state.done and state.held != target and there and _on_surface(there, surface_name, context):
            state.lines.append(f"leave the {target} on the {_spoken(surface_name)}, where it is")  # "make sure …"
            state.last = [target]
            return
        place, x, y = self._promise_spot(surface_name, state, context)
        approach = np.array(context.world.places[place].pose[:2])
        if state.held == target:
            state.steps.append({"navigate": {"place": place}})
            state.steps.append({"place": {"surface": surface_name, "x": x, "y": y}})
            just_taken = bool(state.lines) and state.lines[-1].endswith(f"the {target}")
            state.lines.append(f"put {'it' if just_taken else 'the ' + target} on the {_spoken(surface_name)}")
        else:
            if state.held is not None:
                self._set_down(state, context)
            state.steps.append({"fetch": {"object": target, "to": surface_name, "x": x, "y": y}})
            state.lines.append(f"put the {target} on the {_spoken(surface_name)}")
        state.held = None
        state.last = [target]
        state.done[target] = ("on", surface_name)
        state.surface = surface_name
        state.position = approach

    def _promise_spot(self, surface_name: str, state: _State, context: PlanningContext) -> tuple[str, float, float]:
        """A free spot on the surface, nearest where it is worked from, kept for this plan: (place, x, y)."""
        place = context.world.surfaces[surface_name].place
        approach = np.array(context.world.places[place].pose[:2])
        spot = free_spot(context.belief.surface(surface_name), context.belief, approach, also_taken=state.spots)
        if spot is None:
            raise PlanRefused(f"There is no free spot left on the {_spoken(surface_name)}.")
        state.spots.append(spot)
        return place, round(float(spot[0]), 3), round(float(spot[1]), 3)

    def _nearest_surface(self, state: _State, context: PlanningContext, besides: str | None = None) -> str:
        """The surface nearest where the robot will be that has room (for putting something down)."""
        surfaces = [s for s in context.world.surfaces if s != besides]
        if not surfaces:
            raise PlanRefused("There is no surface here to put things on.")

        def distance(name: str) -> float:
            return float(
                np.hypot(
                    *(np.array(context.world.places[context.world.surfaces[name].place].pose[:2]) - state.position)
                )
            )

        for name in sorted(surfaces, key=distance):
            place = context.world.surfaces[name].place
            approach = np.array(context.world.places[place].pose[:2])
            if free_spot(context.belief.surface(name), context.belief, approach, also_taken=state.spots) is not None:
                return name
        raise PlanRefused("There is no free spot left on any surface.")

    def _surface_of(self, words: str, state: _State, context: PlanningContext) -> str | None:
        """The surface a thing stands on, or was just put on by this plan ("next to it")."""
        if _bare(words) in ("it", "that", "them", "this"):
            return state.surface
        last, used = list(state.last), set(state.used)
        try:
            names = self._objects(words, state, context)
        except (PlanRefused, Question):
            return None
        finally:  # naming the neighbour does not make it "it"
            state.last, state.used = last, used
        tracked = _tracked(names[0], context) if names else None
        under = context.belief.surface_under(tracked.position) if tracked is not None else None
        return under.name if under is not None else None

    def _home_of(self, target: str, state: _State, context: PlanningContext) -> str:
        """Where a thing was seen standing ("put it back"), else the nearest surface."""
        tracked = _tracked(target, context)
        if tracked is not None and tracked.held_by is None:
            under = context.belief.surface_under(tracked.position)
            if under is not None:
                return under.name
        return self._nearest_surface(state, context)

    def _where_is(self, target: str, state: _State, context: PlanningContext) -> np.ndarray:
        tracked = _tracked(target, context)
        if tracked is None or tracked.held_by is not None:
            return state.position
        under = context.belief.surface_under(tracked.position)
        if under is not None and under.name in context.world.surfaces:
            return np.array(context.world.places[context.world.surfaces[under.name].place].pose[:2], dtype=float)
        return np.asarray(tracked.position[:2], dtype=float)

    # --- objects ------------------------------------------------------------------

    def _objects(self, phrase: str, state: _State, context: PlanningContext) -> list[str]:
        """The objects a phrase names: one, several listed, a count of a kind, or every one of a kind."""
        if re.fullmatch(r"(?:that|this|the same) one", phrase.strip().strip(" ,")):
            phrase = "it"  # "pick up the tea and put that one on the table"
        words = _bare(phrase.strip().strip(" ,"))
        words = POINTED_AT.sub(r"\1", words)  # "it off the table": "it" says which, the rest where it is
        if HELD_PHRASE.match(words):
            if state.held is None:
                raise PlanRefused("I am not holding anything.")
            return [state.held]
        pending_words = r"(?:them|those|these|both|all of them|em|it|that|everything|them both|both of them|the two)"
        if state.pending and re.fullmatch(pending_words, words):
            taken, state.pending = state.pending, []  # "grab every can and bin them"
            return taken
        if re.fullmatch(r"(?:it|that|this|that one|this one)", words):
            if not state.last and state.mentioned:  # "my son needs something healthy, put it on the table"
                return self._objects(state.mentioned, state, context)
            if not state.last:
                raise PlanRefused("I don't know what 'it' is; name the object, for example 'the red cube'.")
            return state.last[-1:]
        if re.fullmatch(r"(?:them|those|these|both|all of them|em|them both|both of them|the two)", words):
            if not state.last and state.mentioned:  # "my toddler keeps grabbing the chips, put them up high"
                return self._objects(state.mentioned, state, context)
            if not state.last:
                raise PlanRefused("I don't know what 'them' are; name the objects.")
            return list(state.last)
        one = ONE_OF_THOSE.fullmatch(words) or ONE_OF_A_KIND.fullmatch(phrase.strip().strip(" ,"))
        if state.mentioned and one is not None:
            phrase = state.mentioned + (one["but"] or "")  # "bring one over": one of what the aside wanted
        count = re.fullmatch(r"(?:a couple|a few|\d+|two|three|four|five|six)(?: of them| of those)?", words)
        if state.mentioned and count is not None:  # "the kids want snacks, bring two"
            kind = re.sub(r"^(?:some|a|an|something|anything)\s+", "", state.mentioned)
            phrase = f"{count.group(0).split(' of ')[0]} {kind}"
        wanted = read_wanted(phrase, _surface_words(context))
        wanted.items = [part for item in wanted.items for part in _run_together(item, context)]
        if not wanted.items:
            raise PlanRefused(f"What should I take? I see the {_join(_seen_names(context)) or 'nothing yet'}.")
        first = wanted.items[0].words
        if wanted.simple and not _candidates(first, context) and _world_name_in(first, context) is None:
            targets = [self._one_object(phrase, state, context)]
        else:
            targets = [t for item in wanted.items for t in self._choose(item, wanted, state, context)]
        state.last = targets
        state.used |= set(targets)
        return targets

    def _mentioned(self, aside: str, state: _State, context: PlanningContext) -> None:
        """What an aside talks about becomes "it"/"them"/"one" for the clauses after it."""
        surface = _surface_named_in(aside, context)
        if surface is not None:
            state.mentioned_surface = surface  # "the table's a mess, could you clear it?"
        named = _world_name_in(re.sub(rf"\b(?:on|off|from|in) the {_spoken(surface or '-')}\b", "", aside), context)
        if state.last and named is None:
            return  # an aside that names nothing leaves "it" as it was
        wanted = read_wanted(re.sub(r"^(?:i|we|someone|my \w+)\s+\w+\s+", "", aside), _surface_words(context))
        for listed in wanted.items:
            kind_said = ""
            for start in range(len(listed.words.split())):  # the thing is named somewhere in the aside
                words = " ".join(listed.words.split()[start:])
                name = _world_name_in(words, context)
                if name is None and len(words.split()) <= 3 and _candidates(words, context):
                    kind_said = words  # "she only drinks sparkling water": a kind, not the "water" bottle
                    continue
                if name is not None and kind_said:
                    state.mentioned = kind_said
                    return
                kind_said = ""
                if name is not None:
                    seen = [o for o in context.belief.present() if _world_object(o, context) == name]
                    alike = [_one_of(o, context) for o in seen] or [name]
                    several = bool(listed.every or re.search(r"\b(?:both|all|every)\b", aside))
                    state.counted |= several
                    state.last = alike if several else alike[:1]
                    state.mentioned = state.mentioned or words  # "they love the spicy crisps, put a bag on the table"
                    return
        kinds = re.search(r"\b(?:the|some|those) (?P<kind>[a-z ]+?)$", aside)
        if named is not None:  # "they are not having the energy drink", "the lime soda's gone flat"
            state.last = [named]
            return
        if kinds is not None and _candidates(kinds["kind"], context) and not state.mentioned:
            state.mentioned = kinds.group(0)  # "the safest bet is the fruit": "it" is a fruit
            return
        wanting = re.search(r"\b(?:something|anything|some|a|an)\b.*$", aside)
        wants = re.search(
            r"\b(?:wants|want|needs|need|likes|like|loves|love|fancies|fancy|prefers|prefer|enjoys|enjoy|drinks|eats|"
            r"is after|are after|asked for|asks for|only drinks|only eats) (?!to\b)(?P<what>.+)$",
            aside,
        )
        # "my kid wants something sweet": "something sweet"; "the kids want snacks": "snacks"
        state.mentioned = wanting.group(0) if wanting else wants["what"] if wants else ""

    def _choose(self, listed: Item, wanted: Wanted, state: _State, context: PlanningContext) -> list[str]:
        """The things one listed item stands for: by name, or by what they are, seen ones first, nearest first."""
        item = listed.words
        if item in ("it", "that", "this", "them", "those"):
            return self._objects(item, state, context)
        if listed.alternatives:  # "the pepsi or the coke": whichever of them is nearest
            kinds = list(dict.fromkeys(k for option in listed.alternatives for k in _kinds_named(option, context)))
            if not kinds:
                raise PlanRefused(_not_seen(listed.alternatives[0], context))
            name = None
        else:
            name = _world_name_in(item, context)
            kinds = [name] if name is not None else _candidates(item, context)
        if not kinds and not is_open(item):
            if listed.count or listed.every:
                raise PlanRefused(f"I don't see any {item}.")
            return [self._one_object(item, state, context)]
        if not kinds:
            kinds = list(context.world.objects)  # "anything", "everything"
        excluded = _excluded(wanted.exclude, context)
        kinds = [k for k in kinds if k not in excluded]
        said_without = _opposite_categories(wanted.exclude, context)  # "without sugar": the unsweetened ones
        kinds = [k for k in kinds if said_without <= set(context.world.objects[k].categories)] or kinds
        seen = [
            o
            for o in context.belief.present()
            if _world_object(o, context) in kinds
            and _world_object(o, context) not in excluded
            and (wanted.source is None or _on_surface(o, wanted.source, context))
        ]
        here = state.position
        seen.sort(key=lambda o: (o.held_by is None, float(np.hypot(*(o.position[:2] - here)))))
        twin_used = any(_one_of(o, context) in state.used and _one_of(o, context) != _name_of(o, context) for o in seen)
        specific = listed.every or listed.count or wanted.source is not None or twin_used  # which one matters: by id
        state.counted |= bool(listed.every or (listed.count or 1) > 1 or wanted.source)
        pool = [_one_of(o, context) if specific else _name_of(o, context) for o in seen]
        of = {name: _world_object(o, context) for name, o in zip(pool, seen, strict=True)}
        if not listed.every and not (seen and (wanted.source or listed.definite)):  # not seen yet: find will look
            unseen = [k for k in kinds if k not in of.values()]
            pool += unseen
            of |= {k: k for k in unseen}
        fresh = [p for p in pool if p not in state.used]
        pool = fresh or pool
        what = item if name is None else name
        if listed.every and listed.different:  # "one of each sparkling water": one of every kind there is
            pool = list({of[p]: p for p in reversed(pool)}.values())[::-1]
        if listed.every and wanted.source is not None:
            state.mentioned_surface = wanted.source  # "get rid of everything on the table: the chips to the trash"
        if listed.every:
            if not pool:
                raise PlanRefused(
                    f"I don't see any {item}{' on the ' + _spoken(wanted.source) if wanted.source else ''}."
                )
            return pool
        if listed.definite and not listed.count and name is None and _plural_of_a_kind(item, context):
            there = _on_surface_spoken_of(pool, seen, state, context)
            if there and wanted.source is None:  # "clear the table: recycle the cans": the cans on it
                return there
            return pool if pool else self._choose(Item(item, every=True), wanted, state, context)  # "the bottles"
        count = listed.count or 1
        if listed.different or (count > 1 and name is None):
            distinct = {}
            for p in pool:
                distinct.setdefault(of[p], p)
            pool = list(distinct.values()) if listed.different else pool
        held = [o for o in seen if o.held_by is not None]
        if count == 1 and listed.definite and not listed.every and held:  # "put that bottle down" holding one
            return [_one_of(held[0], context) if specific else _name_of(held[0], context)]
        if count == 1 and listed.definite and not is_open(item) and name is None:
            options = list(dict.fromkeys(of[p] for p in pool))
            there = _on_surface_spoken_of(pool, seen, state, context)
            if len(options) > 1 and len({of[p] for p in there}) == 1:  # "the table's a mess: move the chips"
                return there[:1]
            if len(options) > 1:  # "the caffeinated one" names one thing, and several fit: ask
                raise Question(Choice(command="", phrase=item, options=options), _which(options))
        if len(pool) < count:
            raise PlanRefused(f"I know of only {len(pool)} {what}{'' if len(pool) == 1 else 's'}, not {count}.")
        return pool[:count]

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
        if _unknown_thing(bare, context):  # "a banana" in a kitchen without one: not a look-alike
            raise PlanRefused(_not_seen(bare, context))
        alike = _same_kind(bare, context)
        if len(alike) > 1:  # "the cube" with two cubes in the world, even if one has been seen so far
            raise Question(Choice(command="", phrase=phrase, options=alike), _which(alike))
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


# --- helpers -------------------------------------------------------------------------


def _back(words: str, context: PlanningContext) -> str | None:
    """ "put the sponge back on the counter" without "back" (None when there is no such "back": "the back
    counter" is a name)."""
    for match in BACK.finditer(words):
        after = words[match.start() :].strip()
        if _destination(after, context) is None:
            return (words[: match.start()] + " " + words[match.end() :]).strip()
    return None


def _surface_named_in(text: str, context: PlanningContext) -> str | None:
    """A surface a sentence names, by its name or an alias ("the table's a mess" → the table)."""
    vocabulary = WorldVocabulary.of(context.world)
    words = text.split()
    for length in (3, 2, 1):
        for start in range(len(words) - length + 1):
            surface = vocabulary.surface(" ".join(words[start : start + length]))
            if surface is not None:
                return surface
    return None


SAME_AGAIN = re.compile(
    r"(?:and |then |and then )*(?:also |do )?(?P<np>.+?) (?:too|as well)|"
    r"(?:and |then |and then )*(?:also|likewise|same for|same with|same goes for|and also) (?P<also>.+)"
)


def _same_again(clauses: list[str], context: PlanningContext) -> list[str]:
    """ "put the pepsi in the recycling, then the coke too": the last verb and destination, for another thing."""
    out: list[str] = []
    for clause in clauses:
        again = SAME_AGAIN.fullmatch(clause)
        verb, rest = _verb_of(out[-1]) if out else (None, "")
        if again is not None and verb is not None and _verb_of(clause)[0] is None:
            thing = again["np"] or again["also"]
            what, where = _split_destination(rest, context, moving=True)
            destination = rest[len(what) :].strip() if where is not None and rest.startswith(what) else ""
            out.append(f"{verb} {thing} {destination}".strip())
        else:
            out.append(clause)
    return out


def _telegraphic(clauses: list[str], context: PlanningContext) -> list[str]:
    """ "the coke. table.": a thing, then where it goes, said as two bare words: the thing to that place."""
    out: list[str] = []
    for clause in clauses:
        previous = out[-1] if out else ""
        a_thing = previous and _verb_of(previous)[0] is None and _names_a_thing(previous, context)
        if a_thing and _verb_of(clause)[0] is None and _destination(clause, context) is not None:
            out[-1] = f"{previous} to {clause}"
        else:
            out.append(clause)
    return out


def _fetched_to_put(clauses: list[str]) -> list[str]:
    """ "fetch the apple and chuck it in the compost": the thing is fetched to go somewhere else, not to me."""
    out = list(clauses)
    moving = set(INTENTS["put"].verbs) | set(INTENTS["throw_away"].verbs)
    for i, (clause, following) in enumerate(itertools.pairwise(clauses)):
        verb, rest = _verb_of(clause)
        then, then_rest = _verb_of(following)
        to_someone = re.search(r"\b(?:me|us|here|you)\b", rest)
        acts_on_it = re.match(r"^(?:it|them|those|that)\b", then_rest)
        if verb in BRING_ONLY and then in moving and not to_someone and acts_on_it:
            out[i] = f"take {rest}"
    return out


def _verb_of(clause: str) -> tuple[str | None, str]:
    """The verb a clause starts with (the longest known, "pick up" before "pick") and the words after it."""
    for verb in _ALL_VERBS:
        if clause == verb or clause.startswith(verb + " "):
            return verb, clause[len(verb) :].strip()
    return None, clause


_ALL_VERBS = sorted({v for kind in VERB_CLASSES for v in INTENTS[kind].verbs}, key=len, reverse=True)


_KNOWN: dict[tuple[str, int], frozenset[str]] = {}  # per world: the words requests are corrected towards


def known_words(context: PlanningContext) -> frozenset[str]:
    """The words a request is corrected towards (cached per world)."""
    key = (context.world.name, id(context.world))
    if key not in _KNOWN:
        vocabulary = WorldVocabulary.of(context.world)
        words = {w for intent in INTENTS.values() for verb in intent.verbs for w in verb.split()}
        for names in (vocabulary.objects, vocabulary.places, vocabulary.surfaces, vocabulary.containers):
            words |= {w for name in names for w in name.split()}
        words |= {w for o in context.world.objects.values() for c in o.categories for w in c.split()}
        words |= set(vocabulary.kinds) | set(vocabulary.plurals) | set(vocabulary.colours) | lexicon_words()
        words |= {"me", "the", "it", "them", "and", "then", "every", "all", "both", "each", "some", "any", "something"}
        words |= {"anything", "everything", "please", "onto", "into", "back", "down", "away", "here", "there"}
        words |= {"one", "two", "three", "four", "five", "six", "couple", "pair", "few", "both", "different"}
        _KNOWN[key] = frozenset(w for w in words if w.isalnum())
    return _KNOWN[key]


def _split_destination(
    words: str, context: PlanningContext, moving: bool = False
) -> tuple[str, tuple[str, str] | None]:
    """ "the apple to the far counter" → ("the apple", ("surface", "far_counter")): the last preposition whose
    words name a surface, a bin, a place or the person wins. For a verb that only takes ("pick up", "grab"),
    ``moving`` is False and only "to", "onto", "into" say where to ("grab the cup on the counter" says where it
    is); for one that moves things, "put apple far counter" (words dropped) says where too."""
    pattern = DESTINATION if moving else TOWARDS
    for match in reversed(list(pattern.finditer(" " + words))):
        where = _destination(words[match.end() - 1 :], context)
        if where is not None:
            return words[: max(match.start() - 1, 0)].strip(), where
    tokens = words.split()
    if moving and not any(t in LOCATING for t in tokens):
        for start in range(1, len(tokens)):  # dropped words: the last words name where
            where = _destination(" ".join(tokens[start:]), context)
            if where is not None and where[0] != "person" and _bare(" ".join(tokens[:start])):
                return " ".join(tokens[:start]), where
    return words, None


def _destination(words: str, context: PlanningContext) -> tuple[str, str] | None:
    """What some words name as a destination: the person, a surface, a bin or a place (longest name first)."""
    bare = _bare(words)
    if _destination_named(bare, context) is None:  # "back to the table" (but "the back counter" is a name)
        bare = re.sub(r"^(?:back\s+)?(?:over\s+)?(?:to\s+)?", "", bare)
    if bare in PERSON_WORDS or bare in context.world.person_names or bare in ("me again", "you"):
        return ("person", next(iter(context.world.people), "person")) if bare != "you" else None
    return _destination_named(bare, context)


def _destination_named(bare: str, context: PlanningContext) -> tuple[str, str] | None:
    vocabulary = WorldVocabulary.of(context.world)
    tokens = bare.split()
    for end in range(len(tokens), 0, -1):  # "counter where it lives": the longest start that names something
        head = " ".join(tokens[:end])
        if vocabulary.container(head) is not None:
            return ("container", vocabulary.container(head))  # type: ignore[return-value]
        if vocabulary.surface(head) is not None:
            return ("surface", vocabulary.surface(head))  # type: ignore[return-value]
        if _place_name(head, context) is not None:
            return ("place", _place_name(head, context))  # type: ignore[return-value]
    return None


def _unknown_verb(clause: str, context: PlanningContext) -> bool:
    """Whether a clause starts with a verb the robot does not know ("swap the cans"), not with a thing."""
    first = clause.split()[0]
    if first in known_words(context) or first in ("a", "an", "the", "some", "any", "one", "to", "with", "back"):
        return False
    lemmas = getAllLemmas(first)
    if "VERB" not in lemmas:
        return False
    words = clause.split()
    followed_by_a_thing = len(words) > 2 and words[1] in ("the", "a", "an", "my", "it", "them")  # "swap the …"
    return "NOUN" not in lemmas or followed_by_a_thing


def _is_bin_phrase(words: str, context: PlanningContext) -> bool:
    where = _split_destination(words, context, moving=True)[1]
    return where is not None and where[0] == "container"


def _names_a_thing(words: str, context: PlanningContext) -> bool:
    """Whether words name something to bring: a thing by name, by what it is, or an open "something to eat"."""
    wanted = read_wanted(words, _surface_words(context))
    return any(
        _world_name_in(i.words, context) or _candidates(i.words, context) or is_open(i.words) for i in wanted.items
    )


def _world_name_in(words: str, context: PlanningContext) -> str | None:
    """The world object whose name or alias the words contain (the longest), or None. A category of several
    words is not a name: "sparkling waters" are not the water bottle."""
    text = f" {_canonical(words)} "
    names = WorldVocabulary.of(context.world).objects
    categories = {c for o in context.world.objects.values() for c in o.categories}
    said_of_kinds = {p for p in CATEGORY_WORDS if " " in p and p not in names}  # "fizzy water" is not the water
    for category in sorted(categories | said_of_kinds, key=len, reverse=True):
        if " " in category:
            text = text.replace(f" {_canonical(category)} ", " ")
    for name in sorted(names, key=len, reverse=True):
        if f" {_canonical(name)} " in text:
            return context.world.object_of(names[name]) or names[name]
    return None


def _canonical(words: str) -> str:
    """Words in one form: singular ("apples" → "apple"), and everyday variants made one (crisps are chips)."""
    swaps = {"crisp": "chip", "crisps": "chip", "packet": "bag", "tin": "can"}
    return " ".join(swaps.get(_singular(w), _singular(w)) for w in words.split())


@lru_cache(maxsize=4096)
def _singular(word: str) -> str:
    return getLemma(word, "NOUN")[0] if word.isalpha() and word.endswith("s") else word


def _candidates(item: str, context: PlanningContext) -> list[str]:
    """The world's objects that are what a phrase says (every category, kind and colour it names fits)."""
    world = context.world
    categories = {c for o in world.objects.values() for c in o.categories}
    kinds = {o.kind for o in world.objects.values()}
    said = " ".join(KIND_WORDS.get(w, w) if KIND_WORDS.get(w) in kinds else w for w in _canonical(item).split())
    wanted_categories, wanted_kinds = category_words(said, categories, kinds)
    colours = {w for w in item.split() if w in COLOURS | {o.colour for o in world.objects.values()}}
    partial = _name_words(item, context)
    if not (wanted_categories or wanted_kinds or colours or partial):
        return []
    fitting = []
    for name, declared in world.objects.items():
        has = set(declared.categories) | {declared.kind}
        if any(not (group & has) for group in wanted_categories):  # each word said must fit ("salty snack")
            continue
        if wanted_kinds and declared.kind not in wanted_kinds:
            continue
        if colours and declared.colour not in colours:
            continue
        if partial and not partial <= set(name.split()) | {w for a in declared.aliases for w in a.split()}:
            continue
        fitting.append(name)
    return fitting


def _kinds_named(words: str, context: PlanningContext) -> list[str]:
    """The world's objects a phrase names: by name, or every one that fits what it says."""
    name = _world_name_in(words, context)
    return [name] if name is not None else _candidates(words, context)


def _name_words(item: str, context: PlanningContext) -> set[str]:
    """Words of the phrase that belong to names only (not categories, kinds or colours): "the jalapeno ones"."""
    world = context.world
    generic = {w for o in world.objects.values() for c in [*o.categories, o.kind] for w in c.split()}
    generic |= COLOURS | {"can", "bag", "bottle", "chip", "chips", "bar", "of", "the", "a"}
    name_words = {w for n, o in world.objects.items() for w in [*n.split(), *(x for a in o.aliases for x in a.split())]}
    return {w for w in _canonical(item).split() if w in name_words and w not in generic and len(w) > 2}


def _excluded(words: str, context: PlanningContext) -> set[str]:
    """The world objects and scene instances an exclusion names ("but the apple", "that is not fizzy")."""
    if not words:
        return set()
    out = set()
    for part in re.split(r"\s*(?:,|\band\b|\bor\b|\bnor\b)\s*", words):
        part = _bare(part)
        if not part:
            continue
        name = _world_name_in(part, context)
        if name is not None:
            out.add(name)
            if " " in part:
                continue
        out |= set(_candidates(part, context))  # "no cola": the coke and the pepsi cola
    return out


def _opposite_categories(words: str, context: PlanningContext) -> set[str]:
    """The categories that say positively what an exclusion leaves out ("sugar" → unsweetened), where the world
    uses them."""
    if not words:
        return set()
    world_categories = {c for o in context.world.objects.values() for c in o.categories}
    said, _kinds = category_words(_canonical(words), world_categories, set())
    return {OPPOSITES[c] for group in said for c in group if OPPOSITES.get(c) in world_categories}


def _unknown_thing(bare: str, context: PlanningContext) -> bool:
    """A plain noun the world knows nothing by ("banana", "napkin"): no name, kind, category, colour or open word."""
    words = _canonical(bare).split()
    known = known_words(context) | set(KIND_WORDS) | {"something", "anything", "thing", "one", "stuff"}
    if len(words) > 2 or any(w in known or w in COLOURS for w in words):
        return False
    return all("NOUN" in getAllLemmas(w) for w in words)


def _same_kind(bare: str, context: PlanningContext) -> list[str]:
    """World objects a bare kind word ("cube", "the bottle") could be, when it is nothing more than that word."""
    kind = KIND_WORDS.get(bare)
    if kind is None:
        return []
    return [name for name, o in context.world.objects.items() if o.kind == kind]


def _on_surface_spoken_of(
    pool: list[str], seen: list[TrackedObject], state: _State, context: PlanningContext
) -> list[str]:
    """Those of ``pool`` (named for ``seen``, in order) on the surface an aside or a clear spoke of."""
    surface = state.mentioned_surface
    if surface is None:
        return []
    return [name for name, tracked in zip(pool, seen, strict=False) if _on_surface(tracked, surface, context)]


def _tracked(name: str, context: PlanningContext) -> TrackedObject | None:
    """The believed object a plan's name stands for (the world's name for it, or the robot's own id)."""
    return next((o for o in context.belief.present() if name in (_name_of(o, context), o.id)), None)


def _on_surface(tracked: TrackedObject, surface: str, context: PlanningContext) -> bool:
    under = context.belief.surface_under(tracked.position)
    return under is not None and under.name == surface


def _surface_words(context: PlanningContext) -> dict[str, str]:
    return WorldVocabulary.of(context.world).surfaces


def _surfaces(context: PlanningContext) -> str:
    return ", the ".join(_spoken(s) for s in context.world.surfaces)


def _places_like(kind: str, context: PlanningContext) -> list[str]:
    """ "every counter" → the places whose names or aliases say counter; "the three bins" → the bins'."""
    kind = kind.rstrip("s")
    places = []
    for name, place in context.world.places.items():
        words = {w for n in (_spoken(name), *place.aliases) for w in n.split()}
        if kind in words or (kind in ("bin", "can") and name in {c.place for c in context.world.containers.values()}):
            places.append(name)
    return places


def _prefix_place(words: str, context: PlanningContext) -> str | None:
    where = _destination(words, context)
    if where is None or where[0] == "person":
        return None
    if where[0] == "surface":
        return context.world.surfaces[where[1]].place
    if where[0] == "container":
        return context.world.containers[where[1]].place
    return where[1]


def _home(context: PlanningContext) -> str:
    return "start" if "start" in context.world.places else next(iter(context.world.places))


def _sentence(text: str) -> str:
    return text[:1].upper() + text[1:] + "."


def is_stop(text: str) -> bool:
    """Whether a command asks the robot to stop (its first clause does): cheap enough for every typed line."""
    clauses = split_clauses(normalise(text))
    return bool(clauses) and STOP.match(clauses[0]) is not None


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


def _run_together(item: Item, context: PlanningContext) -> list[Item]:
    """ "the coke the pepsi" (a comma dropped) as two items, when each part names a thing."""
    parts = [p for p in re.split(r"\s+(?=the\s)", item.words) if p]
    if len(parts) > 1 and all(_world_name_in(p, context) for p in parts):
        return [Item(re.sub(r"^the\s+", "", p), definite=True) for p in parts]
    return [item]


def _plural_of_a_kind(item: str, context: PlanningContext) -> bool:
    """ "the bottles", "the drinks": a plural of a kind or category (every one of them), unless names end in
    that very plural ("the chips" may mean the kettle chips: one bag)."""
    last = item.split()[-1]
    singular = _singular(last)
    objects = context.world.objects
    kinds = {o.kind for o in objects.values()}
    categories = {c for o in objects.values() for c in o.categories}
    name_ends = {n.split()[-1] for name, o in objects.items() for n in (name, *o.aliases)}  # "chips", not "can"
    return last.endswith("s") and singular != last and singular in kinds | categories and last not in name_ends


def _seen_names(context: PlanningContext) -> list[str]:
    return sorted({_name_of(o, context) for o in context.belief.present()})


def _one_of(tracked: TrackedObject, context: PlanningContext) -> str:
    """A believed object by a name only it has: the robot's own id when another one looks the same ("both
    apples", "the apple on the far counter"), else its name."""
    name = _name_of(tracked, context)
    twins = [o for o in context.belief.present() if o is not tracked and _name_of(o, context) == name]
    return tracked.id if twins else name


def _world_object(tracked: TrackedObject, context: PlanningContext) -> str | None:
    """The world object a believed one is (whatever the plan calls it)."""
    return context.world.object_of(tracked.name) or context.world.object_of(_name_of(tracked, context))


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
