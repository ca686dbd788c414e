"""A goal's whole-body QP compiled once, then filled by one call each control step.

Built from numbers every step (``solve_ik``), the QP's few dozen numpy
operations cost 3–5 µs each in the control loop, where physics has just
emptied the caches: 0.4–0.5 ms a step, ten times DAQP's own solve. Here the
same tasks and limits are evaluated once on a ``SymbolicKinematics``; the QP's
terms become one CasADi function of the configuration (and of the targets
that move during the goal), which writes straight into the conic solver's
input buffers. A step is then two calls: the function, and DAQP.
"""

from __future__ import annotations

import time
from collections.abc import Callable

import casadi as ca
import numpy as np

from bt_humanoid.control.wbc.conic import DEFAULT_SOLVER, conic
from bt_humanoid.control.wbc.limits.base import Limit
from bt_humanoid.control.wbc.solver import BoxLimit, Solution, qp_terms
from bt_humanoid.control.wbc.symbolic_kinematics import SymbolicKinematics
from bt_humanoid.control.wbc.tasks.base import Task


class CompiledQp:
    """The QP of ``tasks`` within every limit, as ``solve_ik`` builds it, compiled for ``kinematics``' robot."""

    def __init__(
        self,
        kinematics: SymbolicKinematics,
        tasks: list[Task],
        box_limits: list[BoxLimit],
        limits: list[Limit],
        dt: float,
        damping: float = 1e-4,
        solver: str = DEFAULT_SOLVER,
    ) -> None:
        self.n = len(kinematics.joints)
        with kinematics.recording_parameters() as parameters:
            terms = qp_terms(kinematics, tasks, box_limits, limits, dt, damping)
        self._parameters: list[tuple[Callable[[], np.ndarray], slice]] = []
        offset = 0
        for symbol, read in parameters:
            self._parameters.append((read, slice(offset, offset + symbol.numel())))
            offset += symbol.numel()
        symbols = [kinematics.controlled, kinematics.configuration, ca.vertcat(*(ca.vec(s) for s, _ in parameters))]
        outputs = [
            ca.densify(ca.SX(terms.hessian)),
            ca.densify(ca.SX(terms.gradient)),
            ca.densify(ca.SX(terms.constraints)),
            ca.densify(ca.SX(terms.constraints_lower)),
            ca.densify(ca.SX(terms.lower)),
            ca.densify(ca.SX(terms.upper)),
        ]
        self.rows = int(outputs[3].numel())
        self.function = ca.Function("whole_body_qp", symbols, outputs)
        self.qp = conic(solver, self.n, self.rows)
        self.qp.inputs["uba"][:] = np.inf
        self.controlled = np.zeros(self.n)
        self.configuration = np.zeros(kinematics.model.nq)
        self.parameter_values = np.zeros(offset)
        self._buffer, self._evaluate = self.function.buffer()
        for i, array in enumerate((self.controlled, self.configuration, self.parameter_values)):
            self._buffer.set_arg(i, memoryview(array))
        # the outputs are the solver's inputs: dense and column-major alike (H symmetric, A as Aᵀ row-major)
        for i, name in enumerate(("h", "g", "a", "lba", "lbx", "ubx")):
            self._buffer.set_res(i, memoryview(self.qp.inputs[name]))

    def solve(self, controlled: np.ndarray, configuration: np.ndarray) -> Solution:
        """The joint step Δq at these controlled joint positions (the rest of Pinocchio's configuration from
        ``configuration``); zero if the QP has no solution."""
        started = time.perf_counter()
        self.controlled[:] = controlled
        self.configuration[:] = configuration
        for read, where in self._parameters:
            self.parameter_values[where] = np.ravel(read(), order="F")  # CasADi matrices are column-major
        self._evaluate()
        built = time.perf_counter()
        solved = self.qp.solve()
        solved_at = time.perf_counter()
        step = self.qp.outputs["x"].copy() if solved else np.zeros(self.n)
        return Solution(step, solved, solved_at - started, solved_at - built)
