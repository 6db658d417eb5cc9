"""∂u/∂z of a column of spline points, each distinct point differentiated once.

The rows of a constraint made of calls g = F(u) (dynamics, range of motion)
read the same points many times: every foot's range-of-motion call at a
sample reads the base's position and angles. With optimised phase
durations the feet's points are not affine in the variables (the polynomial
that holds a time depends on the durations), and differentiating them is
most of the cost of the rows' Jacobian. The chain rule
∂g/∂z = blockdiag(∂F/∂u) · ∂u/∂z differentiates each distinct point once,
a few at a time, instead of once per row that reads it.
"""

from __future__ import annotations

import casadi as ca

__all__ = ["points_jacobian"]

_POINTS_PER_BLOCK = 12
"""Point values differentiated together: on TOWR's block task with optimised
durations, 12 took 0.18 s of CPU for the dynamics' points, the whole
column at once 0.38 s (CasADi colours a Jacobian's rows or columns, and
every foot point touches most of its foot's variables)."""


def points_jacobian(u: ca.SX, z: ca.SX) -> ca.SX:
    """∂u/∂z of the column ``u``, each distinct entry differentiated once.

    Entries are the same point when they are the same operation node of
    the expression graph; constants and bare symbols are left as they are
    (their rows are cheap and may be shared by unrelated entries).
    """
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
    values = u[distinct]
    m = len(distinct)
    jacobian = ca.vertcat(
        *[
            ca.jacobian(values[s : min(s + _POINTS_PER_BLOCK, m)], z)
            for s in range(0, m, _POINTS_PER_BLOCK)
        ]
    )
    if m == n:
        return jacobian
    select = ca.DM(ca.Sparsity.triplet(n, m, list(range(n)), source), 1)
    return select @ jacobian
