"""A speech grammar's finite-state form, as pocketsphinx compiles it: for tests that walk or query it."""

from __future__ import annotations

import random
from dataclasses import dataclass
from pathlib import Path

from pocketsphinx import Jsgf, LogMath

from bt_humanoid.language.asr import command_grammar
from bt_humanoid.language.embedded import EmbeddedPlanner
from bt_humanoid.language.plan import PlanningContext
from bt_humanoid.language.pronunciation import UNCLEAR_SPEECH


@dataclass
class FiniteStateGrammar:
    start: int
    final: int
    arcs: dict[int, list[tuple[int, str | None]]]  # state → (next state, word or None for an empty arc)


def finite_state_grammar(grammar: str, folder: Path) -> FiniteStateGrammar:
    """Compile JSGF text (rule ``robot.utterance``) in ``folder`` and read the FSG pocketsphinx decodes with."""
    (folder / "g.gram").write_text(grammar)
    jsgf = Jsgf(str(folder / "g.gram"))
    jsgf.build_fsg(jsgf.get_rule("robot.utterance"), LogMath(), 1.0).writefile(str(folder / "g.fsg"))
    fsg = FiniteStateGrammar(0, 0, {})
    for line in (folder / "g.fsg").read_text().splitlines():
        fields = line.split()
        if fields[:1] == ["START_STATE"]:
            fsg.start = int(fields[1])
        elif fields[:1] == ["FINAL_STATE"]:
            fsg.final = int(fields[1])
        elif fields[:1] == ["TRANSITION"]:
            fsg.arcs.setdefault(int(fields[1]), []).append((int(fields[2]), fields[4] if len(fields) > 4 else None))
    return fsg


def grammar_sentences(grammar: str, folder: Path, count: int, seed: int = 0) -> list[str]:
    """Random commands the grammar accepts (walks through its finite-state form), without unclear speech."""
    fsg = finite_state_grammar(grammar, folder)
    start, final, arcs = fsg.start, fsg.final, fsg.arcs
    rng = random.Random(seed)
    sentences: set[str] = set()
    while len(sentences) < count:
        state, words = start, []
        while state != final and len(words) < 30:
            state, word = rng.choice(arcs[state])
            words += [word] if word else []
        if state == final and UNCLEAR_SPEECH not in words:
            sentences.add(" ".join(words))
    return sorted(sentences)


def not_understood(context: PlanningContext, folder: Path) -> dict[str, str]:
    """Random sentences of the world's speech grammar that its planner has no phrasing for, with its answers."""
    planner = EmbeddedPlanner()
    # "I can't …" is the planner's answer to words it has no phrasing for; any other answer (a plan, a question,
    # a refusal with a reason such as "I can't pick up people") means it understood what was asked
    refused = {}
    for sentence in grammar_sentences(command_grammar(context.world), folder, 300):
        plan = planner.plan(sentence, context)
        if plan.kind == "refusal" and plan.say.startswith("I can't") and "I can go to a place" in plan.say:
            refused[sentence] = plan.say
    return refused
