"""A CasADi conic (QP) solver for one problem shape, evaluated on numpy arrays it owns.

    minimise   ½ xᵀ H x + gᵀ x
    subject to lba ≤ A x ≤ uba,  lbx ≤ x ≤ ubx

Calling a casadi Function with numpy matrices converts them element by element and builds its argument
dictionaries each call: for the whole-body IK's 21-variable QP that costs about 0.1 ms median (and up to
2 ms), ten times DAQP's own solve. A ``FunctionBuffer`` reads the arrays' memory directly (column-major), so a
step writes its numbers into ``hessian``, ``constraints_t`` and ``inputs`` and calls ``solve``: about 12 µs
for that QP. Both whole-body solvers (``solve_ik``, ``solve_id``) use it.
"""

from __future__ import annotations

import casadi
import numpy as np

DEFAULT_SOLVER = "daqp"  # dense active-set, exact: the fastest CasADi offers for these sizes
_OPTIONS: dict[str, dict] = {
    "qpoases": {"printLevel": "none"},
    "osqp": {"osqp": {"verbose": False}},
    "qrqp": {"print_iter": False, "print_header": False},
}


class Conic:
    """One QP shape (``n`` variables, ``m`` linear constraints) of ``solver``, built once and reused."""

    def __init__(self, solver: str, n: int, m: int) -> None:
        pattern = {"h": casadi.Sparsity.dense(n, n), "a": casadi.Sparsity.dense(m, n)}
        # a failed solve raises: reading stats()["success"] after every solve cost more than DAQP's own solve
        options = {"error_on_fail": True, **_OPTIONS.get(solver, {})}
        self.function = casadi.conic(f"qp_{n}x{m}", solver, pattern, options)
        self.buffer, self._evaluate = self.function.buffer()
        self.inputs = {name: np.zeros(self.function.nnz_in(name)) for name in casadi.conic_in()}
        self.outputs = {name: np.zeros(self.function.nnz_out(name)) for name in casadi.conic_out()}
        for i, name in enumerate(casadi.conic_in()):
            self.buffer.set_arg(i, memoryview(self.inputs[name]))
        for i, name in enumerate(casadi.conic_out()):
            self.buffer.set_res(i, memoryview(self.outputs[name]))
        self.hessian = self.inputs["h"].reshape(n, n)  # symmetric: row- and column-major alike
        self.constraints_t = self.inputs["a"].reshape(n, m)  # Aᵀ in row-major order is A in column-major order

    def solve(self) -> bool:
        """Solve for what the inputs hold now; the solution is in ``outputs["x"]``. False if the solver failed
        (an infeasible problem, or no convergence)."""
        try:
            self._evaluate()
        except RuntimeError as error:
            if "conic process failed" not in str(error):
                raise  # not the solver's verdict: a mistake in how the problem was set up
            return False
        return True


_conics: dict[tuple[str, int, int], Conic] = {}


def conic(solver: str, n: int, m: int) -> Conic:
    """The process's solver for this shape (each shape's is built once: a few ms)."""
    key = (solver, n, m)
    if key not in _conics:
        _conics[key] = Conic(solver, n, m)
    return _conics[key]
