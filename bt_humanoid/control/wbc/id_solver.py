"""Build and solve the inverse-dynamics QP: one function, tasks in the cost, physics and limits as constraints.

Variables x = (v̇, w_1, …, w_k): the joint accelerations (the free-flyer's six first) and one wrench per sole
(``SoleContact``: the floor's on the foot, in the sole's frame). Torques are not variables; the equations of
motion M v̇ + h = Sᵀτ + Σ J_sᵀ w give them:

    minimise   Σ_tasks ½‖J_i v̇ + J̇_i v − a*_i‖²_{W_i} + ½ λ_a‖v̇‖² + ½ λ_w Σ ‖w − w_ref‖²
    subject to M_u v̇ + h_u = Σ J_{s,u}ᵀ w            (the six unactuated rows: only the floor moves the pelvis)
               J_s v̇ + J̇_s v = −k J_s v              (each stance sole stays put)
               U w ≥ 0, f_min ≤ f_z ≤ f_max          (each stance sole's wrench in its contact wrench cone)
               w = 0                                 (a swinging sole transmits nothing)
               −τ_max ≤ M_a v̇ + h_a − Σ J_{s,a}ᵀ w ≤ τ_max   (torque limits)
               v̇_lower ≤ v̇ ≤ v̇_upper               (joint ranges and speeds, joints held by their servos)

solved with CasADi's DAQP (dense active-set, exact), built once per problem shape and reused (``conic.py``).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from bt_humanoid.control.wbc.conic import DEFAULT_SOLVER, conic
from bt_humanoid.control.wbc.contact import SoleContact
from bt_humanoid.control.wbc.dynamics import BASE_DOFS, RobotDynamics
from bt_humanoid.control.wbc.id_limits.base import AccelerationBounds
from bt_humanoid.control.wbc.id_limits.torque_limit import TorqueLimit
from bt_humanoid.control.wbc.id_tasks.base import AccelerationTask

WRENCH = 6
ACCELERATION_WEIGHT = 1e-4  # keeps the Hessian positive definite in directions no task names
WRENCH_WEIGHT = 1e-4  # spreads the load evenly and keeps each centre of pressure central when nothing else matters


@dataclass
class IdSolution:
    accelerations: np.ndarray  # v̇ (nv)
    wrenches: np.ndarray  # one row per contact: the floor's wrench on the sole, sole frame
    torques: np.ndarray  # τ for every joint below the free-flyer (dynamics.joints order)
    solved: bool
    solve_time: float  # s of wall time spent building and solving the QP
    conic_time: float  # s of it in the conic solver itself


def solve_id(
    dynamics: RobotDynamics,
    contacts: list[SoleContact],
    tasks: list[AccelerationTask],
    bounds: list[AccelerationBounds],
    torque_limit: TorqueLimit,
    dt: float,
    acceleration_weight: float = ACCELERATION_WEIGHT,
    wrench_weight: float = WRENCH_WEIGHT,
    solver: str = DEFAULT_SOLVER,
) -> IdSolution:
    """Joint accelerations and sole wrenches that best serve ``tasks`` under the robot's physics and limits, and
    the joint torques that realise them. Not solved: zeros, with ``solved`` False."""
    started = time.perf_counter()
    nv = dynamics.nv
    k = len(contacts)
    n = nv + WRENCH * k
    mass, bias = dynamics.mass_matrix, dynamics.bias

    hessian = np.zeros((n, n))
    gradient = np.zeros(n)
    for task in tasks:
        h, g = task.objective(dynamics)
        hessian[:nv, :nv] += h
        gradient[:nv] += g
    diagonal = hessian.reshape(-1)[:: n + 1]  # a view of the diagonal
    diagonal[:nv] += acceleration_weight
    diagonal[nv:] += wrench_weight
    active = [c for c in contacts if c.active]
    weight = dynamics.mass * dynamics.gravity
    for i, contact in enumerate(contacts):
        if contact.active:  # about an even share of the weight, pressing through the sole's centre
            gradient[nv + WRENCH * i + 2] -= wrench_weight * weight / len(active)

    # the contact maps: generalised force J_sᵀ w of each sole's wrench
    wrench_maps = np.zeros((n - nv, nv))  # stacked J_s, so that Σ J_sᵀ w = wrench_mapsᵀ w
    for i, contact in enumerate(contacts):
        wrench_maps[WRENCH * i : WRENCH * (i + 1)] = contact.wrench_jacobian(dynamics)
    # τ(x) for every row of the equations of motion: M v̇ − Σ J_sᵀ w = τ − h
    torque_map = np.hstack([mass, -wrench_maps.T])

    rows, lower, upper = [torque_map[:BASE_DOFS]], [-bias[:BASE_DOFS]], [-bias[:BASE_DOFS]]
    for contact in contacts:
        if contact.active:
            jacobian, rhs = contact.acceleration_constraint(dynamics)
            row = np.zeros((WRENCH, n))
            row[:, :nv] = jacobian
            rows.append(row)
            lower.append(rhs)
            upper.append(rhs)
    columns = torque_limit.columns(dynamics)
    rows.append(torque_map[columns])
    lower.append(-torque_limit.maximum - bias[columns])
    upper.append(torque_limit.maximum - bias[columns])
    for i, contact in enumerate(contacts):
        if contact.active:
            row = np.zeros((len(contact.cone), n))
            row[:, nv + WRENCH * i : nv + WRENCH * (i + 1)] = contact.cone
            rows.append(row)
            lower.append(np.zeros(len(contact.cone)))
            upper.append(np.full(len(contact.cone), np.inf))
    A = np.vstack(rows)
    lba, uba = np.concatenate(lower), np.concatenate(upper)

    lbx, ubx = np.full(n, -np.inf), np.full(n, np.inf)
    for limit in bounds:
        low, high = limit.bounds(dynamics, dt)
        lbx[:nv], ubx[:nv] = np.maximum(lbx[:nv], low), np.minimum(ubx[:nv], high)
    lbx[:nv] = np.minimum(lbx[:nv], ubx[:nv])  # conflicting bounds: the upper one wins rather than fail
    for i, contact in enumerate(contacts):
        start = nv + WRENCH * i
        if contact.active:
            lbx[start + 2], ubx[start + 2] = contact.normal_force_bounds()
        else:
            lbx[start : start + WRENCH], ubx[start : start + WRENCH] = 0.0, 0.0

    qp = conic(solver, n, len(lba))
    qp.hessian[:] = hessian
    qp.constraints_t[:] = A.T
    for name, value in (("g", gradient), ("lba", lba), ("uba", uba), ("lbx", lbx), ("ubx", ubx)):
        qp.inputs[name][:] = value
    built = time.perf_counter()
    solved = qp.solve()
    solved_at = time.perf_counter()
    if not solved:
        zeros = np.zeros(nv), np.zeros((k, WRENCH)), np.zeros(nv - BASE_DOFS)
        return IdSolution(*zeros, False, solved_at - started, solved_at - built)
    x = qp.outputs["x"].copy()
    torques = (torque_map @ x + bias)[BASE_DOFS:]
    return IdSolution(
        x[:nv], x[nv:].reshape(k, WRENCH), torques, True, time.perf_counter() - started, solved_at - built
    )
