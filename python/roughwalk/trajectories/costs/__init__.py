"""The terms of CHOMP's objective, one per module (Zucker 2011, §5.1 and §5.3).

:class:`Smoothness` (ξᵀAξ + ξᵀb + c, and the banded solve of the covariant
update), :class:`ObstacleCost` (the arc-length-weighted workspace potential),
:func:`reachability_cost` (§3.2) and :class:`ZmpSupportCost` (stability).
"""

from roughwalk.trajectories.costs.obstacle import ObstacleCost, obstacle_potential
from roughwalk.trajectories.costs.reachability import reachability_cost
from roughwalk.trajectories.costs.smoothness import Smoothness
from roughwalk.trajectories.costs.support import ZmpSupportCost

__all__ = [
    "Smoothness",
    "ObstacleCost",
    "obstacle_potential",
    "reachability_cost",
    "ZmpSupportCost",
]
