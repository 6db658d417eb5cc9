"""A versioned experience dataset: one row per solved task, as npz arrays plus a JSON schema.

The arrays (task, initial guess, final solution vector, cost, status,
iterations, times) go in ``NAME.npz``; ``NAME.json`` says what each column
is, in which unit, the dataset's version and the problem it belongs to
(robot, terrain, gait, steps, variable layout), so that a dataset is
readable without this code and refused when mixed with another problem's.
"""

from __future__ import annotations

import json
import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from roughwalk.errors import ConfigError, InvalidArgumentError

__all__ = ["Dataset", "SCHEMA_VERSION", "COLUMNS", "TIMING_COLUMNS", "MULTIPLIER_COLUMNS"]

SCHEMA_VERSION = 1

# name → (unit, description)
COLUMNS: dict[str, tuple[str, str]] = {
    "index": ("-", "task index within its split (the task space's random stream)"),
    "start": ("m, m, rad", "start base (x, y, yaw)"),
    "goal": ("m, m, rad", "goal base (x, y, yaw)"),
    "x0": ("mixed", "initial guess: the NLP's variable vector (see layout)"),
    "x": ("mixed", "final solution vector (see layout)"),
    "lam_x": ("mixed", "final bound multipliers (NaN where not recorded)"),
    "lam_g": ("mixed", "final constraint multipliers (NaN where not recorded)"),
    "cost": ("-", "objective g(y) of the final solution"),
    "status": ("-", "TrajoptStatus value ('exact', 'iteration_limit', ...)"),
    "iterations": ("-", "IPOPT iterations"),
    "max_violation": ("constraints' units", "largest constraint or bound violation"),
    "max_force_n": ("N", "largest contact force magnitude"),
    "solve_time_s": ("s", "wall time of the solve (without building the NLP)"),
    "first_iteration_s": ("s", "wall time to the end of the first iteration"),
    "time_per_iteration_s": ("s", "mean wall time of the later iterations"),
}
TIMING_COLUMNS = ("solve_time_s", "first_iteration_s", "time_per_iteration_s")
MULTIPLIER_COLUMNS = ("lam_x", "lam_g")


class Dataset:
    """Rows of experience with their metadata (problem, task space, how they were made).

    Parameters
    ----------
    columns:
        Arrays by name (:data:`COLUMNS`), all with the same first dimension.
    meta:
        JSON-able metadata: "problem", "task_space", "layout", "split",
        "seed", "init", "max_iter", ...

    """

    def __init__(self, columns: Mapping[str, NDArray[Any]], meta: Mapping[str, Any]) -> None:
        columns = dict(columns)
        n = len(columns.get("index", ()))
        for name in MULTIPLIER_COLUMNS:
            # Rows made before multipliers were recorded (schema version 1 without them).
            columns.setdefault(name, np.full((n, 0), np.nan))
        missing = [c for c in COLUMNS if c not in columns]
        if missing:
            raise InvalidArgumentError(f"dataset lacks the columns {missing}")
        sizes = {name: len(columns[name]) for name in COLUMNS}
        if len(set(sizes.values())) > 1:
            raise InvalidArgumentError(f"dataset columns differ in length: {sizes}")
        self.columns = {name: np.asarray(columns[name]) for name in COLUMNS}
        self.meta = dict(meta)

    def __len__(self) -> int:
        return len(self.columns["index"])

    def __getitem__(self, name: str) -> NDArray[Any]:
        return self.columns[name]

    @classmethod
    def from_rows(cls, rows: Sequence[Mapping[str, Any]], meta: Mapping[str, Any]) -> Dataset:
        """A dataset from per-task rows (dicts of the :data:`COLUMNS`), sorted by index."""
        ordered = sorted(rows, key=lambda r: int(r["index"]))
        columns: dict[str, NDArray[Any]] = {}
        for name in MULTIPLIER_COLUMNS:
            size = max((np.size(r[name]) for r in ordered if name in r), default=0)
            ordered = [
                r if name in r and np.size(r[name]) == size else {**r, name: np.full(size, np.nan)}
                for r in ordered
            ]
        for name in COLUMNS:
            values = [r[name] for r in ordered]
            if name == "status":
                columns[name] = np.array(values, dtype="U24")
            elif name in ("index", "iterations"):
                columns[name] = np.array(values, dtype=np.int64)
            elif values:
                columns[name] = np.array(values, dtype=np.float64)
            elif name in MULTIPLIER_COLUMNS:
                columns[name] = np.zeros((0, 0), dtype=np.float64)
            else:
                columns[name] = np.zeros((0,), dtype=np.float64)
        return cls(columns, meta)

    def select(self, mask: NDArray[np.bool_]) -> Dataset:
        """The rows where ``mask`` is true."""
        return Dataset({k: v[mask] for k, v in self.columns.items()}, self.meta)

    def append(self, other: Dataset) -> Dataset:
        """Both datasets' rows; refused if they belong to different problems."""
        for key in ("problem", "layout", "task_space", "split", "seed"):
            if self.meta.get(key) != other.meta.get(key):
                raise InvalidArgumentError(
                    f"cannot append: the datasets differ in '{key}' "
                    f"({self.meta.get(key)!r} vs {other.meta.get(key)!r})"
                )
        both = set(self["index"].tolist()) & set(other["index"].tolist())
        if both:
            raise InvalidArgumentError(
                f"cannot append: {len(both)} task indices are in both (e.g. {min(both)})"
            )
        merged = {}
        for k in COLUMNS:
            a, b = self[k], other[k]
            if k in MULTIPLIER_COLUMNS and a.shape[1:] != b.shape[1:]:
                width = max(a.shape[1], b.shape[1])
                a, b = (_pad(v, width) for v in (a, b))
            merged[k] = np.concatenate([a, b])
        order = np.argsort(merged["index"], kind="stable")
        return Dataset({k: v[order] for k, v in merged.items()}, self.meta)

    def schema(self) -> dict[str, Any]:
        """The JSON schema: version, columns with unit, dtype and shape, and the metadata."""
        return {
            "format": "roughwalk.experience",
            "version": SCHEMA_VERSION,
            "rows": len(self),
            "columns": {
                name: {
                    "unit": unit,
                    "description": text,
                    "dtype": str(self.columns[name].dtype),
                    "shape": list(self.columns[name].shape),
                }
                for name, (unit, text) in COLUMNS.items()
            },
            "meta": self.meta,
        }

    def save(self, path: str | Path) -> Path:
        """Write ``path`` (.npz) and its schema beside it (.json), atomically each."""
        target = Path(path).with_suffix(".npz")
        target.parent.mkdir(parents=True, exist_ok=True)
        tmp = target.with_name(target.name + ".part")
        with open(tmp, "wb") as f:
            columns: dict[str, Any] = dict(self.columns)
            np.savez_compressed(f, **columns)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, target)
        schema_path = target.with_suffix(".json")
        tmp_json = schema_path.with_name(schema_path.name + ".part")
        tmp_json.write_text(json.dumps(self.schema(), indent=1) + "\n")
        os.replace(tmp_json, schema_path)
        return target

    @classmethod
    def load(cls, path: str | Path) -> Dataset:
        """Read a dataset written by :meth:`save`; refuse another format or a newer version."""
        target = Path(path).with_suffix(".npz")
        schema_path = target.with_suffix(".json")
        if not target.is_file() or not schema_path.is_file():
            raise ConfigError(
                f"no dataset at {target} (needs {target.name} and {schema_path.name})"
            )
        schema = json.loads(schema_path.read_text())
        if schema.get("format") != "roughwalk.experience":
            raise ConfigError(f"{schema_path} is not a roughwalk experience dataset")
        if int(schema.get("version", 0)) > SCHEMA_VERSION:
            raise ConfigError(
                f"{schema_path} has schema version {schema['version']}; "
                f"this roughwalk reads up to {SCHEMA_VERSION}"
            )
        with np.load(target, allow_pickle=False) as data:
            columns = {name: data[name] for name in data.files}
        return cls(columns, schema.get("meta", {}))

    def same_rows(self, other: Dataset, *, ignore: Sequence[str] = TIMING_COLUMNS) -> bool:
        """Whether both hold the same rows (timings ignored), NaN equal to NaN."""
        return len(self) == len(other) and not self.differing_columns(other, ignore=ignore)

    def differing_columns(
        self, other: Dataset, *, ignore: Sequence[str] = TIMING_COLUMNS
    ) -> list[str]:
        """The columns (``ignore`` left out) whose values differ, NaN equal to NaN.

        Both datasets must have the same number of rows.
        """
        if len(self) != len(other):
            raise ValueError(f"{len(self)} rows against {len(other)}")
        out = []
        for name in COLUMNS:
            if name in ignore:
                continue
            a, b = self[name], other[name]
            if a.dtype.kind in "fc":
                same = a.shape == b.shape and np.array_equal(a, b, equal_nan=True)
            else:
                same = np.array_equal(a, b)
            if not same:
                out.append(name)
        return out


def _pad(values: NDArray[Any], width: int) -> NDArray[Any]:
    """Rows without multipliers widened with NaN to ``width`` columns."""
    if values.shape[1] == width:
        return values
    return np.full((values.shape[0], width), np.nan)
