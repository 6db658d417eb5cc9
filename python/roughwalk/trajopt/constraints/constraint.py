"""What a constraint is: a named block of rows g(x, p) with lower and upper bounds."""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import casadi as ca
import numpy as np
from numpy.typing import NDArray

if TYPE_CHECKING:
    from roughwalk.trajopt.formulation import Formulation

__all__ = ["Call", "Rows", "Constraint", "stack_rows", "stack_calls"]


@dataclass(frozen=True)
class Call:
    """Rows that are one small SX function of a few spline points: ``function(*inputs)``.

    The spline points are affine in the variables when the phase durations
    are fixed (u = A x + b), so the Hessian of λᵀ function(u) is
    Aᵀ ∇²ᵤ(λᵀ function) A: the function's own small Hessian, mapped. The
    formulation builds it that way, in a fraction of the operations of
    differentiating the inlined expression twice.
    """

    function: ca.Function
    inputs: tuple[ca.SX, ...]


@dataclass
class Rows:
    """Constraint rows lower ≤ expr ≤ upper; ``expr`` is an (n, 1) SX.

    ``calls``, when given, are the same rows as function calls, in order
    (see :class:`Call`).
    """

    name: str
    expr: ca.SX
    lower: NDArray[np.float64]
    upper: NDArray[np.float64]
    calls: list[Call] | None = None

    @property
    def size(self) -> int:
        """Number of rows."""
        return int(self.expr.numel())


Bound = float | NDArray[np.float64]


def _as_sx(value: Any) -> ca.SX:
    """``value`` as an SX; itself when it is one.

    ca.SX(sx) copies it through SWIG's slow overload dispatch: over the flat
    trot's thousand parts and calls, a sixth of its build CPU.
    """
    return value if isinstance(value, ca.SX) else ca.SX(value)


def stack_rows(name: str, parts: Sequence[tuple[ca.SX, Bound, Bound]]) -> Rows | None:
    """Rows from (expr, lower, upper) pieces; scalar bounds apply to every row of their piece."""
    if not parts:
        return None
    exprs, lowers, uppers = [], [], []
    for expr, lo, hi in parts:
        e = _as_sx(expr)
        n = int(e.numel())
        exprs.append(e if e.is_column() else ca.vec(e))
        lowers.append(np.broadcast_to(np.asarray(lo, dtype=float), (n,)))
        uppers.append(np.broadcast_to(np.asarray(hi, dtype=float), (n,)))
    return Rows(name, ca.vertcat(*exprs), np.concatenate(lowers), np.concatenate(uppers))


class Constraint(ABC):
    """A constraint of the NLP; subclasses register under a name with :func:`register`."""

    name: str = "constraint"

    @abstractmethod
    def build(self, nlp: Formulation) -> Rows | None:
        """The rows of this constraint for the problem ``nlp`` (None if it has none)."""


def stack_calls(
    name: str, function: ca.Function, calls: Sequence[tuple[Sequence[ca.SX], Bound, Bound]]
) -> Rows | None:
    """Rows ``function(*inputs)`` from (inputs, lower, upper) pieces, keeping the calls.

    A column-valued function is called once, mapped over the pieces: the
    same expressions as calling it piece by piece, in less CPU.
    """
    if not calls or function.n_out() != 1 or function.size2_out(0) != 1:
        rows = stack_rows(name, [(function(*inputs), lo, hi) for inputs, lo, hi in calls])
        if rows is not None:
            rows.calls = [Call(function, tuple(map(_as_sx, inputs))) for inputs, _, _ in calls]
        return rows
    inputs = [tuple(map(_as_sx, args)) for args, _, _ in calls]
    mapped = function.map(len(calls))(
        *[ca.horzcat(*[args[i] for args in inputs]) for i in range(function.n_in())]
    )
    n = function.size1_out(0)
    lower = np.concatenate(
        [np.broadcast_to(np.asarray(lo, dtype=float), (n,)) for _, lo, _ in calls]
    )
    upper = np.concatenate(
        [np.broadcast_to(np.asarray(hi, dtype=float), (n,)) for _, _, hi in calls]
    )
    return Rows(name, ca.vec(mapped), lower, upper, [Call(function, args) for args in inputs])
