"""What a cost is: a named scalar term of the objective."""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass
from typing import TYPE_CHECKING

import casadi as ca

if TYPE_CHECKING:
    from roughwalk.trajopt.formulation import Formulation

__all__ = ["CostTerm", "Cost"]


@dataclass
class CostTerm:
    """A named scalar SX term of the objective."""

    name: str
    expr: ca.SX


class Cost(ABC):
    """A cost of the NLP; subclasses register under a name with :func:`register`."""

    name: str = "cost"

    @abstractmethod
    def build(self, nlp: Formulation) -> CostTerm | None:
        """The term for ``nlp``, or None when its weight is zero."""
