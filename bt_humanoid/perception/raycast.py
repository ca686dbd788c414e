"""Rays from one point through the scene: what range sensors (a depth camera, a laser scanner) measure."""

from __future__ import annotations

import mujoco
import numpy as np


def cast_rays(
    model: mujoco.MjModel,
    data: mujoco.MjData,
    origin: np.ndarray,
    directions: np.ndarray,
    max_range: float,
    geom_ids: np.ndarray,
    distances: np.ndarray,
    exclude_body: int = -1,
) -> None:
    """Cast unit ``directions`` (N, 3) from ``origin``; fills ``geom_ids`` (-1: nothing within range) and ``distances``.

    Static geoms count; ``exclude_body`` (a sensor's own housing) does not.
    """
    count = len(directions)
    mujoco.mj_multiRay(
        model, data, origin, directions.ravel(), None, 1, exclude_body, geom_ids, distances, None, count, max_range
    )
