"""Detect a world's objects with the learned recogniser: the network says what, geometry says where.

1. Geometry finds the regions standing on known surfaces (``detector.segment``):
   depth is better at "there is a thing here" than any network this small.
2. The recogniser judges each region's RGB-D crop: one of the world's objects,
   or none (a fragment, a piece of furniture, something else).
3. Knowing what it is gives its shape and size (world.yaml's model); the
   region's points give where it stands and how it is turned: a cylinder's or
   sphere's centre from its outline, a box's from the rectangle round its top,
   each pushed back from the camera by what the view could not see of it.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np

from bt_humanoid.perception.crops import FEATURES, region_crop, region_features
from bt_humanoid.perception.detector import (
    FLAT_BAND,
    LID_WIDTH,
    MIN_WIDTH,
    RESTING,
    TOP_BAND,
    WELL_SEEN_TOP,
    Detection,
    Region,
    circle,
    cylinder_outline,
    region_noise,
    resting_sphere,
    segment,
    without_fragments,
)
from bt_humanoid.perception.recogniser import NONE, Recogniser
from bt_humanoid.perception.rgbd_camera import RgbdFrame
from bt_humanoid.perception.world_model import SupportSurface
from bt_humanoid.sim.world_config import ObjectModel, WorldConfig

MIN_CONFIDENCE = 0.5  # below this the recogniser is not sure enough to name a region
PARTIAL = 0.8  # of a box's known length and breadth: a top outline shorter both ways is a part of it


@dataclass(frozen=True)
class KnownObject:
    """What the map says about one of the world's objects: its kind and colour in words, its model's shape."""

    kind: str
    colour: str
    model: ObjectModel

    @property
    def height(self) -> float:
        return self.model.size[2] + (self.model.cap.height if self.model.cap is not None else 0.0)


@dataclass
class DetectorTimes:
    network_ms: float = 0.0  # crops and the network
    geometry_ms: float = 0.0  # segmentation and poses


def candidates(frame: RgbdFrame, surfaces: list[SupportSurface]) -> list[Region]:
    """Regions worth judging: resting on their surface (not held above it) and wider than a sliver.

    A region whose foot is out of sight (below the image's edge, or behind the robot's own arm) may rest on
    the surface all the same: it is judged too.
    """
    kept = []
    bottom_row = frame.depth.shape[0] - 1
    for region in segment(frame, surfaces):
        heights = region.points[:, 2] - region.surface.height
        foot_hidden = region.occluded or int(region.rows.max()) >= bottom_row
        if (heights.min() > RESTING and not foot_hidden) or np.count_nonzero(heights > heights.max() - TOP_BAND) < 5:
            continue
        if region_features(region, frame.position)[1] < MIN_WIDTH:
            continue
        kept.append(region)
    return kept


class LearnedDetector:
    """The world's objects in a frame, by the recogniser trained on them."""

    def __init__(self, recogniser: Recogniser, known: dict[str, KnownObject]) -> None:
        missing = [c for c in recogniser.classes if c != NONE and c not in known]
        if missing:
            raise ValueError(f"the detector knows objects the world does not: {', '.join(missing)}")
        self.recogniser = recogniser
        self.known = known
        self.times = DetectorTimes()

    @classmethod
    def for_world(cls, world: WorldConfig, folder: Path | None = None) -> LearnedDetector:
        """The world's trained detector (or the one in ``folder``), with what the world says of its objects."""
        folder = folder or world.detector_path
        if folder is None:
            raise ValueError(f"world '{world.name}' names no detector")
        known = {
            name: KnownObject(o.kind, o.colour, o.model) for name, o in world.objects.items() if o.model is not None
        }
        return cls(Recogniser.load(folder), known)

    def detect(self, frame: RgbdFrame, surfaces: list[SupportSurface]) -> list[Detection]:
        started = time.perf_counter()
        regions = candidates(frame, surfaces)
        segmented = time.perf_counter()
        crops = np.stack([region_crop(frame, r) for r in regions]) if regions else np.zeros((0,))
        features = np.zeros((len(regions), FEATURES), dtype=np.float32)
        for index, region in enumerate(regions):
            features[index] = region_features(region, frame.position)
        judgements = self.recogniser.judge(crops, features)
        judged = time.perf_counter()
        detections = []
        for region, judgement in zip(regions, judgements, strict=True):
            if judgement.label == NONE or judgement.confidence < MIN_CONFIDENCE:
                continue
            known = self.known[judgement.label]
            detection = locate(region, judgement.label, known, frame.position, region_noise(frame, region))
            detection.occluded = region.occluded
            detections.append(detection)
        result = without_fragments(detections)
        done = time.perf_counter()
        self.times = DetectorTimes((judged - segmented) * 1000, ((segmented - started) + (done - judged)) * 1000)
        return result


def locate(region: Region, name: str, known: KnownObject, eye: np.ndarray, noise: float = 0.0) -> Detection:
    """Where a recognised object stands and how it is turned, from its region's points and its known shape;
    ``noise``: σ (m) of the points' depth."""
    points, surface = region.points, region.surface
    heights = points[:, 2] - surface.height
    top = float(heights.max())
    band = points[heights > top - TOP_BAND][:, :2]
    flat_top = points[heights > top - FLAT_BAND][:, :2]
    size = np.array(known.model.size, dtype=float)
    size[2] = known.height
    sight = band.mean(axis=0) - eye[:2]
    sight /= max(float(np.hypot(*sight)), 1e-9)
    yaw = math.atan2(sight[1], sight[0])
    shape = known.model.shape
    partial = False
    if shape == "box":
        (cx, cy), (side_a, side_b), angle = cv2.minAreaRect(band.astype(np.float32))
        long_axis = math.radians(angle) + (0.0 if side_a >= side_b else math.pi / 2)
        narrow = min(side_a, side_b)
        partial = max(side_a, side_b) < PARTIAL * size[0] and narrow < PARTIAL * size[1]
        centre = np.array([cx, cy])
        across_long = np.array([-math.sin(long_axis), math.cos(long_axis)])
        if narrow < size[1]:  # one face seen: the box reaches further from the camera than its visible face
            centre += across_long * math.copysign((size[1] - narrow) / 2, float(across_long @ sight))
        yaw = long_axis
    elif shape == "sphere":
        ball = resting_sphere(points, surface.height, top, noise)
        centre = ball[:2] if ball is not None else circle(band)[0]
    else:
        lid = len(flat_top) >= WELL_SEEN_TOP and circle(flat_top)[1] > LID_WIDTH * size[0] * 0.8
        centre, diameter, _ = cylinder_outline(band, flat_top if lid else None)
        if not lid and diameter < size[0]:  # the near side of a round thing outlines a circle that is too small
            centre = centre + sight * (size[0] - diameter) / 2
    position = np.array([centre[0], centre[1], surface.height + size[2] / 2])
    return Detection(
        known.kind, known.colour, position, size, float(yaw), surface.name, len(points), identity=name, partial=partial
    )
