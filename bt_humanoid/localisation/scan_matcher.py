"""Lay a planar scan onto the map: the pose (x, y, yaw) that brings its points onto the fixed geometry.

Gauss-Newton on the points' signed distances to the map (``ScanMap``), from a guess (the odometry's pose):

    minimise over p   Σ_i ρ(d(R(θ) s_i + t))       s_i a scan point in the scanner's frame, d the map's field

with a Huber ρ (people, chairs and parcels are not on the map: their points are far from every surface and
are left out once the match has closed in). The covariance of the answer is σ² (JᵀWJ)⁻¹: wide along a
corridor's length, narrow across it, so the filter trusts the scan where it constrains the pose.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from bt_humanoid.localisation.scan_map import ScanMap

HUBER = 0.03  # m: residuals beyond this count linearly
OUTLIER = 0.15  # m: a point this far from every surface, once matched, is not on the map (a person, a box)
ITERATIONS = 12
CONVERGED = 1e-4  # m (and rad) of a step
UNCONSTRAINED = 1e-6  # added to the Hessian's diagonal: 1/m² of information every direction has
POINT_SIGMA = 0.03  # m: a point's distance error (scanner noise, the map's box-shaped legs, neighbours' correlation)


@dataclass
class Match:
    pose: np.ndarray  # (x, y, yaw) that lays the scan onto the map
    covariance: np.ndarray  # 3 × 3
    inliers: int  # points within OUTLIER of a surface at ``pose``
    fraction: float  # inliers over all points
    rms: float  # m: the inliers' root-mean-square distance


def transform(points: np.ndarray, pose: np.ndarray) -> np.ndarray:
    """Scanner-frame points (N, 2) placed at ``pose`` (x, y, yaw): world points."""
    c, s = np.cos(pose[2]), np.sin(pose[2])
    return points @ np.array([[c, s], [-s, c]]) + pose[:2]


def match_scan(scan_map: ScanMap, points: np.ndarray, guess: np.ndarray, reach: float = 0.5) -> Match:
    """The pose near ``guess`` that lays ``points`` (scanner frame, N × 2) onto ``scan_map``. Points farther than
    ``reach`` from every surface at the guess are not used at all (the guess is off by less than that)."""
    pose = np.asarray(guess, dtype=float).copy()
    cutoff = reach
    hessian = np.eye(3)
    for _ in range(ITERATIONS):
        world = transform(points, pose)
        distance, gx, gy = scan_map.lookup(world)
        use = np.abs(distance) < cutoff
        if use.sum() < 3:
            break
        d, gx, gy = distance[use], gx[use], gy[use]
        lever = world[use] - pose[:2]
        jacobian = np.stack([gx, gy, gx * -lever[:, 1] + gy * lever[:, 0]], axis=1)
        weight = np.minimum(1.0, HUBER / np.maximum(np.abs(d), 1e-9))
        hessian = (jacobian * weight[:, None]).T @ jacobian
        step = -np.linalg.solve(hessian + UNCONSTRAINED * np.eye(3), (jacobian * weight[:, None]).T @ d)
        pose += step
        cutoff = max(OUTLIER, cutoff * 0.5)  # close in: what stays far is not on the map
        if np.abs(step).max() < CONVERGED:
            break
    distance = scan_map.lookup(transform(points, pose))[0]
    inlier = np.abs(distance) < OUTLIER
    count = int(inlier.sum())
    rms = float(np.sqrt(np.mean(distance[inlier] ** 2))) if count else np.inf
    # a direction no point constrains (a corridor's length) keeps a huge variance rather than an infinite one
    covariance = POINT_SIGMA**2 * np.linalg.inv(hessian + UNCONSTRAINED * np.eye(3))
    return Match(pose, covariance, count, count / max(len(points), 1), rms)
