"""TOWR's heuristic initial guess (Melon 2020, §IV): a straight base, even footholds and timing.

The base moves on the straight line from start to goal at constant speed;
each stance foothold is the nominal stance under the base at the middle of
that stance phase (the last one under the goal pose), on the terrain; the
phase durations are the gait's; the forces share the weight among the feet
in stance.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from roughwalk.errors import ConfigError
from roughwalk.trajopt.formulation import Formulation
from roughwalk.trajopt.gaits import ContactSchedule
from roughwalk.trajopt.initializers.guess import (
    feet_guess,
    finite_difference,
    forces_guess,
    node_times,
    straight_base,
)
from roughwalk.trajopt.task import ResolvedTask, nominal_feet
from roughwalk.trajopt.variables import euler_to_rotation

__all__ = ["HeuristicInitializer", "base_guess"]


def base_guess(nlp: Formulation, task: ResolvedTask) -> dict[str, NDArray[np.float64]]:
    """Base linear and angular variables on the straight line from start to goal."""
    times = node_times(nlp.base_lin, nlp.base_lin.durations)
    positions, euler = straight_base(nlp, task, times)
    return {
        nlp.base_lin.name: nlp.base_lin.pack(positions, finite_difference(positions, times)),
        nlp.base_ang.name: nlp.base_ang.pack(euler, finite_difference(euler, times)),
    }


class HeuristicInitializer:
    """TOWR's heuristic guess; registered as ``heuristic``."""

    name = "heuristic"

    def __init__(self, argument: str | None = None) -> None:
        if argument:
            raise ConfigError(f"the heuristic initialiser takes no argument, got {argument!r}")

    def schedule(self, gait: ContactSchedule) -> ContactSchedule:
        """The gait's schedule."""
        return gait

    def adjust_task(self, task: ResolvedTask) -> ResolvedTask:
        """The task as given."""
        return task

    def guess(self, nlp: Formulation, task: ResolvedTask) -> NDArray[np.float64]:
        """The initial variable vector for ``task``."""
        parts = base_guess(nlp, task)
        durations = [np.asarray(d.nominal) for d in nlp.durations]
        for foot in range(nlp.n_feet):
            bounds = np.concatenate([[0.0], np.cumsum(durations[foot])])
            footholds: dict[int, NDArray[np.float64]] = {}
            last = len(durations[foot]) - 1
            for phase in nlp.stance_phases(foot):
                if nlp.fixed_foothold(foot, phase):
                    footholds[phase] = task.feet[foot]
                    continue
                if phase == last:
                    gx, gy = (float(v) for v in task.goal_xy)
                    feet, _ = nominal_feet(nlp.body, nlp.terrain, gx, gy, float(task.goal_euler[2]))
                    footholds[phase] = feet[foot]
                    continue
                t_mid = 0.5 * (bounds[phase] + bounds[phase + 1])
                base, euler = straight_base(nlp, task, np.array([t_mid]))
                rot = euler_to_rotation(euler[0])
                p = base[0] + rot @ nlp.body.stance[foot]
                p[2] = float(nlp.terrain.height(p[None, :2])[0])
                footholds[phase] = p
            parts[nlp.feet[foot].name] = feet_guess(nlp, task, foot, durations[foot], footholds)
            parts[nlp.forces[foot].name] = forces_guess(nlp, foot, durations[foot], durations)
            parts[nlp.durations[foot].name] = nlp.durations[foot].pack(durations[foot])
        return nlp.join(parts)
