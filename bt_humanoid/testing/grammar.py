"""A speech grammar's finite-state form, as pocketsphinx compiles it: for tests that walk or query it."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from pocketsphinx import Jsgf, LogMath


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
