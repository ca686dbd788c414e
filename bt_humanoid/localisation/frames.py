"""Planar poses (x, y, yaw) and the map: composing them, and placing what a body-mounted sensor measured."""

from __future__ import annotations

import math

import numpy as np


def compose(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Pose ``b`` (given in ``a``'s frame) in ``a``'s parent frame: a ∘ b."""
    c, s = math.cos(a[2]), math.sin(a[2])
    return np.array([a[0] + c * b[0] - s * b[1], a[1] + s * b[0] + c * b[1], a[2] + b[2]])


def inverse(a: np.ndarray) -> np.ndarray:
    """The pose that undoes ``a``: a ∘ inverse(a) is the identity."""
    c, s = math.cos(a[2]), math.sin(a[2])
    return np.array([-(c * a[0] + s * a[1]), s * a[0] - c * a[1], -a[2]])


def turned(velocity: np.ndarray, angle: float) -> np.ndarray:
    """A planar velocity (vx, vy, yaw rate) with its linear part turned by ``angle`` about z."""
    c, s = math.cos(angle), math.sin(angle)
    vx, vy, wz = (float(v) for v in velocity)
    return np.array([c * vx - s * vy, s * vx + c * vy, wz])


def place_on_map(
    position: np.ndarray, rotation: np.ndarray, truth: np.ndarray, belief: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """A 3-D pose a sensor on the robot measured in the world (``position``, ``rotation``), placed on the map
    through where the robot believes its base is: the same pose relative to the base, the base at ``belief``
    instead of at ``truth`` (both x, y, yaw)."""
    turn = math.remainder(float(belief[2] - truth[2]), 2 * math.pi)
    c, s = math.cos(turn), math.sin(turn)
    spin = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    relative = np.asarray(position, dtype=float) - np.array([truth[0], truth[1], 0.0])
    return spin @ relative + np.array([belief[0], belief[1], 0.0]), spin @ np.asarray(rotation, dtype=float)
