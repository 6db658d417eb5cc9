"""A learned initialiser on disk: MLP arrays in an .npz and a JSON header, never a pickle.

The header records what the model is for — task space, robot, terrain, gait,
step count, duration, fixed or optimised phase durations, the trunk's
clearance over swinging feet and the NLP's variable layout — and how it was
made (tasks seen, D_good's size, g_max, LearnedInit round, held-out
figures). A problem that differs in any of these is refused with a message
naming what differs, since Melon et al.'s initialiser is specific to one
environment and one variable layout (Melon 2020, §IV-A).
"""

from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from roughwalk.errors import ConfigError
from roughwalk.learning.mlp import MLP
from roughwalk.learning.problem_spec import ProblemSpec
from roughwalk.learning.solution_library import SolutionLibrary
from roughwalk.learning.task_cost_model import TaskCostModel
from roughwalk.trajopt import Formulation, Task

__all__ = ["LearnedModel", "MODEL_FORMAT", "MODEL_VERSION", "FEATURES", "task_features"]

MODEL_FORMAT = "roughwalk.learned_init"
MODEL_VERSION = 1
FEATURES = ("start_x", "start_y", "start_yaw", "goal_x", "goal_y", "goal_yaw")
# What must match, in the order a mismatch is reported.
_CHECKED = (
    "robot",
    "gait",
    "steps",
    "duration",
    "optimize_durations",
    "terrain",
    "swing_base_clearance",
)
# Checked even where a signature leaves them out: absent means this value (a
# spec's to_dict and every header made before the field leave out None).
_ABSENT_MEANS = {"swing_base_clearance": None}

Start = tuple[NDArray[np.floating], NDArray[np.floating] | None, NDArray[np.floating] | None]
"""A start for IPOPT: the guess, its bound multipliers and constraint multipliers (or None)."""


def task_features(tasks: list[Task]) -> NDArray[np.float64]:
    """The network's inputs (n, 6): start (x, y, yaw), goal (x, y, yaw) [m, m, rad]."""
    return np.array([[*t.start, *t.goal] for t in tasks], dtype=float).reshape(-1, len(FEATURES))


def problem_signature(nlp: Formulation) -> dict[str, Any]:
    """What a model must match, read from a built NLP."""
    return {
        "robot": nlp.body.name,
        "gait": nlp.schedule.name,
        "steps": nlp.schedule.steps,
        "duration": float(nlp.schedule.total_duration),
        "optimize_durations": bool(nlp.config.optimize_durations),
        "terrain": nlp.terrain.name,
        "swing_base_clearance": nlp.config.swing_base_clearance,
        "layout": [[v.name, v.size] for v in nlp.variable_sets],
    }


class LearnedModel:
    """A trained A_θ: task → NLP variable vector, with its header.

    Parameters
    ----------
    mlp:
        The network: task → variable vector.
    header:
        JSON-able metadata ("problem", "task_space", "layout", "training", ...).
    multipliers:
        A second network: task → IPOPT's bound and constraint multipliers
        (lam_x, lam_g) at the solution, or None. IPOPT started from a primal
        guess alone walks the barrier path from its start and gains little
        from a good guess; with multipliers it starts near the path's end.
    library:
        Training solutions (:class:`SolutionLibrary`), or None. With one,
        the guess and the constraint multipliers are the nearest training
        task's solution and multipliers (among the library's candidate
        tasks, the solution nearest the network's guess), the networks'
        only where the library has none (the bound multipliers).

    """

    def __init__(
        self,
        mlp: MLP,
        header: dict[str, Any],
        multipliers: MLP | None = None,
        library: SolutionLibrary | None = None,
    ) -> None:
        self.mlp = mlp
        self.header = header
        self.multiplier_mlp = multipliers
        self.library = library

    def network_only(self) -> LearnedModel:
        """The model without its solution library: the networks' guesses and multipliers."""
        if self.library is None:
            return self
        return LearnedModel(self.mlp, self.header, self.multiplier_mlp, None)

    @property
    def name(self) -> str:
        """The model's name (its file's stem when loaded)."""
        return str(self.header.get("name", "model"))

    @property
    def fingerprint(self) -> str:
        """SHA-256 of the networks' arrays: the same for the same weights, whatever the name."""
        digest = hashlib.sha256()
        nets: list[tuple[str, MLP | SolutionLibrary]] = [("", self.mlp)]
        nets += [("m_", self.multiplier_mlp)] if self.multiplier_mlp else []
        nets += [("lib_", self.library)] if self.library else []
        for prefix, net in nets:
            for key, value in sorted(net.arrays().items()):
                array = np.ascontiguousarray(value)
                digest.update(f"{prefix}{key}:{array.dtype.str}:{array.shape}".encode())
                digest.update(array.tobytes())
        return digest.hexdigest()

    @property
    def problem(self) -> ProblemSpec:
        """The problem it was trained for."""
        return ProblemSpec.from_dict(self.header["problem"])

    def predict_tasks(self, tasks: list[Task]) -> NDArray[np.float64]:
        """Initial guesses (n, n_variables) for ``tasks``."""
        features = task_features(tasks)
        guesses = np.atleast_2d(self.mlp(features))
        if self.library is not None:
            return self.library.x[self._picked(features, guesses)].astype(float)
        return guesses

    def _picked(
        self, features: NDArray[np.float64], guesses: NDArray[np.float64] | None = None
    ) -> NDArray[np.intp]:
        """The library rows whose solutions stand in for the network's guesses."""
        assert self.library is not None
        if guesses is None:
            guesses = np.atleast_2d(self.mlp(features))
        return self.library.pick(features, guesses, self.mlp.out_scale)

    def predict_multipliers(
        self, tasks: list[Task]
    ) -> tuple[NDArray[np.float64] | None, NDArray[np.float64] | None]:
        """Predicted (lam_x (n, n_variables), lam_g (n, n_constraints)), or (None, None)."""
        features = task_features(tasks)
        if self.library is not None:
            lam_g = self.library.lam_g[self._picked(features)].astype(float)
            if self.multiplier_mlp is None:
                return np.zeros((lam_g.shape[0], self.mlp.n_outputs)), lam_g
            lam_x = np.atleast_2d(self.multiplier_mlp(features))[:, : self.mlp.n_outputs]
            return lam_x, lam_g
        if self.multiplier_mlp is None:
            return None, None
        both = np.atleast_2d(self.multiplier_mlp(features))
        n_x = int(self.header["multipliers"]["n_lam_x"])
        return both[:, :n_x], both[:, n_x:]

    def cost_limits(self, tasks: list[Task]) -> NDArray[np.float64] | None:
        """Per task the cost above which a solve ended in a poor minimum, or None.

        The per-task g_max of the training header's task cost model
        (:class:`~roughwalk.learning.task_cost_model.TaskCostModel`); None
        for a model trained without one.
        """
        fitted = self.header.get("training", {}).get("task_cost_model")
        if not fitted:
            return None
        return TaskCostModel.from_dict(fitted).threshold(task_features(tasks))

    def other_starts(self, task: Task) -> list[Start]:
        """Further starts for ``task``: the library's candidates (none without a library).

        The candidate tasks' solutions and constraint multipliers (the bound
        multipliers are the network's), nearest task first, the pick
        included; :func:`~roughwalk.learning.solution_library.farthest`
        chooses among them. Neighbouring tasks' solutions lie in different
        basins of the NLP: on held-out single-pallet tasks 58, 72 and 102
        the pick ends 33, 36 and 32 % above the best cost found, and another
        candidate's solution reaches it.
        """
        if self.library is None:
            return []
        features = task_features([task])
        near = self.library.nearest(features, self.library.candidates)[0]
        lam_x, _ = self.predict_multipliers([task])
        bound = None if lam_x is None else lam_x[0]
        # The library's own float32 rows, not copies: a run of 2000 tasks holds
        # ten candidates for each of its jobs.
        return [(self.library.x[j], bound, self.library.lam_g[j]) for j in near]

    def predict(self, task: Task) -> NDArray[np.float64]:
        """The initial guess (n_variables,) for one task."""
        return self.predict_tasks([task])[0]

    def mismatches(self, signature: dict[str, Any]) -> list[str]:
        """What differs between the model and a problem's signature, in words."""
        mine = {**self.header["problem"], "layout": self.header["layout"]}
        out = []
        for key in _CHECKED:
            if key not in signature and key not in _ABSENT_MEANS:
                continue
            theirs = signature.get(key, _ABSENT_MEANS.get(key))
            if _norm(mine.get(key, _ABSENT_MEANS.get(key))) != _norm(theirs):
                ours = mine.get(key, _ABSENT_MEANS.get(key))
                out.append(f"{key} is {ours!r} in the model but {theirs!r} here")
        layout_differs = _norm(mine["layout"]) != _norm(signature.get("layout", mine["layout"]))
        if not out and layout_differs:
            theirs = {n: s for n, s in signature["layout"]}
            ours = {n: s for n, s in mine["layout"]}
            diff = [n for n in {**ours, **theirs} if ours.get(n) != theirs.get(n)]
            out.append(f"variable layout differs in {', '.join(sorted(diff)) or 'order'}")
        return out

    def check(self, nlp: Formulation) -> None:
        """Refuse ``nlp`` if it is not the problem the model was trained for."""
        self.check_signature(problem_signature(nlp))

    def check_signature(self, signature: dict[str, Any]) -> None:
        """Refuse a problem ``signature`` that differs, naming what differs."""
        problems = self.mismatches(signature)
        if problems:
            raise ConfigError(
                f"learned model '{self.name}' does not fit this problem: " + "; ".join(problems)
            )

    def save(self, path: str | Path) -> Path:
        """Write the model as ``path`` (.npz): arrays plus the header as JSON text."""
        target = Path(path).with_suffix(".npz")
        target.parent.mkdir(parents=True, exist_ok=True)
        header = {**self.header, "name": target.stem}
        header["network"] = {
            "hidden_layers": list(self.mlp.hidden_layers),
            "activation": self.mlp.activation,
            "n_layers": len(self.mlp.weights),
        }
        arrays: dict[str, Any] = dict(self.mlp.arrays())
        if self.multiplier_mlp is not None:
            header["multipliers"] = {
                **header.get("multipliers", {}),
                "hidden_layers": list(self.multiplier_mlp.hidden_layers),
                "activation": self.multiplier_mlp.activation,
                "n_layers": len(self.multiplier_mlp.weights),
            }
            arrays.update({f"m_{k}": v for k, v in self.multiplier_mlp.arrays().items()})
        else:
            header["multipliers"] = None
        if self.library is not None:
            header["library"] = {
                "n_solutions": len(self.library),
                "candidates": self.library.candidates,
                "features": list(FEATURES),
            }
            arrays.update({f"lib_{k}": v for k, v in self.library.arrays().items()})
        else:
            header["library"] = None
        tmp = target.with_name(target.name + ".part")
        with open(tmp, "wb") as f:
            np.savez_compressed(f, header=np.array(json.dumps(header)), **arrays)
        os.replace(tmp, target)
        self.header = header
        return target

    @classmethod
    def load(cls, path: str | Path) -> LearnedModel:
        """Read a model written by :meth:`save` (no pickle is ever loaded)."""
        target = Path(path)
        if not target.is_file():
            raise ConfigError(f"no learned model at {target}")
        with np.load(target, allow_pickle=False) as data:
            arrays = {k: data[k] for k in data.files}
        if "header" not in arrays:
            raise ConfigError(f"{target} is not a learned model (no header)")
        header = json.loads(str(arrays.pop("header")))
        if header.get("format") != MODEL_FORMAT:
            raise ConfigError(f"{target} is not a roughwalk learned model")
        if int(header.get("version", 0)) > MODEL_VERSION:
            raise ConfigError(
                f"{target} has model version {header['version']}; this roughwalk reads "
                f"up to {MODEL_VERSION}"
            )
        net = header["network"]
        header["name"] = target.stem
        multipliers = None
        if header.get("multipliers"):
            m = header["multipliers"]
            own = {k[2:]: v for k, v in arrays.items() if k.startswith("m_")}
            multipliers = MLP.from_arrays(own, m["activation"], int(m["n_layers"]))
        library = None
        if header.get("library"):
            library = SolutionLibrary.from_arrays(
                {k[4:]: v for k, v in arrays.items() if k.startswith("lib_")}
            )
        return cls(
            MLP.from_arrays(arrays, net["activation"], int(net["n_layers"])),
            header,
            multipliers,
            library,
        )


def _norm(value: Any) -> Any:
    """Compare JSON-ish values: tuples as lists, floats rounded."""
    if isinstance(value, (list, tuple)):
        return [_norm(v) for v in value]
    if isinstance(value, float):
        return round(value, 9)
    return value
