"""Splines of cubic Hermite polynomials, symbolic (for the NLP) and numeric (for results).

A spline joins nodes k and k+1 with polynomial k of duration d_k. In the NLP
the node values are CasADi expressions of the decision variables and, when
phase durations are optimised, so are the d_k: the polynomial that holds a
given time then depends on the variables. As TOWR does, the spline evaluates
the polynomial that holds t at the current durations and differentiates
through the rest; with CasADi this is a sum of the candidate polynomials, each
switched on by a comparison that AD treats as constant. Such a sample also
carries its Jacobian (:class:`PickCall`), which the formulation uses instead
of differentiating the sample's graph.
"""

from __future__ import annotations

import functools
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, cast

import casadi as ca
import numpy as np
from numpy.typing import ArrayLike, NDArray

from roughwalk.trajopt.variables.hermite import hermite_point

__all__ = ["NodeSpline", "NumericSpline", "PickCall", "sample_points"]

_EPS = 1e-9  # [s] tolerance of time comparisons against numeric junctions


@functools.cache
def _hermite_function(dim: int) -> ca.Function:
    """Return hermite_point as an SX function of dimension ``dim``.

    Calling it inlines the expressions in C++, which builds large NLPs much
    faster than Python-level arithmetic on symbols.
    """
    x0, v0, x1, v1 = (ca.SX.sym(n, dim) for n in ("x0", "v0", "x1", "v1"))
    d, s = ca.SX.sym("d"), ca.SX.sym("s")
    return ca.Function("hermite", [x0, v0, x1, v1, d, s], list(hermite_point(x0, v0, x1, v1, d, s)))


@functools.cache
def _pick_function(dim: int, n: int) -> ca.Function:
    """Evaluate, at global time t, whichever of n candidate polynomials holds t.

    Inputs: t, lo (n), hi (n), q: the candidates' starts (n), durations (n),
    then x0, v0, x1, v1 (dim × n each, column by column). Candidate k holds
    t when lo_k < t ≤ hi_k (lo = start and hi = start + duration, except
    that the spline's first polynomial also holds t = 0 and its last one any
    t past its start). Outputs: position, velocity and acceleration (dim,
    1), and ∂position/∂q (dim × len q).

    The Jacobian is the Hermite polynomial's own (of the picked node
    values, duration and start) times the candidates' on/off switches,
    which AD treats as constant: one product per nonzero. CasADi's AD of
    the samples' graphs took ~11 instructions a nonzero (271k for the
    dynamics' and range of motion's points on the optimised-durations
    walk). With one candidate (n = 1) lo and hi are not read: the
    polynomial holds t for every admissible duration.
    """
    t = ca.SX.sym("t")
    lo, hi = ca.SX.sym("lo", n), ca.SX.sym("hi", n)
    q = ca.SX.sym("q", n * (2 + 4 * dim))
    starts, durations = q[:n], q[n : 2 * n]
    nodes = ca.reshape(q[2 * n :], dim, 4 * n)
    x0, v0, x1, v1 = (nodes[:, i * n : (i + 1) * n] for i in range(4))
    if n == 1:
        pos, vel, acc, jac_h = _hermite_with_jacobian(dim)(x0, v0, x1, v1, durations, starts, t)
        # jac_h's columns (x0, v0, x1, v1, d, start) in q's order (start, d, x0, v0, x1, v1).
        size = 4 * dim + 2
        to_q = [*range(2, size), 1, 0]
        order = ca.DM(ca.Sparsity.triplet(size, size, list(range(size)), to_q), 1)
        return ca.Function("pick_polynomial", [t, lo, hi, q], [pos, vel, acc, jac_h @ order])
    # Matrix operations, not a loop over candidates: the same scalar
    # operations (sums of one active candidate and exact zeros, so their
    # order does not matter) in under half the CPU to build the function.
    switches = ca.logic_and(lo < t, t <= hi).T
    picked = [
        ca.sum2(ca.if_else(ca.repmat(switches, int(m.size1()), 1), m, 0))
        for m in (x0, v0, x1, v1, durations.T, starts.T)
    ]
    # Only an iterate far outside the duration bounds activates nothing; a
    # unit duration then keeps the expressions finite.
    duration = picked[4] + (1 - ca.sum2(switches))
    pos, vel, acc, jac_h = _hermite_with_jacobian(dim)(
        picked[0], picked[1], picked[2], picked[3], duration, picked[5], t
    )
    # ∂(x0, v0, x1, v1, d, start of the picked polynomial)/∂q: the switches.
    rows: list[int] = []
    cols: list[int] = []
    for k in range(n):
        for role in range(4):
            rows += [role * dim + i for i in range(dim)]
            cols += [2 * n + role * dim * n + k * dim + i for i in range(dim)]
        rows += [4 * dim, 4 * dim + 1]
        cols += [n + k, k]
    entries = ca.vec(ca.repmat(switches, 4 * dim + 2, 1))
    pick = ca.SX.triplet(rows, cols, entries, 4 * dim + 2, int(q.numel()))
    jac = jac_h @ pick
    return ca.Function("pick_polynomial", [t, lo, hi, q], [pos, vel, acc, jac])


@functools.cache
def _hermite_with_jacobian(dim: int) -> ca.Function:
    """hermite_point at t − start and ∂position/∂(x0, v0, x1, v1, d, start), written out.

    With u = s/d: ∂p/∂x0 = 1 − 3u² + 2u³, ∂p/∂x1 = 3u² − 2u³, ∂p/∂v0 =
    s(1 − u)², ∂p/∂v1 = s·u(u − 1), the same for every dimension;
    ∂p/∂d = 6u²(1 − u)(x0 − x1)/d + 2u²(1 − u)v0 + u²(1 − 2u)v1 and
    ∂p/∂start = −velocity. CasADi's AD of the polynomial adds 154
    instructions for these 18 entries (dim 3), the formulas 62.
    """
    x0, v0, x1, v1 = (ca.SX.sym(n, dim) for n in ("x0", "v0", "x1", "v1"))
    d, start, t = ca.SX.sym("d"), ca.SX.sym("start"), ca.SX.sym("t")
    s = t - start
    pos, vel, acc = hermite_point(x0, v0, x1, v1, d, s)
    u = s / d
    uu = u * u
    rest = 1 - u
    to_end = uu * (3 - 2 * u)
    basis = (1 - to_end, s * rest * rest, to_end, s * u * (u - 1))
    by_duration = 6 * uu * rest / d * (x0 - x1) + 2 * uu * rest * v0 + uu * (1 - 2 * u) * v1
    rows, cols, entries = [], [], []
    for i in range(dim):
        for role, value in enumerate(basis):
            rows.append(i)
            cols.append(role * dim + i)
            entries.append(value)
        rows += [i, i]
        cols += [4 * dim, 4 * dim + 1]
        entries += [by_duration[i], -vel[i]]
    jac = ca.SX.triplet(rows, cols, ca.vertcat(*entries), dim, 4 * dim + 2)
    return ca.Function("hermite_jacobian", [x0, v0, x1, v1, d, start, t], [pos, vel, acc, jac])


class NodeSpline:
    """A symbolic spline through nodes (value, derivative) with given polynomial durations.

    Parameters
    ----------
    positions, velocities:
        Per node, its value and derivative: (dim, 1) CasADi SX or numbers.
    durations:
        Per polynomial, its duration [s]: a float, or an SX when optimised.
    windows:
        Per polynomial, (earliest start, latest end) [s] over all admissible
        durations; needed only when some duration is symbolic.

    """

    def __init__(
        self,
        positions: Sequence[Any],
        velocities: Sequence[Any],
        durations: Sequence[Any],
        windows: Sequence[tuple[float, float]] | None = None,
    ) -> None:
        if len(positions) != len(durations) + 1 or len(velocities) != len(positions):
            raise ValueError("a spline needs one node more than it has polynomials")
        self.positions = [p if isinstance(p, ca.SX) else ca.SX(p) for p in positions]
        self.velocities = [v if isinstance(v, ca.SX) else ca.SX(v) for v in velocities]
        self.durations = list(durations)
        self.fixed = all(isinstance(d, int | float) for d in durations)
        self.starts: list[Any] = [0.0]
        for d in self.durations[:-1]:
            self.starts.append(self.starts[-1] + d)
        if self.fixed:
            ends = np.cumsum(np.asarray(self.durations, dtype=float))
            self._ends = ends
            self.windows = [
                (float(e - d), float(e)) for e, d in zip(ends, self.durations, strict=True)
            ]
        else:
            if windows is None:
                raise ValueError("symbolic durations need the polynomials' time windows")
            self.windows = [(float(a), float(b)) for a, b in windows]
        self.picked: dict[int, tuple[PickCall, int]] = {}
        """The position entries of picked samples (by element hash): their call and row."""

    @property
    def n_polys(self) -> int:
        """Number of polynomials."""
        return len(self.durations)

    def poly_point(self, k: int, s: Any) -> tuple[ca.SX, ca.SX, ca.SX]:
        """Position, velocity, acceleration of polynomial k at local time s [s]."""
        out = _hermite_function(int(self.positions[0].numel()))(
            self.positions[k],
            self.velocities[k],
            self.positions[k + 1],
            self.velocities[k + 1],
            self.durations[k],
            s,
        )
        return out[0], out[1], out[2]

    def poly_points(
        self, ks: Sequence[int], ss: Sequence[float]
    ) -> list[tuple[ca.SX, ca.SX, ca.SX]]:
        """:meth:`poly_point` of polynomials ``ks`` at numeric local times ``ss``, in one call.

        The same expressions as calling it point by point, from one mapped
        call: on the flat trot a third of the CPU of its 766 calls.
        """
        if not ks:
            return []
        n = len(ks)
        out = _hermite_function(int(self.positions[0].numel())).map(n)(
            ca.horzcat(*[self.positions[k] for k in ks]),
            ca.horzcat(*[self.velocities[k] for k in ks]),
            ca.horzcat(*[self.positions[k + 1] for k in ks]),
            ca.horzcat(*[self.velocities[k + 1] for k in ks]),
            ca.DM([[float(self.durations[k]) for k in ks]]),
            ca.DM([list(map(float, ss))]),
        )
        return list(zip(*(ca.horzsplit(o) for o in out), strict=True))

    def points(self, times: Sequence[float]) -> list[tuple[ca.SX, ca.SX, ca.SX]]:
        """:meth:`point` at every time of ``times`` [s], from mapped calls.

        Fixed durations: one call. Otherwise one call per number of
        candidate polynomials (:meth:`picked_points`).
        """
        if not self.fixed:
            return self.picked_points(times)
        ks = [self.poly_at(t) for t in times]
        return self.poly_points(ks, [t - self.starts[k] for t, k in zip(times, ks, strict=True)])

    def poly_at(self, t: float) -> int:
        """Index of the polynomial holding time t [s]; a junction belongs to the earlier one."""
        if not self.fixed:
            raise ValueError("poly_at needs fixed durations")
        return min(int(np.searchsorted(self._ends, t - _EPS, side="left")), self.n_polys - 1)

    def candidates(self, t: float) -> list[int]:
        """Polynomials that may hold time t [s] for some admissible durations."""
        if self.fixed:
            return [self.poly_at(t)]
        last = self.n_polys - 1
        return [
            k
            for k, (lo, hi) in enumerate(self.windows)
            if (k == 0 or lo < t + _EPS) and (k == last or t - _EPS <= hi)
        ]

    def point(self, t: float) -> tuple[ca.SX, ca.SX, ca.SX]:
        """Position, velocity, acceleration at global time t [s]."""
        ks = self.candidates(t)
        if self.fixed:
            k = ks[0]
            return self.poly_point(k, t - self.starts[k])
        # Select the active polynomial's node values and timing, then evaluate
        # one polynomial: far smaller expressions (and derivatives) than
        # switching between evaluated candidates.
        dim, n, last = int(self.positions[0].numel()), len(ks), self.n_polys - 1
        lo = [-np.inf if k == 0 or n == 1 else self.starts[k] for k in ks]
        hi = [np.inf if k == last or n == 1 else self.ends[k] for k in ks]
        index = self._pick_index(ks)
        pos, vel, acc, jac = _pick_function(dim, n)(
            t, ca.vertcat(*lo), ca.vertcat(*hi), self.basis[index]
        )
        call = PickCall(self, index, jac, pos)
        for i in range(dim):
            self.picked[pos[i].element_hash()] = (call, i)
        return pos, vel, acc

    def picked_points(self, times: Sequence[float]) -> list[tuple[ca.SX, ca.SX, ca.SX]]:
        """:meth:`point` at every time of ``times`` [s], one mapped call per candidate count.

        The same expressions as point by point (a mapped call inlines the
        same operations), in a fraction of the calls: on the optimised-
        durations walk 630 samples in 36 calls.
        """
        dim, last = int(self.positions[0].numel()), self.n_polys - 1
        candidates = [self.candidates(t) for t in times]
        groups: dict[int, list[int]] = {}
        for j, ks in enumerate(candidates):
            groups.setdefault(len(ks), []).append(j)
        lo_all = ca.vertcat(-np.inf, *self.starts[1:])
        hi_all = ca.vertcat(*self.ends[:last], np.inf)
        out: list[tuple[ca.SX, ca.SX, ca.SX]] = [(ca.SX(), ca.SX(), ca.SX())] * len(times)
        for n, members in groups.items():
            m = len(members)
            indices = [self._pick_index(candidates[j]) for j in members]
            q = ca.reshape(self.basis[[i for index in indices for i in index]], len(indices[0]), m)
            ks = [k for j in members for k in candidates[j]]
            if n == 1:
                lo, hi = ca.DM.ones(1, m) * -np.inf, ca.DM.ones(1, m) * np.inf
            else:
                lo, hi = ca.reshape(lo_all[ks], n, m), ca.reshape(hi_all[ks], n, m)
            t = ca.DM([[float(times[j]) for j in members]])
            pos, vel, acc, jac = _pick_function(dim, n).map(m)(t, lo, hi, q)
            jacobians = ca.horzsplit(jac, len(indices[0]))
            # elements() gives 1×1 SX (typed as SXElem): cheaper than indexing pos.
            hashes = [e.element_hash() for e in cast(list[ca.SX], pos.elements())]
            for c, (j, p, v, a) in enumerate(
                zip(members, ca.horzsplit(pos), ca.horzsplit(vel), ca.horzsplit(acc), strict=True)
            ):
                call = PickCall(self, indices[c], jacobians[c], p)
                for i in range(dim):
                    self.picked[hashes[c * dim + i]] = (call, i)
                out[j] = (p, v, a)
        return out

    @functools.cached_property
    def ends(self) -> list[Any]:
        """Every polynomial's end [s]: start + duration, one expression for all samples."""
        return [start + d for start, d in zip(self.starts, self.durations, strict=True)]

    @functools.cached_property
    def basis(self) -> ca.SX:
        """Every polynomial's start and duration, then every node's value and derivative.

        Affine in the variables: a picked sample's inputs are entries of it.
        """
        return ca.vertcat(
            *self.starts, *self.durations, *map(ca.vec, self.positions), *self.velocities
        )

    def _pick_index(self, ks: Sequence[int]) -> list[int]:
        """Indices in :attr:`basis` of the inputs q of :func:`_pick_function` for ``ks``."""
        dim, n_polys = int(self.positions[0].numel()), self.n_polys
        nodes = 2 * n_polys
        velocities = nodes + (n_polys + 1) * dim
        index = list(ks) + [n_polys + k for k in ks]
        for offset, shift in ((nodes, 0), (velocities, 0), (nodes, 1), (velocities, 1)):
            index += [offset + (k + shift) * dim + i for k in ks for i in range(dim)]
        return index


@dataclass(frozen=True)
class PickCall:
    """A sample of ``spline`` that picks among candidate polynomials (:func:`_pick_function`).

    Its inputs q are ``spline.basis[index]``, affine in the variables, so
    ∂position/∂x = ``jacobian`` · ∂basis[index]/∂x with the second factor
    constant (:func:`~roughwalk.trajopt.point_jacobian.points_jacobian`).
    ``position`` is the sample itself, held so that its entries' element
    hashes (the keys of :attr:`NodeSpline.picked`: node addresses) stay
    theirs: a sample dropped by its caller frees its nodes, and a later
    expression allocated at the same address would take its Jacobian.
    """

    spline: NodeSpline
    index: list[int]
    jacobian: ca.SX
    position: ca.SX


def sample_points(
    splines: Sequence[NodeSpline], times: Sequence[float]
) -> list[list[tuple[ca.SX, ca.SX, ca.SX]]]:
    """Position, velocity, acceleration of every spline (outer list) at every time (inner).

    Every spline's points come from mapped calls (:meth:`NodeSpline.points`).
    With optimised durations the order the points are made in has steered
    IPOPT (the pallet climb took 89 iterations one way, 63 and 69 in others,
    though f, g and their derivatives were equal at every point tried).
    """
    return [s.points(times) for s in splines]


class NumericSpline:
    """The same spline with numeric nodes (N, dim) and durations (N−1,) [s], vectorised in time."""

    def __init__(self, positions: ArrayLike, velocities: ArrayLike, durations: ArrayLike) -> None:
        self.positions = np.atleast_2d(np.asarray(positions, dtype=float))
        self.velocities = np.atleast_2d(np.asarray(velocities, dtype=float))
        self.durations = np.asarray(durations, dtype=float)
        if self.positions.shape != self.velocities.shape:
            raise ValueError("positions and velocities must have the same shape")
        if len(self.positions) != len(self.durations) + 1:
            raise ValueError("a spline needs one node more than it has polynomials")
        self.ends = np.cumsum(self.durations)
        self.node_times = np.concatenate([[0.0], self.ends])

    @property
    def total_duration(self) -> float:
        """End time [s]."""
        return float(self.ends[-1])

    def evaluate(
        self, times: ArrayLike
    ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
        """Position, velocity, acceleration (len(times), dim) at times [s] clamped to [0, T]."""
        t = np.clip(np.atleast_1d(np.asarray(times, dtype=float)), 0.0, self.total_duration)
        k = np.minimum(np.searchsorted(self.ends, t - _EPS, side="left"), len(self.durations) - 1)
        s = (t - self.node_times[k])[:, None]
        d = self.durations[k][:, None]
        pos, vel, acc = hermite_point(
            self.positions[k],
            self.velocities[k],
            self.positions[k + 1],
            self.velocities[k + 1],
            d,
            s,
        )
        return np.asarray(pos), np.asarray(vel), np.asarray(acc)
