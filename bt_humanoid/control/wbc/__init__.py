"""Whole-body control: a task-space QP over base, waist, arms and head, and its inverse-dynamics twin for legs.

Kinematic QP: tasks (``tasks/``) each give an error and a Jacobian; limits (``limits/``) bound the joint step;
``solve_ik`` assembles and solves one QP per control step. ``WholeBodyController`` (control/whole_body.py) runs
it inside the executor and turns the solution into actuator references.

Inverse-dynamics QP (a floating-base robot on its feet): ``RobotDynamics`` evaluates the model; tasks
(``id_tasks/``) each ask for an acceleration; limits (``id_limits/``) and sole contacts (``contact.py``)
constrain; ``solve_id`` finds joint accelerations, sole wrenches and the torques that realise them.
``BalanceController`` (control/walking/balance.py) runs it every physics step.
"""

from bt_humanoid.control.wbc.dynamics import RobotDynamics
from bt_humanoid.control.wbc.id_solver import IdSolution, solve_id
from bt_humanoid.control.wbc.kinematics import RobotKinematics
from bt_humanoid.control.wbc.solver import Solution, solve_ik

__all__ = ["IdSolution", "RobotDynamics", "RobotKinematics", "Solution", "solve_id", "solve_ik"]
