"""Initial guesses by name: ``heuristic``, ``footsteps:PLAN.json`` and a ``learned`` plug-in.

An initialiser may change the contact schedule (a footstep plan brings its
own) and the task's start (the plan's first stance), then gives the initial
variable vector. One with a ``constraints(requested, signature)`` method also
chooses the constraint set (:func:`~roughwalk.trajopt.optimize_motion` asks
it): a learned model's guess belongs to the set it was trained on; one
with ``costs(requested, signature)`` likewise chooses the cost weights. One
with ``has_fallback(nlp)`` and ``fallback(nlp, task)`` offers a second
start (guess and multipliers) for a solve from its guess that has not
converged after ``solver.guess_fallback_after`` iterations; one with
``cost_limit(nlp, task)`` and ``other_start(nlp, task, visited)`` offers
further starts for a solve that converged above that cost (a poor local
minimum), up to ``solver.dear_guess_restarts`` of them. One with
``source()`` names where its guess came from (a learned model), and the
result's message says so. Other
wings add theirs with :func:`register_initializer`; the learning wing
registers ``learned`` (Melon 2020, §IV) when it is imported, since this wing
may not import the wings above it.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Protocol

import numpy as np
from numpy.typing import NDArray

from roughwalk.errors import ConfigError
from roughwalk.trajopt.formulation import Formulation
from roughwalk.trajopt.gaits import ContactSchedule
from roughwalk.trajopt.task import ResolvedTask

__all__ = ["Initializer", "register_initializer", "make_initializer", "initializer_names"]


class Initializer(Protocol):
    """What an initial guess provides."""

    name: str

    def schedule(self, gait: ContactSchedule) -> ContactSchedule:
        """The contact schedule to optimise (the gait's, unless the guess brings its own)."""
        ...

    def adjust_task(self, task: ResolvedTask) -> ResolvedTask:
        """The start and goal states to use (the given ones, unless the guess knows better)."""
        ...

    def guess(self, nlp: Formulation, task: ResolvedTask) -> NDArray[np.float64]:
        """The initial variable vector of ``nlp`` for ``task``."""
        ...


# name → factory(argument after the colon, or None)
_REGISTRY: dict[str, Callable[[str | None], Initializer]] = {}
_PROVIDERS = {
    "learned": "roughwalk.learning (the learned-initialisation issue)",
    "learned_fixed_durations": "roughwalk.learning (the learned-initialisation issue)",
}


def register_initializer(name: str, factory: Callable[[str | None], Initializer]) -> None:
    """Make ``factory`` available as ``--init name[:argument]``."""
    _REGISTRY[name] = factory


def initializer_names() -> list[str]:
    """Registered initialiser names."""
    return sorted(_REGISTRY)


def make_initializer(spec: str) -> Initializer:
    """The initialiser named by ``spec``: "heuristic", "footsteps:PLAN.json", "learned", ..."""
    name, _, argument = str(spec).partition(":")
    name = name.strip()
    if name not in _REGISTRY:
        if name in _PROVIDERS:
            raise ConfigError(
                f"initialiser '{name}' is not available: it is registered by {_PROVIDERS[name]}, "
                f"which is not installed or not imported; known: {', '.join(initializer_names())}"
            )
        raise ConfigError(f"unknown initialiser '{name}'; known: {', '.join(initializer_names())}")
    return _REGISTRY[name](argument.strip() or None)
