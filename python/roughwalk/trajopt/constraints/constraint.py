"""What a constraint is: a named block of rows g(x, p) with lower and upper bounds."""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import casadi as ca
import numpy as np
from numpy.typing import NDArray

if TYPE_CHECKING:
    from roughwalk.trajopt.formulation import Formulation

__all__ = ["Rows", "Constraint", "stack_rows"]


@dataclass
class Rows:
    """Constraint rows lower ≤ expr ≤ upper; ``expr`` is an (n, 1) SX."""

    name: str
    expr: ca.SX
    lower: NDArray[np.float64]
    upper: NDArray[np.float64]

    @property
    def size(self) -> int:
        """Number of rows."""
        return int(self.expr.numel())


Bound = float | NDArray[np.float64]


def stack_rows(name: str, parts: Sequence[tuple[ca.SX, Bound, Bound]]) -> Rows | None:
    """Rows from (expr, lower, upper) pieces; scalar bounds apply to every row of their piece."""
    if not parts:
        return None
    exprs, lowers, uppers = [], [], []
    for expr, lo, hi in parts:
        e = ca.SX(expr)
        n = int(e.numel())
        exprs.append(ca.vec(e))
        lowers.append(np.broadcast_to(np.asarray(lo, dtype=float), (n,)))
        uppers.append(np.broadcast_to(np.asarray(hi, dtype=float), (n,)))
    return Rows(name, ca.vertcat(*exprs), np.concatenate(lowers), np.concatenate(uppers))


class Constraint(ABC):
    """A constraint of the NLP; subclasses register under a name with :func:`register`."""

    name: str = "constraint"

    @abstractmethod
    def build(self, nlp: Formulation) -> Rows | None:
        """The rows of this constraint for the problem ``nlp`` (None if it has none)."""
