"""The result of a trajectory optimisation: status, statistics and the optimised splines.

The splines are kept exactly (node values and polynomial durations), so the
motion can be sampled at any rate (:meth:`TrajoptResult.sample`); the JSON
result holds the nodes and a sampled trajectory (or names an .npz with it),
which is what the whole-body controller reads.

The NLP's base is the single rigid body's centre of mass; samples also give
the robot's base frame origin, c − R·com_in_base.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from roughwalk.errors import PlanningError
from roughwalk.robots._rotations import matrix_to_quat
from roughwalk.trajopt.gaits import ContactSchedule
from roughwalk.trajopt.leg_statics import LegStatics
from roughwalk.trajopt.robot_model import SingleRigidBody
from roughwalk.trajopt.solver import TrajoptStatus
from roughwalk.trajopt.task import Task
from roughwalk.trajopt.variables import (
    NumericSpline,
    angular_velocity,
    euler_to_rotation,
)

__all__ = ["TrajoptResult", "Splines", "RESULT_SCHEMA"]

RESULT_SCHEMA = "trajopt_result"


@dataclass
class Splines:
    """The optimised motion as numeric splines (world frame, SI units).

    Attributes
    ----------
    base_linear:
        CoM position [m] and velocity [m/s].
    base_angular:
        Euler ZYX angles [rad] and rates [rad/s].
    feet:
        Per foot, its position [m].
    forces:
        Per foot, its contact force [N].

    """

    base_linear: NumericSpline
    base_angular: NumericSpline
    feet: list[NumericSpline]
    forces: list[NumericSpline]

    def to_dict(self) -> dict[str, Any]:
        """Node times, values and derivatives of every spline (JSON-ready)."""

        def one(s: NumericSpline) -> dict[str, Any]:
            return {
                "durations": s.durations.tolist(),
                "positions": s.positions.tolist(),
                "velocities": s.velocities.tolist(),
            }

        return {
            "base_linear": one(self.base_linear),
            "base_angular": one(self.base_angular),
            "feet": [one(s) for s in self.feet],
            "forces": [one(s) for s in self.forces],
        }


def _finite(x: float) -> float | None:
    return float(x) if math.isfinite(x) else None


@dataclass
class TrajoptResult:
    """What :func:`~roughwalk.trajopt.optimize_motion` returns.

    Attributes
    ----------
    status:
        How the solve ended (:class:`TrajoptStatus`).
    message:
        A sentence saying why, for people.
    iterations:
        IPOPT iterations.
    solve_time_s:
        Wall time [s] from task to solution, including any building that was not reused.
    build_time_s:
        Of which building the NLP and solver [s] (0 when reused).
    build:
        How the NLP's functions were made: "expression" (CasADi graphs),
        "compiled" (graphs compiled to C and cached; the build time includes
        the compiler's), "cached" (loaded compiled from the cache),
        "serialized" (graphs stored in CasADi's serialised form; the build
        time includes the writing) or "deserialized" (read from that form).
    objective:
        Objective value (0 for TOWR's feasibility problem).
    max_violation:
        Largest constraint violation at the solution (constraints' units: m, N, N·m).
    max_force_n:
        Largest contact force magnitude [N].
    n_variables, n_constraints:
        Size of the NLP.
    task:
        The task.
    config:
        The configuration used (a JSON-ready dict).
    body:
        The single rigid body.
    schedule:
        The contact schedule, with the optimised phase durations.
    splines:
        The optimised splines (None when nothing was solved).
    costs:
        Each cost term's value at the solution.
    violations:
        Each constraint's largest violation at the solution.
    return_status:
        IPOPT's own return status.
    history:
        Per iteration: objective, violation and elapsed time; after a restart
        from an initialiser's fallback guess or a further start, also which
        solve (0, 1, ...) it is of.
    x:
        The solution vector (for warm starts).
    lam_x, lam_g:
        Its bound and constraint multipliers (for warm starts).

    """

    status: TrajoptStatus
    message: str
    iterations: int = 0
    solve_time_s: float = 0.0
    build_time_s: float = 0.0
    build: str = "expression"
    objective: float = float("nan")
    max_violation: float = float("inf")
    max_force_n: float = float("nan")
    n_variables: int = 0
    n_constraints: int = 0
    task: Task | None = None
    config: dict[str, Any] = field(default_factory=dict)
    body: SingleRigidBody | None = None
    schedule: ContactSchedule | None = None
    splines: Splines | None = None
    costs: dict[str, float] = field(default_factory=dict)
    violations: dict[str, float] = field(default_factory=dict)
    return_status: str = ""
    history: list[dict[str, float]] = field(default_factory=list)
    x: NDArray[np.float64] | None = None
    lam_x: NDArray[np.float64] | None = None
    lam_g: NDArray[np.float64] | None = None
    robot: str | None = None
    terrain: str | None = None

    @property
    def solved(self) -> bool:
        """Whether the solve converged (exactly or to IPOPT's acceptable level)."""
        return self.status.solved

    @property
    def duration(self) -> float:
        """Duration of the motion [s] (0 without a solution)."""
        return self.schedule.total_duration if self.schedule is not None else 0.0

    @property
    def time_per_iteration_s(self) -> float:
        """IPOPT's wall time per iteration [s] (building excluded)."""
        return (self.solve_time_s - self.build_time_s) / max(self.iterations, 1)

    # ---------------------------------------------------------------- sampling
    def _need_splines(self) -> Splines:
        if self.splines is None:
            raise PlanningError(f"no trajectory to sample: the solve ended {self.status.value}")
        return self.splines

    def sample(
        self, rate_hz: float | None = None, times: ArrayLike | None = None
    ) -> dict[str, NDArray[Any]]:
        """The motion at ``times`` [s], or every 1/``rate_hz`` [s] from 0 to T inclusive.

        Returns arrays keyed by name: ``t`` (n,); ``com_position``,
        ``base_position`` (robot base frame origin), ``base_linear_velocity``
        (of the CoM), ``base_euler`` (roll, pitch, yaw), ``base_angular_velocity``
        (world frame) (n, 3); ``base_quat`` (n, 4) (w, x, y, z);
        ``feet_position``, ``feet_velocity``, ``forces`` (n, 4, 3); ``contact`` (n, 4).
        """
        s = self._need_splines()
        if times is None:
            rate = rate_hz or 100.0
            if not rate > 0:
                raise PlanningError(f"rate_hz must be > 0, got {rate_hz}")
            n = int(math.floor(self.duration * rate + 1e-9)) + 1
            t = np.arange(n) / rate
            if self.duration - t[-1] > 1e-9:
                t = np.append(t, self.duration)
        else:
            t = np.atleast_1d(np.asarray(times, dtype=float))
        com, com_vel, _ = s.base_linear.evaluate(t)
        euler, rates, _ = s.base_angular.evaluate(t)
        rotations = np.array([euler_to_rotation(e) for e in euler])
        omega = np.array([angular_velocity(e, r) for e, r in zip(euler, rates, strict=True)])
        offset = np.asarray(self.body.com_in_base if self.body else (0.0, 0.0, 0.0))
        base = com - rotations @ offset
        feet = np.stack([f.evaluate(t)[0] for f in s.feet], axis=1)
        feet_vel = np.stack([f.evaluate(t)[1] for f in s.feet], axis=1)
        forces = np.stack([f.evaluate(t)[0] for f in s.forces], axis=1)
        assert self.schedule is not None
        contact = np.stack([self.schedule.in_contact(f, t) for f in range(len(s.feet))], axis=1)
        return {
            "t": t,
            "com_position": com,
            "base_position": base,
            "base_linear_velocity": com_vel,
            "base_euler": euler,
            "base_quat": np.array([matrix_to_quat(r) for r in rotations]),
            "base_angular_velocity": omega,
            "feet_position": feet,
            "feet_velocity": feet_vel,
            "forces": forces,
            "contact": contact,
        }

    # ---------------------------------------------------------------- output
    def summary(self) -> dict[str, Any]:
        """The statistics, JSON-ready (no trajectories)."""
        return {
            "status": self.status.value,
            "solved": self.solved,
            "message": self.message,
            "return_status": self.return_status,
            "iterations": self.iterations,
            "solve_time_s": self.solve_time_s,
            "build_time_s": self.build_time_s,
            "build": self.build,
            "time_per_iteration_s": self.time_per_iteration_s,
            "objective": _finite(self.objective),
            "max_violation": _finite(self.max_violation),
            "max_force_n": _finite(self.max_force_n),
            "n_variables": self.n_variables,
            "n_constraints": self.n_constraints,
        }

    def to_dict(
        self, rate_hz: float | None = None, npz: str | Path | None = None
    ) -> dict[str, Any]:
        """Everything, JSON-ready: statistics, task, schedule, spline nodes and samples.

        With ``npz`` the samples go to that .npz file (which the dict names)
        instead of into the dict.
        """
        out: dict[str, Any] = self.summary()
        out["task"] = (
            {
                "start": [_finite(v) for v in self.task.start],
                "goal": [_finite(v) for v in self.task.goal],
            }
            if self.task
            else None
        )
        out["config"] = self.config
        out["body"] = self.body.to_dict() if self.body else None
        out["costs"] = {k: _finite(v) for k, v in self.costs.items()}
        out["violations"] = {k: _finite(v) for k, v in self.violations.items()}
        out["history"] = self.history
        if self.schedule is not None:
            out["gait"] = self.schedule.name
            out["steps"] = self.schedule.steps
            out["duration"] = self.schedule.total_duration
            out["phase_durations"] = [list(d) for d in self.schedule.durations]
            out["in_contact_at_start"] = list(self.schedule.in_contact_at_start)
        if self.splines is None:
            return out
        out["nodes"] = self.splines.to_dict()
        samples = self.sample(rate_hz or float(self.config.get("sample_rate_hz", 100.0)))
        if npz is not None:
            path = Path(npz)
            path.parent.mkdir(parents=True, exist_ok=True)
            np.savez_compressed(path, **samples)  # type: ignore[arg-type]
            out["trajectory_npz"] = str(path)
        else:
            out["trajectory"] = {k: v.tolist() for k, v in samples.items()}
        return out

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> TrajoptResult:
        """The result written by :meth:`to_dict` (or ``roughwalk optimize --json``), splines exact.

        Samples are not read back: the spline nodes are the motion. Solver
        multipliers and the solution vector are not in the JSON and stay None.
        """

        def spline(d: dict[str, Any]) -> NumericSpline:
            return NumericSpline(d["positions"], d["velocities"], d["durations"])

        try:
            nodes = data.get("nodes")
            splines = (
                Splines(
                    spline(nodes["base_linear"]),
                    spline(nodes["base_angular"]),
                    [spline(f) for f in nodes["feet"]],
                    [spline(f) for f in nodes["forces"]],
                )
                if nodes
                else None
            )
            body = data.get("body")
            schedule = (
                ContactSchedule(
                    str(data.get("gait", "")),
                    tuple(tuple(float(v) for v in foot) for foot in data["phase_durations"]),
                    tuple(bool(c) for c in data["in_contact_at_start"]),
                )
                if "phase_durations" in data
                else None
            )
            return cls(
                status=TrajoptStatus(data["status"]),
                message=str(data.get("message", "")),
                iterations=int(data.get("iterations", 0)),
                solve_time_s=float(data.get("solve_time_s", 0.0)),
                build_time_s=float(data.get("build_time_s", 0.0)),
                build=str(data.get("build", "expression")),
                objective=float(data.get("objective") or math.nan),
                max_violation=float(data.get("max_violation") or 0.0),
                max_force_n=float(data.get("max_force_n") or math.nan),
                n_variables=int(data.get("n_variables", 0)),
                n_constraints=int(data.get("n_constraints", 0)),
                task=Task.from_any(data["task"]) if data.get("task") else None,
                config=dict(data.get("config", {})),
                body=SingleRigidBody(
                    name=body["name"],
                    mass=float(body["mass"]),
                    inertia=tuple(tuple(r) for r in body["inertia"]),  # type: ignore[arg-type]
                    nominal_stance=tuple(tuple(r) for r in body["nominal_stance"]),  # type: ignore[arg-type]
                    max_deviation=tuple(body["max_deviation"]),
                    force_limit=float(body["force_limit"]),
                    friction=float(body["friction"]),
                    com_in_base=tuple(body.get("com_in_base", (0.0, 0.0, 0.0))),
                    reach_centres=None
                    if body.get("reach_centres") is None
                    else tuple(tuple(r) for r in body["reach_centres"]),  # type: ignore[arg-type]
                    reach_radius=body.get("reach_radius"),
                    legs=None
                    if body.get("legs") is None
                    else tuple(LegStatics.from_dict(leg) for leg in body["legs"]),  # type: ignore[arg-type]
                )
                if body
                else None,
                schedule=schedule,
                splines=splines,
                costs={
                    k: float(v) if v is not None else math.nan
                    for k, v in data.get("costs", {}).items()
                },
                violations={
                    k: float(v) if v is not None else math.nan
                    for k, v in data.get("violations", {}).items()
                },
                return_status=str(data.get("return_status", "")),
                history=list(data.get("history", [])),
                robot=data.get("robot"),
                terrain=data.get("terrain"),
            )
        except (KeyError, TypeError, ValueError) as e:
            raise PlanningError(
                f"not a trajopt result (roughwalk optimize --json): {type(e).__name__} {e}"
            ) from None

    @classmethod
    def load(cls, path: str | Path) -> TrajoptResult:
        """Read a result JSON written by ``roughwalk optimize --json`` [file path]."""
        import json

        try:
            data = json.loads(Path(path).read_text())
        except (OSError, ValueError) as e:
            raise PlanningError(f"cannot read trajectory file '{path}': {e}") from None
        if not isinstance(data, dict) or data.get("schema", RESULT_SCHEMA) != RESULT_SCHEMA:
            raise PlanningError(
                f"'{path}' is not a {RESULT_SCHEMA} JSON (roughwalk optimize --json writes one)"
            )
        return cls.from_dict(data)

    def __repr__(self) -> str:
        return (
            f"TrajoptResult({self.status.value}, {self.iterations} iterations, "
            f"{self.solve_time_s:.3f} s, objective {self.objective:.4g}, "
            f"max violation {self.max_violation:.2e})"
        )
