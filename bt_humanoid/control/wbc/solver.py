"""Build and solve the whole-body QP: one function, tasks in the cost, limits as constraints.

    minimise   Σ_tasks ½‖J_i Δq − k_i e_i‖²_{W_i} + ½ λ‖Δq‖²
    subject to lb ≤ Δq ≤ ub          (joint position and velocity limits)
               G Δq ≥ h              (torso margin, hand clearance, base keep-out)

solved with a CasADi conic solver (DAQP by default: dense active-set, exact,
fastest of those CasADi offers for this size). Solvers are built once per
problem shape and reused.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Protocol

import casadi
import numpy as np

from bt_humanoid.control.wbc.kinematics import RobotKinematics
from bt_humanoid.control.wbc.limits.base import Limit
from bt_humanoid.control.wbc.tasks.base import Task

DEFAULT_SOLVER = "daqp"
_SOLVER_OPTIONS: dict[str, dict] = {
    "qpoases": {"printLevel": "none"},
    "osqp": {"osqp": {"verbose": False}},
    "qrqp": {"print_iter": False, "print_header": False},
}


class BoxLimit(Protocol):
    def bounds(self, kinematics: RobotKinematics, dt: float) -> tuple[np.ndarray, np.ndarray]: ...


@dataclass
class Solution:
    step: np.ndarray  # Δq over the controlled joints
    solved: bool
    solve_time: float  # s of wall time spent building and solving the QP
    conic_time: float  # s of it in the conic solver itself (the rest is building the problem)


_solvers: dict[tuple[str, int, int], casadi.Function] = {}


def _conic(solver: str, n: int, m: int) -> casadi.Function:
    key = (solver, n, m)
    if key not in _solvers:
        pattern = {"h": casadi.Sparsity.dense(n, n), "a": casadi.Sparsity.dense(m, n)}
        # an infeasible step is reported through stats()["success"], not raised
        options = {"error_on_fail": False, **_SOLVER_OPTIONS.get(solver, {})}
        _solvers[key] = casadi.conic("wbc", solver, pattern, options)
    return _solvers[key]


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
    hessian = damping * np.eye(n)
    gradient = np.zeros(n)
    for task in tasks:
        h, g = task.objective(kinematics)
        hessian += h
        gradient += g
    lower, upper = np.full(n, -np.inf), np.full(n, np.inf)
    for box in box_limits:
        low, high = box.bounds(kinematics, dt)
        lower, upper = np.maximum(lower, low), np.minimum(upper, high)
    lower = np.minimum(lower, upper)  # conflicting bounds: hold still rather than fail
    inequalities = [limit.inequality(kinematics, dt) for limit in limits]
    G = np.vstack([ineq.G for ineq in inequalities]) if inequalities else np.zeros((0, n))
    h = np.concatenate([ineq.lower for ineq in inequalities]) if inequalities else np.zeros(0)
    qp = _conic(solver, n, len(h))
    built = time.perf_counter()
    result = qp(h=hessian, g=gradient, a=G, lba=h, uba=np.full(len(h), np.inf), lbx=lower, ubx=upper)
    solved_at = time.perf_counter()
    solved = bool(qp.stats()["success"])
    step = np.asarray(result["x"]).ravel() if solved else np.zeros(n)
    return Solution(step, solved, time.perf_counter() - started, solved_at - built)
