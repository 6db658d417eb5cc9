"""IPOPT through CasADi, built once per problem structure and reused for every task.

CasADi derives the exact first and second derivatives of the whole NLP when
the solver is built, which is the expensive part; the task (start, goal)
enters as the parameter vector p and the initial guess as x0, so a
:class:`TrajoptSolver` solves any number of tasks without rebuilding.

The iteration and time limits and the user's per-iteration callback are
termination conditions checked in IPOPT's intermediate callback, so that each
solve can set its own (IPOPT's options are fixed when the solver is built).
"""

from __future__ import annotations

import ctypes
import enum
import functools
import math
import os
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import casadi as ca
import numpy as np
from numpy.typing import ArrayLike, NDArray

from roughwalk.errors import InvalidArgumentError
from roughwalk.trajopt.formulation import Formulation
from roughwalk.trajopt.parameters import SolverOptions

__all__ = ["TrajoptStatus", "IterationInfo", "SolveOutcome", "TrajoptSolver", "hessian_choice"]


class TrajoptStatus(enum.Enum):
    """How a solve ended (the planner statuses of the project, plus the iteration limit)."""

    EXACT = "exact"
    """IPOPT converged to its tolerance."""
    APPROXIMATE = "approximate"
    """IPOPT stopped at its acceptable tolerance."""
    ITERATION_LIMIT = "iteration_limit"
    """The iteration limit was reached first."""
    TIMEOUT = "timeout"
    """The time limit was reached first."""
    CANCELLED = "cancelled"
    """The user's callback asked to stop."""
    INFEASIBLE = "infeasible"
    """IPOPT found the constraints locally infeasible."""
    FAILED = "failed"
    """IPOPT failed otherwise (restoration failure, numerical trouble)."""
    INVALID_INPUT = "invalid_input"
    """The task or its terrain was rejected before solving."""

    @property
    def solved(self) -> bool:
        """Whether this status carries a solution."""
        return self in (TrajoptStatus.EXACT, TrajoptStatus.APPROXIMATE)


_IPOPT_STATUS = {
    "Solve_Succeeded": TrajoptStatus.EXACT,
    "Solved_To_Acceptable_Level": TrajoptStatus.APPROXIMATE,
    "Maximum_Iterations_Exceeded": TrajoptStatus.ITERATION_LIMIT,
    "Maximum_CpuTime_Exceeded": TrajoptStatus.TIMEOUT,
    "Maximum_WallTime_Exceeded": TrajoptStatus.TIMEOUT,
    "Infeasible_Problem_Detected": TrajoptStatus.INFEASIBLE,
}


@dataclass(frozen=True)
class IterationInfo:
    """What the per-iteration callback receives.

    Attributes
    ----------
    iteration:
        IPOPT's iteration number (0 is the initial point).
    elapsed_s:
        Wall time [s] since the solve started.
    objective:
        Objective value.
    max_violation:
        Largest constraint violation (constraints' units).
    x:
        The current iterate (a copy).

    """

    iteration: int
    elapsed_s: float
    objective: float
    max_violation: float
    x: NDArray[np.float64]


@dataclass
class SolveOutcome:
    """The raw result of one IPOPT solve."""

    status: TrajoptStatus
    return_status: str
    iterations: int
    solve_time_s: float
    x: NDArray[np.float64]
    lam_x: NDArray[np.float64]
    lam_g: NDArray[np.float64]
    objective: float
    g: NDArray[np.float64]
    costs: NDArray[np.float64]
    history: list[dict[str, float]] = field(default_factory=list)


_IPOPT_ITERATION_CEILING = 1_000_000
"""IPOPT's own iteration limit; the per-solve limits are the monitor's."""


def violation(
    values: NDArray[np.float64], lower: NDArray[np.float64], upper: NDArray[np.float64]
) -> NDArray[np.float64]:
    """Per-row violation max(lower − v, v − upper, 0) (NaN counts as infinitely violated)."""
    v = np.maximum(np.maximum(lower - values, values - upper), 0.0)
    return np.where(np.isnan(values), np.inf, v)


def _ipopt_value(text: str) -> int | float | str:
    """An IPOPT option value from text: an int, a float, else the string."""
    for kind in (int, float):
        try:
            return kind(text)
        except ValueError:
            pass
    return text


@functools.cache
def _single_threaded_blas() -> bool:
    """Run the OpenBLAS bundled with CasADi (MUMPS's BLAS) on one thread.

    The KKT systems' dense fronts are small: a second BLAS thread only spins,
    which on the Melon single-pallet solve cost 2.4 s of system CPU time for
    2.4 s of useful work, with no gain in wall time. A user's own
    OPENBLAS_NUM_THREADS is respected. Returns whether the setting was applied.
    """
    if "OPENBLAS_NUM_THREADS" in os.environ:
        return False
    library = Path(ca.__file__).resolve().parent / "libcasadi-tp-openblas.so.0"
    try:
        ctypes.CDLL(str(library)).openblas_set_num_threads(1)
    except (OSError, AttributeError):
        return False
    return True


def hessian_choice(options: SolverOptions, has_costs: bool) -> str:
    """IPOPT's Hessian: the options' choice; "auto" is exact with costs, L-BFGS without."""
    if options.hessian == "auto":
        return "exact" if has_costs else "limited-memory"
    return options.hessian


class _Monitor(ca.Callback):
    """IPOPT's intermediate callback: limits, history and the user's callback."""

    def __init__(
        self, nx: int, ng: int, np_: int, lbg: NDArray[np.float64], ubg: NDArray[np.float64]
    ) -> None:
        ca.Callback.__init__(self)
        # Only what the monitor reads: IPOPT's multipliers would be copied into
        # it at every iteration for nothing.
        self._sizes = {"x": nx, "g": ng, "f": 1}
        self.lbg, self.ubg = lbg, ubg
        self.reset(None, None, None)
        self._read = [ca.nlpsol_out().index(name) for name in ("x", "f", "g")]
        self.construct("trajopt_monitor", {})

    def reset(
        self,
        max_iter: int | None,
        time_limit_s: float | None,
        user: Callable[[IterationInfo], bool | None] | None,
    ) -> None:
        self.max_iter = max_iter
        self.time_limit_s = time_limit_s
        self.user = user
        self.count = 0
        self.start = time.perf_counter()
        self.stopped_by: TrajoptStatus | None = None
        self.history: list[dict[str, float]] = []

    def get_n_in(self) -> int:
        return ca.nlpsol_n_out()

    def get_n_out(self) -> int:
        return 1

    def get_name_in(self, i: int) -> str:
        return ca.nlpsol_out(i)

    def get_name_out(self, i: int) -> str:
        return "stop"

    def get_sparsity_in(self, i: int) -> ca.Sparsity:
        n = self._sizes.get(ca.nlpsol_out(i), 0)
        return ca.Sparsity.dense(n, 1) if n else ca.Sparsity(0, 0)

    def has_eval_buffer(self) -> bool:
        return True

    def eval_buffer(self, arg: Any, res: Any) -> int:
        """The callback on IPOPT's own buffers (CasADi's DM inputs cost 0.6 ms an iteration)."""
        x, f, g = (np.frombuffer(arg[i], dtype=np.float64) for i in self._read)
        np.frombuffer(res[0], dtype=np.float64)[:] = self._step(x, f, g)
        return 0

    def _step(self, x: NDArray[np.float64], f: NDArray[np.float64], g: NDArray[np.float64]) -> int:
        """Record the iteration; 1 if the solve must stop."""
        iteration = self.count
        self.count += 1
        elapsed = time.perf_counter() - self.start
        viol = violation(g, self.lbg, self.ubg)
        info = IterationInfo(
            iteration,
            elapsed,
            float(f[0]),
            float(viol.max()) if viol.size else 0.0,
            x.copy(),
        )
        self.history.append(
            {
                "iteration": iteration,
                "elapsed_s": elapsed,
                "objective": info.objective,
                "max_violation": info.max_violation,
            }
        )
        if self.user is not None and self.user(info):
            self.stopped_by = TrajoptStatus.CANCELLED
        elif self.max_iter is not None and iteration >= self.max_iter:
            self.stopped_by = TrajoptStatus.ITERATION_LIMIT
        elif self.time_limit_s is not None and elapsed >= self.time_limit_s:
            self.stopped_by = TrajoptStatus.TIMEOUT
        return 1 if self.stopped_by is not None else 0


class TrajoptSolver:
    """The IPOPT solver of one :class:`Formulation`; :meth:`solve` runs it for a task.

    Parameters
    ----------
    nlp:
        The problem.
    options:
        IPOPT's settings and the default limits.

    """

    def __init__(self, nlp: Formulation, options: SolverOptions | None = None) -> None:
        start = time.perf_counter()
        self.nlp = nlp
        self.options = options or SolverOptions()
        o = self.options
        _single_threaded_blas()
        fixed = not nlp.config.optimize_durations
        self.hessian = hessian_choice(o, bool(nlp.cost_names))
        pivot_order = o.mumps_pivot_order
        if pivot_order is None:
            # See SolverOptions.mumps_pivot_order: AMD with the exact Hessian.
            pivot_order = 0 if self.hessian == "exact" else (7 if fixed else 5)
        scaling = o.mumps_scaling
        if scaling is None:
            scaling = self.hessian != "exact"
        mumps: dict[str, Any] = {"mumps_pivot_order": pivot_order}
        if not scaling:
            mumps.update(mumps_scaling=0, mumps_permuting_scaling=0)
        self._monitor = _Monitor(
            nlp.n_variables, nlp.n_constraints, int(nlp.p.numel()), nlp.lbg, nlp.ubg
        )
        ipopt: dict[str, Any] = {
            "print_level": o.print_level,
            "sb": "yes",
            "tol": o.tol,
            "acceptable_tol": o.acceptable_tol,
            "constr_viol_tol": o.constr_viol_tol,
            "linear_solver": o.linear_solver,
            "hessian_approximation": self.hessian,
            **(mumps if o.linear_solver == "mumps" else {}),
            # Only a ceiling: each solve's own limit is enforced by the monitor, because
            # IPOPT's options are fixed when the solver is built and a cached solver
            # serves solves with other limits (one built for max_iter=0 stopped every
            # later solve after 2 iterations).
            "max_iter": _IPOPT_ITERATION_CEILING,
            **({"print_timing_statistics": "yes"} if o.print_level >= 5 else {}),
        }
        for item in o.ipopt_options:
            name, _, value = item.partition("=")
            ipopt[name.strip()] = _ipopt_value(value.strip())
        # The formulation's block-wise derivatives (CasADi's own are far slower to build).
        solver_options: dict[str, Any] = {"jac_g": nlp.jac_g, "grad_f": nlp.grad_f}
        if self.hessian == "exact":
            solver_options["hess_lag"] = nlp.hess_lag
        self._options = {
            **solver_options,
            # Without these, nlpsol differentiates the whole NLP once more in MX
            # ("nlp_grad", for the multipliers of p, which nothing here reads):
            # 0.06 s of the flat trot's 0.40 s build, 0.17 s with optimised
            # durations, and an evaluation after every solve. lam_x and lam_g
            # are IPOPT's own either way.
            "no_nlp_grad": True,
            "calc_lam_p": False,
            "ipopt": ipopt,
            "print_time": False,
            "iteration_callback": self._monitor,
            "iteration_callback_ignore_errors": False,
            "error_on_fail": False,
        }
        self.solver = ca.nlpsol("trajopt", "ipopt", nlp.nlp, self._options)
        self._warm_solvers: dict[str, ca.Function] = {}
        self.build_time_s = time.perf_counter() - start

    def _warm(self, predicted: bool) -> ca.Function:
        """A second IPOPT that starts from given multipliers as well as the primal guess.

        Its options are the cold solver's with ``warm_ipopt_options`` on top
        (a previous solution's multipliers) or ``guess_ipopt_options``
        (``predicted`` ones). The derivatives are the same Functions, so each
        costs a fraction of a second to build, once.
        """
        kind = "guess" if predicted else "warm"
        if kind not in self._warm_solvers:
            ipopt = dict(self._options["ipopt"])
            extra = (
                self.options.guess_ipopt_options if predicted else self.options.warm_ipopt_options
            )
            for item in extra:
                name, _, value = item.partition("=")
                ipopt[name.strip()] = _ipopt_value(value.strip())
            self._warm_solvers[kind] = ca.nlpsol(
                f"trajopt_{kind}", "ipopt", self.nlp.nlp, {**self._options, "ipopt": ipopt}
            )
        return self._warm_solvers[kind]

    def solve(
        self,
        task: ArrayLike,
        x0: ArrayLike,
        *,
        max_iter: int | None = None,
        time_limit_s: float | None = None,
        callback: Callable[[IterationInfo], bool | None] | None = None,
        lam_x0: ArrayLike | None = None,
        lam_g0: ArrayLike | None = None,
        predicted: bool = False,
    ) -> SolveOutcome:
        """Solve for the task parameter vector ``task`` from the initial guess ``x0``.

        ``max_iter`` and ``time_limit_s`` [s] default to the options'; the
        ``callback`` sees every iteration and stops the solve by returning True.
        With multipliers ``lam_x0`` and ``lam_g0`` IPOPT warm-starts from them as
        well as from ``x0``: with the options for a previous solution's, or
        for ``predicted`` ones (a learned guess; see :class:`SolverOptions`).
        """
        p = np.asarray(task, dtype=float).ravel()
        x_init = np.asarray(x0, dtype=float).ravel()
        if x_init.size != self.nlp.n_variables:
            raise InvalidArgumentError(
                f"initial guess has {x_init.size} values, the NLP has {self.nlp.n_variables}"
            )
        limit = self.options.max_iter if max_iter is None else int(max_iter)
        seconds = self.options.time_limit_s if time_limit_s is None else float(time_limit_s)
        self._monitor.reset(limit, seconds, callback)
        start = time.perf_counter()
        bounds = {
            "lbx": self.nlp.lbx,
            "ubx": self.nlp.ubx,
            "lbg": self.nlp.lbg,
            "ubg": self.nlp.ubg,
        }
        if lam_x0 is not None and lam_g0 is not None:
            multipliers = {
                "lam_x0": np.asarray(lam_x0, dtype=float),
                "lam_g0": np.asarray(lam_g0, dtype=float),
            }
            warm = self._warm(predicted)
            out = warm(x0=x_init, p=p, **multipliers, **bounds)
            stats = warm.stats()
        else:
            out = self.solver(x0=x_init, p=p, **bounds)
            stats = self.solver.stats()
        elapsed = time.perf_counter() - start
        return_status = str(stats.get("return_status", "unknown"))
        if return_status == "User_Requested_Stop" and self._monitor.stopped_by is not None:
            status = self._monitor.stopped_by
        else:
            status = _IPOPT_STATUS.get(return_status, TrajoptStatus.FAILED)
        x = np.asarray(out["x"]).ravel()
        f_val, g_val, costs = self.nlp.evaluator(x, p)
        objective = float(f_val)
        return SolveOutcome(
            status=status,
            return_status=return_status,
            iterations=int(stats.get("iter_count", 0)),
            solve_time_s=elapsed,
            x=x,
            lam_x=np.asarray(out["lam_x"]).ravel(),
            lam_g=np.asarray(out["lam_g"]).ravel(),
            objective=objective if math.isfinite(objective) else float("nan"),
            g=np.asarray(g_val).ravel(),
            costs=np.asarray(costs).ravel(),
            history=list(self._monitor.history),
        )
