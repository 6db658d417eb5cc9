"""The whole-body QP: joint accelerations, torques and contact forces in one solve.

Unknowns x = [q̈, τ, f] (:class:`~roughwalk.tracking.tasks.QPLayout`). Hard
constraints: the floating-base equations of motion M q̈ + h = Sᵀτ + J_cᵀ f
(all nv rows, so τ is exactly what the actuators must produce), a friction
pyramid and normal-force bounds per stance foot, and the actuators' torque
limits. The objective is a weighted sum of least-squares tasks (base pose,
swing feet, stance feet, planned forces, regularisation), in the spirit of
Bellicoso et al. 2016's whole-body controller that Melon et al. 2020 §V ran
their trajectories on (weighted instead of strictly prioritised: one QP per
tick instead of one per priority level).
"""

from __future__ import annotations

import functools
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from roughwalk.errors import ConfigError
from roughwalk.tracking.tasks import LeastSquaresTask, QPLayout

__all__ = ["WholeBodyQP", "QPSolution", "friction_pyramid"]


@dataclass(frozen=True)
class QPSolution:
    """One solve of the whole-body QP.

    Attributes
    ----------
    success:
        The solver returned a solution (False: the other fields are zeros).
    qacc:
        (nv,) generalised accelerations q̈.
    tau:
        (nu,) joint torques τ [N·m].
    forces:
        (n_contacts, 3) contact forces on the stance feet [N], world axes.
    x:
        The solution vector [q̈, τ, f].
    stalled:
        The solver stopped at its iteration limit without a solution (a tick
        a 400 Hz controller cannot afford; ``success`` is False then).
    """

    success: bool
    qacc: NDArray[np.float64]
    tau: NDArray[np.float64]
    forces: NDArray[np.float64]
    x: NDArray[np.float64]
    stalled: bool = False
    relaxed: bool = False
    """The hard contact rows made the QP infeasible; it was solved with
    them left to the stance-foot tasks (the cone and torque limits kept)."""


def friction_pyramid(normal: ArrayLike, friction: float) -> NDArray[np.float64]:
    """(4, 3) rows C with C f ≤ 0 ⇔ f inside the 4-sided pyramid of ``normal`` and μ."""
    n = np.asarray(normal, dtype=float)
    n = n / np.linalg.norm(n)
    helper = np.array([1.0, 0.0, 0.0]) if abs(n[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    t1 = np.cross(n, helper)
    t1 /= np.linalg.norm(t1)
    t2 = np.cross(n, t1)
    return np.array([t1 - friction * n, -t1 - friction * n, t2 - friction * n, -t2 - friction * n])


@functools.lru_cache(maxsize=16)
def _upright_pyramid(friction: float) -> NDArray[np.float64]:
    """The pyramid of a z-up normal (the default), built once per μ."""
    rows = friction_pyramid((0.0, 0.0, 1.0), friction)
    rows.setflags(write=False)
    return rows


class WholeBodyQP:
    """Build and solve the whole-body QP with a qpsolvers backend.

    Parameters
    ----------
    actuated_dofs:
        (nu,) indices of the actuated joints' degrees of freedom in q̇ (S's columns).
    torque_limit:
        (nu,) |τ| bound [N·m] per actuated joint.
    friction:
        Friction coefficient μ of the pyramids (keep it under the ground's).
    min_normal_force, max_normal_force:
        Bounds [N] of each stance foot's normal force.
    solver:
        qpsolvers' solver name ("proxqp", "osqp", ...).
    max_iter:
        The solver's iteration limit (proxqp: outer iterations, and as many
        at most 100 inner ones each; osqp: ADMM iterations); None: 1000 for
        proxqp, 20000 for osqp. proxqp's own limits (10⁴ × 1500) let one
        ill-conditioned tick run for minutes; a tick that hits the limit is
        reported as stalled.
    """

    def __init__(
        self,
        actuated_dofs: ArrayLike,
        torque_limit: ArrayLike,
        friction: float,
        min_normal_force: float = 0.0,
        max_normal_force: float = np.inf,
        solver: str = "proxqp",
        max_iter: int | None = None,
    ) -> None:
        import qpsolvers

        if solver not in qpsolvers.available_solvers:
            raise ConfigError(
                f"QP solver '{solver}' is not installed; available: "
                f"{', '.join(qpsolvers.available_solvers) or 'none'} (pip install proxsuite)"
            )
        self.actuated_dofs = np.asarray(actuated_dofs, dtype=np.int64)
        self.torque_limit = np.asarray(torque_limit, dtype=float)
        if self.torque_limit.shape != self.actuated_dofs.shape:
            raise ConfigError(
                f"torque_limit has {self.torque_limit.shape}, actuated_dofs "
                f"{self.actuated_dofs.shape}: one limit per actuated joint"
            )
        self.friction = float(friction)
        self.min_normal_force = float(min_normal_force)
        self.max_normal_force = float(max_normal_force)
        if max_iter is not None and max_iter < 1:
            raise ConfigError(f"the QP's max_iter must be ≥ 1, got {max_iter}")
        self.solver = solver
        self.max_iter = _DEFAULT_MAX_ITER.get(solver, 1000) if max_iter is None else int(max_iter)

    def layout(self, nv: int, n_contacts: int) -> QPLayout:
        """The unknowns' layout for a model of ``nv`` DoF with ``n_contacts`` stance feet."""
        return QPLayout(nv, len(self.actuated_dofs), n_contacts)

    def solve(
        self,
        mass_matrix: ArrayLike,
        bias: ArrayLike,
        contact_jacobian: ArrayLike,
        tasks: Sequence[LeastSquaresTask],
        normals: ArrayLike | None = None,
        contact_bias: ArrayLike | None = None,
        friction: ArrayLike | None = None,
        qacc_bounds: tuple[ArrayLike, ArrayLike] | None = None,
    ) -> QPSolution:
        """Minimise Σ w‖A x − b‖² subject to dynamics, friction and torque limits.

        Parameters
        ----------
        mass_matrix:
            (nv, nv) M(q) (MuJoCo's ``mj_fullM``).
        bias:
            (nv,) h = C(q, q̇) q̇ + g(q) − passive forces (``qfrc_bias − qfrc_passive``).
        contact_jacobian:
            (3·nc, nv) stacked translational Jacobians of the stance feet.
        tasks:
            The objective's tasks, all over this layout.
        normals:
            (nc, 3) terrain normals at the stance feet (default: z up).
        contact_bias:
            (3·nc,) J̇_c q̇ [m/s²]: when given, the stance feet do not accelerate,
            J_c q̈ + J̇_c q̇ = 0, as a hard constraint (else it is up to the tasks).
            When no torque within the limits and no force inside the cones
            can hold every stance foot still, the QP is solved again without
            these rows: the stance-foot tasks then ask for it as hard as
            they can (``relaxed`` in the solution), instead of the tick
            failing and the previous tick's torques being applied again.
        friction:
            (nc,) μ per stance foot (default: the solver's μ for all).
        qacc_bounds:
            (nv,) lower and upper bounds on q̈ (±inf where free): joint limits
            turned into acceleration bounds by the caller. When they make the
            QP infeasible it is solved again without them.
        """
        m = np.asarray(mass_matrix, dtype=float)
        h = np.asarray(bias, dtype=float)
        nv = m.shape[0]
        jc = np.asarray(contact_jacobian, dtype=float).reshape(-1, nv)
        nc = jc.shape[0] // 3
        lay = self.layout(nv, nc)
        n = lay.size
        nrm = np.tile([0.0, 0.0, 1.0], (nc, 1)) if normals is None else np.asarray(normals)
        mu = np.full(nc, self.friction) if friction is None else np.asarray(friction, dtype=float)

        # M q̈ − Sᵀτ − J_cᵀ f = −h
        a_eq = np.zeros((nv, n))
        a_eq[:, lay.qacc] = m
        a_eq[self.actuated_dofs, lay.tau] = -np.eye(lay.nu)
        a_eq[:, nv + lay.nu :] = -jc.T
        b_eq = -h
        if contact_bias is not None and nc:
            rows = np.zeros((3 * nc, n))
            rows[:, lay.qacc] = jc
            a_eq = np.vstack([a_eq, rows])
            b_eq = np.concatenate([b_eq, -np.asarray(contact_bias, dtype=float)])

        g_rows: list[NDArray[np.float64]] = []
        h_rows: list[NDArray[np.float64]] = []
        t_rows = np.zeros((2 * lay.nu, n))
        t_rows[: lay.nu, lay.tau] = np.eye(lay.nu)
        t_rows[lay.nu :, lay.tau] = -np.eye(lay.nu)
        g_rows.append(t_rows)
        h_rows.append(np.concatenate([self.torque_limit, self.torque_limit]))
        for i in range(nc):
            normal = nrm[i] / np.linalg.norm(nrm[i])
            rows = np.zeros((6, n))
            rows[:4, lay.force(i)] = (
                _upright_pyramid(float(mu[i]))
                if normals is None
                else friction_pyramid(normal, float(mu[i]))
            )
            rows[4, lay.force(i)] = -normal
            rows[5, lay.force(i)] = normal
            g_rows.append(rows)
            h_rows.append(
                np.array([0.0, 0.0, 0.0, 0.0, -self.min_normal_force, self.max_normal_force])
            )
        g = np.vstack(g_rows)
        g_h = np.concatenate(h_rows)
        if not np.isfinite(self.max_normal_force):
            keep = np.isfinite(g_h)
            g, g_h = g[keep], g_h[keep]

        # Σ w‖A x − b‖² = ‖Ā x − b̄‖² with rows scaled by √w: one product, not one per task.
        roots = [np.sqrt(task.weight) for task in tasks]
        a_all = np.vstack([r * task.matrix for r, task in zip(roots, tasks, strict=True)])
        b_all = np.concatenate([r * task.target for r, task in zip(roots, tasks, strict=True)])
        p = a_all.T @ a_all + 1e-9 * np.eye(n)
        q = -(a_all.T @ b_all)
        x = None
        if qacc_bounds is not None:
            lb = np.full(n, -np.inf)
            ub = np.full(n, np.inf)
            lb[lay.qacc] = qacc_bounds[0]
            ub[lay.qacc] = qacc_bounds[1]
            x, _ = self._solve_qp(p, q, g, g_h, a_eq, b_eq, lb, ub)
        stalled = False
        if x is None:
            x, stalled = self._solve_qp(p, q, g, g_h, a_eq, b_eq, None, None)
        relaxed = False
        if x is None and a_eq.shape[0] > nv:
            # Without the contact rows q̈ is free in M q̈ + h = Sᵀτ + J_cᵀ f: always feasible.
            x, stalled = self._solve_qp(p, q, g, g_h, a_eq[:nv], b_eq[:nv], None, None)
            relaxed = x is not None
        if x is None:
            zero = np.zeros(n)
            return QPSolution(
                False, zero[lay.qacc], zero[lay.tau], np.zeros((nc, 3)), zero, stalled
            )
        x = np.asarray(x, dtype=float)
        forces = x[nv + lay.nu :].reshape(nc, 3)
        return QPSolution(
            True, x[lay.qacc].copy(), x[lay.tau].copy(), forces.copy(), x, relaxed=relaxed
        )

    def _solve_qp(
        self,
        p: NDArray[np.float64],
        q: NDArray[np.float64],
        g: NDArray[np.float64],
        g_h: NDArray[np.float64],
        a_eq: NDArray[np.float64],
        b_eq: NDArray[np.float64],
        lb: NDArray[np.float64] | None,
        ub: NDArray[np.float64] | None,
    ) -> tuple[NDArray[np.float64] | None, bool]:
        """(x or None, whether the solver stopped at its iteration limit)."""
        if self.solver == "proxqp":
            return self._solve_proxqp(p, q, g, g_h, a_eq, b_eq, lb, ub)
        import qpsolvers

        problem = qpsolvers.Problem(p, q, g, g_h, a_eq, b_eq, lb, ub)
        options = _solver_options(self.solver, self.max_iter)
        solution = qpsolvers.solve_problem(problem, solver=self.solver, **options)
        x = solution.x
        if solution.found and x is not None and np.all(np.isfinite(x)):
            return np.asarray(x, dtype=float), False
        info = solution.extras.get("info")
        return None, "maximum iterations" in str(getattr(info, "status", "")).lower()

    def _solve_proxqp(
        self,
        p: NDArray[np.float64],
        q: NDArray[np.float64],
        g: NDArray[np.float64],
        g_h: NDArray[np.float64],
        a_eq: NDArray[np.float64],
        b_eq: NDArray[np.float64],
        lb: NDArray[np.float64] | None,
        ub: NDArray[np.float64] | None,
    ) -> tuple[NDArray[np.float64] | None, bool]:
        """Solve with proxqp directly: qpsolvers cannot set its inner iteration limit.

        proxqp's sparse backend, not its dense one: the dense one (its AVX-512
        build, the one proxsuite loads here) rounds by where its work buffers
        land in memory, so one QP solved twice gives solutions 1e-10 apart
        (measured: 60 solves of one tracking tick's QP in one process, two
        solutions in about equal shares; the sparse backend: one, the same in
        every process). On a dynamic gait that difference grows, within a few
        hundred ticks, into a fall in one run and a tracked motion in the next
        (issue 10). The sparse backend costs about 0.2 ms more per tick.
        """
        import scipy.sparse as sp
        from proxsuite import proxqp

        n = q.size
        c, lower, upper = g, np.full(g_h.size, -np.inf), g_h
        if lb is not None and ub is not None:
            bounded = np.isfinite(lb) | np.isfinite(ub)
            c = np.vstack([g, np.eye(n)[bounded]])
            lower = np.concatenate([lower, lb[bounded]])
            upper = np.concatenate([upper, ub[bounded]])
        solver = proxqp.sparse.QP(n, a_eq.shape[0], c.shape[0])
        # Tight tolerances: the torques are applied as solved, and a loose
        # equality would be a force error the base feels.
        solver.settings.eps_abs = 1e-8
        solver.settings.eps_rel = 0.0
        solver.settings.max_iter = self.max_iter
        solver.settings.max_iter_in = _PROXQP_MAX_ITER_IN
        # proxqp's infeasibility test (default 1e-4) is absolute: with forces
        # of kN and torques of 80 N·m in one vector it declared QPs infeasible
        # after 3–10 iterations that are feasible by construction (q̈ free in
        # the dynamics rows alone); issue 10 counted up to 20 such failed
        # ticks a run, each re-applying the previous torques.
        solver.settings.eps_primal_inf = _PROXQP_EPS_INFEASIBLE
        solver.settings.eps_dual_inf = _PROXQP_EPS_INFEASIBLE
        solver.settings.verbose = False
        solver.init(sp.csc_matrix(p), q, sp.csc_matrix(a_eq), b_eq, sp.csc_matrix(c), lower, upper)
        solver.solve()
        status = solver.results.info.status
        x = np.array(solver.results.x, dtype=float)
        if status == proxqp.QPSolverOutput.PROXQP_SOLVED and np.all(np.isfinite(x)):
            return x, False
        return None, bool(status == proxqp.QPSolverOutput.PROXQP_MAX_ITER_REACHED)


# proxqp's outer iterations: the whole-body QP takes 5–150, each with a few inner
# ones; 1000 × 100 bounds a tick to about a second of CPU in the worst case
# (proxqp's own limits, 10⁴ × 1500, to minutes).
_DEFAULT_MAX_ITER = {"proxqp": 1000, "osqp": 20000}
_PROXQP_MAX_ITER_IN = 100
_PROXQP_EPS_INFEASIBLE = 1e-12


def _solver_options(solver: str, max_iter: int) -> dict[str, Any]:
    if solver == "osqp":
        return {"eps_abs": 1e-7, "eps_rel": 1e-7, "max_iter": max_iter, "polish": True}
    return {}
