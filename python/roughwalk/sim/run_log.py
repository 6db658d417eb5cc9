"""The :class:`RunLog`: the states of a run at the control rate, and its events.

Saved as two files side by side: ``NAME.npz`` (the arrays, float32 but for
time) and ``NAME.json`` (what was run, the events, the outcome). Either
path loads both; ``roughwalk replay`` re-renders a run from them.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from roughwalk.errors import InvalidArgumentError

if TYPE_CHECKING:
    from roughwalk.sim.measured_state import MeasuredState
    from roughwalk.sim.trajectory_buffer import DesiredState

__all__ = ["RunLog", "MODES", "OTHER_PHASE"]

MODES = ("walk", "wait", "recovery", "replan", "blend", "done", "gate")
"""What the executor was doing, by the code stored in ``mode``."""

OTHER_PHASE = 3
"""The ``phase`` code of a tick whose desired state is not a footstep's
(a hold, a blend, a recovery); a footstep's are 0 shift, 1 swing, 2 settle,
and -1 means no desired state."""

_FIELDS: dict[str, tuple[int, ...]] = {
    "qpos": (-1,),
    "q": (12,),
    "q_desired": (12,),
    "q_command": (12,),
    "base_pos": (3,),
    "base_quat": (4,),
    "base_pos_desired": (3,),
    "base_quat_desired": (4,),
    "base_vel": (3,),
    "feet": (4, 3),
    "feet_desired": (4, 3),
    "foot_forces": (4, 3),
    "forces_desired": (4, 3),
    "support_desired": (4,),
    "actuator_force": (12,),
    "integrator": (4, 3),
    "stiffness": (4,),
}


def _json_safe(value: Any) -> Any:
    if isinstance(value, dict):
        return {str(k): _json_safe(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_json_safe(v) for v in value]
    if isinstance(value, np.ndarray):
        return _json_safe(value.tolist())
    if isinstance(value, np.generic):
        return _json_safe(value.item())
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


class RunLog:
    """Per-tick records and timed events of one run.

    Parameters
    ----------
    meta:
        What was run (robot, terrain spec, start, goal, rates, joint names,
        config...), stored in the JSON file.
    """

    def __init__(self, meta: dict[str, Any] | None = None) -> None:
        self.meta: dict[str, Any] = dict(meta or {})
        self.events: list[dict[str, Any]] = []
        self._rows: dict[str, list[Any]] = {
            k: [] for k in (*_FIELDS, "time", "mode", "step", "phase")
        }
        self._arrays: dict[str, NDArray[Any]] | None = None

    def __len__(self) -> int:
        """Ticks recorded."""
        if self._arrays is not None:
            return int(len(self._arrays["time"]))
        return len(self._rows["time"])

    def record(
        self,
        qpos: NDArray[np.float64],
        measured: MeasuredState,
        desired: DesiredState | None,
        q_command: NDArray[np.float64],
        integrator: NDArray[np.float64],
        stiffness: NDArray[np.float64],
        mode: str,
    ) -> None:
        """Append one control tick."""
        rows = self._rows
        self._arrays = None
        rows["time"].append(np.float64(measured.time))
        rows["mode"].append(np.int8(MODES.index(mode)))
        rows["step"].append(np.int16(desired.step if desired is not None else 0))
        if desired is None:
            phase = -1
        else:
            phase = desired.phase if desired.kind == "step" else OTHER_PHASE
        rows["phase"].append(np.int8(phase))
        rows["qpos"].append(np.asarray(qpos, dtype=np.float32))
        rows["q"].append(measured.q.astype(np.float32))
        rows["q_command"].append(np.asarray(q_command, dtype=np.float32))
        rows["base_pos"].append(measured.base_pos.astype(np.float32))
        rows["base_quat"].append(measured.base_quat.astype(np.float32))
        rows["base_vel"].append(measured.base_vel.astype(np.float32))
        rows["feet"].append(measured.feet.astype(np.float32))
        rows["foot_forces"].append(measured.foot_forces.astype(np.float32))
        rows["actuator_force"].append(measured.actuator_force.astype(np.float32))
        rows["integrator"].append(np.asarray(integrator, dtype=np.float32))
        rows["stiffness"].append(np.asarray(stiffness, dtype=np.float32))
        if desired is None:
            nan = np.float32(np.nan)
            rows["q_desired"].append(np.full(12, nan))
            rows["base_pos_desired"].append(np.full(3, nan))
            rows["base_quat_desired"].append(np.full(4, nan))
            rows["feet_desired"].append(np.full((4, 3), nan))
            rows["forces_desired"].append(np.full((4, 3), nan))
            rows["support_desired"].append(np.zeros(4, dtype=bool))
        else:
            rows["q_desired"].append(desired.q.astype(np.float32))
            rows["base_pos_desired"].append(desired.base_pos.astype(np.float32))
            rows["base_quat_desired"].append(desired.base_quat.astype(np.float32))
            rows["feet_desired"].append(desired.feet.astype(np.float32))
            rows["forces_desired"].append(desired.forces.astype(np.float32))
            rows["support_desired"].append(np.asarray(desired.support, dtype=bool))

    def event(self, time: float, kind: str, **details: Any) -> None:
        """Note an event at simulated ``time`` [s]."""
        self.events.append({"time": float(time), "kind": kind, **_json_safe(details)})

    def events_of(self, kind: str) -> list[dict[str, Any]]:
        """The events of one kind, in order."""
        return [e for e in self.events if e["kind"] == kind]

    @property
    def arrays(self) -> dict[str, NDArray[Any]]:
        """Every field stacked over ticks: ``time`` (n,), ``qpos`` (n, nq), ..."""
        if self._arrays is None:
            out: dict[str, NDArray[Any]] = {}
            for k, rows in self._rows.items():
                if rows:
                    out[k] = np.stack(rows)
                else:
                    shape = _FIELDS.get(k, ())
                    out[k] = np.zeros((0, *[max(s, 0) for s in shape]))
            self._arrays = out
        return self._arrays

    def __getitem__(self, name: str) -> NDArray[Any]:
        """One field's array (see :attr:`arrays`)."""
        return self.arrays[name]

    def save(self, path: str | Path) -> tuple[Path, Path]:
        """Write ``path`` with suffixes .npz and .json; returns both paths."""
        base = Path(path)
        if base.suffix in (".npz", ".json"):
            base = base.with_suffix("")
        base.parent.mkdir(parents=True, exist_ok=True)
        npz, js = base.with_suffix(".npz"), base.with_suffix(".json")
        with npz.open("wb") as f:
            arrays: dict[str, Any] = self.arrays
            np.savez_compressed(f, **arrays)
        doc = {"meta": _json_safe(self.meta), "events": self.events, "arrays": npz.name}
        js.write_text(json.dumps(doc, indent=1) + "\n")
        return npz, js

    @classmethod
    def load(cls, path: str | Path) -> RunLog:
        """Read a log written by :meth:`save` (either file's path)."""
        base = Path(path)
        if base.suffix in (".npz", ".json"):
            base = base.with_suffix("")
        npz, js = base.with_suffix(".npz"), base.with_suffix(".json")
        for p in (npz, js):
            if not p.is_file():
                raise InvalidArgumentError(
                    f"run log '{p}' does not exist; a log is a .npz and a .json side by side "
                    "(written by roughwalk run --out-dir)"
                )
        try:
            doc = json.loads(js.read_text())
            meta, events = doc["meta"], doc["events"]
        except (ValueError, KeyError, TypeError) as e:
            raise InvalidArgumentError(f"run log '{js}' is not a roughwalk run log: {e}") from None
        log = cls(meta)
        log.events = list(events)
        try:
            with np.load(npz) as data:
                log._arrays = {k: data[k] for k in data.files}
        except (OSError, ValueError) as e:
            raise InvalidArgumentError(f"run log '{npz}' cannot be read: {e}") from None
        missing = {"time", "qpos"} - set(log._arrays)
        if missing:
            raise InvalidArgumentError(f"run log '{npz}' lacks {sorted(missing)}")
        return log
