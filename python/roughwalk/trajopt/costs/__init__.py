"""The NLP's costs, one per file (TOWR's ``costs/``), registered by name.

Every registered cost is built; a cost whose weight in
:class:`~roughwalk.trajopt.parameters.CostWeights` is zero adds nothing.
"""

from __future__ import annotations

import importlib
import pkgutil
from collections.abc import Callable
from typing import TYPE_CHECKING

from roughwalk.trajopt.costs.cost import Cost, CostTerm

if TYPE_CHECKING:
    from roughwalk.trajopt.formulation import Formulation

__all__ = ["Cost", "CostTerm", "register", "make_costs", "cost_names"]

_REGISTRY: dict[str, type[Cost]] = {}
_LOADED = False


def register(name: str) -> Callable[[type[Cost]], type[Cost]]:
    """Class decorator: make a cost available under ``name``."""

    def wrap(cls: type[Cost]) -> type[Cost]:
        cls.name = name
        _REGISTRY[name] = cls
        return cls

    return wrap


def _load() -> None:
    global _LOADED
    if not _LOADED:
        for info in pkgutil.iter_modules(__path__):
            if info.name not in ("cost", "integral"):
                importlib.import_module(f"{__name__}.{info.name}")
        _LOADED = True


def cost_names() -> list[str]:
    """Names of every registered cost."""
    _load()
    return sorted(_REGISTRY)


def make_costs(nlp: Formulation) -> list[CostTerm | None]:
    """Every registered cost's term for ``nlp`` (None where the weight is zero)."""
    _load()
    return [_REGISTRY[name]().build(nlp) for name in sorted(_REGISTRY)]
