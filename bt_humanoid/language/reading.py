"""Reading a request as people write it: sentences, misspellings, contractions, politeness, needs and asides.

"Ugh, I knocked my drink over. Could you get me smth to mop it up pls?"
is read as the clauses the planner acts on: ["get me something to mop it
up"]. The steps, in order:

1. plain text (``words.normalise``: lower case, digits for measured numbers),
   accents dropped ("jalapeño"), sentences and numbered steps broken apart;
2. contractions and chat words expanded ("i'm", "u", "pls");
3. misspelt words corrected against the words the robot knows — its verbs,
   the world's names, categories and places, the lexicon — when the word is
   not English (lemminflect's lexicon) and one known word is close
   (rapidfuzz): "wter botle" → "water bottle", "tabel" → "table";
4. the framing around a request dropped ("would you mind …", "how would you
   …", "… when you get a chance"), a want said as such made a request
   ("i'd like the apple" → "bring me the apple"), a need stated made one
   too ("i'm parched" → "bring me something to drink");
5. clauses that only give context ("I knocked my drink over") are kept, for
   the planner to drop when another clause asks for something.
"""

from __future__ import annotations

import re
import unicodedata
from functools import lru_cache

from lemminflect import getAllLemmas, getInflection
from rapidfuzz import fuzz, process

from bt_humanoid.language.lexicon import (
    CATEGORY_WORDS,
    CONTRACTIONS,
    FILLERS,
    FRAMING,
    NEEDS,
    SLANG,
    TROUBLES,
    TYPOS,
    WANTING,
)
from bt_humanoid.language.vocabulary import split_clauses, starts_clause
from bt_humanoid.language.words import normalise

WHERE_IT_WAS = re.compile(
    r"\s+(?:back\s+)?(?:where|from where) (?:you|i|we) (?:got|found|took|picked up) (?:it|them)(?: from)?\b"
)
WHERE_ASIDE = re.compile(r"\s+where (?:she|he|they|nobody|no one|the kids?|it|it will|they will)\b.*$")
SAID_APART = re.compile(r"\s+(?:but|so|and so|and)\s+")  # "my mate wants a coke but he can't stand cola"
SUBJECT_OR_MODAL = re.compile(r"^(?:i|he|she|they|we|it|my|our|can|could|would|will|please|no)\b")
NOTHING_ASKED = ("if so", "if you do", "if we do", "if there is", "if there are")
REWORDINGS = [  # said another way, read the same
    (re.compile(p), r)
    for p, r in (
        # "recycle it before they see it": when, not what
        (r"\s+(?:before|so that|so) (?:they|he|she|anyone|someone|somebody|the kids?|nobody|no one) \w+\b.*$", ""),
        (r"\s+(?:somewhere|anywhere)(?: (?:safe|sensible|nearby|else))?(?=$|\s+and\b)", ""),  # "set it down somewhere"
        (r"\b(put|get|move|stick|pop|place) (them|it|those|that) up (?=on|onto|there)", r"\1 \2 "),  # "put it up on"
        (r"\b(?:in the kitchen|in here|around here|in the house|lying around|knocking about)\b", ""),
        (
            r"\b(?:before|until|when|once) (?:she|he|they|the kids?|anyone|my \w+) (?:gets?|comes?|arrives?|is|are) "
            r"(?:here|home|back|in)\b",
            "",
        ),  # "before she gets here": when, not what
        (
            r"\b(tidy up|clean up|clear up|tidy|clean) (?:after|before) (?:lunch|dinner|breakfast|supper|the party|"
            r"cooking|the kids|me|us|them)\b",
            r"\1",
        ),
        (r"\bwhat(?:ever)? (?P<x>[a-z]+(?: [a-z]+)?) (?:is|are) (?=(?:on|in|at)\b)", r"all the \g<x> "),
        (r"\b(them|those) all\b", r"\1"),  # "whatever drinks are on the counter, bring them all"
        (r"^(?:how would you |how do you )?go about (\w+ing)\b", r"\1"),  # "how would you go about getting me …"
        (r"\b(?:come|get|head|hurry) back(?: here| to me| over)?(?: and)? with (?!(?:it|them|that)$)", "bring me "),
    )
]
MID_FILLER = re.compile(  # words that say nothing wherever they stand
    r"\b(?:when you get there|once you get there|once you are there|when you are there|while you are there|"
    r"while you are at it|once there|one by one|one at a time|in turn)\b"
)
BOTH_AND = re.compile(  # "both the coke and the pepsi", "both coke and pepsi"; not "both sparkling waters and …"
    r"\bboth\s+(?=the\s+[a-z0-9 -]+?\s+and\s+|[a-z0-9 -]*?[a-z0-9-]*[^s\s]\s+and\s+)"
)
IS_CONTRACTED = re.compile(
    r"(?<=[a-z])'s\s+(?=(?:a|an|so|really|all|gone|not|empty|full|dirty|sticky|messy|covered|filthy|over|still|"
    r"been|getting|too|very|quite|pretty|such|soft|bad|off|finished|done)\b)",
    re.IGNORECASE,
)
HELD_THING = re.compile(
    r"\b(?:the|that|this) (?:\w+ ){1,2}(?:you're|you are|you've got|you have got|you have|u r|ur) "
    r"(?:holding|carrying|got in your hand|got in your hands)\b",
    re.IGNORECASE,
)
HOW_WOULD_YOU = re.compile(
    r"\bhow (?:would|do|could|can|will|should|might) (?:you|i|we)\b"
    r"|\bwhat(?:'s| is| would be) (?:the|your) (?:\w+ )?(?:way|plan) (?:for you )?(?:to|for getting)?\b",
    re.IGNORECASE,
)
GO_AHEAD = re.compile(
    r"^(?:(?:go ahead|yes|yeah|ok|okay|then)\s+)*(?:and\s+)?(?:do it|do that|do so|go for it|go ahead|make it so)$"
)
REPORTED = re.compile(  # "my doctor says i need more fruit": what they said is the request's context
    r"^(?:my|our|the|his|her) (?:\w+ ){1,2}(?:says|said|thinks|reckons|told me|tells me)(?: that)?\s+"
)
NOT_THAT = re.compile(  # "not spicy though", "not the pepsi, the other one": what the request before must not be
    r"^(?:but |and )?not (?P<what>(?!(?:sure|really|now|yet)\b).+?)(?:\s+(?:though|tho|please|thanks))?"
    r"(?:\s*,\s*the other(?: one)?)?$"
)
OPEN_BRING = re.compile(
    r"^(?:bring|get|fetch|grab|give) me (?:something|anything|one|some)(?: over| here)?(?: without .+)?$"
)
ROMAN_STEP = r"(?:i|ii|iii|iv|v|vi|vii|viii|ix|x)[.)]"
SENTENCE_BREAK = re.compile(  # sentences, arrows, and numbered or lettered steps: "2.", "(2)", "b)", "iii."
    r"(?:[.!?;:]+(?=\s|$)|\s+(?:->|→|=>|-+)\s+|\n|\s(?:step\s+)?\(?\d+[.)]\s|\s\(?[a-h]\)\s|\s" + ROMAN_STEP + r"\s)"
)
STEP_NUMBER = re.compile(r"^(?:step\s+\d+|\(?\d+[.)]?|\(?[a-z][.)]|" + ROMAN_STEP + r")\s+")
UNMARKED = {
    word.replace("'", ""): full
    for word, full in CONTRACTIONS.items()
    if "n't" in word or word in ("i'm", "i've", "you're", "they're", "that's", "what's", "there's")
}
HEDGES = {"maybe", "perhaps", "possibly", "probably", "definitely", "actually", "also", "still"}
MIN_TYPO_LENGTH = 3  # shorter words are too often other words
TYPO_SCORE = 78.0  # rapidfuzz ratio (0-100) from which a word is taken for a known one
STATEMENT = re.compile(  # a verb that tells ("the apples are soft"), not in a relative clause ("one that is …")
    r"(?<!that )(?<!which )(?<!who )\b(?:is|are|was|were|has|have|had|got|went|looks?|seems?|feels?)\b"
    r"(?! (?:not )?(?:on|in)\b)"
)
SUBJECTS = re.compile(
    r"^(?:i|we|my|our|it|its|there|this|that|these|those|he|she|they|someone|somebody|the kids?|your|you are|"
    r"(?:do|does|did) not|nobody|no one|everyone|everybody|none of)\b"
)


def read(text: str, known: frozenset[str]) -> list[str]:
    """The clauses of a request, each plain and corrected; ``known``: the words the robot knows (``known_words``)."""
    text = re.sub(r"\s*[–—]\s*", " - ", text)  # a dash between clauses, before the dashes are dropped as non-ASCII
    text = unicodedata.normalize("NFKD", text).encode("ascii", "ignore").decode()  # jalapeño → jalapeno
    text = text.replace("’", "'").replace("->", " -> ").replace("→", " -> ")
    text = HOW_WOULD_YOU.sub(" ", text)  # "how would you …" asks for the plan: the planner explains and does it
    text = re.sub(r"\b(?:yourself|urself|itself)\b", " ", text, flags=re.IGNORECASE)
    text = IS_CONTRACTED.sub(" is ", text)  # "the table's a mess": "is", not whose
    text = HELD_THING.sub("what you are holding", text)  # "the can you're holding" ("can you" is not a request)
    clauses = []
    for sentence in SENTENCE_BREAK.split(" " + text.lower() + " "):
        sentence = STEP_NUMBER.sub("", sentence.strip())
        plain = normalise(sentence)
        if not plain:
            continue
        words = [_expand(word) for word in plain.split()]
        words = [w if w in known or "-" not in w else w.replace("-", " ") for w in words]  # "whole-grain"
        plain = " ".join(w for w in words if w)
        plain = _joined(" ".join(correct(word, known) for word in plain.split()), known)
        plain = MID_FILLER.sub(" ", plain).strip()
        corrected = CORRECTION.match(plain)
        asked = OBJECT_AFTER_VERB.match(clauses[-1]) if clauses and corrected else None
        if corrected is not None and asked is not None:  # "bring me the pepsi - actually no, make it a coke"
            clauses[-1] = f"{asked['verb']}{corrected['what']}{asked['rest'] or ''}"
            continue
        sure = MAKE_SURE.match(FRAMING_AT_START.sub("", plain))
        plain = f"put {sure['what']} {sure['where']}" if sure is not None else plain  # "make sure X is on S"
        plain = re.sub(r"\b(?:and also|as well as)\b", "and", plain)
        for pattern, replacement in REWORDINGS:
            plain = pattern.sub(replacement, plain)
        plain = re.sub(r"(?<=\w)\s+(?:and|then|and then)\s+stop(?: there)?$", "", plain)  # "drive up to X and stop"
        plain = re.sub(r"(?<=\w)\s+(?:first|second|third|next|last|after that)(?=\s*(?:,|$))", "", plain)
        plain = WHERE_IT_WAS.sub(" back", plain)  # "put it back where you got it"
        plain = WHERE_ASIDE.sub("", plain)  # "onto the counter where she cannot reach it"
        plain = re.sub(r"\s+and\s+(?=(?:onto|into|on to|in to|over to)\b)", " ", plain)  # "off A and onto B"
        plain = BOTH_AND.sub("", plain)  # "both the coke and the pepsi": the two named
        plain = re.sub(r"(?<=\w )what(?:ever)?(?: is| there is)?(?= (?:on|in|at|from|off)\b)", "everything", plain)
        pieces: list[str] = []
        # a comma ends a clause before a verb or an aside only; "X goes to A and Y to B" is two
        chunks = [part for chunk in re.split(r"\s*,\s*", plain) for part in BELONGS_BREAK.split(chunk)]
        chunks = [part for chunk in chunks for part in _said_apart(chunk)]
        for piece in (part for chunk in chunks for part in TOO_BREAK.split(chunk)):
            piece = unframe(piece)
            if not piece:
                continue
            open_before = pieces and re.search(r"\b(?:a|an|some|something|anything|or)\b", pieces[-1])
            if open_before and ANY_WILL_DO.match(piece):
                continue  # "get me a drink, any drink": any one will do
            refined = REFINED.match(piece)
            if pieces and refined and pieces[-1].startswith("bring me ") and not starts_clause(piece):
                pieces[-1] = f"bring me {refined['what']}"  # "need a pick me up, something with caffeine"
                continue
            if pieces and pieces[-1] in NEED_REQUESTS and not starts_clause(piece) and not is_context(piece):
                pieces[-1] = f"bring me {piece}"  # "thirsty af, water pls": the water is what meets it
                continue
            again = re.search(r"\b(?:too|as well)$", piece)  # "…, then the coke too": the same again, apart
            joins = not again and not starts_clause(piece) and not is_context(piece)
            if pieces and joins and not is_context(pieces[-1]):
                pieces[-1] += " , " + piece
            else:
                pieces.append(piece)
        clauses += [clause for piece in _in_order(pieces) for clause in split_clauses(piece)]
    clauses = [unframe(clause) for clause in clauses if unframe(clause)]
    clauses = _refined(clauses)
    clauses = _avoiding(_topic_first(_in_order(_asked_if_there(clauses))))
    if clauses and all(is_context(c) for c in clauses):  # "my desk is sticky, help": the trouble says what
        trouble = next((TROUBLES[w] for c in clauses for w in c.split() if w in TROUBLES), None)
        if trouble is not None:
            clauses.append(f"bring me {trouble}")
    needs = [c for c in clauses if c in NEED_REQUESTS]
    clauses = [c for i, c in enumerate(clauses) if c not in NEED_REQUESTS or c not in clauses[:i]]  # said twice
    asked = [c for c in clauses if c not in NEED_REQUESTS and not is_context(c)]
    if not asked or not needs:
        return clauses
    # "i'm starving, bring me two snacks": the request says it; "i'm thirsty, bring me something": the need says what
    wanted = NEED_REQUESTS[needs[0]]
    return [re.sub(r"\b(?:something|anything)$", wanted, c) for c in clauses if c not in NEED_REQUESTS]


def _said_apart(chunk: str) -> list[str]:
    """ "my kid is allergic to apples so get them off the table": broken at "but"/"so" before a new clause only
    ("anything but the apple" stays whole)."""
    pieces = re.split(r"\s+(but|so|and so|and)\s+", chunk)
    out = pieces[:1]
    for word, part in zip(pieces[1::2], pieces[2::2], strict=True):
        apart = SUBJECT_OR_MODAL.match(part) or (word != "and" and starts_clause(unframe(part)))
        if apart and not (word == "and" and not is_context(out[-1])):  # "and" parts only an aside from the rest
            out.append(part)
        else:
            out[-1] += f" {word} {part}"
    return out


def _refined(clauses: list[str]) -> list[str]:
    """Clauses that only narrow the request before ("…, not spicy though", "the yellow ones", "any will do")
    folded into it; "bring me something" dropped where another clause already says what to bring."""
    out: list[str] = []
    for clause in clauses:
        asking = bool(out) and not is_context(out[-1])
        not_that = NOT_THAT.match(clause)
        if not_that is not None and not starts_clause(not_that["what"]):
            if asking:
                out[-1] += f" but not {not_that['what']}"
            continue  # after a complaint ("i wanted the tea, not the water") it asks nothing
        if asking and ANY_WILL_DO.match(clause):
            continue
        left = LEAVE_OUT.match(clause)
        if asking and left is not None and re.search(r"\b(?:all|every|everything|both)\b", out[-1]):
            out[-1] += f" except {left['what']}"  # "recycle all the cans on the far counter, but leave the red bull"
            continue
        just_one = re.match(r"^(?:(?:just|only)\s+)?(?:one|1|a single)(?:\s+\w+)?$", clause)
        if asking and just_one is not None:  # "any chips except the spicy ones. just one bag."
            out[-1] = re.sub(r"\b(?:any|some)\s+(?=\w)", "a ", out[-1], count=1)
            continue
        which = re.match(r"^(?:the|those|that)\s+(?P<how>(?:\w+\s+){1,2})(?:one|ones)$", clause)
        if asking and which is not None:  # "fetch me a packet of crisps. the yellow ones.": yellow crisps
            out[-1] = _narrowed(out[-1], which["how"].strip())
            continue
        out.append(clause)
    named = [c for c in out if c.startswith("bring me ") and not OPEN_BRING.match(c)]
    out = [c for c in out if not (OPEN_BRING.match(c) and named)]
    # "maybe the lime one? yeah, bring me the lime seltzer": a thing said tentatively, then asked for plainly
    asked = [i for i, c in enumerate(out) if starts_clause(c) and not is_context(c)]
    return [c for i, c in enumerate(out) if not (TENTATIVE.match(c) and any(j > i for j in asked))]


CORRECTION = re.compile(  # "actually no, make it a coke", "no wait, the blue bag, the chips one"
    r"^(?:actually|no|nope|wait|sorry|oh|or rather|scratch that|on second thought|i mean)\b[\s,]*"
    r"(?:(?:actually|no|nope|wait|sorry)\b[\s,]*)*(?:make (?:it|that)|i mean|rather|instead|i meant)?\s*"
    r"(?P<what>(?:the|a|an|some)\b.+?)(?:\s*,\s*the \w+ ones?)?(?:\s+instead)?$"
)
OBJECT_AFTER_VERB = re.compile(
    r"^(?P<verb>(?:bring|get|grab|fetch|give|hand|pass|pick up|take|put|recycle|compost|throw away|bin)(?: me)? )"
    r"(?P<what>(?:the|a|an|some|that|this|my)\b.+?)(?P<rest>\s+(?:on|onto|in|into|to)\s+.+)?$"
)
LEAVE_OUT = re.compile(
    r"^(?:but )?(?:leave|keep|skip|not|except|apart from)(?: out)? (?P<what>.+?)"
    r"(?: alone| there| out| where (?:it|they) (?:is|are))?$"
)
TENTATIVE = re.compile(r"^(?:maybe|perhaps|possibly|probably|like)\s+(?:the|a|an|some)\b")


def _narrowed(request: str, how: str) -> str:
    """ "fetch me a packet of crisps" narrowed by "yellow": "fetch me the yellow crisps"."""
    thing = re.search(r"\b(?:a|an|some|the|any)\s+(?:(?:\w+)\s+of\s+)?(?P<head>[\w -]+)$", request)
    if thing is None or DESTINATION_WORDS.search(thing["head"]):
        return f"{request} , the {how} ones"
    return f"{request[: thing.start()]}the {how} {thing['head']}"


def _in_order(clauses: list[str]) -> list[str]:
    """Clauses in the order to do them: "before you come back, grab the red bull" → grab, then come back;
    "once you've picked up the apple, put it …" → pick up, then put; "if you see a coke, …" names the coke."""
    out: list[str] = []
    later: list[str] = []
    for clause in clauses:
        before = re.match(r"^before (?:you|i)\s+(?P<rest>.+)$", clause)
        if before is not None:
            later.append(_base_form(before["rest"]))
            continue
        once = re.match(r"^(?:once|after|when|as soon as) you(?: have| are)?\s+(?P<rest>.+)$", clause)
        once = once or re.match(r"^(?:once|after|when|as soon as)\s+(?P<rest>\w+ing\b.+)$", clause)
        if once is not None:
            rest = re.sub(r"^(?:done|finished|through)(?: with)?\s+(?=\w+ing\b)", "", once["rest"])
            clause = _gerund(rest) if rest.split()[0].endswith("ing") else _base_form(rest)
        seen = re.match(r"^if you (?:see|find|spot|can find) (?P<thing>.+)$", clause)
        if seen is not None:
            clause = f"with {seen['thing']}"
        out.append(clause)
        out += later
        later = []
    return out + later


ANY_WILL_DO = re.compile(  # "any drink", "whichever one is easier to reach", "either is fine"
    r"^(?:any|anything|whatever|whichever|either)\b"
    r"(?!.*\b(?:(?:on|in|from|off|at|to)\s+the|but|except|without|other than|not|apart from)\b)(?:\s+\w+){0,5}$"
)
PRONOUN = re.compile(r"\b(?:it|them)\b")
DESTINATION_WORDS = re.compile(r"\b(?:to|into|onto|towards?)\b")


def _topic_first(clauses: list[str]) -> list[str]:
    """A thing named first and then acted on as "it": "the coke, bring it here" → "bring the coke here"."""
    out: list[str] = []
    for clause in clauses:
        topic = out[-1] if out else None
        if (
            topic is not None
            and not starts_clause(topic)
            and not is_context(topic)
            and not DESTINATION_WORDS.search(topic)
            and not PRONOUN.search(topic)
            and starts_clause(clause)
            and PRONOUN.search(clause)
        ):
            out[-1] = PRONOUN.sub(topic.replace("\\", ""), clause, count=1)
        else:
            out.append(clause)
    return out


AVOIDING = (
    r"(?:off|avoiding|avoid|cutting out|cut out|staying off|allergic to|cutting back on|cut back on|cutting down on|"
    r"cut down on|not (?:having|drinking|eating)|no|"
    r"(?:cannot|can not|do not|does not|will not|would not) (?:stand|like|drink|eat|have|do|want|bear|handle|touch))"
)
OFF = re.compile(  # "i'm off sugar this month", "he can't stand cola", "no caffeine for me": asked for without it
    r"^(?:(?:my|our|the) (?:[\w-]+ ){1,3}|i |we |he |she |they )?(?:am |are |is |have gone |has gone |went |have been |"
    r"has been )?(?:trying to |going to )?" + AVOIDING + r"\s+(?:(?:anything|something) with\s+)?"
    r"(?P<what>.+?)(?:\s+in it)?(?:\s+(?:this|for|at|right|these|anymore|any more|at all|after|today|tonight)\b.*)?$"
)
OPEN_REQUEST = re.compile(  # a request that leaves the choice open: "something", "a drink", "one", "me caffeine"
    r"\b(?:something|anything|a drink|a snack|some\s+\w+)\b|^\w+(?: \w+)? one\b|^bring me (?!the\b|my\b|your\b)"
)


def _asked_if_there(clauses: list[str]) -> list[str]:
    """ "do we have any sparkling water? i'd like one": the question names what the next clause asks for."""
    out = list(clauses)
    for i, clause in enumerate(clauses[:-1]):
        there = HAVE_ANY.match(clause)
        asked_next = starts_clause(clauses[i + 1]) or WANT_AT_START.match(clauses[i + 1])
        if there is not None and asked_next:
            out[i] = f"with {there['what'] or there['other'] or there['third']}"
    return out


def _avoiding(clauses: list[str]) -> list[str]:
    """ "i'm off sugar and caffeine, anything i can drink?", "i need caffeine and i can't stand fizzy drinks": the
    open requests are made "without" what is avoided. The clause that says so stays, as context ("my kid is
    allergic to apples, get them off the table": "them")."""
    avoided = [off["what"] for off in map(OFF.match, clauses) if off is not None]
    if not avoided:
        return clauses
    without = " and ".join(avoided)
    return [
        f"{clause} without {without}"
        if OPEN_REQUEST.search(clause) and " without " not in clause and not OFF.match(clause)
        else clause
        for clause in clauses
    ]


def _base_form(clause: str) -> str:
    """ "picked up the apple" → "pick up the apple"."""
    first, _, rest = clause.partition(" ")
    lemma = getAllLemmas(first).get("VERB", (first,))[0]
    return f"{lemma} {rest}".strip()


def _joined(text: str, known: frozenset[str]) -> str:
    """Two words that make one known word written apart ("7 up", "grape fruit") joined."""
    words = text.split()
    out: list[str] = []
    for word in words:
        if (out and out[-1] + word in known and out[-1] not in known | {"a", "the"}) or (
            out and out[-1] + word in known and word not in known
        ):
            out[-1] += word
        else:
            out.append(word)
    return " ".join(out)


def _expand(word: str) -> str:
    if word in TYPOS:
        return TYPOS[word]
    if word in CONTRACTIONS:
        return CONTRACTIONS[word]
    if word in UNMARKED:  # "isnt", "dont": contractions typed without the apostrophe
        return UNMARKED[word]
    for ending, full in (("'d", " would"), ("'ll", " will"), ("'re", " are"), ("'ve", " have")):
        if word.endswith(ending) and len(word) > len(ending) + 1:  # "it'd", "we'll", "they're"
            return word[: -len(ending)] + full
    if word in SLANG:
        return SLANG[word]
    if word.endswith("'s") and len(word) > 3:
        return word[:-2]  # "the kid's", "robot's": the owner is not the point
    return word.replace("'", "")


def correct(word: str, known: frozenset[str]) -> str:
    """``word``, or the known word it is a misspelling of (see the module's docstring)."""
    if len(word) < MIN_TYPO_LENGTH or word in known or not word.isalpha() or getAllLemmas(word):
        return word
    return _closest(word, known)


@lru_cache(maxsize=4096)
def _closest(word: str, known: frozenset[str]) -> str:
    best = process.extractOne(word, known, scorer=fuzz.ratio, score_cutoff=TYPO_SCORE)
    return best[0] if best is not None else word


FRAMING_AT_START = re.compile(
    r"^(?:" + "|".join(re.escape(f) for f in sorted(FRAMING, key=len, reverse=True)) + r")\b\s*"
)
FRAMING_AT_END = re.compile(
    r"\s*\b(?:" + "|".join(re.escape(f) for f in sorted(FRAMING, key=len, reverse=True)) + r")$"
)
FILLER_AT_START = re.compile(
    r"^(?:" + "|".join(re.escape(f) for f in sorted(FILLERS, key=len, reverse=True)) + r")\b\s*"
)
WANT_AT_START = re.compile(r"^(?:" + "|".join(re.escape(w) for w in sorted(WANTING, key=len, reverse=True)) + r")\b\s*")
NEED_REQUESTS = {f"bring me {wanted}": wanted for wanted in NEEDS.values()}
WOULD_BE = re.compile(
    r"^(?P<what>(?:some|a|an|something|anything)\b.*?)\s+(?:would|will|could)\s+(?:be|do|hit the spot)\b.*$"
)
BELONGS = re.compile(  # "the water bottle needs to go on the table", "the apple belongs in the compost"
    r"^(?P<what>.+?)\s+(?:needs? to|has to|have to|should|must|ought to|can|could|will|would|is to)?\s*"
    r"(?:go|goes|belongs?|be put|be placed|be moved|be kept|live|lives|stay|stays|be better(?: off)?|look better|"
    r"fit better|be happier)\s+"
    r"(?P<where>(?:back\s+)?(?:on|in|into|onto|on top of|to|inside|over on|next to|by)\s+.+?)"
    r"(?:\s+(?:than|rather than|instead of)\s+.+)?$"
)
MAKE_SURE = re.compile(
    r"^(?:make sure|ensure|see to it|check|double check)(?: that)? (?P<what>.+?) (?:is|are|ends? up|get|gets)"
    r"(?: all| both| back)? (?P<where>(?:on|in|into|onto|inside|at) .+)$"
)
MUST_GO = re.compile(r"^(?P<what>.+?) (?:needs? to|has to|have to|must|should|can) go(?: away)?$")
PEOPLE_AND_THEN = r"^(?:i|we|you|he|she|they|someone|somebody)\b|\bthen\b"
# "the kettle chips go to the close counter and the rice chips go to the table": two requests
BELONGS_BREAK = re.compile(
    r"\s+(?:and|,)\s+(?=[a-z0-9 -]+?\s+(?:needs? to |has to |should |must )?(?:go|goes|belongs?)\s+"
    r"(?:back\s+)?(?:on|in|into|onto|to|inside)\b)"
)
TOO_BREAK = re.compile(r"\s+(?:and then|then|and)\s+(?=(?:also\s+)?(?:the |a |an )?[a-z0-9 -]+? (?:too|as well)$)")
COME_TO_ME = re.compile(r"^(?:come|go)(?: and)? (?:find|see|join|get) (?:me|us)$|^find me$")
GO_AND_STAY = re.compile(r"^(?P<go>go|come|head)(?: and| over and| over)? (?:stand|wait|park|stay|sit|hang out|be)\b")
ANYTHING_TO = re.compile(
    r"^(?:is there|have you got|have we got|do you have|do we have|got)\s+(?:anything|something)\s+"
    r"(?:(?:that\s+)?(?:i|we)\s+(?:can|could)\s+|to\s+)(?P<verb>drink|eat|snack on|have)\b"
    r"|^what (?:can|could|should|shall) (?:i|we) (?P<other>drink|eat|snack on|have)\b"
)
REFINED = re.compile(r"^(?:preferably|ideally|maybe|like|say)?\s*(?P<what>something\b(?!.*\b(?:but|except)\b).*)$")
FOR_ME = re.compile(r"^(?:get|grab|fetch|snag|nab|pick up|go get)\s+(?P<what>.+?)\s+for (?:me|us)(?:\s+please)?$")
HAVE_ANY = re.compile(
    r"^(?:do|have) (?:we|you) (?:still )?(?:have|got) (?:any|some)(?: of (?:those|the|these))? (?P<what>.+)$|"
    r"^(?:is|are) there (?:still )?(?:any|some)(?: of (?:those|the|these))? (?P<other>.+?)"
    r"(?: left| around| here)?$|^(?:(?:you |we )?got )?any (?P<third>.+?)(?: left| around)?$"
)
PARTICIPLES = {
    **dict.fromkeys(("moved", "put", "placed", "taken", "carried", "brought", "set", "left"), "put"),
    **dict.fromkeys(("thrown", "binned", "tossed", "chucked", "dumped"), "throw"),
    "recycled": "recycle",
    "composted": "compost",
}
DONE_TO = re.compile(r"^(?P<what>.+?)\s+(?P<done>" + "|".join(PARTICIPLES) + r")\b\s*(?P<rest>.*)$")
NEED = re.compile(
    r"^(?:i am|we are|i feel|feeling|i get|getting)\s+(?:so\s+|really\s+|absolutely\s+|a bit\s+|kinda\s+)*(?P<need>"
    + "|".join(NEEDS)
    + r")\b"
)
BARE_NEED = re.compile(  # "thirsty af", "so hungry!!": the need alone, said without "i am"
    r"^(?:so\s+|really\s+|absolutely\s+|kinda\s+|super\s+)*(?P<need>"
    + "|".join(NEEDS)
    + r")(?:\s+(?:af|rn|now|right now|lol|too|as hell|here|over here|today))*"
    r"(?:\s+(?:after|from|because|since|cause|cos)\b.*)?$"  # "so thirsty after my run"
)


def unframe(clause: str) -> str:
    """A clause without the words around what it asks ("could you please …", "… for me"); a want or a need as a
    request to bring something."""
    for_me = FOR_ME.match(clause)
    if for_me is not None:  # "could you get the coke for me": get it to me
        clause = f"bring me {for_me['what']}"
    clause = re.sub(r"\s+if (?:you|we) (?:have|have got|got|can find|can|see) (?:it|one|any|some)$", "", clause)
    clause = re.sub(  # "something he can drink": something to drink
        r"\b(?:something|anything) (?:that )?(?:he|she|they|we|i|you|the kids?) (?:can|could|would|will|might) "
        r"(?P<verb>drink|eat|have|snack on)\b",
        r"something to \g<verb>",
        clause,
    )
    clause = re.sub(r"^(?:i|we) (?:really|just|actually|so|kind of|kinda|totally|badly|desperately) ", "i ", clause)
    allowed = re.match(
        r"^what (?:is|are) (?P<what>(?:a|an|some) \w+)(?: that)? (?:i|we) (?:am|are|can|could) "
        r"(?:allowed|have|drink|eat)\b",
        clause,
    )
    if allowed is not None:  # "what's a drink i'm allowed?"
        return f"bring me {allowed['what']}"
    if GO_AHEAD.match(clause) or clause in NOTHING_ASKED:  # "go ahead and do it", "if so": nothing more asked
        return ""
    previous = None
    while clause != previous:
        previous = clause
        clause = REPORTED.sub("", clause).strip()
        clause = FILLER_AT_START.sub("", clause).strip()
        clause = FRAMING_AT_START.sub("", clause).strip()
        if not re.match(r"^(?:say|tell|announce)\b", clause):  # what is to be said stays as it is
            clause = FRAMING_AT_END.sub("", clause).strip()
    sure = MAKE_SURE.match(clause)
    if sure is not None:  # "make sure the coke and the tea are on the table"
        return f"put {sure['what']} {sure['where']}"
    gone = MUST_GO.match(clause)
    if gone is not None:  # "everything on the table needs to go", "the chips have to go"
        everything = re.match(r"^(?:everything|all|it all|all of it|all the stuff) (?:on|from|off) ", gone["what"])
        return f"clear {gone['what'][everything.end() :]}" if everything else f"throw away {gone['what']}"
    belongs = BELONGS.match(clause)
    if belongs is not None and not starts_clause(belongs["what"]) and not re.search(PEOPLE_AND_THEN, belongs["what"]):
        if re.match(r"^(?:in|into|to) (?:my|our) hands?$|^to (?:me|us)$", belongs["where"]):
            return f"bring me {belongs['what']}"
        return f"put {belongs['what']} {belongs['where']}"
    if COME_TO_ME.match(clause):
        return "come here"
    clause = GO_AND_STAY.sub(lambda m: m["go"], clause)  # "go stand by the bin"
    anything = ANYTHING_TO.match(clause)
    if anything is not None:  # "is there anything i can drink?"
        return f"bring me something to {anything['verb'] or anything['other']}"
    would = WOULD_BE.match(clause)
    if would is not None:
        return f"bring me {would['what']}"
    need = NEED.match(clause) or BARE_NEED.match(clause)
    if need is not None:
        return f"bring me {NEEDS[need['need']]}"
    wanted = WANT_AT_START.match(clause)
    if wanted is not None and clause[wanted.end() :].strip():
        rest = clause[wanted.end() :].strip()
        own_errand = re.match(r"^to (?!(?:have|eat|drink|snack|munch|try)\b)", rest)
        if own_errand is not None and not re.match(r"^i (?:would like|want) you\b", clause):
            return clause  # "i need to take a tablet": what the speaker will do, context for the request
        rest = re.sub(r"^(?:you to|to have|to)\s+", "", rest)
        rest = re.sub(r"^(?:eat|drink|have|snack on|munch on|try)\s+(?:some\s+)?(?:more\s+)?(?=\w)", "", rest)
        done = DONE_TO.match(rest)
        if done is not None:  # "i want the chips moved to the table"
            return f"{PARTICIPLES[done['done']]} {done['what']} {done['rest']}".strip()
        placed = re.search(r"\s(?:over )?there$|\s(?:on|onto|into) (?:the )?\w", rest) and re.match(
            r"^(?:i|we) (?:need|want|will need|will want|am going to need)\b", clause
        )
        if placed and not _starts_with_verb_like(rest):
            return f"put {rest}"  # "i need the sponge over there", "we need two waters on the table"
        return rest if _starts_with_verb_like(rest) else f"bring me {rest}"
    return _gerund(_without_adverb(clause))


def _without_adverb(clause: str) -> str:
    """ "terribly putting the lemonade …" (after "would you mind") → "putting the lemonade …"; "maybe grab …"."""
    first, _, rest = clause.partition(" ")
    lemmas = getAllLemmas(first)
    adverb = (first.endswith("ly") and "ADV" in lemmas and not {"NOUN", "VERB"} & set(lemmas)) or first in HEDGES
    if adverb and rest and (rest.split()[0].endswith("ing") or starts_clause(rest)):
        return rest
    return clause


def _starts_with_verb_like(text: str) -> bool:
    first = text.split()[0] if text else ""
    return "VERB" in getAllLemmas(first) and "NOUN" not in getAllLemmas(first)


def _gerund(clause: str) -> str:
    """ "grabbing the coke" (after "would you mind") → "grab the coke"."""
    first, _, rest = clause.partition(" ")
    if first.endswith("ing") and len(first) > 4:
        lemmas = getAllLemmas(first).get("VERB")
        if lemmas:
            return f"{lemmas[0]} {rest}".strip()
    return clause


def is_context(clause: str) -> bool:
    """A clause that tells something rather than asks: "i knocked my drink over", "the apples are soft",
    "got a meeting in five"."""
    if SUBJECTS.match(clause) is not None or STATEMENT.search(clause) is not None or OFF.match(clause):
        return True  # "no caffeine for me today" says what not to bring: context for the request
    first = clause.split()[0] if clause else ""
    lemma = getAllLemmas(first).get("VERB", ("",))[0]
    return bool(lemma) and first != lemma and getInflection(lemma, "VBD") == (first,)  # "knocked", "got", "left"


def lexicon_words() -> set[str]:
    """The lexicon's words, for ``known``: what a misspelling may be corrected to."""
    return {word for phrase in CATEGORY_WORDS for word in phrase.split()}
