"""Find objects standing on support surfaces in an RGB-D frame, with their kind, colour, pose and size.

Classical and explainable:

1. every pixel becomes a world point (depth + camera pose);
2. points over a known support surface and a little above it are object
   candidates; depth jumps split touching things; connected regions of the
   image are the objects;
3. each region's points give its size and pose: the top few centimetres
   outline its footprint (square: a box; round: a cylinder, a mug or a ball),
   the highest point its height;
4. shape decides the kind (a sphere fitted to the points that rests on the
   surface is a ball, a flat round top with a handle sticking out a mug, a
   tall round one a bottle), the colour of its best-lit pixels its colour name.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np

from bt_humanoid.perception.rgbd_camera import RgbdFrame
from bt_humanoid.perception.world_model import SupportSurface

MIN_HEIGHT = 0.008  # m above a surface before a point can belong to an object
MAX_HEIGHT = 0.45  # m above a surface: taller things are not objects on it
EDGE_MARGIN = 0.01  # m inside a surface's edge (its rim is not an object)
DEPTH_JUMP = 0.03  # m between neighbouring pixels that separates two things
EDGE_SIGMAS = 3.0  # ... or this many σ of the difference of two noisy readings, where that is more (far away)
MIN_PIXELS = 10  # smaller regions are noise (or too far to judge)
MIN_WIDTH = 0.025  # m across the line of sight: narrower regions are slivers of something
TOP_BAND = 0.03  # m below the highest point that outlines the footprint
FLAT_BAND = 0.006  # m below the highest point that counts as a flat top
RESTING = 0.03  # m: a region whose lowest point is higher above the surface is held, not resting
MUG_PROPORTION = 1.4  # height / diameter below which a round thing without a visible handle is a mug
MIN_MUG_HEIGHT = 0.065  # m: a common-sense prior, cups and mugs are taller than this
SQUARE = 0.87  # share of its bounding rectangle a flat top fills, above which it is a box's (a disc fills π/4)
TALL = 2.0  # height / width above which a thing is a bottle
SPHERE_FIT = 0.03  # RMS distance from a fitted sphere, relative to its radius, within which the points are a ball's
# of a depth camera's noise σ, the share that shows as distance from a ball's fitted sphere (measured: the rays
# meet a ball's visible side square on near its middle, aslant at its rim, and the fit absorbs some of it)
NOISE_ON_SPHERE = 0.75
# share of a thing's points within FLAT_BAND of its top above which it has a lid, not a ball's cap: a ball's cap
# holds 0.04-0.13 of its points, a cube's lid 0.2-0.42 (measured over the perception benchmark's scenes, with and
# without depth noise). It decides only when the noise makes the sphere fit loose: then a cube's points fit a
# sphere as well as a ball's
BALL_FLATNESS = 0.16
RESTS = 0.15  # relative error allowed in a ball's resting pose: centre one radius above the surface, top two
BOX_FLATNESS = 0.3  # share of a thing's visible points on its flat top above which it is a box (a lid faces up)
LID_WIDTH = 0.6  # share of a thing's width a flat top must span to be its lid
HANDLE_VIEW = 100  # points of a round thing from which a lump sticking out of it is taken for a handle
OCCLUSION_BORDER = 3  # pixels: a region this close to the robot's own body in the image may be cut off by it
WELL_SEEN_TOP = 40  # points on a flat top from which its outline tells a square from a disc


@dataclass
class Detection:
    kind: str  # cube, box, bottle, can, mug, ball
    colour: str
    position: np.ndarray  # centre (world, m)
    size: np.ndarray  # extents along the object's x, y and up (m)
    yaw: float  # rad; a mug's handle points along its x
    surface: str
    pixels: int
    yaw_known: bool = True  # false for a mug whose handle was not seen (its yaw is a guess)
    occluded: bool = False  # partly hidden behind the robot's own arm: what shows is a cut-off part of it
    partial: bool = False  # smaller both ways than the thing it is: a part of it shows, its pose is a guess
    identity: str | None = None  # which of the world's objects it is, when a recogniser tells them apart by look


@dataclass
class Region:
    """A connected patch of the image standing on a support surface: one object, or a part of one."""

    rows: np.ndarray  # pixel rows
    cols: np.ndarray  # pixel columns
    surface: SupportSurface
    points: np.ndarray  # (N, 3) world points of its pixels
    colours: np.ndarray  # (N, 3) RGB of its pixels
    occluded: bool  # touches the robot's own body in the image: it may be cut off


def detect(frame: RgbdFrame, surfaces: list[SupportSurface]) -> list[Detection]:
    """Objects resting on any of ``surfaces`` in the frame, told apart by shape rules."""
    detections = []
    for region in segment(frame, surfaces):
        detection = _describe(
            region.points, region.colours, region.surface, frame.position, region_noise(frame, region)
        )
        if detection is not None:
            detection.occluded = region.occluded
            detections.append(detection)
    return without_fragments(detections)


def segment(frame: RgbdFrame, surfaces: list[SupportSurface]) -> list[Region]:
    """The image's regions that stand on one of ``surfaces``: points above it, split at depth jumps."""
    points = frame.points()
    returned = frame.depth > 0  # a depth camera reports 0 where its pattern did not come back
    candidate = np.zeros(frame.depth.shape, dtype=bool)
    surface_of = np.full(frame.depth.shape, -1, dtype=int)
    for index, surface in enumerate(surfaces):
        (x0, y0), (x1, y1) = surface.region + np.array([[EDGE_MARGIN], [-EDGE_MARGIN]])
        x, y, z = points[..., 0], points[..., 1], points[..., 2]
        height = z - surface.height
        over = (x > x0) & (x < x1) & (y > y0) & (y < y1) & (height > MIN_HEIGHT) & (height < MAX_HEIGHT) & returned
        surface_of[over & ~candidate] = index
        candidate |= over
    jump = _jump(frame)
    edges = _depth_edges(frame.depth, jump)
    count, labels, stats, _ = cv2.connectedComponentsWithStats((candidate & ~edges).astype(np.uint8), connectivity=4)
    labels = _reattach(labels, candidate & edges, frame.depth, jump)
    beside_robot = _beside(frame.hidden)
    regions = []
    for label in range(1, count):
        if stats[label, cv2.CC_STAT_AREA] < MIN_PIXELS:
            continue
        rows, cols = np.nonzero(labels == label)
        surface = surfaces[int(np.bincount(surface_of[rows, cols]).argmax())]
        occluded = bool(beside_robot is not None and beside_robot[rows, cols].any())
        regions.append(Region(rows, cols, surface, points[rows, cols], frame.rgb[rows, cols], occluded))
    return regions


def _beside(hidden: np.ndarray | None) -> np.ndarray | None:
    """Pixels within ``OCCLUSION_BORDER`` of the robot's own body in the image (None: nothing of it in view)."""
    if hidden is None or not hidden.any():
        return None
    size = 2 * OCCLUSION_BORDER + 1
    return cv2.dilate(hidden.astype(np.uint8), np.ones((size, size), np.uint8)).astype(bool)


def without_fragments(detections: list[Detection]) -> list[Detection]:
    """Drop a region that lies within a bigger one's footprint: a part of it cut off by a depth jump."""
    kept: list[Detection] = []
    for detection in sorted(detections, key=lambda d: -d.pixels):
        inside = any(np.hypot(*(detection.position[:2] - k.position[:2])) < max(k.size[:2]) / 2 + 0.01 for k in kept)
        if not inside:
            kept.append(detection)
    return kept


def _jump(frame: RgbdFrame) -> np.ndarray:
    """Per pixel, the depth step (m) to a neighbour that separates two things: ``DEPTH_JUMP``, or more where the
    camera's noise makes neighbouring readings differ that much (at 3 m, σ 1.4 cm: a 5 cm cube's 18 pixels
    otherwise broke into slivers at false edges, and the cube was not seen)."""
    sigmas = frame.depth_sigmas()
    if sigmas is None:
        return np.full(frame.depth.shape, DEPTH_JUMP)
    return np.maximum(DEPTH_JUMP, EDGE_SIGMAS * math.sqrt(2.0) * sigmas)


def _depth_edges(depth: np.ndarray, jump: np.ndarray) -> np.ndarray:
    """Pixels next to a depth jump (more than ``jump`` of either pixel): boundaries between things that touch."""
    jump_rows = np.abs(np.diff(depth, axis=0)) > np.maximum(jump[1:], jump[:-1])
    jump_cols = np.abs(np.diff(depth, axis=1)) > np.maximum(jump[:, 1:], jump[:, :-1])
    edges = np.zeros(depth.shape, dtype=bool)
    edges[1:] |= jump_rows
    edges[:, 1:] |= jump_cols
    return edges


def _reattach(labels: np.ndarray, loose: np.ndarray, depth: np.ndarray, jump: np.ndarray) -> np.ndarray:
    """Give pixels cut off at depth jumps back to the neighbouring region at their own depth (within ``jump``)."""
    labels = labels.copy()
    for _ in range(2):
        for dr, dc in ((1, 0), (-1, 0), (0, 1), (0, -1)):
            neighbour = np.roll(labels, (dr, dc), axis=(0, 1))
            near = np.abs(np.roll(depth, (dr, dc), axis=(0, 1)) - depth) < jump
            take = loose & (labels == 0) & (neighbour > 0) & near
            labels[take] = neighbour[take]
    return labels


def region_noise(frame: RgbdFrame, region: Region) -> float:
    """σ (m) of the depth of a region's points (0 from an exact camera)."""
    return frame.depth_sigma(float(np.linalg.norm(region.points.mean(axis=0) - frame.position)))


def _describe(
    points: np.ndarray, colours: np.ndarray, surface: SupportSurface, eye: np.ndarray, noise: float = 0.0
) -> Detection | None:
    """What a region's points and colours are; ``noise``: σ (m) of their depth."""
    heights = points[:, 2] - surface.height
    if heights.min() > RESTING:
        return None  # floating: something held above the surface
    top = float(heights.max())
    band = points[heights > top - TOP_BAND][:, :2]
    flat_top = points[heights > top - FLAT_BAND][:, :2]
    if len(band) < 5:
        return None
    # shape cues that one oblique view gives reliably: the silhouette's width across the line of sight, how much
    # of the object is its flat top and how full that top's outline is, and how well a sphere fits the points
    width = extent(points[:, :2], across(points[:, :2], eye))
    if width < MIN_WIDTH:
        return None  # a sliver: the edge of something mostly hidden, or a fragment cut off at a depth jump
    flatness = float(np.mean(heights > top - FLAT_BAND))
    # a flat top as wide as the thing is its lid, and outlines its body (a bottle's cap is narrower)
    lid = len(flat_top) >= WELL_SEEN_TOP and circle(flat_top)[1] > LID_WIDTH * width
    centre, diameter, handle = cylinder_outline(band, flat_top if lid else None)
    if len(points) < HANDLE_VIEW:
        handle = None  # a few pixels of outline do not show a handle reliably
    yaw_known = True
    ball = resting_sphere(points, surface.height, top)  # as tight a fit as a ball's points give without noise
    if ball is None and noise > 0 and flatness < BALL_FLATNESS:  # as loose as the noise makes it, and no lid
        ball = resting_sphere(points, surface.height, top, noise)
    if ball is not None:  # first: a ball half hidden looks narrow and tall
        kind = "ball"
        centre, diameter = ball[:2], 2.0 * float(ball[2])
    elif top > TALL * width:
        kind = "bottle"
    elif handle is not None and top >= MIN_MUG_HEIGHT:
        kind = "mug"
    elif _boxy(flat_top, flatness, top, width) or top < MIN_MUG_HEIGHT:  # too low for a cup: a small box
        kind = "box"
    else:  # a cylinder's silhouette is as wide as it is, from any side
        kind = "mug" if top < MUG_PROPORTION * max(diameter, width) else "can"
    if kind == "box":
        (cx, cy), (side_a, side_b), angle = cv2.minAreaRect(band.astype(np.float32))
        narrow, long = sorted((side_a, side_b))
        kind = "cube" if _cube(narrow, max(long, width), top, len(flat_top)) else "box"
        centre, size = np.array([cx, cy]), np.array([long, narrow, top])
        yaw = math.radians(angle) + (0.0 if side_a >= side_b else math.pi / 2)
    else:
        size = np.array([diameter, diameter, top])
        if handle is not None:
            yaw = math.atan2(handle[1], handle[0])
        else:  # a mug whose handle is not seen has it behind, pointing away from the camera
            sight = centre - eye[:2]
            yaw, yaw_known = math.atan2(sight[1], sight[0]), kind != "mug"
    position = np.array([centre[0], centre[1], surface.height + top / 2])
    colour = colour_name(_best_lit(colours))
    return Detection(kind, colour, position, size, yaw, surface.name, len(points), yaw_known)


def resting_sphere(points: np.ndarray, surface_height: float, top: float, noise: float = 0.0) -> np.ndarray | None:
    """Centre (x, y) and radius of a ball the points lie on, if they do and it rests on the surface; else None.

    A least-squares sphere through the points (|p - c|² = r² is linear in c and r² - |c|²); a ball also sits
    one radius above its surface and reaches two radii high, which a cube's corner or a mug's rim does not.
    ``noise`` (σ of the points' depth, m) is allowed for: the squared distance it adds to the fit (with a margin
    for how few points estimate it), and the height it adds to the highest point (two σ).
    """
    if len(points) < 10:
        return None
    a = np.c_[2.0 * points, np.ones(len(points))]
    solution, *_ = np.linalg.lstsq(a, (points**2).sum(axis=1), rcond=None)
    centre = solution[:3]
    radius = math.sqrt(max(float(solution[3] + centre @ centre), 1e-12))
    squared = float(np.mean((np.linalg.norm(points - centre, axis=1) - radius) ** 2))
    allowed = (SPHERE_FIT * radius) ** 2 + (NOISE_ON_SPHERE * noise) ** 2 * (1 + 3 * math.sqrt(2 / len(points)))
    sits = abs(centre[2] - surface_height - radius) < RESTS * radius + noise
    reaches = abs(top - 2 * noise - 2 * radius) < RESTS * 2 * radius + noise
    return np.array([centre[0], centre[1], radius]) if squared < allowed and sits and reaches else None


def _cube(narrow: float, long: float, top: float, top_points: int) -> bool:
    """Whether a box is a cube: as tall as it is long, and as deep as it is wide when its lid is seen well.

    From afar the lid is a few pixel rows, so its depth is unknown: then height and width decide.
    """
    if abs(top - long) >= 0.4 * long:
        return False
    return long < 1.6 * narrow if top_points >= WELL_SEEN_TOP else True


def _boxy(flat_top: np.ndarray, flatness: float, top: float, width: float) -> bool:
    """A box's lid rather than a cylinder's disc: by the lid's outline when it is seen well, else by proportions."""
    if len(flat_top) >= WELL_SEEN_TOP:
        return _fill(flat_top) > SQUARE
    return flatness >= BOX_FLATNESS or (top < 0.8 * width and flatness >= 0.22)


def across(xy: np.ndarray, eye: np.ndarray) -> np.ndarray:
    """Unit vector on the floor across the line of sight from the camera to these points."""
    sight = xy.mean(axis=0) - eye[:2]
    sight /= max(float(np.hypot(*sight)), 1e-9)
    return np.array([-sight[1], sight[0]])


def extent(xy: np.ndarray, direction: np.ndarray) -> float:
    if len(xy) < 2:
        return 0.0
    projected = xy @ direction
    return float(projected.max() - projected.min())


def _fill(xy: np.ndarray) -> float:
    """How much of its smallest bounding rectangle a point set's outline covers: 1 a rectangle, π/4 a disc."""
    if len(xy) < 3:
        return 0.0
    (_, _), (a, b), _ = cv2.minAreaRect(xy.astype(np.float32))
    return _area(xy) / max(a * b, 1e-9)


def _area(xy: np.ndarray) -> float:
    return float(cv2.contourArea(cv2.convexHull(xy.astype(np.float32)))) if len(xy) >= 3 else 0.0


def circle(xy: np.ndarray) -> tuple[np.ndarray, float]:
    (cx, cy), radius = cv2.minEnclosingCircle(xy.astype(np.float32))
    return np.array([cx, cy]), 2.0 * radius


def cylinder_outline(xy: np.ndarray, rim: np.ndarray | None) -> tuple[np.ndarray, float, np.ndarray | None]:
    """Body centre and diameter of a round footprint, and the direction of a handle sticking out of it (if any).

    The rim (the flat top's points), when seen well, outlines the body alone: a mug's handle stays below it.
    Otherwise the body is the bulk of the footprint, and a handle a lump further out on one side.
    """
    if rim is not None:
        body_centre, body_diameter = circle(rim)
    else:
        centre, _ = circle(xy)
        distance = np.hypot(*(xy - centre).T)
        body_centre, body_diameter = circle(xy[distance <= np.percentile(distance, 80)])
    offsets = xy - body_centre
    distance = np.hypot(*offsets.T)
    outside = distance > body_diameter / 2 + 0.008
    if outside.sum() >= max(3, 0.04 * len(xy)):
        direction = offsets[outside].mean(axis=0)
        return body_centre, body_diameter, direction / max(float(np.hypot(*direction)), 1e-9)
    return body_centre, body_diameter, None


COLOUR_HUES = [  # OpenCV hue (0..180) upper bounds
    (8, "red"),
    (20, "orange"),
    (34, "yellow"),
    (85, "green"),
    (130, "blue"),
    (155, "purple"),
    (170, "pink"),
    (180, "red"),
]


def _best_lit(colours: np.ndarray) -> np.ndarray:
    """The median colour of the brightest tenth of an object's pixels: shade darkens a side, not its colour."""
    value = colours.max(axis=1)  # HSV's value
    return np.median(colours[value >= np.percentile(value, 90)], axis=0)


def colour_name(rgb: np.ndarray) -> str:
    """The everyday name of a colour: hue decides, unless it is too pale or too dark to have one."""
    pixel = np.clip(np.asarray(rgb, dtype=float), 0, 255).astype(np.uint8).reshape(1, 1, 3)
    hue, saturation, value = (int(v) for v in cv2.cvtColor(pixel, cv2.COLOR_RGB2HSV)[0, 0])
    if value < 50:
        return "black"
    if saturation < 45:
        return "white" if value > 170 else "grey"
    return next(name for bound, name in COLOUR_HUES if hue < bound)
