"""Supervised learning of A_θ: task → solution vector, the loss weighted per category.

θ = argmin Σ_{x ∈ D_good} ‖A_θ(x) − y(x)‖²_W (Melon 2020, eq. 3). Melon et
al. found the base positions, phase durations and contact forces the values
that matter most in a guess (§IV-B) and weighted those categories more.
scikit-learn's ``MLPRegressor`` minimises a plain mean squared error, so the
targets are centred and divided by their category's RMS deviation over √w
of the category: the plain MSE on the scaled targets is the W-weighted one.
"""

from __future__ import annotations

import time
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from roughwalk.errors import ConfigError, InvalidArgumentError
from roughwalk.learning.dataset import Dataset
from roughwalk.learning.filtering import best_per_task, filter_good, fit_task_cost
from roughwalk.learning.mlp import MLP
from roughwalk.learning.model_file import FEATURES, MODEL_FORMAT, MODEL_VERSION, LearnedModel
from roughwalk.learning.problem_spec import ProblemSpec, build_problem, variable_categories
from roughwalk.learning.solution_library import SolutionLibrary
from roughwalk.learning.task_cost_model import TaskCostModel

__all__ = [
    "CATEGORY_WEIGHTS",
    "TrainReport",
    "train_model",
    "load_datasets",
    "fit_mlp",
    "category_scales",
]

CATEGORY_WEIGHTS: dict[str, float] = {
    "base_position": 10.0,
    "phase_duration": 10.0,
    "force": 10.0,
    "base_velocity": 1.0,
    "base_angular": 1.0,
    "foot_position": 1.0,
    "foot_velocity": 1.0,
    "other": 1.0,
}
_MIN_STD = 1e-9


@dataclass
class TrainReport:
    """What training saw and how well it fits.

    Attributes
    ----------
    n_rows, n_feasible, n_good:
        Rows given, feasible ones, and D_good's size.
    g_max:
        The cost threshold used; ``automatic`` whether it was found.
    layers:
        Hidden layer sizes.
    fit_s:
        Training wall time [s].
    rmse:
        Root-mean-square training error per category (variables' units).

    """

    n_rows: int
    n_feasible: int
    n_good: int
    g_max: float
    automatic: bool
    layers: tuple[int, ...]
    fit_s: float
    rmse: dict[str, float] = field(default_factory=dict)

    def summary(self) -> str:
        """One paragraph for the terminal."""
        errors = ", ".join(f"{k} {v:.3g}" for k, v in sorted(self.rmse.items()))
        how = "automatic" if self.automatic else "given"
        return (
            f"{self.n_good} of {self.n_rows} solutions kept (feasible {self.n_feasible}, "
            f"g_max {self.g_max:.4g}, {how}); MLP {self.layers} fitted in {self.fit_s:.1f} s; "
            f"training RMSE: {errors}"
        )


def load_datasets(paths: Sequence[str | Path]) -> Dataset:
    """Run folders (finished solves so far) or dataset files, merged into one.

    A task solved in more than one of them (a re-solve from a later round's
    model) keeps its best solve (:func:`~roughwalk.learning.filtering.best_per_task`).
    """
    from roughwalk.learning.experience import read_run

    datasets = [read_run(Path(p)) if Path(p).is_dir() else Dataset.load(p) for p in paths]
    if not datasets:
        raise InvalidArgumentError("no dataset given")
    return best_per_task(datasets)


def category_scales(
    targets: NDArray[np.float64], categories: NDArray[np.str_], weights: Mapping[str, float]
) -> NDArray[np.float64]:
    """Per-variable divisor σ_c / √w_c: the RMS deviation of its category over the weight.

    One scale per category, not per variable: a variable that barely varies
    (a velocity pinned by a constraint) keeps its small deviations small
    instead of having its numerical noise blown up to unit variance.
    """
    centred = np.asarray(targets, dtype=float) - np.mean(targets, axis=0)
    out = np.ones(centred.shape[1])
    for c in np.unique(categories):
        mask = categories == c
        rms = float(np.sqrt(np.mean(centred[:, mask] ** 2)))
        out[mask] = max(rms, _MIN_STD) / np.sqrt(weights.get(str(c), 1.0))
    return out


def fit_mlp(
    inputs: NDArray[np.float64],
    targets: NDArray[np.float64],
    scale: NDArray[np.float64],
    *,
    layers: tuple[int, ...] = (64, 64),
    seed: int = 0,
    max_epochs: int = 300,
    alpha: float = 1e-4,
    max_components: int = 64,
) -> MLP:
    """Fit an MLP minimising Σ_j ((y_j − ŷ_j) / scale_j)² over standardised inputs."""
    from sklearn.exceptions import ConvergenceWarning
    from sklearn.neural_network import MLPRegressor

    x = np.asarray(inputs, dtype=float)
    y = np.asarray(targets, dtype=float)
    in_std = x.std(axis=0)
    in_mean = x.mean(axis=0)
    in_scale = np.where(in_std > _MIN_STD, in_std, 1.0)
    out_mean = y.mean(axis=0)
    out_scale = np.asarray(scale, dtype=float)
    net = MLPRegressor(
        hidden_layer_sizes=layers,
        activation="tanh",
        solver="lbfgs",
        alpha=alpha,
        max_iter=max_epochs,
        max_fun=4 * max_epochs,
        random_state=seed,
    )
    z = (y - out_mean) / out_scale
    # Fit the targets' coordinates in their principal axes: a rotation leaves
    # the squared error unchanged, but L-BFGS's line search fails at once on
    # the raw columns, where a few contact forces lie hundreds of category
    # deviations out; the basis is folded into the last layer afterwards.
    # Axes beyond 99.9 % of the weighted variance (at most ``max_components``)
    # are dropped: the solutions of a three-parameter task family lie near a
    # low-dimensional surface, and the fit is then far faster.
    _, sv, vt = np.linalg.svd(z, full_matrices=False)
    energy = np.cumsum(sv**2) / max(float(np.sum(sv**2)), 1e-300)
    keep = min(int(np.searchsorted(energy, 0.999)) + 1, max_components, len(sv))
    basis = vt[: max(keep, min(2, len(sv)))]  # two at least: sklearn wants 2-D targets
    with warnings.catch_warnings():
        # max_epochs is a budget, not a promise of convergence.
        warnings.simplefilter("ignore", ConvergenceWarning)
        net.fit((x - in_mean) / in_scale, z @ basis.T)
    weights = [np.asarray(w, dtype=float) for w in net.coefs_]
    biases = [np.asarray(b, dtype=float).ravel() for b in net.intercepts_]
    weights[-1] = weights[-1] @ basis
    biases[-1] = biases[-1] @ basis
    return MLP(
        tuple(w.astype(np.float32) for w in weights),
        tuple(b.astype(np.float32) for b in biases),
        "tanh",
        in_mean,
        in_scale,
        out_mean,
        out_scale,
    )


def train_model(
    data: Dataset,
    *,
    layers: tuple[int, ...] = (64, 64),
    g_max: float | None = None,
    seed: int = 0,
    max_epochs: int = 300,
    weights: Mapping[str, float] = CATEGORY_WEIGHTS,
    note: str = "",
    learned_round: int = 1,
    extra: Mapping[str, Any] | None = None,
    task_cost: TaskCostModel | None | str = "fit",
    library: bool = False,
) -> tuple[LearnedModel, TrainReport]:
    """Filter ``data`` (D_good) and fit A_θ on it.

    Parameters
    ----------
    data:
        Experience of one problem (its meta names the problem and task space).
    layers:
        Hidden layer sizes (Melon et al.: two layers first, three later).
    g_max:
        Cost threshold; None finds it (:func:`~roughwalk.learning.filtering.cost_threshold`).
    seed, max_epochs:
        Training seed and L-BFGS iteration budget.
    weights:
        Loss weight per variable category.
    note:
        Free text for the header.
    learned_round:
        Which LearnedInit round this model is (1: trained on heuristic solves).
    extra:
        More header fields (e.g. held-out figures).
    task_cost:
        Without ``g_max``, filter with this per-task g_max; "fit" (default)
        fits one on ``data`` when it has enough feasible solutions
        (:func:`~roughwalk.learning.filtering.fit_task_cost`), None uses the
        global threshold.
    library:
        Also keep D_good's solutions and constraint multipliers in the model
        (:class:`~roughwalk.learning.solution_library.SolutionLibrary`): its
        guess is then the nearest training task's solution.

    """
    if "problem" not in data.meta or "layout" not in data.meta:
        raise ConfigError("dataset meta lacks 'problem' or 'layout': not from an experience run")
    spec = ProblemSpec.from_dict(data.meta["problem"])
    cost_model = fit_task_cost(data) if task_cost == "fit" else task_cost
    assert not isinstance(cost_model, str)
    result = filter_good(data, g_max, task_cost=cost_model)
    if result.n_good < 2:
        raise InvalidArgumentError(
            f"only {result.n_good} of {len(data)} solutions pass the filter "
            f"(g_max {result.g_max:.4g}); need at least 2 to train"
        )
    good = data.select(result.good)
    nlp = build_problem(spec).formulation
    categories = variable_categories(nlp)
    if categories.size != good["x"].shape[1]:
        raise ConfigError(
            f"dataset vectors have {good['x'].shape[1]} values, the problem has {categories.size}"
        )
    scale = category_scales(good["x"], categories, weights)
    inputs = np.column_stack([good["start"], good["goal"]])
    start = time.perf_counter()
    mlp = fit_mlp(inputs, good["x"], scale, layers=layers, seed=seed, max_epochs=max_epochs)
    fit_s = time.perf_counter() - start
    multiplier_mlp, n_multiplier_rows = _fit_multipliers(
        good, inputs, layers=layers, seed=seed, max_epochs=max_epochs
    )
    error = mlp(inputs) - good["x"]
    rmse = {c: float(np.sqrt(np.mean(error[:, categories == c] ** 2))) for c in set(categories)}
    report = TrainReport(
        len(data),
        int(result.feasible.sum()),
        result.n_good,
        result.g_max,
        result.automatic,
        tuple(layers),
        fit_s,
        rmse,
    )
    header = {
        "format": MODEL_FORMAT,
        "version": MODEL_VERSION,
        "problem": spec.to_dict(),
        "constraints": data.meta.get("constraints"),
        "costs": data.meta.get("costs"),
        "task_space": data.meta.get("task_space"),
        "layout": [list(item) for item in data.meta["layout"]],
        "features": list(FEATURES),
        "loss_weights": dict(weights),
        "training": {
            "learned_init_round": learned_round,
            "n_tasks": len(data),
            "task_indices": [int(data["index"].min()), int(data["index"].max())],
            "split": data.meta.get("split"),
            "seed": data.meta.get("seed"),
            "source_init": data.meta.get("init"),
            "source_max_iter": data.meta.get("max_iter"),
            "n_feasible": report.n_feasible,
            "n_good": report.n_good,
            "g_max": report.g_max,
            "g_max_automatic": report.automatic,
            "filter": "per-task g_max (task_cost_model)"
            if g_max is None and cost_model is not None
            else "global g_max",
            "fit_seed": seed,
            "rmse": rmse,
            "task_cost_model": _task_cost_model(data, result.feasible),
            "note": note,
        },
        "multipliers": {
            "n_lam_x": int(good["lam_x"].shape[1]),
            "n_lam_g": int(good["lam_g"].shape[1]),
            "n_rows": n_multiplier_rows,
        }
        if multiplier_mlp is not None
        else None,
        **(dict(extra) if extra else {}),
    }
    kept = _library(good, inputs) if library else None
    return LearnedModel(mlp, header, multiplier_mlp, kept), report


def _library(good: Dataset, inputs: NDArray[np.float64]) -> SolutionLibrary:
    """D_good's solutions that recorded their constraint multipliers, as a library."""
    rows = np.all(np.isfinite(good["lam_g"]), axis=1) & (good["lam_g"].shape[1] > 0)
    if not rows.any():
        raise InvalidArgumentError("no solution in D_good recorded its multipliers: no library")
    return SolutionLibrary.build(inputs[rows], good["x"][rows], good["lam_g"][rows])


def _task_cost_model(data: Dataset, feasible: NDArray[np.bool_]) -> dict[str, Any] | None:
    """A per-task g_max (:class:`TaskCostModel`) from the feasible solutions, if enough."""
    tasks = np.column_stack([data["start"], data["goal"]])[feasible]
    try:
        return TaskCostModel.fit(tasks, data["cost"][feasible]).to_dict()
    except InvalidArgumentError:
        return None


def _fit_multipliers(
    good: Dataset,
    inputs: NDArray[np.float64],
    *,
    layers: tuple[int, ...],
    seed: int,
    max_epochs: int,
) -> tuple[MLP | None, int]:
    """Task → (lam_x, lam_g) on the rows that recorded multipliers; None with fewer than 2."""
    lam = np.hstack([good["lam_x"], good["lam_g"]])
    rows = np.all(np.isfinite(lam), axis=1) if lam.shape[1] else np.zeros(len(good), bool)
    if lam.shape[1] == 0 or rows.sum() < 2:
        return None, int(rows.sum())
    categories = np.array(
        ["bound_multiplier"] * good["lam_x"].shape[1]
        + ["constraint_multiplier"] * good["lam_g"].shape[1]
    )
    scale = category_scales(lam[rows], categories, {})
    mlp = fit_mlp(inputs[rows], lam[rows], scale, layers=layers, seed=seed, max_epochs=max_epochs)
    return mlp, int(rows.sum())
