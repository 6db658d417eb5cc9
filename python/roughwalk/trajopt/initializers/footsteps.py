"""An initial guess from a footstep plan (``roughwalk plan``): in neither paper, it joins them.

The plan's JSON result lists ``footsteps`` [{leg, x, y, z}] in execution
order, starting with the initial stance (one entry per leg); every later
entry is one step of its leg, landing there. The guess takes from it

* the contact sequence: one foot swinging at a time, in the plan's order,
  between two stand phases, over the requested duration;
* the footholds, and the start stance;
* a base that follows the centroid of the feet at the nominal height, facing
  from the hind feet to the front feet;
* forces sharing the weight among the feet in stance.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from roughwalk.errors import InvalidArgumentError
from roughwalk.robots.canonical_frame import LEG_NAMES
from roughwalk.trajopt.formulation import Formulation
from roughwalk.trajopt.gaits import ContactSchedule, schedule_from_swings
from roughwalk.trajopt.initializers.guess import (
    feet_guess,
    finite_difference,
    forces_guess,
    node_times,
)
from roughwalk.trajopt.task import ResolvedTask

__all__ = ["FootstepPlan", "FootstepsInitializer", "read_footstep_plan"]


class FootstepPlan:
    """Footholds (n, 3) [m] and their legs (n,) (0..3 = LF, RF, LH, RH), start stance first."""

    def __init__(
        self, legs: list[int], positions: NDArray[np.float64], source: str = "plan"
    ) -> None:
        if len(legs) != len(positions):
            raise InvalidArgumentError("a footstep plan needs one leg per foothold")
        if len(legs) < 5 or sorted(legs[:4]) != [0, 1, 2, 3]:
            raise InvalidArgumentError(
                f"footstep plan '{source}' must start with the initial stance (each of "
                f"{', '.join(LEG_NAMES)} once) followed by at least one step; got legs "
                f"{[LEG_NAMES[i] for i in legs[:6]]}..."
            )
        if not np.all(np.isfinite(positions)):
            raise InvalidArgumentError(f"footstep plan '{source}' has non-finite coordinates")
        self.legs = legs
        self.positions = positions
        self.source = source

    @property
    def start_stance(self) -> NDArray[np.float64]:
        """(4, 3) initial footholds [m] in leg order LF, RF, LH, RH."""
        out = np.zeros((4, 3))
        for leg, p in zip(self.legs[:4], self.positions[:4], strict=True):
            out[leg] = p
        return out

    @property
    def swing_order(self) -> list[int]:
        """The legs of the steps, in order."""
        return self.legs[4:]

    def footholds(self, leg: int) -> list[NDArray[np.float64]]:
        """The successive footholds [m] of ``leg``, its start foothold first."""
        return [p for lg, p in zip(self.legs, self.positions, strict=True) if lg == leg]


def read_footstep_plan(path: str | Path) -> FootstepPlan:
    """Read the ``footsteps`` of a plan JSON; raise naming what is wrong."""
    p = Path(path)
    if not p.is_file():
        raise InvalidArgumentError(f"footstep plan '{p}' does not exist")
    try:
        data: Any = json.loads(p.read_text())
    except json.JSONDecodeError as e:
        raise InvalidArgumentError(f"footstep plan '{p}' is not valid JSON: {e}") from None
    steps = data.get("footsteps") if isinstance(data, dict) else None
    if not isinstance(steps, list):
        raise InvalidArgumentError(f"footstep plan '{p}' has no 'footsteps' list")
    legs, positions = [], []
    for i, step in enumerate(steps):
        try:
            leg = LEG_NAMES.index(str(step["leg"]).upper())
            positions.append([float(step["x"]), float(step["y"]), float(step["z"])])
        except (KeyError, TypeError, ValueError):
            raise InvalidArgumentError(
                f"footstep plan '{p}': entry {i} must be {{leg ∈ {LEG_NAMES}, x, y, z}}, "
                f"got {step!r}"
            ) from None
        legs.append(leg)
    return FootstepPlan(legs, np.array(positions, dtype=float), str(p))


def _base_from_feet(feet: NDArray[np.float64], height: float) -> tuple[NDArray[np.float64], float]:
    """CoM (3,) over the feet's centroid at ``height`` above their mean, and the heading [rad]."""
    front = 0.5 * (feet[0] + feet[1])
    hind = 0.5 * (feet[2] + feet[3])
    heading = math.atan2(front[1] - hind[1], front[0] - hind[0])
    centre = feet.mean(axis=0)
    return np.array([centre[0], centre[1], centre[2] + height]), heading


class FootstepsInitializer:
    """The guess from a footstep plan; registered as ``footsteps:PLAN.json``."""

    name = "footsteps"

    def __init__(self, argument: str | None = None, plan: FootstepPlan | None = None) -> None:
        if plan is None:
            if not argument:
                raise InvalidArgumentError(
                    "the footsteps initialiser needs a plan: footsteps:PLAN.json"
                )
            plan = read_footstep_plan(argument)
        self.plan = plan

    def schedule(self, gait: ContactSchedule) -> ContactSchedule:
        """One foot at a time in the plan's order, over the gait's duration."""
        return schedule_from_swings(self.plan.swing_order, gait.total_duration)

    def adjust_task(self, task: ResolvedTask) -> ResolvedTask:
        """Start on the plan's initial stance, the base over it (goal unchanged)."""
        feet = self.plan.start_stance
        height = float(task.base_position[2] - task.feet[:, 2].mean())
        base, heading = _base_from_feet(feet, height)
        return ResolvedTask(
            task.task,
            base,
            np.array([0.0, 0.0, heading]),
            feet,
            task.goal_xy,
            task.goal_euler,
            task.goal_z,
        )

    def _feet_at(self, nlp: Formulation, t: float) -> NDArray[np.float64]:
        """Where each foot is at time t [s] when swings go straight between footholds."""
        out = np.zeros((4, 3))
        for foot in range(4):
            holds = self.plan.footholds(foot)
            bounds = nlp.schedule.phase_times(foot)
            phase = int(np.clip(np.searchsorted(bounds, t, side="right") - 1, 0, len(bounds) - 2))
            stance_before = sum(nlp.schedule.is_stance(foot, k) for k in range(phase + 1))
            if nlp.schedule.is_stance(foot, phase):
                out[foot] = holds[stance_before - 1]
            else:
                frac = (t - bounds[phase]) / (bounds[phase + 1] - bounds[phase])
                a, b = holds[stance_before - 1], holds[stance_before]
                out[foot] = a + frac * (b - a)
        return out

    def guess(self, nlp: Formulation, task: ResolvedTask) -> NDArray[np.float64]:
        """The initial variable vector from the plan."""
        height = float(task.base_position[2] - task.feet[:, 2].mean())
        times = node_times(nlp.base_lin, nlp.base_lin.durations)
        base = np.zeros((len(times), 3))
        euler = np.zeros((len(times), 3))
        for i, t in enumerate(times):
            base[i], euler[i, 2] = _base_from_feet(self._feet_at(nlp, float(t)), height)
        euler[:, 2] = np.unwrap(euler[:, 2])
        parts = {
            nlp.base_lin.name: nlp.base_lin.pack(base, finite_difference(base, times)),
            nlp.base_ang.name: nlp.base_ang.pack(euler, finite_difference(euler, times)),
        }
        durations = [np.asarray(d.nominal) for d in nlp.durations]
        for foot in range(nlp.n_feet):
            holds = self.plan.footholds(foot)
            footholds = {phase: holds[i] for i, phase in enumerate(nlp.stance_phases(foot))}
            parts[nlp.feet[foot].name] = feet_guess(nlp, task, foot, durations[foot], footholds)
            parts[nlp.forces[foot].name] = forces_guess(nlp, foot, durations[foot], durations)
            parts[nlp.durations[foot].name] = nlp.durations[foot].pack(durations[foot])
        return nlp.join(parts)
