"""Fuse detections from camera frames into the WorldModel's tracked objects.

A detection joins the tracked object it lies closest to, each object taking
at most one detection a frame, moving its estimate towards the new one and
adding a vote for its kind, colour and identity: one view may take a mug
with its handle hidden for a can, or a coke seen from afar for a pepsi, the
next view sees better, and the votes settle it, a nearer view's vote
counting for more (six looks from 3 m called a mug a ball; four from 1-2 m
saw the mug). How close is close grows
with range: a far object's centre is guessed from its front surface, and its
depth is noisier, so two looks at a bottle 3 m away can put it 9 cm apart.
A nearer view counts for more than a farther one. A detection near no
tracked object starts a new one; two tracks of one colour that come to lie
within that distance of each other, not both seen in one frame, are one
object seen twice, and the younger is folded into the older. A tracked
object that should be in view (inside the image, in range, nothing nearer
in front of it, not behind the robot's own arm) but is not seen loses
confidence; at zero it is gone. A detection cut off by the robot's own arm
confirms the object it belongs to but says nothing of its shape or pose:
the visible part's centre is off, and its cut edge can look like a handle.
"""

from __future__ import annotations

import numpy as np

from bt_humanoid.perception.detector import Detection
from bt_humanoid.perception.rgbd_camera import RgbdFrame
from bt_humanoid.perception.world_model import TrackedObject, WorldModel

ASSOCIATE = 0.06  # m: a detection this close to a tracked object's centre, both seen from near, is that object
NEAR = 1.0  # m: up to this range a detection's centre is good to a centimetre (measured: median 0.5 cm at 0.5-1 m)
# m more per metre beyond NEAR, for the detection's range and for the track's nearest view: measured errors in
# the apartment's fetch suite with sensor noise are 1.2 cm median, 2.1 cm p90 at 1.5-2 m, and up to 4.5 cm at 3.5-4 m
RANGE_GATE = 0.025
MAX_GATE = 0.15  # m: however far the looks, no nearer than this is the same thing (a mug 20 cm from a bottle is not)
GAIN = 0.35  # confidence gained per sighting
LOSS = 0.5  # factor on confidence per frame an object should have been seen and was not
GONE = 0.15  # below this confidence an object is no longer believed to be there
SIGHT_RANGE = 2.0  # m: a farther object may go undetected, so not seeing it there says nothing
MIN_APPARENT = 8  # pixels across an object must span before not seeing it counts against it
BORDER = 8  # pixels: an object this close to the image's edge may be cut off
UPRIGHT = ("bottle", "mug", "can", "bag")  # kinds carried upright (they spill or fall over otherwise)


def integrate(belief: WorldModel, detections: list[Detection], frame: RgbdFrame) -> None:
    """Update ``belief`` with one frame's detections."""
    seen: set[str] = set()
    ranges = [float(np.linalg.norm(d.position - frame.position)) for d in detections]
    matched = _associate(belief, detections, ranges)
    for index, detection in enumerate(detections):
        tracked = matched.get(index)
        if tracked is None and detection.occluded:
            continue  # a part of something: a later, clear view will say what and where
        if tracked is None:
            tracked = _new(belief, detection, frame.time, ranges[index])
        elif detection.occluded or detection.partial:  # there, but this view does not say where exactly
            _confirm(tracked, frame.time)
        else:
            _update(tracked, detection, frame.time, ranges[index])
        seen.add(tracked.id)
    for tracked in belief.objects.values():
        if tracked.id in seen or tracked.held_by is not None or tracked.confidence <= 0.0:
            continue
        if _should_be_visible(tracked, frame):
            tracked.confidence *= LOSS
            if tracked.confidence < GONE:
                tracked.confidence = 0.0
    for key in seen:
        belief.objects[key].seen_with |= seen - {key}
    _fold_duplicates(belief, seen)
    _rejoin_split(belief, seen)
    _reidentify(belief)


def gate(tracked: TrackedObject, distance: float, colour: str | None = None) -> float:
    """How near (m) a detection made from ``distance`` m must lie to ``tracked``'s centre to be it. Only one of
    the same ``colour`` gets the allowance for range: a white mug seen beside a blue bottle from across the room
    is not the bottle."""
    if colour is not None and colour != tracked.colour:
        return ASSOCIATE
    grown = RANGE_GATE * (max(0.0, distance - NEAR) + max(0.0, tracked.seen_from - NEAR))
    return min(ASSOCIATE + grown, MAX_GATE)


def _associate(belief: WorldModel, detections: list[Detection], ranges: list[float]) -> dict[int, TrackedObject]:
    """Detections to tracked objects, nearest pairs first, each object at most once (two cans side by side seen in
    one frame are two cans)."""
    pairs = []
    for index, detection in enumerate(detections):
        for tracked in belief.objects.values():
            if tracked.held_by is not None:
                continue
            distance = float(np.linalg.norm(tracked.position - detection.position))
            if distance < gate(tracked, ranges[index], detection.colour):
                pairs.append((distance, index, tracked.id))
    matched: dict[int, TrackedObject] = {}
    taken: set[str] = set()
    for _, index, key in sorted(pairs):
        if index not in matched and key not in taken:
            matched[index] = belief.objects[key]
            taken.add(key)
    return matched


def _fold_duplicates(belief: WorldModel, seen: set[str]) -> None:
    """Two believed objects of one colour closer than the gate, one of them seen in this frame and never both in
    one frame, are one object seen twice (a far look's guess and a near look's): the younger is folded into the
    older, whose id plans hold."""
    present = sorted(
        (o for o in belief.objects.values() if o.held_by is None and o.confidence > 0.0), key=lambda o: o.first_seen
    )
    for older_index, older in enumerate(present):
        for younger in present[older_index + 1 :]:
            if younger.id not in belief.objects or older.id not in belief.objects or not _alike_in_look(older, younger):
                continue
            if (older.id in seen) == (younger.id in seen) or younger.id in older.seen_with:
                continue  # a frame saw both (two things), or this one neither (nothing new to say)
            if np.linalg.norm(older.position - younger.position) < gate(older, younger.seen_from):
                _fold(belief, younger, older)


def _alike_in_look(a: TrackedObject, b: TrackedObject) -> bool:
    """Of one colour, and not told apart by look (a coke and a cherry coke are)."""
    return a.colour == b.colour and (a.identity is None or b.identity is None or a.identity == b.identity)


def _fold(belief: WorldModel, younger: TrackedObject, older: TrackedObject) -> None:
    better = older if older.seen_from <= younger.seen_from else younger
    older.position, older.size, older.seen_from = better.position.copy(), better.size.copy(), better.seen_from
    if younger.yaw_known or not older.yaw_known:
        older.yaw, older.yaw_known = younger.yaw, younger.yaw_known
    older.votes += younger.votes
    older.seen_with |= younger.seen_with
    older.confidence = max(older.confidence, younger.confidence)
    older.last_seen = max(older.last_seen, younger.last_seen)
    _vote(older)
    _retire(belief, younger.id, older.id)


def _reidentify(belief: WorldModel) -> None:
    """An object that is gone from where it was, and one like it that turned up since, are the same object.

    Someone moved it, or it fell: the old identity (which plans and the blackboard refer to) takes the new
    sighting, when exactly one gone object and exactly one newcomer of that kind and colour pair up.
    """
    objects = belief.objects

    def alike(a: TrackedObject, b: TrackedObject) -> bool:
        return a.kind == b.kind and a.colour == b.colour and a.identity == b.identity

    gone = [o for o in objects.values() if o.confidence <= 0.0 and o.held_by is None]
    for old in gone:
        newcomers = [o for o in objects.values() if o.confidence > 0 and alike(o, old) and o.first_seen > old.last_seen]
        if len(newcomers) != 1:
            continue
        new = newcomers[0]
        if sum(1 for o in gone if alike(o, new) and new.first_seen > o.last_seen) != 1:
            continue
        _take_over(belief, old, new)


def _rejoin_split(belief: WorldModel, seen: set[str]) -> None:
    """A track gone from view (it should have been seen and was not) while one of its colour, seen now, lies
    within the gate of it: one object that a frame once saw as two (a mug's body and its handle as a bottle
    beside it), and the camera now sees as one. The seen one's sighting goes to the gone one's id, which plans
    may hold (fetch episode 84 at seed 1: the plan's mug went, as a 'white bottle', 5 cm from the mug)."""
    objects = belief.objects
    for old in [o for o in objects.values() if o.confidence <= 0.0 and o.held_by is None]:
        near = [
            o
            for o in objects.values()
            if o.id in seen
            and _alike_in_look(o, old)
            and np.linalg.norm(o.position - old.position) < gate(o, old.seen_from)
        ]
        if len(near) == 1:
            _take_over(belief, old, near[0])


def _take_over(belief: WorldModel, old: TrackedObject, new: TrackedObject) -> None:
    """``old``'s id, which plans and the blackboard refer to, takes ``new``'s sighting; the votes of both count."""
    votes = old.votes + new.votes
    for name in ("position", "yaw", "yaw_known", "size", "confidence", "last_seen", "first_seen", "seen_from"):
        setattr(old, name, getattr(new, name))
    old.votes = votes
    _vote(old)
    _retire(belief, new.id, old.id)


def _retire(belief: WorldModel, key: str, into: str) -> None:
    """Track ``key`` is now ``into``: gone from the objects, and every id that named it names ``into``."""
    del belief.objects[key]
    belief.merged[key] = into
    for merged, target in belief.merged.items():
        if target == key:
            belief.merged[merged] = into


def _new(belief: WorldModel, detection: Detection, time: float, distance: float) -> TrackedObject:
    used = [*belief.objects, *belief.merged]  # a merged sighting's id stays taken: plans may still name it
    number = 1 + sum(1 for key in used if key.startswith(f"{detection.kind}-"))
    tracked = TrackedObject(
        id=f"{detection.kind}-{number}",
        name=detection.identity or f"{detection.colour} {detection.kind}",
        kind=detection.kind,
        colour=detection.colour,
        position=detection.position.copy(),
        yaw=detection.yaw,
        yaw_known=detection.yaw_known,
        size=detection.size.copy(),
        confidence=GAIN,
        last_seen=time,
        first_seen=time,
        keep_upright=detection.kind in UPRIGHT,
        identity=detection.identity,
        seen_from=distance,
    )
    _add_vote(tracked, detection, distance)
    belief.update(tracked)
    return tracked


def _confirm(tracked: TrackedObject, time: float) -> None:
    """A sighting: the object is there now."""
    tracked.confidence = min(1.0, tracked.confidence + GAIN)
    tracked.last_seen = time


def _update(tracked: TrackedObject, detection: Detection, time: float, distance: float) -> None:
    # the error grows with range: a view from as near counts half, from nearer more, from farther less
    near, old = max(distance, NEAR), max(tracked.seen_from, NEAR)
    weight = old**2 / (old**2 + near**2)
    tracked.position = (1 - weight) * tracked.position + weight * detection.position
    tracked.size = (1 - weight) * tracked.size + weight * detection.size
    tracked.seen_from = min(tracked.seen_from, distance) if tracked.seen_from > 0 else distance
    _confirm(tracked, time)
    _add_vote(tracked, detection, distance)
    _vote(tracked)
    # a seen handle beats any guess; a view that took the thing for another kind (a mug for a box) says nothing
    # of which way it faces
    if detection.kind == tracked.kind and (detection.yaw_known or not tracked.yaw_known):
        tracked.yaw, tracked.yaw_known = detection.yaw, detection.yaw_known


def _add_vote(tracked: TrackedObject, detection: Detection, distance: float) -> None:
    """A sighting's vote for what the thing is, weighed as its position is: by the inverse square of the range
    beyond NEAR (the pixels on it, and so the detail that tells a mug's handle, fall with the square of range)."""
    tracked.votes[(detection.kind, detection.colour, detection.identity)] += 1.0 / max(distance, NEAR) ** 2


def _vote(tracked: TrackedObject) -> None:
    """Kind, colour and identity: what most sightings said."""
    (kind, colour, identity), _ = tracked.votes.most_common(1)[0]
    tracked.kind, tracked.colour, tracked.identity = kind, colour, identity
    tracked.name = identity or f"{colour} {kind}"
    tracked.keep_upright = kind in UPRIGHT


def _should_be_visible(tracked: TrackedObject, frame: RgbdFrame) -> bool:
    local = frame.rotation.T @ (tracked.position - frame.position)
    distance = -local[2]
    if distance <= 0.1 or distance > SIGHT_RANGE:
        return False
    if frame.focal * float(max(tracked.size)) / distance < MIN_APPARENT:
        return False  # too small in this view to be sure of seeing it
    col = int(frame.centre[0] + frame.focal * local[0] / distance)
    row = int(frame.centre[1] - frame.focal * local[1] / distance)
    height, width = frame.depth.shape
    if not (BORDER <= row < height - BORDER and BORDER <= col < width - BORDER):
        return False
    if frame.is_hidden(row, col):
        return False  # behind the robot's own arm
    return bool(frame.depth[row, col] > distance - 0.05)  # nothing nearer in front of it
