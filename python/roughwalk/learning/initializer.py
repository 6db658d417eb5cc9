"""The ``learned`` / ``learned:MODEL`` initialiser: A_θ's guess for the NLP (Melon 2020, §IV).

``learned`` picks, among the models shipped in ``roughwalk/learning/models/``,
the one trained for this problem's robot, terrain, gait, step count,
duration and variable layout; ``learned:MODEL`` uses a model file (a path,
or a shipped model's name) and refuses a problem it was not trained for.
The contact schedule and the task are left as they are.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from roughwalk.errors import ConfigError
from roughwalk.learning.model_constraints import constraints_for_model
from roughwalk.learning.model_costs import costs_for_model
from roughwalk.learning.model_file import LearnedModel, Start, problem_signature
from roughwalk.learning.problem_spec import ProblemSpec
from roughwalk.learning.solution_library import farthest
from roughwalk.trajopt import ContactSchedule, Formulation, register_initializer
from roughwalk.trajopt.parameters import CostWeights
from roughwalk.trajopt.task import ResolvedTask

__all__ = [
    "LearnedInitializer",
    "MODELS_DIR",
    "shipped_models",
    "load_model",
    "model_for_spec",
    "bounded_start",
    "choose_start",
]

MODELS_DIR = Path(__file__).resolve().parent / "models"

# Loaded models by file, with the (mtime, size) they were read at. `roughwalk
# optimize --init learned` makes a new initialiser per solve, and reading the
# three shipped models (compressed .npz) took 25 ms of CPU, 8 % of a learned
# single-pallet solve; a rewritten file is read again.
_loaded: dict[Path, tuple[tuple[int, int], LearnedModel]] = {}


def _load_file(path: Path) -> LearnedModel:
    """``LearnedModel.load(path)``, read once per version of the file."""
    key = path.absolute()
    stat = key.stat()
    version = (stat.st_mtime_ns, stat.st_size)
    cached = _loaded.get(key)
    if cached is None or cached[0] != version:
        cached = (version, LearnedModel.load(key))
        _loaded[key] = cached
    return cached[1]


def shipped_models() -> list[Path]:
    """The model files shipped with the package."""
    return sorted(MODELS_DIR.glob("*.npz"))


def load_model(name: str) -> LearnedModel:
    """A model by path, or by the name of a shipped one ("anymal_c_single_pallet_walk16")."""
    path = Path(name)
    if path.is_file():
        return _load_file(path)
    shipped = MODELS_DIR / f"{name.removesuffix('.npz')}.npz"
    if shipped.is_file():
        return _load_file(shipped)
    names = ", ".join(p.stem for p in shipped_models()) or "none"
    raise ConfigError(f"no learned model {name!r} (not a file); shipped models: {names}")


def _pick(signature: dict[str, object]) -> LearnedModel:
    """The shipped model that fits ``signature``; say what is shipped if none does."""
    models = [_load_file(p) for p in shipped_models()]
    for model in models:
        if not model.mismatches(signature):
            return model
    have = "; ".join(
        f"{m.name} ({m.header['problem']['robot']}, {m.header['problem']['terrain']}, "
        f"{m.header['problem']['gait']} {m.header['problem']['steps']} steps, "
        f"{m.header['problem']['duration']} s"
        f"{_clearance(m.header['problem'].get('swing_base_clearance'))})"
        for m in models
    )
    raise ConfigError(
        f"no shipped learned model fits robot {signature.get('robot')!r}, terrain "
        f"{signature.get('terrain')!r}, gait {signature.get('gait')!r}, "
        f"{signature.get('steps')} steps, {signature.get('duration')} s"
        f"{_clearance(signature.get('swing_base_clearance'))}; shipped: "
        f"{have or 'none'}; train one with `roughwalk init` and use learned:MODEL"
        + (
            ", or start from a fixed-duration model's guess with learned_fixed_durations"
            if signature.get("optimize_durations")
            else ""
        )
    )


def _clearance(value: object) -> str:
    """', swing_base_clearance 0.5' for a set clearance, '' for None (as base_clearance)."""
    return "" if value is None else f", swing_base_clearance {value}"


def model_for_spec(init: str, spec: ProblemSpec) -> LearnedModel:
    """The model ``init`` uses for ``spec``'s problem, checked against it.

    ``init`` is "learned", "learned:MODEL" or the fixed-duration model's
    ``learned_fixed_durations[:MODEL]`` (:mod:`.fixed_durations_initializer`).
    """
    name, _, argument = init.partition(":")
    signature = {k: v for k, v in spec.to_dict().items()}
    if name == "learned_fixed_durations":
        from roughwalk.learning.fixed_durations_initializer import fixed_durations_model

        return fixed_durations_model(argument or None, signature)
    if name != "learned":
        raise ConfigError(
            f"expected 'learned', 'learned:MODEL' or 'learned_fixed_durations[:MODEL]', "
            f"got {init!r}"
        )
    model = _pick(signature) if not argument else load_model(argument)
    model.check_signature(signature)
    return model


class LearnedInitializer:
    """A_θ's guess; registered as ``learned`` (shipped model) and ``learned:MODEL``.

    Parameters
    ----------
    argument:
        A model file or shipped model name; None picks the shipped model
        that fits the problem when the guess is asked for.

    """

    name = "learned"

    def __init__(self, argument: str | None = None) -> None:
        self.model = load_model(argument) if argument else None

    def schedule(self, gait: ContactSchedule) -> ContactSchedule:
        """The gait's schedule (the model was trained for it)."""
        return gait

    def adjust_task(self, task: ResolvedTask) -> ResolvedTask:
        """The task as given."""
        return task

    def _model(self, signature: dict[str, object]) -> LearnedModel:
        """The model, picked on first use from the shipped ones that fit ``signature``."""
        if self.model is None:
            self.model = _pick(signature)
        return self.model

    def source(self) -> str | None:
        """The model the guess comes from (None before one is chosen), for the result's message."""
        return None if self.model is None else f"learned model '{self.model.name}'"

    def constraints(
        self, requested: tuple[str, ...], signature: dict[str, object]
    ) -> tuple[str, ...]:
        """The constraint set to solve with: the model's own unless another was chosen.

        ``signature`` is the problem's (:func:`problem_signature` without the
        layout), to pick the shipped model; see :mod:`.model_constraints`.
        """
        return constraints_for_model(self._model(signature), requested)

    def costs(self, requested: CostWeights, signature: dict[str, object]) -> CostWeights:
        """The cost weights to solve with: the model's recorded ones where none was chosen.

        A weight the configuration changed from the default is kept (the
        user's override wins); see :mod:`.model_costs`.
        """
        return costs_for_model(self._model(signature), requested)

    def guess(self, nlp: Formulation, task: ResolvedTask) -> NDArray[np.float64]:
        """A_θ(task), within the NLP's variable bounds; refuses a problem the model does not fit."""
        signature = problem_signature(nlp)
        model = self._model(signature)
        model.check_signature(signature)
        return np.clip(model.predict(task.task), nlp.lbx, nlp.ubx)

    def multipliers(
        self, nlp: Formulation, task: ResolvedTask
    ) -> tuple[NDArray[np.float64] | None, NDArray[np.float64] | None]:
        """A_θ's multipliers (lam_x, lam_g) for IPOPT's warm start, or (None, None)."""
        lam_x, lam_g = self._model(problem_signature(nlp)).predict_multipliers([task.task])
        if lam_x is None or lam_g is None:
            return None, None
        return lam_x[0], _complete_rows(nlp, lam_g[0])

    def has_fallback(self, nlp: Formulation) -> bool:
        """Whether :meth:`fallback` differs from the guess: the model has a solution library."""
        return self._model(problem_signature(nlp)).library is not None

    def fallback(
        self, nlp: Formulation, task: ResolvedTask
    ) -> tuple[NDArray[np.float64], NDArray[np.float64] | None, NDArray[np.float64] | None]:
        """The network's own guess and multipliers, for a library pick that does not converge.

        A library pick is a solution of a neighbouring task; when it lies in
        a basin IPOPT does not leave for this task, the network's guess (an
        average over neighbours, in no one basin) often converges: see
        ``solver.guess_fallback_after``.
        """
        network = self._model(problem_signature(nlp)).network_only()
        x0 = np.clip(network.predict(task.task), nlp.lbx, nlp.ubx)
        lam_x, lam_g = network.predict_multipliers([task.task])
        if lam_x is None or lam_g is None:
            return x0, None, None
        return x0, lam_x[0], _complete_rows(nlp, lam_g[0])

    def cost_limit(self, nlp: Formulation, task: ResolvedTask) -> float | None:
        """The cost above which a converged solve is a poor minimum: the model's per-task g_max.

        A solve from the guess that ends dearer is started again from
        :meth:`other_start` (``solver.dear_guess_restarts``); None (a model
        without a task cost model) never restarts.
        """
        limits = self._model(problem_signature(nlp)).cost_limits([task.task])
        return None if limits is None else float(limits[0])

    def other_start(
        self, nlp: Formulation, task: ResolvedTask, visited: Sequence[NDArray[np.float64]]
    ) -> tuple[NDArray[np.float64], NDArray[np.float64] | None, NDArray[np.float64] | None] | None:
        """A further start: the library candidate farthest from every start and solution so far.

        None when the model has no library or every candidate was tried.
        """
        model = self._model(problem_signature(nlp))
        return choose_start(nlp, model.other_starts(task.task), visited, model.mlp.out_scale)


def choose_start(
    nlp: Formulation,
    pool: Sequence[Start],
    visited: Sequence[NDArray[np.float64]],
    scale: NDArray[np.float64],
) -> tuple[NDArray[np.float64], NDArray[np.float64] | None, NDArray[np.float64] | None] | None:
    """The start of ``pool`` farthest from ``visited`` (:func:`farthest`), within the bounds."""
    if not pool:
        return None
    starts = [bounded_start(nlp, start) for start in pool]
    k = farthest([x for x, _, _ in starts], visited, scale)
    return None if k is None else starts[k]


def bounded_start(
    nlp: Formulation,
    start: Start,
) -> tuple[NDArray[np.float64], NDArray[np.float64] | None, NDArray[np.float64] | None]:
    """A start within ``nlp``'s variable bounds, its lam_g padded for appended rows."""
    x, lam_x, lam_g = start
    rows = None if lam_g is None else _complete_rows(nlp, np.asarray(lam_g, dtype=float))
    bound = None if lam_x is None else np.asarray(lam_x, dtype=float)
    return np.clip(np.asarray(x, dtype=float), nlp.lbx, nlp.ubx), bound, rows


def _complete_rows(nlp: Formulation, lam_g: NDArray[np.float64]) -> NDArray[np.float64]:
    """``lam_g`` for every row of ``nlp``: zeros for constraints appended after the model's.

    Constraints are stacked in the config's order, so a problem that gained a
    constraint at the end (``leg_reach``) keeps the model's rows as its
    prefix; the new rows start inactive (multiplier 0) rather than losing
    the whole warm start. Returned unchanged when the prefix does not end on
    a constraint block's boundary (the solver then drops the multipliers).
    """
    n = lam_g.size
    if n >= nlp.n_constraints:
        return lam_g
    ends = np.cumsum([size for _, size in nlp.row_layout])
    if n not in ends:
        return lam_g
    return np.concatenate([lam_g, np.zeros(nlp.n_constraints - n)])


register_initializer("learned", LearnedInitializer)
