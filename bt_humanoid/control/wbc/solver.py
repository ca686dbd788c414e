"""Build and solve the whole-body QP: tasks in the cost, limits as constraints.

    minimise   Σ_tasks ½‖J_i Δq − k_i e_i‖²_{W_i} + ½ λ‖Δq‖²
    subject to lb ≤ Δq ≤ ub          (joint position and velocity limits)
               G Δq ≥ h              (torso margin, hand clearance, base keep-out)

solved with a CasADi conic solver (DAQP by default: dense active-set, exact,
fastest of those CasADi offers for this size), built once per problem shape
and reused, fed through a buffer (``conic.py``). ``qp_terms`` builds the terms from numbers or from symbols;
``solve_ik`` solves them from numbers, ``CompiledQp`` (``compiled.py``) from a function compiled once per kind
of goal.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Protocol

import numpy as np

from bt_humanoid.control.wbc.conic import DEFAULT_SOLVER, conic
from bt_humanoid.control.wbc.kinematics import RobotKinematics
from bt_humanoid.control.wbc.limits.base import Limit
from bt_humanoid.control.wbc.maths import Value, concat, maximum, minimum, stack_rows
from bt_humanoid.control.wbc.tasks.base import Task, stacked_objective


class BoxLimit(Protocol):
    def bounds(self, kinematics: RobotKinematics, dt: float) -> tuple[Value, Value]: ...

    def signature(self) -> tuple: ...


@dataclass
class Solution:
    step: np.ndarray  # Δq over the controlled joints
    solved: bool
    solve_time: float  # s of wall time spent building and solving the QP
    conic_time: float  # s of it in the conic solver itself (the rest is building the problem)


@dataclass
class QpTerms:
    """The QP's matrices and vectors (numbers, or CasADi expressions of the configuration)."""

    hessian: Value  # n × n
    gradient: Value  # n
    constraints: Value  # m × n: G
    constraints_lower: Value  # m: h (FREE rows hold no bound this step)
    lower: Value  # n: lower bounds on Δq
    upper: Value  # n


def qp_terms(
    kinematics: RobotKinematics,
    tasks: list[Task],
    box_limits: list[BoxLimit],
    limits: list[Limit],
    dt: float,
    damping: float = 1e-4,
) -> QpTerms:
    """The QP of ``tasks`` within every limit, at the kinematics' configuration."""
    n = len(kinematics.joints)
    if tasks:
        hessian, gradient = stacked_objective([task.residual(kinematics) for task in tasks])
    else:
        hessian, gradient = np.zeros((n, n)), np.zeros(n)
    hessian = hessian + damping * np.eye(n)
    lower, upper = np.full(n, -np.inf), np.full(n, np.inf)
    for box in box_limits:
        low, high = box.bounds(kinematics, dt)
        lower, upper = maximum(lower, low), minimum(upper, high)
    lower = minimum(lower, upper)  # conflicting bounds: hold still rather than fail
    inequalities = [ineq for ineq in (limit.inequality(kinematics, dt) for limit in limits) if ineq.G.shape[0]]
    G = stack_rows([ineq.G for ineq in inequalities], n)
    h = concat([ineq.lower for ineq in inequalities]) if inequalities else np.zeros(0)
    return QpTerms(hessian, gradient, G, h, lower, upper)


def solve_ik(
    kinematics: RobotKinematics,
    tasks: list[Task],
    box_limits: list[BoxLimit],
    limits: list[Limit],
    dt: float,
    damping: float = 1e-4,
    solver: str = DEFAULT_SOLVER,
) -> Solution:
    """The joint step Δq that best serves ``tasks`` within every limit; zero if the QP has no solution.

    Built afresh from numbers: the reference for ``CompiledQp``, which the whole-body controller runs."""
    started = time.perf_counter()
    terms = qp_terms(kinematics, tasks, box_limits, limits, dt, damping)
    n = len(kinematics.joints)
    qp = conic(solver, n, len(terms.constraints_lower))
    qp.hessian[:] = terms.hessian
    qp.constraints_t[:] = terms.constraints.T
    inputs = (
        ("g", terms.gradient),
        ("lba", terms.constraints_lower),
        ("uba", np.inf),
        ("lbx", terms.lower),
        ("ubx", terms.upper),
    )
    for name, value in inputs:
        qp.inputs[name][:] = value
    built = time.perf_counter()
    solved = qp.solve()
    solved_at = time.perf_counter()
    step = qp.outputs["x"].copy() if solved else np.zeros(n)
    return Solution(step, solved, time.perf_counter() - started, solved_at - built)
