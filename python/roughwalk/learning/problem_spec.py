"""The one NLP a learned initialiser belongs to: robot, terrain, gait, steps, duration.

Melon et al. learn one initialiser per environment and gait, for a fixed
number of optimisation variables (Melon 2020, §IV-A): the solution vector's
length and meaning depend on all of these. A :class:`ProblemSpec` names
them, builds the :class:`~roughwalk.trajopt.TrajoptProblem` once per worker
process (:func:`build_problem` caches it) and describes its variable layout.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from roughwalk.errors import ConfigError
from roughwalk.trajopt import (
    Formulation,
    TrajoptConfig,
    TrajoptProblem,
    make_gait,
    melon_config,
    rigid_body_model,
)
from roughwalk.trajopt.terrain_model import TerrainModel

__all__ = ["ProblemSpec", "build_problem", "variable_layout", "variable_categories"]

_problems: dict[ProblemSpec, TrajoptProblem] = {}


@dataclass(frozen=True)
class ProblemSpec:
    """Which NLP: ``robot``, ``gait`` with ``steps`` swings in ``duration`` [s], ``terrain``.

    Attributes
    ----------
    robot:
        A registered robot's name (its single rigid body is used).
    terrain:
        A terrain spec (generator name, file, course).
    gait:
        The gait ("walk", "trot", ...).
    steps:
        Number of swings of all feet.
    duration:
        Total duration T [s].
    optimize_durations:
        Whether the phase durations are optimised (else fixed at the gait's).

    """

    robot: str = "anymal_c"
    terrain: str = "single_pallet"
    gait: str = "walk"
    steps: int = 16
    duration: float = 5.5
    optimize_durations: bool = False

    def config(self) -> TrajoptConfig:
        """Melon et al.'s configuration for this problem."""
        return melon_config(
            gait=self.gait,
            steps=self.steps,
            duration=self.duration,
            optimize_durations=self.optimize_durations,
        )

    def to_dict(self) -> dict[str, Any]:
        """Plain data for JSON."""
        return asdict(self)

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> ProblemSpec:
        """The spec written by :meth:`to_dict`."""
        try:
            return cls(
                robot=str(data["robot"]),
                terrain=str(data["terrain"]),
                gait=str(data["gait"]),
                steps=int(data["steps"]),
                duration=float(data["duration"]),
                optimize_durations=bool(data["optimize_durations"]),
            )
        except KeyError as e:
            raise ConfigError(f"problem spec lacks the field {e}; got {sorted(data)}") from None


def build_problem(spec: ProblemSpec) -> TrajoptProblem:
    """The NLP of ``spec``, built once per process and reused for every task."""
    if spec not in _problems:
        from roughwalk.robots import load_robot
        from roughwalk.terrain import load_terrain

        cfg = spec.config()
        body = rigid_body_model(cfg.body_model, load_robot(spec.robot))
        terrain = TerrainModel(load_terrain(spec.terrain), cfg.terrain, cfg.costs.step_edge_sigma)
        schedule = make_gait(cfg.gait, cfg.steps, cfg.duration)
        _problems[spec] = TrajoptProblem(body, terrain, schedule, cfg)
    return _problems[spec]


def variable_layout(nlp: Formulation) -> list[tuple[str, int]]:
    """(name, size) of each variable set, in the solution vector's order."""
    return [(v.name, v.size) for v in nlp.variable_sets]


def variable_categories(nlp: Formulation) -> NDArray[np.str_]:
    """Each variable's category (Melon 2020, §IV-B weighs the loss by category).

    "base_position", "base_velocity", "base_angular", "foot_position",
    "foot_velocity", "force" or "phase_duration".
    """
    out: list[str] = []
    for v in nlp.variable_sets:
        index = getattr(v, "index", None)
        if v.name.startswith("durations"):
            out += ["phase_duration"] * v.size
        elif v.name.startswith("foot_force"):
            out += ["force"] * v.size
        elif index is None:
            out += ["other"] * v.size
        else:
            kinds = [places[0].kind for places in index]
            if v.name == "base_lin":
                out += ["base_position" if k == "pos" else "base_velocity" for k in kinds]
            elif v.name == "base_ang":
                out += ["base_angular"] * v.size
            else:
                out += ["foot_position" if k == "pos" else "foot_velocity" for k in kinds]
    return np.array(out)
