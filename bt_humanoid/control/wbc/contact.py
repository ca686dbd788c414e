"""A flat rectangular sole in contact with the floor: the wrench it may transmit and the motion it may not make.

The wrench w = (f_x, f_y, f_z, τ_x, τ_y, τ_z) is the floor's on the foot, about the sole frame's origin (the
rectangle's centre on the sole plane), in the sole frame's axes. A sole standing still on the floor can transmit
exactly the wrenches that forces at its four corners, each inside a friction pyramid, add up to: the contact
wrench cone of a rectangle, which Caron, Pham and Nakamura (ICRA 2015) give in closed form as sixteen linear
inequalities (``cone_matrix``), here with f_z's own bounds kept apart as variable bounds.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from bt_humanoid.control.wbc.dynamics import RobotDynamics

# N a stance foot keeps pressing on the floor. The QP's wrenches are the model's; the floor's differ by some tens
# of newtons while the robot is shaken (soft contact, the servos' lag), so a foot planned at 10 N lifted or slid
# in sideways pushes. 80 N (a sixth of the biped's weight) kept both feet planted up to the largest pushes
# survived (benchmarks/balance.py), at the cost of a little sideways reach of the centre of pressure.
MIN_NORMAL_FORCE = 80.0
# m kept between the centre of pressure and the sole's edges: at the edge itself the far corners carry nothing
# and the smallest error (soft contact, a model's mass) rolls the foot onto that edge, where a controller that
# counts on a flat foot loses it
COP_MARGIN = 0.01


def cone_matrix(half_length: float, half_width: float, friction: float) -> np.ndarray:
    """U (16 × 6) with U w ≥ 0 for every wrench w (sole frame, about the sole's centre) that forces at the
    corners (±X, ±Y) of the rectangle, inside friction pyramids of coefficient μ, can produce."""
    X, Y, mu = half_length, half_width, friction
    rows = [
        [-1, 0, mu, 0, 0, 0],  # |f_x| ≤ μ f_z
        [1, 0, mu, 0, 0, 0],
        [0, -1, mu, 0, 0, 0],  # |f_y| ≤ μ f_z
        [0, 1, mu, 0, 0, 0],
        [0, 0, Y, -1, 0, 0],  # |τ_x| ≤ Y f_z: the centre of pressure within the width
        [0, 0, Y, 1, 0, 0],
        [0, 0, X, 0, -1, 0],  # |τ_y| ≤ X f_z: and within the length
        [0, 0, X, 0, 1, 0],
    ]
    # τ_min ≤ τ_z ≤ τ_max, with τ_min = −μ(X+Y) f_z + |Y f_x − μ τ_x| + |X f_y − μ τ_y| and
    # τ_max = μ(X+Y) f_z − |Y f_x + μ τ_x| − |X f_y + μ τ_y|: each absolute value opens into two rows
    for a in (1, -1):
        for b in (1, -1):
            rows.append([-a * Y, -b * X, mu * (X + Y), -a * mu, -b * mu, -1])  # τ_z ≤ τ_max
            rows.append([-a * Y, -b * X, mu * (X + Y), a * mu, b * mu, 1])  # τ_z ≥ τ_min
    return np.array(rows, dtype=float)


@dataclass
class SoleContact:
    """One foot's sole on the floor. ``active``: it stands (its wrench in the cone, its sole still); otherwise it
    swings and transmits nothing. ``max_normal_force`` ramps a foot's load in and out in double support."""

    frame: str
    length: float  # m along the sole's x
    width: float  # m along its y
    friction: float
    active: bool = True
    min_normal_force: float = MIN_NORMAL_FORCE
    max_normal_force: float = np.inf
    #: the foot's velocity that the acceleration constraint damps out (1/s); 0 asks for zero acceleration only
    velocity_gain: float = 0.0
    cop_margin: float = COP_MARGIN

    def __post_init__(self) -> None:
        self.cone = cone_matrix(self.length / 2 - self.cop_margin, self.width / 2 - self.cop_margin, self.friction)

    def wrench_jacobian(self, dynamics: RobotDynamics) -> np.ndarray:
        """6 × nv map J_s with generalised force J_sᵀ w for a sole-frame wrench w: the frame Jacobian in the sole's
        own axes."""
        rotation = dynamics.pose(self.frame).rotation
        jacobian = dynamics.jacobian(self.frame)
        return np.vstack([rotation.T @ jacobian[:3], rotation.T @ jacobian[3:]])

    def acceleration_constraint(self, dynamics: RobotDynamics) -> tuple[np.ndarray, np.ndarray]:
        """(J, b) with J v̇ = b: the sole does not accelerate (world axes), and any velocity it has decays."""
        jacobian = dynamics.jacobian(self.frame)
        return jacobian, -dynamics.drift(self.frame) - self.velocity_gain * (jacobian @ dynamics.v)

    def normal_force_bounds(self) -> tuple[float, float]:
        if not self.active:
            return 0.0, 0.0
        # a foot being unloaded (max_normal_force ramping to zero) may go below the minimum: the ramp wins
        return min(self.min_normal_force, self.max_normal_force), self.max_normal_force
