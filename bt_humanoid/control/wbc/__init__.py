"""Whole-body control: a task-space QP over base, waist, arms and head.

Tasks (``tasks/``) each give an error and a Jacobian; limits (``limits/``)
bound the joint step; ``solve_ik`` assembles and solves one QP per control
step. ``WholeBodyController`` (control/whole_body.py) runs it inside the
executor and turns the solution into actuator references.
"""

from bt_humanoid.control.wbc.kinematics import RobotKinematics
from bt_humanoid.control.wbc.solver import Solution, solve_ik

__all__ = ["RobotKinematics", "Solution", "solve_ik"]
