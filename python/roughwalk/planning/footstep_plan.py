"""The result of a footstep plan: footsteps, pose certificates, anytime solutions, totals.

Its JSON (:meth:`FootstepPlan.to_json`) is what ``roughwalk plan --json``
writes and what trajectory generation reads: ``footsteps`` [{leg, x, y, z}]
in execution order starting with the initial stance (four feet, LF, RF, LH,
RH), ``certificates`` [{step, base_pos, base_quat, q}] — one per footstep
after the initial stance, ``step`` counting from 1, holding the stance that
step reaches with the CoM over the support triangle of the next step —
``initial_pose`` (the initial stance's certificate), and the search's
statistics.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

__all__ = ["Footstep", "PoseCertificate", "SolutionReport", "FootstepPlan"]


def _finite_or_none(x: float | None) -> float | None:
    return None if x is None or not math.isfinite(x) else float(x)


@dataclass(frozen=True)
class Footstep:
    """A foothold: leg name and the contact point on the terrain (x, y, z) [m]."""

    leg: str
    x: float
    y: float
    z: float

    def to_json(self) -> dict[str, Any]:
        """``{leg, x, y, z}``."""
        return {"leg": self.leg, "x": self.x, "y": self.y, "z": self.z}


@dataclass(frozen=True)
class PoseCertificate:
    """A certified 18-DOF pose (Zucker 2011, §4.4).

    Attributes
    ----------
    step:
        The step whose stance it holds (1 = first step; 0 = the initial stance).
    base_pos:
        Trunk position [m].
    base_quat:
        Trunk orientation (w, x, y, z).
    q:
        (12,) joint angles [rad] in ``Robot.joint_names`` order.
    com, com_margin:
        Whole-body centre of mass [m] and its distance inside the support
        triangle of the next step [m].
    clearance:
        Least body clearance (feet excluded) [m], at least the planner's
        ``preferred_clearance`` when equal to it.
    singularity:
        Least normalised leg-Jacobian volume (1 far from singular, 0 singular).
    penalty:
        Its pose cost (singularity and clearance penalties).
    iterations:
        Correction rounds the search took.

    """

    step: int
    base_pos: NDArray[np.float64]
    base_quat: NDArray[np.float64]
    q: NDArray[np.float64]
    com: NDArray[np.float64]
    com_margin: float
    clearance: float
    singularity: float
    penalty: float
    iterations: int

    def to_json(self) -> dict[str, Any]:
        """``{step, base_pos, base_quat, q}`` plus the certificate's diagnostics."""
        return {
            "step": self.step,
            "base_pos": self.base_pos.tolist(),
            "base_quat": self.base_quat.tolist(),
            "q": self.q.tolist(),
            "com": self.com.tolist(),
            "com_margin": self.com_margin,
            "clearance": self.clearance,
            "singularity": self.singularity,
            "penalty": self.penalty,
            "iterations": self.iterations,
        }


@dataclass(frozen=True)
class SolutionReport:
    """One improved solution of the anytime search, as it was found."""

    time_s: float
    cost: float
    epsilon: float
    epsilon_bound: float
    expansions: int

    def to_json(self) -> dict[str, Any]:
        """``{time_s, cost, epsilon, epsilon_bound, expansions}``."""
        return {
            "time_s": self.time_s,
            "cost": self.cost,
            "epsilon": self.epsilon,
            "epsilon_bound": _finite_or_none(self.epsilon_bound),
            "expansions": self.expansions,
        }


@dataclass(frozen=True)
class FootstepPlan:
    """What :meth:`FootstepPlanner.plan` returns.

    Attributes
    ----------
    status:
        ``"solved"`` (a plan reaches the goal; how good it is, is
        ``epsilon_bound``), ``"no_solution"`` (the budget ran out first),
        ``"infeasible"`` (the search space was exhausted) or ``"invalid_input"``.
    reason:
        Why the input was invalid (None otherwise).
    start_off_foothold:
        With ``"invalid_input"`` because a start foot stands on no foothold
        (off the terrain, unknown, or of infinite cost on the planner's
        lattice): that foot's leg (``"LF"``, ...). None otherwise. A caller
        may move that foot onto a foothold and plan again.
    footsteps:
        The initial stance (LF, RF, LH, RH), then one footstep per step.
    certificates:
        One per step (``step`` 1, 2, ...).
    initial_pose:
        The initial stance's certificate (``step`` 0), if there is a plan.
    heuristic:
        ``"dubins"`` or ``"euclidean"``.
    bound_guaranteed:
        Whether ``epsilon_bound`` is proven (only with the admissible Euclidean heuristic).
    epsilon0, epsilon_decrement, final_epsilon:
        The ε schedule and the ε of the last iteration.
    epsilon_bound:
        Suboptimality bound ε′ of the plan (cost ≤ ε′ × optimum when guaranteed).
    cost:
        Cost of the plan.
    solutions:
        Every improved solution in the order found.
    states_expanded, states_generated, actions_evaluated:
        Search totals. An action is evaluated when its certificate search ran.
    search_s, elapsed_s:
        Time in the search, and of the whole call [s].
    certificate_cache_hits:
        Actions whose certificate outcome came from the cache.
    certificate_rounds:
        Correction rounds of the certificates found (1 when the guessed pose
        needed none), summed.
    certificate_failures:
        Failed certificate searches by what was left to correct:
        ``{"unreachable", "center_of_mass", "collision"}``.
    tree:
        (N, 5) search-tree foot moves [leg, x0, y0, x1, y1] for pictures.
    robot, terrain:
        The robot's name and the terrain's spec.
    start, goal:
        The start (x, y, yaw) or feet it planned from, and the goal (x, y).

    """

    status: str
    reason: str | None
    footsteps: tuple[Footstep, ...]
    certificates: tuple[PoseCertificate, ...]
    initial_pose: PoseCertificate | None
    heuristic: str
    bound_guaranteed: bool
    epsilon0: float
    epsilon_decrement: float
    final_epsilon: float
    epsilon_bound: float
    cost: float | None
    solutions: tuple[SolutionReport, ...]
    states_expanded: int
    states_generated: int
    actions_evaluated: int
    search_s: float
    elapsed_s: float
    certificate_cache_hits: int
    certificate_rounds: int
    certificate_failures: dict[str, int]
    tree: NDArray[np.float64] = field(repr=False)
    robot: str = ""
    terrain: str = ""
    start: tuple[float, ...] = ()
    goal: tuple[float, float] = (math.nan, math.nan)
    start_off_foothold: str | None = None

    @property
    def solved(self) -> bool:
        """Whether a plan reaches the goal."""
        return self.status == "solved"

    @property
    def first_solution_s(self) -> float | None:
        """Time to the first plan [s] (None without one)."""
        return self.solutions[0].time_s if self.solutions else None

    @property
    def actions_per_s(self) -> float:
        """Actions evaluated per second of search [1/s]."""
        return self.actions_evaluated / self.search_s if self.search_s > 0 else 0.0

    @property
    def steps(self) -> int:
        """Number of steps (footsteps after the initial stance)."""
        return max(len(self.footsteps) - 4, 0)

    def stances(self) -> NDArray[np.float64]:
        """(steps + 1, 4, 3) feet [m], canonical order: the initial stance, then after each step."""
        if not self.footsteps:
            return np.zeros((0, 4, 3))
        legs = ("LF", "RF", "LH", "RH")
        current = np.array([[f.x, f.y, f.z] for f in self.footsteps[:4]])
        out = [current.copy()]
        for f in self.footsteps[4:]:
            current[legs.index(f.leg)] = (f.x, f.y, f.z)
            out.append(current.copy())
        return np.array(out)

    def to_json(self) -> dict[str, Any]:
        """The plan as JSON-ready data (the fields of the issue, then diagnostics)."""
        return {
            "status": self.status,
            "reason": self.reason,
            "start_off_foothold": self.start_off_foothold,
            "footsteps": [f.to_json() for f in self.footsteps],
            "certificates": [c.to_json() for c in self.certificates],
            "initial_pose": None if self.initial_pose is None else self.initial_pose.to_json(),
            "heuristic": self.heuristic,
            "bound_guaranteed": self.bound_guaranteed,
            "epsilon0": self.epsilon0,
            "epsilon_decrement": self.epsilon_decrement,
            "final_epsilon": self.final_epsilon,
            "first_solution_s": self.first_solution_s,
            "solutions": [s.to_json() for s in self.solutions],
            "states_expanded": self.states_expanded,
            "states_generated": self.states_generated,
            "actions_evaluated": self.actions_evaluated,
            "actions_per_s": self.actions_per_s,
            "cost": self.cost,
            "epsilon_bound": _finite_or_none(self.epsilon_bound),
            "search_s": self.search_s,
            "elapsed_s": self.elapsed_s,
            "certificate_cache_hits": self.certificate_cache_hits,
            "certificate_rounds": self.certificate_rounds,
            "certificate_failures": dict(self.certificate_failures),
            "robot": self.robot,
            "terrain": self.terrain,
            "start": [_finite_or_none(v) for v in self.start],
            "goal": [_finite_or_none(v) for v in self.goal],
        }
