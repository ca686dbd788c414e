"""Whole-body control: a task-space QP over base, waist, arms and head, and its inverse-dynamics twin for legs.

Kinematic QP: tasks (``tasks/``) each give an error and a Jacobian; limits (``limits/``) bound the joint step;
``qp_terms`` assembles the QP and ``solve_ik`` solves it from numbers. ``CompiledQp`` builds the same QP once
in CasADi symbols (``SymbolicKinematics``) and solves it each step with one call; ``WholeBodyController``
(control/whole_body.py) runs that inside the executor and turns the solution into actuator references.

Inverse-dynamics QP (a floating-base robot on its feet): ``RobotDynamics`` evaluates the model; tasks
(``id_tasks/``) each ask for an acceleration; limits (``id_limits/``) and sole contacts (``contact.py``)
constrain; ``solve_id`` finds joint accelerations, sole wrenches and the torques that realise them.
``BalanceController`` (control/walking/balance.py) runs it every physics step.
"""

from bt_humanoid.control.wbc.compiled import CompiledQp
from bt_humanoid.control.wbc.dynamics import RobotDynamics
from bt_humanoid.control.wbc.id_solver import IdSolution, solve_id
from bt_humanoid.control.wbc.kinematics import RobotKinematics
from bt_humanoid.control.wbc.solver import Solution, qp_terms, solve_ik
from bt_humanoid.control.wbc.symbolic_kinematics import SymbolicKinematics

__all__ = [
    "CompiledQp",
    "IdSolution",
    "RobotDynamics",
    "RobotKinematics",
    "Solution",
    "SymbolicKinematics",
    "qp_terms",
    "solve_id",
    "solve_ik",
]
