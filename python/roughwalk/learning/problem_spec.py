"""The one NLP a learned initialiser belongs to: robot, terrain, gait, steps, duration.

Melon et al. learn one initialiser per environment and gait, for a fixed
number of optimisation variables (Melon 2020, §IV-A): the solution vector's
length and meaning depend on all of these. A :class:`ProblemSpec` names
them, builds the :class:`~roughwalk.trajopt.TrajoptProblem` once per worker
process (:func:`build_problem` caches it) and describes its variable layout.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import asdict, dataclass, replace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from roughwalk.config import override, parse_set
from roughwalk.errors import ConfigError
from roughwalk.trajopt import (
    Formulation,
    TrajoptConfig,
    TrajoptProblem,
    make_gait,
    melon_config,
    rigid_body_model,
)
from roughwalk.trajopt.parameters import (
    MELON_CONSTRAINTS,
    MELON_REACH_CONSTRAINTS,
    TOWR_CONSTRAINTS,
)
from roughwalk.trajopt.robot_model import SingleRigidBody
from roughwalk.trajopt.task import Task, task_problems
from roughwalk.trajopt.terrain_model import TerrainModel

__all__ = [
    "ProblemSpec",
    "CONSTRAINT_SETS",
    "constraint_set",
    "task_refusal",
    "cost_weights",
    "NLP_SETTINGS",
    "nlp_settings",
    "LEARNED_SOLVE_SETTINGS",
    "UNRECORDED_SOLVE_SETTINGS",
    "solve_settings",
    "solver_settings",
    "build_problem",
    "variable_layout",
    "variable_categories",
]

CONSTRAINT_SETS: dict[str, tuple[str, ...]] = {
    "melon": MELON_CONSTRAINTS,
    "melon_reach": MELON_REACH_CONSTRAINTS,
    "towr": TOWR_CONSTRAINTS,
}
"""Named constraint sets (``roughwalk init generate --constraints NAME``)."""

NLP_SETTINGS = ("swing_base_clearance",)
"""Top-level :class:`~roughwalk.trajopt.TrajoptConfig` fields a :class:`ProblemSpec` may set.

They change the NLP's rows (here their bounds), not its variable layout, so
a model trained under one value starts IPOPT at the optimum of another
problem: a run folder and a model header record them, and a problem that
differs is refused (``roughwalk init generate --set swing_base_clearance=0.5``).
"""

LEARNED_SOLVE_SETTINGS = ("guess_fallback_after", "dear_guess_restarts")
"""The ``solver`` fields that change where a solve from a learned guess ends.

The restarts from a learned guess: the network's guess after a stuck
library pick, further library candidates after a dear converged one. A
learned run folder records them (:func:`solve_settings`), so that a folder
is not resumed under others; a heuristic solve uses neither.
"""

UNRECORDED_SOLVE_SETTINGS: dict[str, int | None] = {
    "guess_fallback_after": 40,
    "dear_guess_restarts": 0,
}
"""What a learned run folder that records no ``solver`` settings was solved with.

Folders from before the record (session 10): ``guess_fallback_after`` was
40 from its introduction (340b041) until raised to 50 (1ebd6dc), and
``dear_guess_restarts`` did not exist (34ed209 added it). Folders from
before 340b041 had no fallback at all; they cannot be told apart and count
as these too.
"""

_problems: dict[ProblemSpec, TrajoptProblem] = {}
_grounds: dict[ProblemSpec, tuple[SingleRigidBody, TerrainModel]] = {}


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
    constraints:
        The NLP's constraint names; None: :func:`~roughwalk.trajopt.melon_config`'s
        default set (left out of :meth:`to_dict` then, so that runs recorded
        before the field existed still resume).
    costs:
        Cost weights that differ from ``melon_config``'s, as (dotted name,
        value) pairs (("force_between_nodes_penalty", 10.0),); None: the
        default weights (left out of :meth:`to_dict` then, as ``constraints``).
    solver:
        :data:`LEARNED_SOLVE_SETTINGS` that differ from ``melon_config``'s, as
        (name, value) pairs (("guess_fallback_after", 40),); None: the
        defaults. Never in :meth:`to_dict`: they change how a solve from a
        learned guess restarts, not the NLP a model fits, and a run records
        all of them, defaults too, under "solver" (:func:`solve_settings`).
    swing_base_clearance:
        Least height of the base above a swinging foot, as a fraction of the
        nominal base height (:class:`~roughwalk.trajopt.TrajoptConfig`'s
        field); None: as ``base_clearance`` (0.7), the problem of every run
        and model made before the field existed (left out of :meth:`to_dict`
        then, so that they still resume and fit).

    """

    robot: str = "anymal_c"
    terrain: str = "single_pallet"
    gait: str = "walk"
    steps: int = 16
    duration: float = 5.5
    optimize_durations: bool = False
    constraints: tuple[str, ...] | None = None
    costs: tuple[tuple[str, float], ...] | None = None
    solver: tuple[tuple[str, int | None], ...] | None = None
    swing_base_clearance: float | None = None

    def config(self) -> TrajoptConfig:
        """Melon et al.'s configuration for this problem."""
        changes: dict[str, object] = {}
        if self.constraints is not None:
            changes["constraints"] = tuple(self.constraints)
        config = melon_config(
            gait=self.gait,
            steps=self.steps,
            duration=self.duration,
            optimize_durations=self.optimize_durations,
            **changes,
        )
        if self.swing_base_clearance is not None:
            config = replace(config, swing_base_clearance=float(self.swing_base_clearance))
        if self.costs:
            config = override(config, {f"costs.{k}": v for k, v in self.costs})
        if self.solver:
            config = override(config, {f"solver.{k}": v for k, v in self.solver})
        return config

    def to_dict(self) -> dict[str, Any]:
        """Plain data for JSON (``constraints``, ``costs``, the clearance only when set)."""
        data = asdict(self)
        del data["solver"]
        if self.swing_base_clearance is None:
            del data["swing_base_clearance"]
        if self.constraints is None:
            del data["constraints"]
        else:
            data["constraints"] = list(self.constraints)
        if self.costs is None:
            del data["costs"]
        else:
            data["costs"] = dict(self.costs)
        return data

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
                constraints=None
                if data.get("constraints") is None
                else tuple(str(c) for c in data["constraints"]),
                costs=None
                if data.get("costs") is None
                else tuple(sorted((str(k), float(v)) for k, v in data["costs"].items())),
                swing_base_clearance=None
                if data.get("swing_base_clearance") is None
                else float(data["swing_base_clearance"]),
            )
        except KeyError as e:
            raise ConfigError(f"problem spec lacks the field {e}; got {sorted(data)}") from None


def constraint_set(text: str) -> tuple[str, ...]:
    """A named set (:data:`CONSTRAINT_SETS`) or comma-separated constraint names."""
    from roughwalk.trajopt.constraints import constraint_names

    if text in CONSTRAINT_SETS:
        return CONSTRAINT_SETS[text]
    names = tuple(n.strip() for n in text.split(",") if n.strip())
    known = constraint_names()
    unknown = [n for n in names if n not in known]
    if unknown or not names:
        raise ConfigError(
            f"unknown constraint set or names {text!r}: give one of "
            f"{', '.join(CONSTRAINT_SETS)} or names among {', '.join(sorted(known))}"
        )
    return names


def cost_weights(items: Iterable[str]) -> tuple[tuple[str, float], ...] | None:
    """``costs.NAME=VALUE`` items (``roughwalk init generate --set``) as :attr:`ProblemSpec.costs`.

    Spelled and parsed as ``roughwalk optimize --set`` (:func:`~roughwalk.config.parse_set`,
    dotted names such as ``costs.force.weight``); each weight is checked
    against :func:`~roughwalk.trajopt.melon_config`'s, and a bad name or value
    raises :class:`~roughwalk.errors.ConfigError` naming the item (``solver.``
    items are :func:`solver_settings`'s). Only the weights that differ from
    the defaults are kept (None: none), as the run records them, so that an
    explicit default value makes the same problem.
    """
    from roughwalk.learning.model_costs import cost_changes, cost_leaves

    weights = melon_config().costs
    known = cost_leaves(weights)
    for key, value in parse_set(items).items():
        if key.startswith("solver.") or key in NLP_SETTINGS:
            continue  # solver_settings's, nlp_settings's
        name = key.removeprefix("costs.")
        if name == key or name not in known:
            raise ConfigError(
                f"--set {key}={value}: not a cost weight; give costs.NAME=VALUE with NAME "
                f"among {', '.join(known)} (or one of {', '.join(NLP_SETTINGS)}=VALUE)"
            )
        try:
            weights = override(weights, {name: value})
        except ConfigError as e:
            raise ConfigError(f"--set {key}={value}: {e}") from None
    changes = cost_changes(weights)
    return tuple(sorted(changes.items())) if changes else None


def nlp_settings(items: Iterable[str]) -> dict[str, float | None]:
    """``NAME=VALUE`` items of ``--set`` whose NAME is one of :data:`NLP_SETTINGS`, as values.

    Checked against :func:`~roughwalk.trajopt.melon_config` ("none" for None);
    items of other sections (``costs.``, ``solver.``) are left to
    :func:`cost_weights` and :func:`solver_settings`. Give the result to
    :class:`ProblemSpec` as keywords.
    """
    config = melon_config()
    chosen = {k: v for k, v in parse_set(items).items() if k in NLP_SETTINGS}
    try:
        config = override(config, chosen)
    except ConfigError as e:
        raise ConfigError(f"--set {chosen}: {e}") from None
    return {name: getattr(config, name) for name in chosen}


def solver_settings(items: Iterable[str]) -> tuple[tuple[str, int | None], ...] | None:
    """``solver.NAME=VALUE`` items of ``--set`` as :attr:`ProblemSpec.solver`.

    NAME is one of :data:`LEARNED_SOLVE_SETTINGS` ("none" for None); items
    of other sections (``costs.``) are left to :func:`cost_weights`. Only the
    values that differ from :func:`~roughwalk.trajopt.melon_config`'s are kept
    (None: none), so that an explicit default makes the same problem.
    """
    default = melon_config().solver
    solver = default
    for key, value in parse_set(items).items():
        name = key.removeprefix("solver.")
        if name == key:
            continue
        if name not in LEARNED_SOLVE_SETTINGS:
            raise ConfigError(
                f"--set {key}={value}: not a learned-solve setting; give solver.NAME=VALUE "
                f"with NAME among {', '.join(LEARNED_SOLVE_SETTINGS)}"
            )
        try:
            solver = override(solver, {name: value})
        except ConfigError as e:
            raise ConfigError(f"--set {key}={value}: {e}") from None
    changes = tuple(
        (name, getattr(solver, name))
        for name in LEARNED_SOLVE_SETTINGS
        if getattr(solver, name) != getattr(default, name)
    )
    return changes or None


def solve_settings(spec: ProblemSpec) -> dict[str, int | None]:
    """:data:`LEARNED_SOLVE_SETTINGS` as ``spec``'s solves use them (a run's "solver" record)."""
    solver = spec.config().solver
    return {name: getattr(solver, name) for name in LEARNED_SOLVE_SETTINGS}


def _ground(spec: ProblemSpec) -> tuple[SingleRigidBody, TerrainModel]:
    """The body and terrain model of ``spec`` (the built NLP's, when there is one)."""
    if spec in _problems:
        return _problems[spec].body, _problems[spec].terrain
    if spec not in _grounds:
        from roughwalk.robots import load_robot
        from roughwalk.terrain import load_terrain

        cfg = spec.config()
        body = rigid_body_model(cfg.body_model, load_robot(spec.robot))
        terrain = TerrainModel(load_terrain(spec.terrain), cfg.terrain, cfg.costs.step_edge_sigma)
        _grounds[spec] = (body, terrain)
    return _grounds[spec]


def build_problem(spec: ProblemSpec) -> TrajoptProblem:
    """The NLP of ``spec``, built once per process and reused for every task."""
    if spec not in _problems:
        cfg = spec.config()
        body, terrain = _ground(spec)
        schedule = make_gait(cfg.gait, cfg.steps, cfg.duration)
        _problems[spec] = TrajoptProblem(body, terrain, schedule, cfg)
    return _problems[spec]


def task_refusal(spec: ProblemSpec, task: Task) -> str | None:
    """Why ``task`` cannot be solved in ``spec``'s NLP, or None when it can be tried.

    The checks of ``roughwalk optimize`` (:func:`~roughwalk.trajopt.task.task_problems`):
    a start or goal inside an obstacle, a start stance out of its legs'
    range of motion, a goal where no level base stands. A task space's box
    holds such starts (on the single pallet 1 of 200 held-out tasks and 12
    of 2000 training tasks: a foot on the pallet's edge), and their solves
    can only end infeasible.
    """
    body, terrain = _ground(spec)
    cfg = spec.config()
    problems = task_problems(
        body, terrain, task, tuple(cfg.constraints), cfg.solver.constr_viol_tol
    )
    return "; ".join(problems) if problems else None


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
