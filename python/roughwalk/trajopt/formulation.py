"""The NLP, gathered from its parts (TOWR's ``NlpFormulation``).

:class:`Formulation` only gathers: it makes the variable sets (TOWR's order
and layout: base linear, base angular, foot motions, foot forces, phase
durations), asks every constraint named in the config for its rows and every
cost for its term, and assembles them into a CasADi NLP whose parameter
vector p is the task. The parts read what they need through the methods
here (spline points, sample times, terrain queries, task symbols).

Terrain heights are B-splines, which CasADi evaluates only in MX, while the
rest is far cheaper in SX. Parts therefore ask :meth:`Formulation.terrain_at`
for a point's terrain values and receive placeholder symbols; assembly then
composes, in MX, the SX function of the query points, the mapped terrain
function and the SX function of costs and constraints.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import casadi as ca
import numpy as np
from numpy.typing import ArrayLike, NDArray

from roughwalk.errors import InvalidArgumentError
from roughwalk.trajopt.compiled_nlp import CompiledNlp
from roughwalk.trajopt.constraints import Rows, make_constraint
from roughwalk.trajopt.costs import CostTerm, make_costs
from roughwalk.trajopt.gaits import ContactSchedule
from roughwalk.trajopt.parameters import TrajoptConfig
from roughwalk.trajopt.point_jacobian import points_jacobian
from roughwalk.trajopt.robot_model import SingleRigidBody
from roughwalk.trajopt.task import TASK_SIZE
from roughwalk.trajopt.terrain_model import TerrainModel
from roughwalk.trajopt.variables import (
    BaseAngular,
    BaseLinear,
    FootForce,
    FootMotion,
    PhaseDurations,
    VariableSet,
    base_poly_durations,
)
from roughwalk.trajopt.variables.spline import PickCall

__all__ = ["Formulation", "TaskSymbols"]

_ROWS_PER_BLOCK = 6  # constraint rows differentiated together (one dynamics sample)


@dataclass(frozen=True)
class TaskSymbols:
    """The task's slices of the parameter vector p (see :meth:`ResolvedTask.vector`)."""

    start_position: ca.SX
    start_euler: ca.SX
    start_feet: list[ca.SX]
    goal_xy: ca.SX
    goal_euler: ca.SX
    goal_z: ca.SX

    @classmethod
    def of(cls, p: ca.SX) -> TaskSymbols:
        """Slice p."""
        return cls(
            p[0:3],
            p[3:6],
            [p[6 + 3 * f : 9 + 3 * f] for f in range(4)],
            p[18:20],
            p[20:23],
            p[23],
        )


def _balanced_sum(terms: list[ca.SX]) -> ca.SX:
    """Sum sparse matrices pairwise, so that merging sparsity patterns stays cheap."""
    while len(terms) > 1:
        terms = [
            terms[i] + terms[i + 1] if i + 1 < len(terms) else terms[i]
            for i in range(0, len(terms), 2)
        ]
    return terms[0]


def _chunk_hessians(expr: ca.SX, weights: ca.SX, z: ca.SX, rows_per_block: int) -> list[ca.SX]:
    """∇²_z (λᵀ g) of every block of rows of ``expr`` that is not linear in z."""
    blocks = []
    for start in range(0, int(expr.numel()), rows_per_block):
        stop = min(start + rows_per_block, int(expr.numel()))
        chunk = expr[start:stop]
        # Linear rows (start, goal, apex, most bounds) have no curvature.
        if any(ca.which_depends(chunk, z, 2, True)):
            blocks.append(ca.triu(ca.hessian(ca.dot(weights[start:stop], chunk), z)[0]))
    return blocks


def _column(value: ca.SX) -> ca.SX:
    """``value`` as a column: itself when it is one.

    ca.vec copies even a column, ~24 µs a call; the flat trot's call rows
    make 1,600 of them.
    """
    return value if value.size2() == 1 else ca.vec(value)


def _call_jacobian(
    rows: Rows, z: ca.SX, affine: bool, picked: Mapping[int, tuple[PickCall, int]] | None = None
) -> ca.SX | None:
    """∂g/∂z of rows made of calls g = F(u) of one function F, by the chain rule.

    blockdiag(∂F/∂u mapped over the calls) · ∂u/∂z, projected onto the
    rows' own sparsity so that IPOPT sees the same structure as from
    differentiating the rows. ∂u/∂z is constant when the points are
    ``affine`` in z (fixed durations): about a third of the CPU of the row
    blocks' Jacobians. Otherwise (optimised durations) it is
    :func:`points_jacobian`: the ``picked`` samples' own Jacobians, the
    other points differentiated once each. None when the calls mix
    functions or u was expected affine and is not.
    """
    calls = rows.calls or []
    if not calls or any(call.function is not calls[0].function for call in calls):
        return None
    fn = calls[0].function
    points = ca.horzcat(*[ca.vertcat(*map(_column, call.inputs)) for call in calls])
    a: ca.DM | ca.SX
    if affine:
        constant = ca.jacobian(ca.vec(points), z)
        if not constant.is_constant():
            return None
        a = ca.DM(constant)
    else:
        a = points_jacobian(ca.vec(points), z, picked)
    symbols = [ca.SX.sym(f"u{i}", fn.sparsity_in(i)) for i in range(fn.n_in())]
    flat = ca.vertcat(*[ca.vec(v) for v in symbols])
    local = ca.Function(f"{fn.name()}_jacobian", [flat], [ca.jacobian(ca.vec(fn(*symbols)), flat)])
    diagonal = ca.diagcat(*ca.horzsplit(local.map(len(calls))(points), int(flat.numel())))
    return ca.project(diagonal @ a, ca.jacobian_sparsity(rows.expr, z))


def _call_hessians(
    rows: Rows,
    weights: ca.SX,
    z: ca.SX,
    affine: list[tuple[ca.DM, ca.SX]] | None = None,
    curved_points: bool = False,
    picked: Mapping[int, tuple[PickCall, int]] | None = None,
) -> tuple[list[ca.SX], list[tuple[ca.SX, ca.SX]]]:
    """∇²_z (λᵀ g) of rows made of calls g = F(u(z)), by the chain rule.

    ∇²_z = Jᵀ ∇²ᵤ(λᵀF) J + Σⱼ μⱼ ∇²_z uⱼ with J = ∂u/∂z and μ = ∇ᵤ(λᵀF):
    F's own small Hessian, mapped, plus the curvature of the spline points
    u, which is zero when they are affine in z (fixed durations) and
    otherwise a far smaller graph to differentiate twice than F∘u. Returns
    the blocks Jᵀ ∇²ᵤ(λᵀF) J and, for points that are not affine, the pairs
    (u, μ): the caller adds Σⱼ μⱼ ∇²uⱼ for all rows at once.

    All calls of one function are handled at once: one mapped local
    Hessian, one block-diagonal product Jᵀ D J (which also sums the calls'
    overlapping blocks) and one Jacobian of all their points. Per call, the
    same products cost about twice the CPU to build (Python loops and
    hundreds of small Jacobians and sums).

    With a list ``affine``, groups whose points are affine (J constant)
    append (J, D) to it instead of a block: :func:`_merged_product` then
    forms one product for the calls of all rows. With ``curved_points``
    (optimised durations) J is :func:`points_jacobian`, each distinct point
    differentiated once.
    """
    calls = rows.calls or []
    groups: dict[int, tuple[ca.Function, list[tuple[int, int]]]] = {}
    start = 0
    for k, call in enumerate(calls):
        groups.setdefault(id(call.function), (call.function, []))[1].append((k, start))
        start += int(call.function.numel_out(0))
    blocks = []
    curved = []
    for fn, members in groups.values():
        n_rows = int(fn.numel_out(0))
        symbols = [ca.SX.sym(f"u{i}", fn.sparsity_in(i)) for i in range(fn.n_in())]
        flat = ca.vertcat(*[ca.vec(v) for v in symbols])
        lam = ca.SX.sym("lam", n_rows)
        hess, grad = ca.hessian(ca.dot(lam, ca.vec(fn(*symbols))), flat)
        local = ca.Function(f"{fn.name()}_hessian", [flat, lam], [hess, grad])
        points = ca.horzcat(*[ca.vertcat(*map(_column, calls[k].inputs)) for k, _ in members])
        row_weights = ca.horzcat(*[weights[s : s + n_rows] for _, s in members])
        h_u, mu = local.map(len(members))(points, row_weights)
        diagonal = ca.diagcat(*ca.horzsplit(h_u, int(flat.numel())))
        u = ca.vec(points)
        jac = points_jacobian(u, z, picked) if curved_points else ca.jacobian(u, z)
        if jac.is_constant() and affine is not None:
            affine.append((ca.DM(jac), diagonal))
        elif jac.is_constant():
            a = ca.DM(jac)
            blocks.append(ca.triu(a.T @ (diagonal @ a)))
        else:
            blocks.append(ca.triu(jac.T @ (diagonal @ jac)))
            curved.append((u, ca.vec(mu)))
    return blocks, curved


def _merged_product(pairs: list[tuple[ca.DM, ca.SX]]) -> ca.SX:
    """triu(Σ Jᵀ D J) over the (J, D) of affine call groups, equal rows of J merged.

    Calls at one sample share spline points: the base's position and angles
    enter every foot's range-of-motion and leg-reach call, and both
    constraints sample the same times. A point's row of J appears once per
    call that reads it; merging equal rows first (D's rows and columns summed
    by a 0/1 matrix P, D' = Pᵀ D P) leaves the product Jᵤᵀ D' Jᵤ over
    distinct rows only. Rows of J that are zero (constant inputs) drop out.
    """
    a = ca.vertcat(*[j for j, _ in pairs])
    d = ca.diagcat(*[block for _, block in pairs])
    csr = a.sparse().tocsr()
    first: dict[tuple[bytes, bytes], int] = {}
    rows: list[int] = []
    cols: list[int] = []
    keep: list[int] = []
    for r in range(csr.shape[0]):
        lo, hi = csr.indptr[r], csr.indptr[r + 1]
        if lo == hi:
            continue
        key = (csr.indices[lo:hi].tobytes(), csr.data[lo:hi].tobytes())
        if key not in first:
            first[key] = len(keep)
            keep.append(r)
        rows.append(r)
        cols.append(first[key])
    select = ca.DM(ca.Sparsity.triplet(a.size1(), len(keep), rows, cols), 1.0)
    merged = select.T @ (d @ select)
    a_unique = a[keep, :]
    return ca.triu(a_unique.T @ (merged @ a_unique))


class Formulation:
    """The NLP of one (body, contact schedule, duration, terrain, config).

    Parameters
    ----------
    config:
        Which constraints and costs, discretisation, bounds.
    body:
        The single rigid body.
    schedule:
        The contact schedule (its total duration is T).
    terrain:
        The smooth terrain.
    compiled:
        The NLP's functions loaded from the cache (:mod:`.compiled_nlp`):
        then no constraint or cost expression is built, only the variables.

    """

    def __init__(
        self,
        config: TrajoptConfig,
        body: SingleRigidBody,
        schedule: ContactSchedule,
        terrain: TerrainModel,
        compiled: CompiledNlp | None = None,
    ) -> None:
        if config.optimize_durations and not config.phase_bounds_admit_gait:
            # Optimised durations start inside their bounds (see ContactSchedule.fitted);
            # bounds that admit the gait hold its own schedule already.
            schedule = schedule.fitted(config.phase_duration_bounds)
        self.config = config
        self.body = body
        self.schedule = schedule
        self.terrain = terrain
        self.total_duration = schedule.total_duration
        if self.total_duration <= 0:
            raise InvalidArgumentError(f"duration must be > 0 s, got {self.total_duration}")

        base_durations = base_poly_durations(self.total_duration, config.base_poly_duration)
        self.base_lin = BaseLinear(base_durations)
        self.base_ang = BaseAngular(base_durations)
        self.durations = [
            PhaseDurations(
                f,
                schedule.durations[f],
                config.phase_duration_bounds,
                config.optimize_durations,
                admit_nominal=config.phase_bounds_admit_gait,
            )
            for f in range(schedule.n_feet)
        ]
        self.feet = [
            FootMotion(
                f, schedule.in_contact_at_start[f], config.foot_polys_per_swing, self.durations[f]
            )
            for f in range(schedule.n_feet)
        ]
        self.forces = [
            FootForce(
                f, schedule.in_contact_at_start[f], config.force_polys_per_stance, self.durations[f]
            )
            for f in range(schedule.n_feet)
        ]
        # TOWR's order: base linear, base angular, motions, forces, schedules.
        self.variable_sets: list[VariableSet] = [
            self.base_lin,
            self.base_ang,
            *self.feet,
            *self.forces,
            *self.durations,
        ]
        self.x = ca.vertcat(*[v.symbols for v in self.variable_sets])
        self.p = ca.SX.sym("task", TASK_SIZE)
        self.task = TaskSymbols.of(self.p)

        self._query_keys: dict[str, int] = {}
        self._query_xy: list[ca.SX] = []
        self._query_symbols: list[ca.SX] = []

        self.rows: list[Rows] = []
        self.costs: list[CostTerm] = []
        self.nlp: dict[str, Any] | ca.Function
        self._hess_lag: ca.Function | None = None
        self.lbx = np.concatenate([v.lower for v in self.variable_sets])
        self.ubx = np.concatenate([v.upper for v in self.variable_sets])
        if compiled is not None:
            self._load(compiled)
            return
        for name in config.constraints:
            rows = make_constraint(name).build(self)
            if rows is not None and rows.size:
                self.rows.append(rows)
        self.costs = [c for c in make_costs(self) if c is not None]
        self.row_layout = [(r.name, r.size) for r in self.rows]
        self.cost_names = [c.name for c in self.costs]
        self._assemble()

    def _load(self, compiled: CompiledNlp) -> None:
        """Take the NLP's functions and row layout from the compiled library."""
        if compiled.n_variables != self.n_variables:
            raise InvalidArgumentError(
                f"the compiled NLP has {compiled.n_variables} variables, "
                f"this layout {self.n_variables}"
            )
        self.row_layout = list(compiled.row_layout)
        self.cost_names = list(compiled.cost_names)
        self.lbg, self.ubg = compiled.lbg, compiled.ubg
        f = compiled.functions
        self.nlp = f["nlp"]
        self.evaluator = f["evaluate"]
        self.jac_g = f["nlp_jac_g"]
        self.grad_f = f["nlp_grad_f"]
        self._hess_lag = f.get("nlp_hess_l")

    def functions(self, hessian: bool) -> dict[str, ca.Function]:
        """The functions IPOPT and the results call, by name, for :mod:`.compiled_nlp`."""
        nlp = self.nlp
        if isinstance(nlp, ca.Function):
            raise InvalidArgumentError("this NLP was loaded compiled; it has no expressions")
        out = {
            "nlp": ca.Function(
                "nlp", [nlp["x"], nlp["p"]], [nlp["f"], nlp["g"]], ["x", "p"], ["f", "g"]
            ),
            "nlp_jac_g": self.jac_g,
            "nlp_grad_f": self.grad_f,
            "evaluate": self.evaluator,
        }
        if hessian:
            out["nlp_hess_l"] = self.hess_lag
        return out

    def layout(self) -> dict[str, Any]:
        """Constraint bounds, row layout and cost names, for :mod:`.compiled_nlp`."""
        return {
            "lbg": self.lbg,
            "ubg": self.ubg,
            "row_layout": self.row_layout,
            "cost_names": self.cost_names,
            "n_variables": self.n_variables,
        }

    # ------------------------------------------------------------------ parts' API
    @property
    def picked(self) -> dict[int, tuple[PickCall, int]]:
        """The feet's and forces' picked samples, by element hash (see :func:`points_jacobian`)."""
        out: dict[int, tuple[PickCall, int]] = {}
        for nodes in (*self.feet, *self.forces):
            out.update(nodes.spline.picked)
        return out

    @property
    def n_variables(self) -> int:
        """Number of decision variables."""
        return int(self.x.numel())

    @property
    def n_constraints(self) -> int:
        """Number of constraint rows."""
        return int(sum(size for _, size in self.row_layout))

    @property
    def n_feet(self) -> int:
        """Number of feet (4)."""
        return self.schedule.n_feet

    def sample_times(self, dt: float) -> list[float]:
        """0, dt, 2·dt, ... and T itself [s], without a repeat at T."""
        t_total = self.total_duration
        times = list(np.arange(0.0, t_total, dt))
        if times and t_total - times[-1] < 1e-6:
            times.pop()
        return [float(t) for t in times] + [t_total]

    def terrain_at(self, key: str, xy: ca.SX) -> ca.SX:
        """Terrain (h [m], ∂h/∂x, ∂h/∂y, edge cost) (4, 1) at ``xy`` (2, 1).

        ``key`` names the point, so that parts asking for the same point share one query.
        """
        if self.terrain.flat:
            return ca.SX(ca.DM([self.terrain.flat_height, 0.0, 0.0, 0.0]))
        if key not in self._query_keys:
            self._query_keys[key] = len(self._query_xy)
            self._query_xy.append(ca.SX(xy))
            self._query_symbols.append(ca.SX.sym(f"terrain_{len(self._query_xy)}", 4))
        return self._query_symbols[self._query_keys[key]]

    def foothold_terrain(self, foot: int, phase: int) -> ca.SX:
        """Terrain values at the foothold of ``foot``'s stance ``phase``."""
        return self.terrain_at(f"foothold/{foot}/{phase}", self.feet[foot].foothold(phase)[:2])

    def stance_phases(self, foot: int) -> list[int]:
        """Indices of ``foot``'s stance phases."""
        return [k for k, s in enumerate(self.feet[foot].stance_phases) if s]

    def swing_phases(self, foot: int) -> list[int]:
        """Indices of ``foot``'s swing phases."""
        return [k for k, s in enumerate(self.feet[foot].stance_phases) if not s]

    def fixed_foothold(self, foot: int, phase: int) -> bool:
        """Whether the foothold of stance ``phase`` is the start foothold (fixed by the task)."""
        return phase == 0 and self.schedule.in_contact_at_start[foot]

    # ------------------------------------------------------------------ assembly
    def _assemble(self) -> None:
        """Build the NLP functions: values, and first derivatives row block by row block.

        CasADi's Jacobian of the whole g colours its columns or rows; with
        optimised durations every dynamics row touches most foot variables, so
        that takes hundreds of sweeps over the whole graph. Differentiating a
        few rows at a time in reverse mode costs a few sweeps of their own
        small graphs instead, and the blocks are stacked into the Jacobian IPOPT
        gets (``jac_g``). Terrain values enter as extra inputs whose chain rule
        is applied in MX.
        """
        g = ca.vertcat(*[r.expr for r in self.rows]) if self.rows else ca.SX(0, 1)
        cost_vector = (
            ca.vertcat(*[ca.SX(c.expr) for c in self.costs]) if self.costs else ca.SX(0, 1)
        )
        f = ca.sum1(cost_vector) if self.costs else ca.SX(0)
        self.lbg = np.concatenate([r.lower for r in self.rows]) if self.rows else np.zeros(0)
        self.ubg = np.concatenate([r.upper for r in self.rows]) if self.rows else np.zeros(0)

        tq = ca.vertcat(*self._query_symbols) if self._query_symbols else ca.SX(0, 1)
        z = ca.vertcat(self.x, tq)
        nx = self.n_variables
        jac_blocks = []
        durations = (
            ca.vertcat(*[d.symbols for d in self.durations])
            if self.config.optimize_durations
            else None
        )
        # With optimised durations the points are not affine (the check alone
        # would cost more than the chain rule through each distinct point).
        affine = not self.config.optimize_durations
        picked = self.picked
        for rows in self.rows:
            call_jacobian = (
                _call_jacobian(rows, z, affine, picked) if rows.calls is not None else None
            )
            if call_jacobian is not None:
                jac_blocks.append(call_jacobian)
                continue
            if durations is None or not ca.depends_on(rows.expr, durations):
                # Rows that do not pick among polynomials are differentiated at
                # once: on the flat walk 0.6 ms for the force rows, 11 ms in
                # blocks of six.
                jac_blocks.append(ca.jacobian(rows.expr, z))
                continue
            for start in range(0, rows.size, _ROWS_PER_BLOCK):
                chunk = rows.expr[start : min(start + _ROWS_PER_BLOCK, rows.size)]
                jac_blocks.append(ca.jacobian(chunk, z))
        jac_z = ca.vertcat(*jac_blocks) if jac_blocks else ca.SX(0, z.numel())
        grad_z = ca.gradient(f, z)
        inputs = [self.x, self.p, tq]
        values = ca.Function("nlp_values", inputs, [f, g, cost_vector])
        jac = ca.Function("nlp_jac_parts", inputs, [g, jac_z[:, :nx], jac_z[:, nx:]])
        grad = ca.Function("nlp_grad_parts", inputs, [f, grad_z[:nx], grad_z[nx:]])

        x_mx = ca.MX.sym("x", nx)
        p_mx = ca.MX.sym("p", TASK_SIZE)
        if self._query_xy:
            queries = ca.Function(
                "terrain_queries", [self.x, self.p], [ca.horzcat(*self._query_xy)]
            )
            t_mx = ca.vec(self.terrain.mapped(len(self._query_xy))(queries(x_mx, p_mx)))
            dt_dx = ca.jacobian(t_mx, x_mx)
        else:
            t_mx = ca.MX(0, 1)
            dt_dx = ca.MX(0, nx)
        f_mx, g_mx, c_mx = values(x_mx, p_mx, t_mx)
        g_j, jx, jt = jac(x_mx, p_mx, t_mx)
        f_g, gx, gt = grad(x_mx, p_mx, t_mx)
        # IPOPT asks for f and g apart, and an SX function computes all its outputs:
        # from ``values`` each would cost both (f alone is a tenth of the work).
        objective = ca.Function("nlp_objective", inputs, [f])
        constraints = ca.Function("nlp_constraints", inputs, [g])
        self.nlp = {
            "x": x_mx,
            "p": p_mx,
            # Dense: a cost-free problem (TOWR's) still has a number for f.
            "f": ca.densify(objective(x_mx, p_mx, t_mx)),
            "g": constraints(x_mx, p_mx, t_mx),
        }
        self.evaluator = ca.Function("evaluate", [x_mx, p_mx], [f_mx, g_mx, c_mx])
        self.jac_g = ca.Function(
            "nlp_jac_g", [x_mx, p_mx], [g_j, jx + jt @ dt_dx], ["x", "p"], ["g", "jac_g_x"]
        )
        # IPOPT reads dense buffers: a structurally empty objective must still be a number.
        self.grad_f = ca.Function(
            "nlp_grad_f",
            [x_mx, p_mx],
            [ca.densify(f_g), ca.densify(gx + dt_dx.T @ gt)],
            ["x", "p"],
            ["f", "grad_f_x"],
        )
        self._mx = (x_mx, p_mx, t_mx, dt_dx, tq, g, f)

    @property
    def hess_lag(self) -> ca.Function:
        """IPOPT's Hessian of the Lagrangian (upper triangle), built on first use.

        Block by block like the Jacobian: the Hessian of λ_bᵀ g_b for every row
        block b and of every cost term, summed; terrain values contribute
        through the chain rule, their own curvature included.

        Every block keeps only its upper triangle, the part IPOPT reads: an
        SX function evaluates only the entries its outputs use, so the lower
        ones are never computed (on the learned single-pallet problem 1.06 M
        instead of 1.46 M instructions, 6.5 instead of 8.4 ms an evaluation,
        the same values). The affine call groups of all rows share one
        product with the points' equal rows merged (:func:`_merged_product`):
        0.81 M instructions.
        """
        if self._hess_lag is None:
            self._hess_lag = self._build_hessian()
        return self._hess_lag

    def _build_hessian(self) -> ca.Function:
        x_mx, p_mx, t_mx, dt_dx, tq, g, f = self._mx
        z = ca.vertcat(self.x, tq)
        nx = self.n_variables
        ng = int(g.numel())
        lam_g = ca.SX.sym("lam_g", ng)
        lam_f = ca.SX.sym("lam_f")
        blocks = []
        curved: list[tuple[ca.SX, ca.SX]] = []
        affine: list[tuple[ca.DM, ca.SX]] = []
        picked = self.picked
        offset = 0
        for rows in self.rows:
            weights = lam_g[offset : offset + rows.size]
            if rows.calls is not None:
                call_blocks, call_curved = _call_hessians(
                    rows, weights, z, affine, self.config.optimize_durations, picked
                )
                blocks.extend(call_blocks)
                curved.extend(call_curved)
            else:
                blocks.extend(_chunk_hessians(rows.expr, weights, z, _ROWS_PER_BLOCK))
            offset += rows.size
        if affine:
            blocks.append(_merged_product(affine))
        for cost in self.costs:
            blocks.append(ca.triu(lam_f * ca.hessian(ca.SX(cost.expr), z)[0]))
        hess_z = _balanced_sum(blocks) if blocks else ca.SX(z.numel(), z.numel())
        # ∂L/∂t: how much the Lagrangian feels each terrain value.
        mu = ca.gradient(lam_f * f + ca.dot(lam_g, g), tq)
        # The spline points' curvature Σⱼ μⱼ ∇²ₓ uⱼ, μ = ∇ᵤ(λᵀF) held fixed, is a
        # function of its own fed with μ in MX: substituting μ into the SX
        # Hessian cost as much CPU as building it.
        points = ca.vertcat(*[u for u, _ in curved]) if curved else ca.SX(0, 1)
        points_mu = ca.vertcat(*[m for _, m in curved]) if curved else ca.SX(0, 1)
        parts = ca.Function(
            "nlp_hess_parts",
            [self.x, self.p, tq, lam_f, lam_g],
            [hess_z[:nx, :nx], hess_z[:nx, nx:], hess_z[nx:, nx:], mu, points_mu],
        )
        lam_f_mx = ca.MX.sym("lam_f")
        lam_g_mx = ca.MX.sym("lam_g", ng)
        h_xx, h_xt, h_tt, mu_mx, points_mu_mx = parts(x_mx, p_mx, t_mx, lam_f_mx, lam_g_mx)
        hessian = h_xx
        if curved:
            m = ca.SX.sym("mu_points", points.numel())
            points_curvature = ca.Function(
                "spline_point_curvature",
                [self.x, self.p, m],
                [ca.triu(ca.hessian(ca.dot(m, points), self.x)[0])],
            )
            hessian = hessian + points_curvature(x_mx, p_mx, points_mu_mx)
        if self._query_xy:
            # Σⱼ μⱼ ∇²ₓ tⱼ(x): the terrain's own curvature, μ held fixed.
            mu_sym = ca.MX.sym("mu", t_mx.numel())
            curvature = ca.Function(
                "terrain_curvature",
                [x_mx, p_mx, mu_sym],
                [ca.hessian(ca.dot(mu_sym, t_mx), x_mx)[0]],
            )
            cross = h_xt @ dt_dx
            hessian = (
                hessian
                + cross
                + cross.T
                + dt_dx.T @ ca.triu2symm(h_tt) @ dt_dx
                + curvature(x_mx, p_mx, mu_mx)
            )
        return ca.Function(
            "nlp_hess_l",
            [x_mx, p_mx, lam_f_mx, lam_g_mx],
            [ca.triu(hessian)],
            ["x", "p", "lam_f", "lam_g"],
            ["hess_gamma_x_x"],
        )

    # ------------------------------------------------------------------ numbers
    def split(self, x: ArrayLike) -> dict[str, NDArray[np.float64]]:
        """A solution vector cut into its variable sets, by name."""
        values = np.asarray(x, dtype=float).ravel()
        out, start = {}, 0
        for v in self.variable_sets:
            out[v.name] = values[start : start + v.size]
            start += v.size
        return out

    def join(self, parts: Mapping[str, ArrayLike]) -> NDArray[np.float64]:
        """A solution vector from per-set values (every set must be given)."""
        missing = [v.name for v in self.variable_sets if v.name not in parts]
        if missing:
            raise InvalidArgumentError(f"initial guess lacks the variable sets {missing}")
        chunks = []
        for v in self.variable_sets:
            chunk = np.asarray(parts[v.name], dtype=float).ravel()
            if chunk.size != v.size:
                raise InvalidArgumentError(
                    f"initial guess for '{v.name}' has {chunk.size} values, expected {v.size}"
                )
            chunks.append(chunk)
        return np.concatenate(chunks) if chunks else np.zeros(0)

    def row_slices(self) -> dict[str, slice]:
        """Where each constraint's rows sit in g."""
        out, start = {}, 0
        for name, size in self.row_layout:
            out[name] = slice(start, start + size)
            start += size
        return out
