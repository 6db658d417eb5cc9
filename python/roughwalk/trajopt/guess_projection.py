"""Move an initial guess onto the NLP's linearised constraints before IPOPT starts.

A learned guess is an average of solutions, not a solution: on the double
pallet the shipped model's guesses miss the dynamics by 4–68 N at the
knots, leave a stance foot's friction pyramid at 6–56 % of the force nodes
and, between the nodes (which no row of the default set looks at), at
40–90 % of the stance samples. IPOPT stopped after 0–5 iterations returns
that guess nearly unchanged (its steps from a warm start are cut short by
the fraction-to-boundary rule), and the tracking controller inherits it.

One Gauss–Newton projection step solves the quadratic programme

    min ½ Σᵢ ((x − x₀)ᵢ / σᵢ)² + ½ ρ Σⱼ sⱼ²
    s.t. lbg ≤ g(xₖ) + J(xₖ)(x − xₖ) + s ≤ ubg,   lbx ≤ x ≤ ubx,

over every row of the NLP (dynamics, friction pyramid at the force nodes,
kinematics, start and goal), optionally with the friction pyramid and
unilaterality at the inner Bézier control points of every stance force
segment as well (:mod:`.constraints.force_between_nodes`'s rows, with the
terrain basis frozen at xₖ's footholds), so that the forces stay inside the
pyramid all along their splines. Each row is divided by the σ-weighted norm
of its gradient, so that its slack sⱼ measures a distance in the same
units as the step; ρ is large (nearly hard rows), and the slacks keep the
programme feasible where linearised rows contradict each other. σ says
which variables should give: forces and their rates much more than the
base and feet. The rows are linearised again at each step's result.

Off by default (``GuessProjection.steps`` 0): it does not make the double
pallet's plans track more often. Measured on held-out tasks 0–29
(``bench_tracking.py --tasks 30 --env double_pallet --init learned
--durations fixed --iters 0,5 --trajopt guess_projection.steps=1,...``,
paired with the same command without it, 21/30 at 0 and 5 iterations, load
8–13): with the default σ, 8/20 against 17/20 at 0 iterations (the
projection moves each plan to its task's start, which the learned guesses
miss by a median 32 cm, and drags the trunk into rolls of ±1.7 rad/s); with
the trunk and feet held (σ 2 mm, 0.5 mrad, 1 mm) and ``initial_state``
left out, the forces alone give way and the plans keep the pyramid at the
force nodes and between them — see docs/measurements.md, session 12, for
the paired counts. One step is not a projection there, though: on tasks
0–3 it takes the pyramid rows (force 7–161 → 17–50 N, unilaterality between
nodes 12–333 → 1.5–7.6 N) but not the dynamics (4–68 → 32–167 N: the
torque rows are bilinear, and the bases on the smoothed pallet edge, tilted
75–82°, move with the footholds). The controller weighs the planned forces
at 10⁻⁴ (a preference); what it must realise is the base motion, which
this does not make more feasible. More steps, damped, are untried.
"""

from __future__ import annotations

import weakref
from typing import TYPE_CHECKING

import casadi as ca
import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

from roughwalk.errors import PlanningError
from roughwalk.trajopt.constraints.force_between_nodes import inner_control_points
from roughwalk.trajopt.parameters import GuessProjection
from roughwalk.trajopt.variables.variable_set import NodeVariableSet

if TYPE_CHECKING:
    from roughwalk.trajopt.formulation import Formulation

__all__ = ["project_guess", "between_node_rows", "variable_scales"]

_BETWEEN: weakref.WeakKeyDictionary[Formulation, ca.Function] = weakref.WeakKeyDictionary()


def variable_scales(nlp: Formulation, settings: GuessProjection) -> NDArray[np.float64]:
    """σ (n,) of every decision variable: how far [its unit] it may move at unit cost."""
    sigma = np.empty(nlp.n_variables)
    start = 0
    for v in nlp.variable_sets:
        if v.name.startswith("base_lin"):
            pos, vel = settings.base_position_m, settings.base_velocity_m_s
        elif v.name.startswith("base_ang"):
            pos, vel = settings.base_angle_rad, settings.base_rate_rad_s
        elif v.name.startswith("foot_motion"):
            pos, vel = settings.foot_position_m, settings.foot_velocity_m_s
        elif v.name.startswith("foot_force"):
            pos, vel = settings.force_n, settings.force_rate_n_s
        else:  # phase durations [s]
            pos = vel = settings.duration_s
        if isinstance(v, NodeVariableSet):
            kinds = [places[0].kind for places in v.index]
            sigma[start : start + v.size] = [pos if k == "pos" else vel for k in kinds]
        else:
            sigma[start : start + v.size] = pos
        start += v.size
    return sigma


def _between_function(nlp: Formulation) -> ca.Function:
    """Function of x: inner control points (3, K) [N] and footholds' xy (2, K) [m] of stances."""
    if nlp in _BETWEEN:
        return _BETWEEN[nlp]
    points, footholds = [], []
    for foot, force in enumerate(nlp.forces):
        for phase in nlp.stance_phases(foot):
            xy = nlp.feet[foot].foothold(phase)[:2]
            for k in force.phase_nodes(phase)[:-1]:
                for f in inner_control_points(
                    force.node_pos[k],
                    force.node_vel[k],
                    force.node_pos[k + 1],
                    force.node_vel[k + 1],
                    force.spline.durations[k],
                ):
                    points.append(f)
                    footholds.append(xy)
    p = ca.horzcat(*points) if points else ca.SX.zeros(3, 0)
    q = ca.horzcat(*footholds) if footholds else ca.SX.zeros(2, 0)
    flat = ca.vec(p)
    fn = ca.Function(
        "between_nodes", [nlp.x], [flat, ca.jacobian(flat, nlp.x), q], ["x"], ["f", "jac", "xy"]
    )
    _BETWEEN[nlp] = fn
    return fn


def between_node_rows(
    nlp: Formulation, x: NDArray[np.float64], mu: float, f_max: float
) -> tuple[NDArray[np.float64], sp.csr_matrix, NDArray[np.float64], NDArray[np.float64]]:
    """(values, Jacobian, lower, upper) of the pyramid rows at the inner control points at ``x``.

    The rows of :func:`~roughwalk.trajopt.constraints.force.force_limit_rows`
    with the terrain's normal and tangents evaluated at ``x``'s footholds
    (held fixed: the rows are then linear in the force variables).
    """
    values, jac, xy = _between_function(nlp)(x)
    f = np.asarray(values).reshape(-1, 3)  # (K, 3), column-major vec of (3, K)
    jf = sp.csr_matrix(jac.sparse())
    k_points = f.shape[0]
    if k_points == 0:
        empty = np.zeros(0)
        return empty, sp.csr_matrix((0, nlp.n_variables)), empty, empty
    terrain = nlp.terrain.evaluate(np.asarray(xy).T.reshape(-1, 2))
    hx, hy = terrain[:, 1], terrain[:, 2]
    n = np.column_stack([-hx, -hy, np.ones(k_points)])
    t1 = np.column_stack([np.ones(k_points), np.zeros(k_points), hx])
    t2 = np.column_stack([np.zeros(k_points), np.ones(k_points), hy])
    n, t1, t2 = (a / np.linalg.norm(a, axis=1, keepdims=True) for a in (n, t1, t2))
    directions = np.stack([n, t1 - mu * n, t1 + mu * n, t2 - mu * n, t2 + mu * n], axis=1)
    inf = np.inf
    lower = np.tile([0.0, -inf, 0.0, -inf, 0.0], k_points)
    upper = np.tile([f_max, 0.0, inf, 0.0, inf], k_points)
    # Row (k, r) = directions[k, r] · f_k; f_k's three rows of jf are 3k..3k+2.
    d = sp.block_diag([directions[k] for k in range(k_points)], format="csr")
    return (d @ f.ravel()), d @ jf, lower, upper


def project_guess(
    nlp: Formulation, x0: NDArray[np.float64], p: NDArray[np.float64], settings: GuessProjection
) -> NDArray[np.float64]:
    """``x0`` moved onto the linearised rows of ``nlp`` (and the between-node pyramid), see above.

    ``p`` is the task's parameter vector. Returns ``x0`` itself when
    ``settings.steps`` is 0; raises :class:`PlanningError` when the QP solver fails.
    """
    from qpsolvers import solve_qp

    x0 = np.asarray(x0, dtype=float)
    if settings.steps == 0:
        return x0
    sigma = variable_scales(nlp, settings)
    x = np.clip(x0, nlp.lbx, nlp.ubx)
    n = x.size
    for _ in range(settings.steps):
        g_dm, jac_dm = nlp.jac_g(x, p)
        g = np.asarray(g_dm).ravel()
        jac = sp.csr_matrix(jac_dm.sparse())
        lbg, ubg = np.asarray(nlp.lbg, dtype=float), np.asarray(nlp.ubg, dtype=float)
        if settings.between_nodes:
            bg, bj, bl, bu = between_node_rows(nlp, x, nlp.body.friction, nlp.body.force_limit)
            g = np.concatenate([g, bg])
            jac = sp.vstack([jac, bj], format="csr")
            lbg, ubg = np.concatenate([lbg, bl]), np.concatenate([ubg, bu])
        # Row j in step units: divide by its gradient's σ-weighted norm.
        norms = np.sqrt(np.asarray(jac.multiply(jac) @ (sigma**2)).ravel())
        live = norms > 1e-12
        slices = nlp.row_slices()
        for name in settings.left_out:
            if name not in slices:
                raise PlanningError(
                    f"guess_projection.left_out names {name!r}, not a constraint of this NLP; "
                    f"its constraints: {', '.join(slices)}"
                )
            live[slices[name]] = False
        scale = np.where(live, 1.0 / np.where(live, norms, 1.0), 0.0)
        a = sp.diags(scale) @ jac @ sp.diags(sigma)  # in u = (x − xₖ)/σ
        with np.errstate(invalid="ignore"):  # ±inf bounds of rows without a gradient
            lo = np.where(live, (lbg - g) * scale, -np.inf)
            hi = np.where(live, (ubg - g) * scale, np.inf)
        m = a.shape[0]
        # Variables z = (u, s): rows a u + s within [lo, hi]; cost ½|u − u₀|² + ½ρ|s|².
        # Only finite bounds become rows: proxqp scales badly with "infinite" ones.
        u0 = (x0 - x) / sigma
        rows = sp.hstack([a, sp.identity(m)], format="csr")
        eq = np.isfinite(lo) & np.isfinite(hi) & np.isclose(lo, hi)
        upper_rows = ~eq & np.isfinite(hi)
        lower_rows = ~eq & np.isfinite(lo)
        box = sp.hstack([sp.identity(n), sp.csr_matrix((n, m))], format="csr")
        x_lo, x_hi = (nlp.lbx - x) / sigma, (nlp.ubx - x) / sigma
        x_upper, x_lower = np.isfinite(x_hi), np.isfinite(x_lo)
        g_ineq = sp.vstack(
            [rows[upper_rows], -rows[lower_rows], box[x_upper], -box[x_lower]], format="csc"
        )
        h_ineq = np.concatenate([hi[upper_rows], -lo[lower_rows], x_hi[x_upper], -x_lo[x_lower]])
        pmat = sp.diags(np.concatenate([np.ones(n), np.full(m, settings.row_weight)]), format="csc")
        q = np.concatenate([-u0, np.zeros(m)])
        z = solve_qp(
            pmat,
            q,
            g_ineq,
            h_ineq,
            rows[eq].tocsc(),
            lo[eq],
            solver="proxqp",
            eps_abs=settings.tolerance,
        )
        if z is None:
            raise PlanningError("the guess projection's QP failed (proxqp found no solution)")
        x = np.clip(x + sigma * z[:n], nlp.lbx, nlp.ubx)
    return x
