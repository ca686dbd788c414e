"""The recogniser's pronouncing dictionary: the grammar's words, as Americans and the British say them.

pocketsphinx's dictionary (CMUdict) is American. A British speaker drops an r
that no vowel follows ("meter" ends in a schwa, "forward" has none before
the d) and says "half" with the long vowel of "father". With only the
American forms such words fall out of the decoder's beams: in the voice
benchmark's en-gb voice, "go back half a meter" was heard as nothing. So
each word also gets its British form as an alternative pronunciation. A
dictionary of only the grammar's words also loads faster than all of
CMUdict's 130,000.
"""

from __future__ import annotations

import re
from functools import lru_cache
from pathlib import Path

from bt_humanoid.errors import UserError

VOWELS = frozenset({"AA", "AE", "AH", "AO", "AW", "AY", "EH", "ER", "EY", "IH", "IY", "OW", "OY", "UH", "UW"})
BATH_CONSONANTS = frozenset({"F", "S", "TH"})  # "half", "after", "glass", "path": the vowel of "father" in British
CENTRING = frozenset({"IH", "EH", "UH"})  # "here", "there", "tour": the lost r leaves a schwa behind
# The grammar's word for speech that is not one of its words, said as the acoustic model's "spoken noise"
# (+SPN+, its model of speech nobody could transcribe). A run of it is heard where a person says something the
# robot does not know ("bring me the banana" as "bring me the" and it), instead of the nearest word that fits.
UNCLEAR_SPEECH = "unclear_speech"
SPOKEN_NOISE = "+SPN+"


def cmudict_path() -> Path:
    from pocketsphinx import get_model_path

    return Path(get_model_path()) / "en-us" / "cmudict-en-us.dict"


def british(phones: str) -> str:
    """A CMUdict (American) pronunciation as a British speaker says it: non-rhotic, with the broad a of "bath"."""
    sounds = phones.split()
    out: list[str] = []
    for i, sound in enumerate(sounds):
        following = sounds[i + 1] if i + 1 < len(sounds) else None
        before_vowel = following in VOWELS
        if sound == "ER" and i > 0 and not before_vowel:
            out.append("AH")  # "meter", "forward", "counter"
        elif sound == "R" and out and out[-1] in VOWELS and not before_vowel:
            if out[-1] in CENTRING:
                out.append("AH")  # "where": W EH AH
        elif sound == "AE" and following in BATH_CONSONANTS:
            out.append("AA")  # "half": HH AA F
        else:
            out.append(sound)
    return " ".join(out)


def grammar_words(grammar: str) -> list[str]:
    """The words a JSGF grammar can produce (its rule names, header, weights and comments left out)."""
    body = "\n".join(line for line in grammar.splitlines() if not line.startswith(("#JSGF", "grammar ")))
    body = re.sub(r"<[^>]*>|//.*|/[0-9.]+/|\bpublic\b", " ", body)
    return sorted(set(re.findall(r"[a-z'_]+", body)))


@lru_cache(maxsize=1)
def known_words() -> frozenset[str]:
    """Every word of pocketsphinx's dictionary: the words a grammar may use."""
    return frozenset(read_cmudict())


def read_cmudict(path: Path | None = None) -> dict[str, list[str]]:
    """Every word's pronunciations, first the main one, then its numbered alternatives."""
    entries: dict[str, list[str]] = {}
    for line in (path or cmudict_path()).read_text().splitlines():
        word, _, phones = line.partition(" ")
        entries.setdefault(re.sub(r"\(\d+\)$", "", word), []).append(" ".join(phones.split()))
    return entries


def pronunciations(words: list[str], cmudict: dict[str, list[str]], where: str | None = None) -> dict[str, list[str]]:
    """Each word's American pronunciations and the British forms that differ.

    A word CMUdict lacks is a UserError, at ``where`` (the grammar's source).
    """
    missing = [w for w in words if w not in cmudict]
    if missing:
        raise UserError(
            f"the recogniser cannot hear {', '.join(repr(w) for w in missing)}: not in pocketsphinx's dictionary",
            where=where,
            hint="name objects, places and surfaces with English words",
        )
    result = {}
    for word in words:
        forms = list(cmudict[word])
        forms += [b for b in dict.fromkeys(british(f) for f in cmudict[word]) if b not in forms]
        result[word] = forms
    return result


def write_dictionary(grammar: str, path: Path, where: str | None = None) -> Path:
    """A pocketsphinx dictionary of the grammar's words, in both accents, at ``path``; ``where`` names the source.

    The grammar's ``UNCLEAR_SPEECH`` word is spoken noise.
    """
    words = grammar_words(grammar)
    lines = [f"{UNCLEAR_SPEECH} {SPOKEN_NOISE}"] if UNCLEAR_SPEECH in words else []
    spoken = [w for w in words if w != UNCLEAR_SPEECH]
    for word, forms in pronunciations(spoken, read_cmudict(), where).items():
        lines += [f"{word if i == 0 else f'{word}({i + 1})'} {phones}" for i, phones in enumerate(forms)]
    path.write_text("\n".join(lines) + "\n")
    return path
