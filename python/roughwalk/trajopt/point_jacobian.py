"""∂u/∂z of a column of spline points, each distinct point differentiated once.

The rows of a constraint made of calls g = F(u) (dynamics, range of motion)
read the same points many times: every foot's range-of-motion call at a
sample reads the base's position and angles. With optimised phase
durations the feet's points are not affine in the variables (the polynomial
that holds a time depends on the durations), and differentiating them is
most of the cost of the rows' Jacobian. The chain rule
∂g/∂z = blockdiag(∂F/∂u) · ∂u/∂z differentiates each distinct point once,
a few at a time, instead of once per row that reads it. A point picked
among candidate polynomials (:class:`~roughwalk.trajopt.variables.spline.PickCall`)
is not differentiated at all: its own Jacobian with respect to its affine
inputs times their constant Jacobian gives its row. On the flat walk with
optimised durations this took the points' Jacobians from 0.23–0.29 s of
CPU to 0.16–0.18 s.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

import casadi as ca

if TYPE_CHECKING:
    from roughwalk.trajopt.variables.spline import PickCall

__all__ = ["points_jacobian"]

_POINTS_PER_BLOCK = 12
"""Point values differentiated together: on TOWR's block task with optimised
durations, 12 took 0.18 s of CPU for the dynamics' points, the whole
column at once 0.38 s (CasADi colours a Jacobian's rows or columns, and
every foot point touches most of its foot's variables)."""


def points_jacobian(
    u: ca.SX, z: ca.SX, picked: Mapping[int, tuple[PickCall, int]] | None = None
) -> ca.SX:
    """∂u/∂z of the column ``u``, each distinct entry differentiated once.

    Entries are the same point when they are the same operation node of
    the expression graph; constants and bare symbols are left as they are
    (their rows are cheap and may be shared by unrelated entries). Entries
    found in ``picked`` (a spline's samples among candidate polynomials, by
    element hash: see :attr:`NodeSpline.picked`) take their row from the
    sample's own Jacobian times the constant ∂q/∂z of its affine inputs;
    the others are differentiated by CasADi, a few at a time.
    """
    picked = picked or {}
    n = int(u.numel())
    first: dict[int, int] = {}
    distinct: list[int] = []
    source: list[int] = []
    for i in range(n):
        element = u[i]
        key = None if element.is_constant() or element.is_symbolic() else element.element_hash()
        if key is None or key not in first:
            if key is not None:
                first[key] = len(distinct)
            source.append(len(distinct))
            distinct.append(i)
        else:
            source.append(first[key])
    # Distinct entries in two groups: picked samples and the rest.
    hashes = [u[i].element_hash() for i in distinct]
    from_picks = [
        j for j, h in enumerate(hashes) if h in picked and not u[distinct[j]].is_constant()
    ]
    chosen = set(from_picks)
    others = [j for j in range(len(distinct)) if j not in chosen]
    blocks = []
    if from_picks:
        blocks.append(_picked_jacobian([picked[hashes[j]] for j in from_picks], z))
    values = u[[distinct[j] for j in others]]
    if from_picks:
        # The rest (in TOWR's and Melon's rows the base's points, affine) in one call.
        blocks.append(ca.jacobian(values, z))
    else:
        m = len(others)
        blocks += [
            ca.jacobian(values[s : min(s + _POINTS_PER_BLOCK, m)], z)
            for s in range(0, m, _POINTS_PER_BLOCK)
        ]
    # Row of each entry of u in vertcat(blocks).
    position = {j: r for r, j in enumerate(from_picks + others)}
    rows = [position[j] for j in source]
    stacked = ca.vertcat(*blocks) if blocks else ca.SX(0, z.numel())
    if rows == list(range(n)):
        return stacked
    return stacked[rows, :]


def _picked_jacobian(entries: list[tuple[PickCall, int]], z: ca.SX) -> ca.SX:
    """Rows ∂pos_i/∂z of picked samples (call, i): row i of the call's Jacobian times ∂q/∂z.

    q is affine in z, so ∂q/∂z is a constant: the rows of each spline's
    ∂basis/∂z that the call reads. All entries share one product.
    """
    splines: dict[int, tuple[int, Any]] = {}
    calls: dict[int, int] = {}
    jacobians: list[ca.SX] = []
    basis_rows: list[int] = []
    entry_rows: list[int] = []
    row_offset = 0
    for call, i in entries:
        spline = call.spline
        if id(spline) not in splines:
            offset = sum(int(b.size1()) for _, b in splines.values())
            splines[id(spline)] = (offset, _constant_jacobian(spline.basis, z))
        if id(call) not in calls:
            calls[id(call)] = row_offset
            row_offset += int(call.jacobian.size1())
            jacobians.append(call.jacobian)
            basis_rows += [splines[id(spline)][0] + k for k in call.index]
        entry_rows.append(calls[id(call)] + i)
    local = ca.diagcat(*jacobians)[entry_rows, :]
    basis = ca.vertcat(*[b for _, b in splines.values()])
    return local @ basis[basis_rows, :]


def _constant_jacobian(expr: ca.SX, z: ca.SX) -> ca.DM:
    """∂expr/∂z of an expression affine in z."""
    jac = ca.jacobian(expr, z)
    if not jac.is_constant():
        raise ValueError("a picked sample's inputs must be affine in the variables")
    return ca.DM(jac)
