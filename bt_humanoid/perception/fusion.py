"""Fuse detections from camera frames into the WorldModel's tracked objects.

A detection joins the tracked object it lies closest to (same surface,
within a few centimetres), moving its estimate towards the new one and
adding a vote for its kind, colour and identity: one view may take a mug
with its handle hidden for a can, or a coke seen from afar for a pepsi, the
next view sees better, and the votes settle it. A detection near no tracked object starts a new one. A tracked
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

ASSOCIATE = 0.06  # m: a detection this close to a tracked object's centre is that object
NEW_WEIGHT = 0.5  # share of a new detection in a tracked object's updated position
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
    for detection in detections:
        tracked = _nearest(belief, detection)
        if tracked is None and detection.occluded:
            continue  # a part of something: a later, clear view will say what and where
        if tracked is None:
            tracked = _new(belief, detection, frame.time)
        elif detection.occluded or detection.partial:  # there, but this view does not say where exactly
            _confirm(tracked, frame.time)
        else:
            _update(tracked, detection, frame.time)
        seen.add(tracked.id)
    for tracked in belief.objects.values():
        if tracked.id in seen or tracked.held_by is not None or tracked.confidence <= 0.0:
            continue
        if _should_be_visible(tracked, frame):
            tracked.confidence *= LOSS
            if tracked.confidence < GONE:
                tracked.confidence = 0.0
    _reidentify(belief)


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
        for name in ("position", "yaw", "yaw_known", "size", "confidence", "last_seen", "first_seen", "votes"):
            setattr(old, name, getattr(new, name))
        del objects[new.id]
        belief.merged[new.id] = old.id


def _nearest(belief: WorldModel, detection: Detection) -> TrackedObject | None:
    candidates = [
        o
        for o in belief.objects.values()
        if o.held_by is None and np.linalg.norm(o.position - detection.position) < ASSOCIATE
    ]
    return min(candidates, key=lambda o: np.linalg.norm(o.position - detection.position)) if candidates else None


def _new(belief: WorldModel, detection: Detection, time: float) -> TrackedObject:
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
    )
    tracked.votes[(detection.kind, detection.colour, detection.identity)] += 1
    belief.update(tracked)
    return tracked


def _confirm(tracked: TrackedObject, time: float) -> None:
    """A sighting: the object is there now."""
    tracked.confidence = min(1.0, tracked.confidence + GAIN)
    tracked.last_seen = time


def _update(tracked: TrackedObject, detection: Detection, time: float) -> None:
    tracked.position = (1 - NEW_WEIGHT) * tracked.position + NEW_WEIGHT * detection.position
    tracked.size = (1 - NEW_WEIGHT) * tracked.size + NEW_WEIGHT * detection.size
    _confirm(tracked, time)
    tracked.votes[(detection.kind, detection.colour, detection.identity)] += 1
    (kind, colour, identity), _ = tracked.votes.most_common(1)[0]
    if detection.yaw_known or not tracked.yaw_known:  # a seen handle beats any guess
        tracked.yaw, tracked.yaw_known = detection.yaw, detection.yaw_known
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
