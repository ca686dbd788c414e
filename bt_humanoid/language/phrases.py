"""What an object phrase asks for: which things, how many, which not, and from where.

"two different snacks", "every can on the far counter", "a drink that
isn't fizzy", "the apple, the tea and a bag of crisps" are parsed here into
a ``Wanted``: the listed items, a count or "every", exclusions and the
surface they come from. Which objects of the robot's belief fit is the
planner's business (``embedded.py``); this module only reads the words.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from bt_humanoid.language.lexicon import CATEGORY_WORDS, COUNT_WORDS, EVERY_WORDS, KIND_SYNONYMS

ARTICLES = re.compile(r"^(?:the|a|an|some|any|my|your|our|that|this|those|these|one|another)\s+")
EXCLUSION = re.compile(
    r"\s*\b(?:but not|but|except for|except|other than|apart from|besides|excluding|instead of|rather than|"
    r"that is not|that are not|which is not|which are not|that does not have|that has no|not|without|with no|no)\b\s*"
)
LIST_BREAK = re.compile(
    r"\s*(?:,|\band also\b|\band then\b|\bthen\b|\bfollowed by\b|\band\b|\bplus\b|\bas well as\b|\balong with\b|&)\s*"
)
DIFFERENT = re.compile(r"\b(?:different|distinct|separate|various|assorted|other)\s+")
SOURCE = re.compile(r"\s*\b(?:from|off of|off|on|at|in|sitting on|lying on|over on|over at|out of)\s+(?:the\s+)?")
OPEN_WORDS = ("something", "anything", "one", "ones", "thing", "things", "stuff", "whatever")


@dataclass
class Item:
    """One listed thing: its words (article and quantity gone) and how many of it."""

    words: str  # "apple", "bag of chips", "something fizzy"
    count: int | None = None  # "three drinks": 3; None: one
    every: bool = False  # "all the cans", "every bottle", "everything on the table"
    different: bool = False  # "two different snacks": not two of one kind
    definite: bool = False  # "the caffeinated one" names one thing; "a drink" lets the robot choose
    alternatives: tuple[str, ...] = ()  # "the pepsi or the coke": any one of these will do


@dataclass
class Wanted:
    """An object phrase read: the things listed, which not, from which surface."""

    items: list[Item]
    exclude: str = ""  # "anything but the apple": "apple"
    source: str | None = None  # the surface they come from ("the coke on the table")

    @property
    def simple(self) -> bool:
        """One thing, named plainly: no count, no "every", no exclusion."""
        item = self.items[0] if len(self.items) == 1 else None
        return item is not None and not (item.count or item.every or item.different or self.exclude)


def read_wanted(phrase: str, surfaces: dict[str, str]) -> Wanted:
    """Read an object phrase; ``surfaces``: words → surface name (for "from the far counter")."""
    text = " ".join(phrase.split())
    wanted = Wanted(items=[])
    excluded = EXCLUSION.search(text)
    if excluded is not None:  # "anything but the apple", "a drink that is not fizzy", "not the apple"
        wanted.exclude = _bare(text[excluded.end() :])
        text = text[: excluded.start()].strip()
    text, wanted.source = _source(text, surfaces)  # "the apple from the far counter, not the one on the table"
    if re.search(r"\bor\b", text):  # "the pepsi or the coke", "a coke, a pepsi or a 7up": one of them
        text = re.sub(r"^either\s+", "", text)
        options = tuple(_bare(p) for p in re.split(r"\s*(?:,\s*)?\bor\b\s*|\s*,\s*", text) if _bare(p))
        if len(options) > 1:
            wanted.items.append(Item(" or ".join(options), alternatives=options))
            return wanted
    for part in LIST_BREAK.split(text):
        item = _item(part.strip())
        if item is not None:
            wanted.items.append(item)
    said = [item.words for item in wanted.items]
    wanted.items = [item for i, item in enumerate(wanted.items) if item.words not in said[:i]]  # "a cuppa, tea"
    if len(wanted.items) > 1:  # "a snack, anything but the apple": the bare "anything" restates the snack
        wanted.items = [item for item in wanted.items if item.words not in OPEN_WORDS] or wanted.items[:1]
    if not wanted.items and wanted.exclude:
        wanted.items = [Item("anything")]
    return wanted


def _item(text: str) -> Item | None:
    definite = bool(re.match(r"^(?:the|this|that|these|those|my|your)\b", text))
    text, count, every = _quantity(text)
    different = DIFFERENT.search(text) is not None or re.match(r"^one of (?:each|every)\b", text) is not None
    words = _bare(DIFFERENT.sub("", text))
    if not words:
        return Item("anything", count, every, different, definite) if every or count else None
    return Item(words, count, every, different, definite)


def _source(text: str, surfaces: dict[str, str]) -> tuple[str, str | None]:
    """The phrase without "on the far counter" (and the surface), when the words after it name one."""
    for match in reversed(list(SOURCE.finditer(text))):
        tail = text[match.end() :]
        for words in sorted(surfaces, key=len, reverse=True):
            if tail == words or tail.startswith(words + " "):
                rest = (text[: match.start()] + " " + tail[len(words) :]).strip()
                return rest, surfaces[words]
    return text, None


def _quantity(text: str) -> tuple[str, int | None, bool]:
    """The phrase without its quantity words, the count they give and whether they mean every one."""
    text = (
        re.sub(r"^(?:the|my)\s+", "", text) if re.match(r"^(?:the|my)\s+(?:\d+|two|three|four|five)\b", text) else text
    )
    each = re.match(r"^one of (?:each|every)(?: kind of| sort of| type of)?(?: (?:of )?the)?\s+", text)
    if each:  # "one of each sparkling water": every kind once (the caller marks it different)
        return text[each.end() :], None, True
    for words in sorted(EVERY_WORDS, key=len, reverse=True):
        if text == words or text.startswith(words + " "):
            rest = re.sub(r"^(?:of\s+)?(?:the\s+)?", "", text[len(words) :].strip())
            return (rest or "anything"), None, True
    both = re.match(r"^both\s+(?:of\s+)?(?:the\s+)?", text)
    if both:
        return text[both.end() :], 2, False
    number = re.match(r"^(\d+)\s+(?:of\s+)?(?:the\s+)?", text)
    if number:
        return text[number.end() :], int(number.group(1)), False
    for words, value in sorted(COUNT_WORDS.items(), key=lambda item: -len(item[0])):
        match = re.match(rf"^{re.escape(words)}\s+(?:of\s+)?(?:the\s+)?", text)
        if match and text[match.end() :]:
            return text[match.end() :], value if words not in ("one", "a single") else None, False
    return text, None, False


def _bare(text: str) -> str:
    text = text.strip()
    previous = None
    while text != previous:
        previous = text
        text = ARTICLES.sub("", text).strip()
    return re.sub(r"\s+(?:please|now|for me|again|too|as well|there|here|over here|over)$", "", text).strip()


def category_words(text: str, world_categories: set[str], kinds: set[str]) -> tuple[list[set[str]], set[str]]:
    """The categories and kinds a phrase names, by the world's own words and the lexicon's: "a salty snack" →
    ([{salty}, {snack}], {}); "a bag of crisps" → ([{chips}], {bag}). Each set is one word's meaning (a thing
    must fit every one, and any category in each); longer phrases win ("something to drink")."""
    categories: list[set[str]] = []
    found_kinds: set[str] = set()
    rest = f" {text} "
    for category in sorted(world_categories, key=len, reverse=True):
        if f" {category} " in rest:
            categories.append({category})
            rest = rest.replace(f" {category} ", " ")
    for phrase in sorted(CATEGORY_WORDS, key=len, reverse=True):
        if f" {phrase} " in rest:
            categories.append(set(CATEGORY_WORDS[phrase]))
            rest = rest.replace(f" {phrase} ", " ")
    for word in rest.split():
        word = KIND_SYNONYMS.get(word, word)
        if word in kinds:
            found_kinds.add(word)
        elif word.endswith("s") and word[:-1] in kinds:
            found_kinds.add(word[:-1])
    return categories, found_kinds


def is_open(text: str) -> bool:
    """Whether a phrase leaves the choice to the robot: "something to drink", "anything", "one"."""
    return text.split()[0] in OPEN_WORDS if text else True
