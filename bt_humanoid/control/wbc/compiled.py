"""The whole-body QP compiled once per kind of goal, then filled by one call each control step.

Built from numbers every step (``solve_ik``), the QP's few dozen numpy
operations cost 3–5 µs each in the control loop, where physics has just
emptied the caches: 0.4–0.5 ms a step, ten times DAQP's own solve. Here the
same tasks and limits are evaluated once on a ``SymbolicKinematics``; the QP's
terms become one CasADi function of the configuration and of the numbers the
tasks and limits read through ``kinematics.parameter`` (targets, outlines),
which writes straight into the conic solver's input buffers. A step is then
two calls: the function, and DAQP.

A goal of the same signatures as an earlier one (another reach with the same
tasks and limits, another look) reuses the function, fed its own numbers: the
process compiles each kind of goal once (about 15 ms), whichever controller
asks.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass

import casadi as ca
import numpy as np

from bt_humanoid.control.wbc.conic import DEFAULT_SOLVER, conic
from bt_humanoid.control.wbc.kinematics import Parameter, RobotKinematics
from bt_humanoid.control.wbc.limits.base import Limit
from bt_humanoid.control.wbc.solver import BoxLimit, Solution, qp_terms
from bt_humanoid.control.wbc.symbolic_kinematics import SymbolicKinematics
from bt_humanoid.control.wbc.tasks.base import Task


@dataclass(frozen=True)
class QpFunction:
    """A QP's terms as one CasADi function of (controlled joints, whole configuration, parameters)."""

    function: ca.Function
    layout: tuple[tuple[tuple[int, int], bool], ...]  # each parameter's shape and whether it moves, in order
    joints: int  # controlled joints: the QP's variables
    rows: int  # linear constraints
    configuration: int  # Pinocchio's nq


def compile_qp(
    kinematics: SymbolicKinematics,
    tasks: list[Task],
    box_limits: list[BoxLimit],
    limits: list[Limit],
    dt: float,
) -> tuple[QpFunction, list[Parameter]]:
    """The QP of ``tasks`` within every limit, as ``qp_terms`` builds it, compiled; with the parameters these
    tasks and limits asked for (to ``bind`` them)."""
    with kinematics.recording_parameters() as parameters:
        terms = qp_terms(kinematics, tasks, box_limits, limits, dt)
    inputs = [kinematics.controlled, kinematics.configuration, ca.vertcat(*(ca.vec(p.symbol) for p in parameters))]
    outputs = [
        ca.densify(ca.SX(term))
        for term in (
            terms.hessian,
            terms.gradient,
            terms.constraints,
            terms.constraints_lower,
            terms.lower,
            terms.upper,
        )
    ]
    layout = tuple((p.shape, p.moving) for p in parameters)
    rows = int(ca.SX(terms.constraints_lower).numel())
    function = ca.Function("whole_body_qp", inputs, outputs)
    return QpFunction(function, layout, len(kinematics.joints), rows, kinematics.model.nq), parameters


class CompiledQp:
    """One controller's use of a compiled QP: its own buffers, bound to one goal's numbers at a time."""

    def __init__(self, compiled: QpFunction, solver: str = DEFAULT_SOLVER) -> None:
        self.compiled = compiled
        self.n = compiled.joints
        self.qp = conic(solver, self.n, compiled.rows)
        self.controlled = np.zeros(self.n)
        self.configuration = np.zeros(compiled.configuration)
        self.parameter_values = np.zeros(sum(shape[0] * shape[1] for shape, _ in compiled.layout))
        self._moving: list[tuple[Callable[[], np.ndarray], slice]] = []
        self._buffer, self._evaluate = compiled.function.buffer()
        for i, array in enumerate((self.controlled, self.configuration, self.parameter_values)):
            self._buffer.set_arg(i, memoryview(array))
        # the outputs are the solver's inputs: dense and column-major alike (H symmetric, A as Aᵀ row-major)
        for i, name in enumerate(("h", "g", "a", "lba", "lbx", "ubx")):
            self._buffer.set_res(i, memoryview(self.qp.inputs[name]))

    def bind(self, parameters: list[Parameter]) -> None:
        """Serve the goal whose tasks and limits recorded ``parameters``: read the fixed ones now, the moving
        ones every step. ValueError if they are not laid out as the compiled QP's."""
        if tuple((p.shape, p.moving) for p in parameters) != self.compiled.layout:
            raise ValueError("these tasks and limits ask for other parameters than the compiled QP's")
        self._moving = []
        offset = 0
        for parameter in parameters:
            where = slice(offset, offset + parameter.shape[0] * parameter.shape[1])
            offset = where.stop
            if parameter.moving:
                self._moving.append((parameter.read, where))
            else:
                self.parameter_values[where] = _column_major(parameter.read())

    def solve(self, controlled: np.ndarray, configuration: np.ndarray) -> Solution:
        """The joint step Δq at these controlled joint positions (the rest of Pinocchio's configuration from
        ``configuration``); zero if the QP has no solution."""
        started = time.perf_counter()
        self.controlled[:] = controlled
        self.configuration[:] = configuration
        for read, where in self._moving:
            self.parameter_values[where] = _column_major(read())
        self.qp.inputs["uba"][:] = np.inf  # the solver is shared by every QP of its shape
        self._evaluate()
        built = time.perf_counter()
        solved = self.qp.solve()
        solved_at = time.perf_counter()
        step = self.qp.outputs["x"].copy() if solved else np.zeros(self.n)
        return Solution(step, solved, solved_at - started, solved_at - built)


_functions: dict[tuple, QpFunction] = {}  # the process's compiled QPs, per robot, joints, dt and goal signature


class QpCache:
    """A whole-body controller's QPs, one per kind of goal (its tasks' and limits' signatures), each bound in
    turn to the goals of that kind."""

    def __init__(self, symbolic: SymbolicKinematics, numeric: RobotKinematics) -> None:
        self.symbolic, self.numeric = symbolic, numeric
        self._mine: dict[tuple, CompiledQp] = {}
        self.compile_times: list[float] = []  # s for each QP this controller compiled
        self.bind_times: list[float] = []  # s for each goal served by a QP compiled before (here or elsewhere)

    def for_goal(self, tasks: list[Task], box_limits: list[BoxLimit], limits: list[Limit], dt: float) -> CompiledQp:
        """The compiled QP of this goal (``dt`` s per control step), bound to its tasks and limits."""
        started = time.perf_counter()
        key = (
            self.symbolic.robot,
            tuple(self.symbolic.joints),
            dt,
            tuple(t.signature() for t in tasks),
            tuple(b.signature() for b in box_limits),
            tuple(lim.signature() for lim in limits),
        )
        compiled = key not in _functions
        if compiled:
            _functions[key], parameters = compile_qp(self.symbolic, tasks, box_limits, limits, dt)
        else:
            # the numbers are read by building the QP from numbers: the same calls, in the same order
            with self.numeric.recording_parameters() as parameters:
                qp_terms(self.numeric, tasks, box_limits, limits, dt)
        if key not in self._mine:
            self._mine[key] = CompiledQp(_functions[key])
        qp = self._mine[key]
        qp.bind(parameters)
        (self.compile_times if compiled else self.bind_times).append(time.perf_counter() - started)
        return qp


def _column_major(value: np.ndarray) -> np.ndarray:
    return np.ravel(value, order="F")  # CasADi's matrices are column-major
