"""Plain text for the planner: lower case, no punctuation, numbers as digits, the wake word gone.

"Hey robot, walk forward two meters and turn left ninety degrees."
becomes "walk forward 2 meters and turn left 90 degrees". Spoken numbers
come from speech recognition as words, typed ones as digits; the planner
sees digits either way.
"""

from __future__ import annotations

import re

UNCLEAR = "…"  # stands in a transcript for speech the recogniser could not make out ("bring me the …")
WAKE_WORDS = ("hey robot", "ok robot", "okay robot", "robot")
# Polite words around a command, left out before planning. The speech grammar hears the spoken ones before a
# command, and AFTER ones at its end ("turn left please", "go home now"); typed, any of them go anywhere.
POLITE_SPOKEN = ("please", "could you", "can you", "would you")
POLITE = (*POLITE_SPOKEN, "will you", "i want you to", "i would like you to")
AFTER = ("please", "now")

UNITS = {
    "zero": 0,
    "a": 1,
    "an": 1,
    "one": 1,
    "two": 2,
    "three": 3,
    "four": 4,
    "five": 5,
    "six": 6,
    "seven": 7,
    "eight": 8,
    "nine": 9,
    "ten": 10,
    "eleven": 11,
    "twelve": 12,
    "thirteen": 13,
    "fourteen": 14,
    "fifteen": 15,
    "sixteen": 16,
    "seventeen": 17,
    "eighteen": 18,
    "nineteen": 19,
}
TENS = {"twenty": 20, "thirty": 30, "forty": 40, "fifty": 50, "sixty": 60, "seventy": 70, "eighty": 80, "ninety": 90}
FRACTIONS = {"half a": 0.5, "half": 0.5, "a half": 0.5, "quarter of a": 0.25, "a quarter of a": 0.25}
NUMBER_WORD = re.compile(r"\b(?:" + "|".join([*TENS, *UNITS, "hundred", "and", "point"]) + r")\b")
UNIT_AFTER = re.compile(r"^\s*(?:meters?|metres?|m|degrees?|deg|times|centimeters?|centimetres?|cm|steps?)\b")


def is_unclear(text: str) -> bool:
    """Whether a transcript has speech the recogniser could not make out: UNCLEAR as a word of its own, as
    transcripts write it (a typed "mug…" is not)."""
    return UNCLEAR in text.split()


def normalise(text: str) -> str:
    """Lower case, digits for number words, without punctuation, polite words or the wake word."""
    text = text.lower().replace("’", "'")
    text = re.sub(r"[^a-z0-9.',-]+", " ", text).replace(",", " , ")  # a comma stays: it can end a clause
    text = re.sub(r"(?<![0-9])\.|\.(?![0-9])", " ", text)  # full stops, but not decimal points
    text = " ".join(text.split())
    for wake in WAKE_WORDS:
        if text == wake or text.startswith(wake + " "):
            text = text[len(wake) :].strip(" ,")
            break
    for polite in POLITE:
        text = re.sub(rf"\b{polite}\b", " ", text)
    text = re.sub(rf"(?:\s+(?:{'|'.join(AFTER)}))+\s*$", "", " " + " ".join(text.split()))  # "… now" at the end
    text = " ".join(text.split()).strip(" ,")
    return _digits(text)


def _digits(text: str) -> str:
    """Replace spelt-out numbers that measure something ("two meters", "ninety degrees") with digits."""
    for words, value in sorted(FRACTIONS.items(), key=lambda item: -len(item[0])):
        text = re.sub(rf"\b{words}\b(?= (?:meter|metre|m\b))", str(value), text)
    tokens = text.split(" ")
    out: list[str] = []
    i = 0
    while i < len(tokens):
        value, used = _number_at(tokens, i)
        if used and UNIT_AFTER.match(" ".join(tokens[i + used :])):
            out.append(_format(value))
            i += used
        else:
            out.append(tokens[i])
            i += 1
    return " ".join(out)


def _number_at(tokens: list[str], start: int) -> tuple[float, int]:
    """A number spelt out from ``tokens[start]``: its value and how many tokens it took (0 if none)."""
    total, current, used = 0.0, 0.0, 0
    i = start
    while i < len(tokens):
        word = tokens[i]
        if word in UNITS and not (word in ("a", "an") and used):
            current += UNITS[word]
        elif word in TENS:
            current += TENS[word]
        elif word == "hundred" and used:
            current *= 100
        elif word == "and" and used and i + 1 < len(tokens) and tokens[i + 1] in {*UNITS, *TENS}:
            pass
        elif word == "point" and used and i + 1 < len(tokens) and tokens[i + 1] in UNITS:
            total += current + UNITS[tokens[i + 1]] / 10
            return total, i + 2 - start
        else:
            break
        used = i + 1 - start
        i += 1
    return total + current, used


def _format(value: float) -> str:
    return str(int(value)) if value == int(value) else f"{value:g}"
