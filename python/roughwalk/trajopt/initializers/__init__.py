"""Initial guesses for the NLP, by name (Melon 2020, §IV).

* ``heuristic``: TOWR's straight-line guess (:class:`HeuristicInitializer`);
* ``footsteps:PLAN.json``: contact sequence and footholds from a footstep plan
  (:class:`FootstepsInitializer`);
* ``learned``: registered by the learning wing (:func:`register_initializer`).
"""

from roughwalk.trajopt.initializers.footsteps import (
    FootstepPlan,
    FootstepsInitializer,
    read_footstep_plan,
)
from roughwalk.trajopt.initializers.heuristic import HeuristicInitializer
from roughwalk.trajopt.initializers.registry import (
    Initializer,
    initializer_names,
    make_initializer,
    register_initializer,
)

register_initializer("heuristic", HeuristicInitializer)
register_initializer("footsteps", FootstepsInitializer)

__all__ = [
    "Initializer",
    "HeuristicInitializer",
    "FootstepsInitializer",
    "FootstepPlan",
    "read_footstep_plan",
    "register_initializer",
    "make_initializer",
    "initializer_names",
]
