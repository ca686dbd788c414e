"""Build and solve the whole-body QP: one function, tasks in the cost, limits as constraints.

    minimise   Σ_tasks ½‖J_i Δq − k_i e_i‖²_{W_i} + ½ λ‖Δq‖²
    subject to lb ≤ Δq ≤ ub          (joint position and velocity limits)
               G Δq ≥ h              (torso margin, hand clearance, base keep-out)

solved with a CasADi conic solver (DAQP by default: dense active-set, exact,
fastest of those CasADi offers for this size), built once per problem shape
and reused, fed through a buffer (``conic.py``).
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Protocol

import numpy as np

from bt_humanoid.control.wbc.conic import DEFAULT_SOLVER, conic
from bt_humanoid.control.wbc.kinematics import RobotKinematics
from bt_humanoid.control.wbc.limits.base import Limit
from bt_humanoid.control.wbc.tasks.base import Task, stacked_objective


class BoxLimit(Protocol):
    def bounds(self, kinematics: RobotKinematics, dt: float) -> tuple[np.ndarray, np.ndarray]: ...


@dataclass
class Solution:
    step: np.ndarray  # Δq over the controlled joints
    solved: bool
    solve_time: float  # s of wall time spent building and solving the QP
    conic_time: float  # s of it in the conic solver itself (the rest is building the problem)


def solve_ik(
    kinematics: RobotKinematics,
    tasks: list[Task],
    box_limits: list[BoxLimit],
    limits: list[Limit],
    dt: float,
    damping: float = 1e-4,
    solver: str = DEFAULT_SOLVER,
) -> Solution:
    """The joint step Δq that best serves ``tasks`` within every limit; zero if the QP has no solution."""
    started = time.perf_counter()
    n = len(kinematics.joints)
    hessian, gradient = stacked_objective([task.residual(kinematics) for task in tasks]) if tasks else (0.0, 0.0)
    hessian = hessian + damping * np.eye(n)
    gradient = gradient + np.zeros(n)
    lower, upper = np.full(n, -np.inf), np.full(n, np.inf)
    for box in box_limits:
        low, high = box.bounds(kinematics, dt)
        lower, upper = np.maximum(lower, low), np.minimum(upper, high)
    lower = np.minimum(lower, upper)  # conflicting bounds: hold still rather than fail
    inequalities = [limit.inequality(kinematics, dt) for limit in limits]
    G = np.vstack([ineq.G for ineq in inequalities]) if inequalities else np.zeros((0, n))
    h = np.concatenate([ineq.lower for ineq in inequalities]) if inequalities else np.zeros(0)
    qp = conic(solver, n, len(h))
    qp.hessian[:] = hessian
    qp.constraints_t[:] = G.T
    for name, value in (("g", gradient), ("lba", h), ("uba", np.inf), ("lbx", lower), ("ubx", upper)):
        qp.inputs[name][:] = value
    built = time.perf_counter()
    solved = qp.solve()
    solved_at = time.perf_counter()
    step = qp.outputs["x"].copy() if solved else np.zeros(n)
    return Solution(step, solved, time.perf_counter() - started, solved_at - built)
