"""The NLP's constraints, one per file (TOWR's ``constraints/``), registered by name.

Every module here that defines a :class:`Constraint` subclass decorated with
:func:`register` is imported on first use, so a new constraint is one new
file plus its name in :attr:`TrajoptConfig.constraints`.
"""

from __future__ import annotations

import importlib
import pkgutil
from collections.abc import Callable

from roughwalk.errors import ConfigError
from roughwalk.trajopt.constraints.constraint import (
    Call,
    Constraint,
    Rows,
    stack_calls,
    stack_rows,
)

__all__ = [
    "Call",
    "Constraint",
    "Rows",
    "stack_rows",
    "stack_calls",
    "register",
    "make_constraint",
    "constraint_names",
]

_REGISTRY: dict[str, type[Constraint]] = {}
_LOADED = False


def register(name: str) -> Callable[[type[Constraint]], type[Constraint]]:
    """Class decorator: make a constraint available under ``name``."""

    def wrap(cls: type[Constraint]) -> type[Constraint]:
        cls.name = name
        _REGISTRY[name] = cls
        return cls

    return wrap


def _load() -> None:
    global _LOADED
    if not _LOADED:
        for info in pkgutil.iter_modules(__path__):
            if info.name != "constraint":
                importlib.import_module(f"{__name__}.{info.name}")
        _LOADED = True


def constraint_names() -> list[str]:
    """Names of every registered constraint."""
    _load()
    return sorted(_REGISTRY)


def make_constraint(name: str) -> Constraint:
    """A new constraint object of the registered ``name``."""
    _load()
    if name not in _REGISTRY:
        raise ConfigError(f"unknown constraint '{name}'; known: {', '.join(sorted(_REGISTRY))}")
    return _REGISTRY[name]()
