"""Small NLPs shared by the trajopt tests."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from roughwalk.terrain import load_terrain
from roughwalk.trajopt import (
    TOWR_ANYMAL,
    Formulation,
    HeuristicInitializer,
    Task,
    TerrainModel,
    make_gait,
)
from roughwalk.trajopt.parameters import TrajoptConfig
from roughwalk.trajopt.task import resolve


def pallet_edge_climb(
    config: TrajoptConfig,
) -> tuple[Formulation, dict[str, np.ndarray], Task]:
    """A 4-step, 2 s climb onto the single pallet, guessed by the heuristic.

    The front left foot's second foothold is put on the pallet's edge, where
    the terrain spline curves the most (the terrain's derivatives are in play
    there). Returns the formulation, the guess split into its variable sets,
    and the resolved task.
    """
    terrain = TerrainModel(
        load_terrain("single_pallet"), config.terrain, config.costs.step_edge_sigma
    )
    nlp = Formulation(config, TOWR_ANYMAL, make_gait("walk", 4, 2.0), terrain)
    task = resolve(Task((0.55, 0.0, 0.0), (0.95, 0.05, 0.1)), TOWR_ANYMAL, terrain)
    parts = nlp.split(HeuristicInitializer().guess(nlp, task))
    motion = nlp.feet[0]
    pos, vel = motion.unpack(parts[motion.name])
    node = motion.phase_nodes(nlp.stance_phases(0)[1])[0]
    pos[node : node + 2, 0] = 1.01
    parts[motion.name] = motion.pack(pos, vel)
    return nlp, parts, task


def central_differences(
    f: Callable[[np.ndarray], np.ndarray], x: np.ndarray, columns: np.ndarray, h: float = 1e-6
) -> np.ndarray:
    """Central differences of ``f`` at ``x`` along ``columns``: one column per variable."""
    out = []
    for j in columns:
        e = np.zeros_like(x)
        e[j] = h
        out.append((f(x + e) - f(x - e)) / (2 * h))
    return np.array(out).T
