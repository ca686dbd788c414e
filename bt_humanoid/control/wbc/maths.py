"""The few operations whole-body tasks and limits need, for numbers and CasADi symbols alike.

A task or limit is written once. Given a ``RobotKinematics`` its quantities
are numpy arrays (vectors 1-D); given a ``SymbolicKinematics`` they are CasADi
SX expressions (vectors are columns), and the QP built from them is compiled
(``compiled.py``). numpy defers to SX in mixed arithmetic, so ``+ - * /`` and
indexing need nothing here; what differs between the two is below.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import casadi as ca
import numpy as np
import pinocchio as pin

Value = Any  # np.ndarray | float, or ca.SX


def is_symbolic(*values: Value) -> bool:
    return any(isinstance(v, ca.SX) for v in values)


def concat(parts: Sequence[Value]) -> Value:
    """One vector from vectors and scalars, in order."""
    if is_symbolic(*parts):
        return ca.vertcat(*parts)
    return np.concatenate([np.atleast_1d(np.asarray(p, dtype=float)) for p in parts])


def stack_rows(rows: Sequence[Value], columns: int) -> Value:
    """A matrix of ``rows`` (each 1 × ``columns``, or a block of rows); none gives 0 × ``columns``."""
    if not rows:
        return np.zeros((0, columns))
    if is_symbolic(*rows):
        # constant rows (a posture's selection) kept sparse: the products built from them stay small
        return ca.vertcat(*(r if isinstance(r, ca.SX) else ca.sparsify(ca.DM(np.atleast_2d(r))) for r in rows))
    return np.vstack(rows)


def along(direction: Value, matrix: Value) -> Value:
    """``directionᵀ matrix``: a Jacobian's rate of change along a direction (one row)."""
    if is_symbolic(direction, matrix):
        return ca.SX(direction).T @ matrix
    return direction @ matrix


def norm(vector: Value) -> Value:
    return ca.norm_2(vector) if is_symbolic(vector) else float(np.linalg.norm(vector))


def cross(a: Value, b: Value) -> Value:
    """a × b (np.cross costs ten times more than the skew product on 3-vectors)."""
    return ca.cross(a, b) if is_symbolic(a, b) else pin.skew(a) @ b


def minimum(a: Value, b: Value) -> Value:
    return ca.fmin(a, b) if is_symbolic(a, b) else np.minimum(a, b)


def maximum(a: Value, b: Value) -> Value:
    return ca.fmax(a, b) if is_symbolic(a, b) else np.maximum(a, b)


def where(condition: Value, if_true: Value, if_false: Value) -> Value:
    """Elementwise choice; with symbols both branches are built and the condition picks at run time."""
    if is_symbolic(condition, if_true, if_false):
        return ca.if_else(condition, if_true, if_false)
    return np.where(condition, if_true, if_false)


def log3(rotation: Value) -> Value:
    """The rotation vector (axis × angle) of a rotation matrix, as ``pinocchio.log3``.

    In symbols: the angle from the trace, the axis from the skew part, with
    the series of θ / sin θ near zero. Exact to about 1e-7 rad up to 1e-5 rad
    short of a half turn, and wrong within about 1e-6 rad of it, where the
    skew part vanishes; a whole-body task's target moves a little each step,
    so its error stays far from there.
    """
    if not is_symbolic(rotation):
        return pin.log3(rotation)
    cosine = ca.fmin(ca.fmax((ca.trace(rotation) - 1) / 2, -1), 1)
    angle = ca.acos(cosine)
    skew = ca.vertcat(rotation[2, 1] - rotation[1, 2], rotation[0, 2] - rotation[2, 0], rotation[1, 0] - rotation[0, 1])
    factor = ca.if_else(angle < 1e-4, 0.5 + angle**2 / 12, angle / (2 * ca.sin(ca.fmax(angle, 1e-4))))
    return factor * skew


def outer(a: Value, b: Value) -> Value:
    """a bᵀ."""
    return a @ ca.SX(b).T if is_symbolic(a, b) else np.outer(a, b)


def identity(size: int, like: Value) -> Value:
    return ca.SX.eye(size) if is_symbolic(like) else np.eye(size)


def all_of(*conditions: Value) -> Value:
    """Whether every condition holds (elementwise for symbols: 1 or 0)."""
    if is_symbolic(*conditions):
        result = conditions[0]
        for condition in conditions[1:]:
            result = ca.logic_and(result, condition)
        return result
    return bool(np.all(conditions))


def scale_rows(matrix: Value, weights: np.ndarray) -> Value:
    """Each row of ``matrix`` times its weight."""
    if is_symbolic(matrix):
        return ca.diag(ca.DM(weights)) @ matrix
    return matrix * weights[:, None]
