"""Where on a support surface there is room to put something down, from what the robot believes is on it."""

from __future__ import annotations

import numpy as np

from bt_humanoid.perception.world_model import SupportSurface, WorldModel

EDGE_DEPTH = 0.15  # m behind the near edge: well within the arm's reach, clear of the rim
ROW_DEPTHS = (EDGE_DEPTH, 0.26, 0.34)  # m behind the near edge, tried in turn (the arm reaches 0.42: stance.py)
CLEARANCE = 0.13  # m between the spot and the centre of anything already there
GRID = 0.025  # m between candidate spots


def free_spot(
    surface: SupportSurface, belief: WorldModel, approach: np.ndarray, also_taken: list[np.ndarray] | None = None
) -> np.ndarray | None:
    """A spot (x, y) on ``surface`` clear of the objects believed on it, reached from the edge nearest ``approach``.

    Spots lie in rows behind that edge (``ROW_DEPTHS``): the shallowest row with room wins, and in it the spot
    nearest ``approach``. ``also_taken``: spots promised to other things already. None if every row is full.
    """
    (x0, y0), (x1, y1) = surface.region
    ax, ay = float(approach[0]), float(approach[1])
    # the near edge: the side of the rectangle the approach point is farthest outside of
    outside = {"west": x0 - ax, "east": ax - x1, "south": y0 - ay, "north": ay - y1}
    edge = max(outside, key=outside.__getitem__)
    taken = [o.position[:2] for o in belief.present() if o.held_by is None]
    taken += list(also_taken or [])
    for depth in ROW_DEPTHS:
        if edge in ("west", "east"):
            x = x0 + depth if edge == "west" else x1 - depth
            ys = np.arange(y0 + EDGE_DEPTH, y1 - EDGE_DEPTH + 1e-9, GRID)
            candidates = np.column_stack([np.full(len(ys), x), ys])
        else:
            y = y0 + depth if edge == "south" else y1 - depth
            xs = np.arange(x0 + EDGE_DEPTH, x1 - EDGE_DEPTH + 1e-9, GRID)
            candidates = np.column_stack([xs, np.full(len(xs), y)])
        if taken and len(candidates):
            nearest = np.min(np.linalg.norm(candidates[:, None, :] - np.array(taken)[None, :, :], axis=2), axis=1)
            candidates = candidates[nearest >= CLEARANCE]
        if len(candidates):
            return candidates[int(np.argmin(np.linalg.norm(candidates - np.array([ax, ay]), axis=1)))]
    return None


MAX_SHIFT = 0.15  # m a spot asked for may move to clear what stands there
PLACE_GAP = 0.02  # m between a thing put down and its neighbours
EDGE_MARGIN = 0.05  # m a spot keeps from the surface's edge


def nearest_free(
    surface: SupportSurface, belief: WorldModel, spot: np.ndarray, radius: float, exclude: tuple[str, ...] = ()
) -> np.ndarray | None:
    """``spot`` if a thing ``radius`` round fits there clear of what is believed on ``surface``; else the nearest
    spot within ``MAX_SHIFT`` that does, on the surface; None if there is none."""
    others = [
        (o.position[:2], o.footprint_radius)
        for o in belief.present()
        if o.held_by is None and o.id not in exclude and surface.contains(o.position[:2])
    ]

    def free(xy: np.ndarray) -> bool:
        inside = surface.contains(xy, margin=min(radius, EDGE_MARGIN))
        return inside and all(np.hypot(*(xy - c)) >= radius + r + PLACE_GAP for c, r in others)

    spot = np.asarray(spot, dtype=float)[:2]
    if free(spot):
        return spot
    angles = np.linspace(0.0, 2 * np.pi, 24, endpoint=False)
    for shift in np.arange(0.01, MAX_SHIFT + 1e-9, 0.01):
        ring = spot + shift * np.column_stack([np.cos(angles), np.sin(angles)])
        fits = [xy for xy in ring if free(xy)]
        if fits:
            return fits[0]
    return None
