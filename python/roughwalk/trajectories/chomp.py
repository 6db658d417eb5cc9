"""CHOMP: covariant gradient descent on a sampled trajectory (Ratliff 2009; Zucker 2011, §5.1).

The trajectory ξ (n interior samples × m coordinates, ends fixed) minimises
U(ξ) = f_smooth(ξ) + Σ other terms, by the covariant ("natural") update

    ξ ← ξ − α·A⁻¹·∇U(ξ),

A the smoothness metric (:class:`~roughwalk.trajectories.costs.Smoothness`),
applied by a banded solve. The other terms come from an ``evaluate``
callback so a pass (trunk or swing leg, §5.3) computes its kinematics once
per iteration for all of them. Only the deterministic optimisation is used,
as in the paper (no Hamiltonian Monte Carlo).

Safeguards, all off the paper's path when steps are small: a trust region
caps how far one update moves any sample; (optionally) a step that would
raise U is halved until it does not, and when no halving helps the
optimiser has converged; and a step must not worsen the evaluation's
``violation`` of hard requirements (a supporting foot lost, a joint velocity
limit broken), which the penalty terms only discourage.
"""

from __future__ import annotations

import enum
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from roughwalk.errors import InvalidArgumentError
from roughwalk.trajectories.costs.smoothness import Smoothness

__all__ = ["Chomp", "ChompStatus", "ChompResult", "Evaluation"]

_HALVINGS = 6


@dataclass(frozen=True)
class Evaluation:
    """What an ``evaluate(ξ)`` callback returns for the non-smoothness terms.

    ``value`` and ``gradient`` (n, m) are their sum; ``parts`` names each
    term's value; ``feasible`` says whether the trajectory already meets
    every requirement (CHOMP then stops); ``violation`` (≥ 0) measures how
    badly it breaks the hard ones, which no accepted step may increase.
    """

    value: float
    gradient: NDArray[np.float64]
    parts: dict[str, float] = field(default_factory=dict)
    feasible: bool = False
    violation: float = 0.0


class ChompStatus(enum.Enum):
    """Why an optimisation stopped."""

    VALID = "valid"
    """The trajectory met every requirement."""
    ITERATION_LIMIT = "iteration_limit"
    """The iteration budget ran out."""
    CONVERGED = "converged"
    """No step (even halved) lowered the objective any more."""
    FIXED_INFEASIBLE = "fixed_samples_infeasible"
    """Samples CHOMP may not move (ends, lift-off, touchdown) already break a
    requirement, so it was not run: the plan's poses are at fault."""


@dataclass
class ChompResult:
    """The optimised interior samples and how the optimisation went.

    ``objective`` holds U before the first and after every iteration;
    ``halvings`` how often each iteration's step was halved.
    """

    xi: NDArray[np.float64]
    status: ChompStatus
    iterations: int
    objective: list[float]
    halvings: list[int]
    last: Evaluation


class Chomp:
    """The CHOMP update on one block of coordinates.

    Parameters
    ----------
    smoothness:
        f_smooth and its metric A (with the coordinate weights).
    evaluate:
        ξ (n, m) → :class:`Evaluation` of every other term.
    step_size:
        α.
    max_step:
        Trust region [m]: the largest √w_d·|Δξ_{t,d}| one update may make.
    line_search:
        Halve steps that would raise U.
    project:
        Optional map applied after each update (e.g. clamping to joint limits).
    """

    def __init__(
        self,
        smoothness: Smoothness,
        evaluate: Callable[[NDArray[np.float64]], Evaluation],
        *,
        step_size: float,
        max_step: float = np.inf,
        line_search: bool = True,
        project: Callable[[NDArray[np.float64]], NDArray[np.float64]] | None = None,
    ) -> None:
        if not step_size > 0:
            raise InvalidArgumentError(f"CHOMP step size must be positive, got {step_size}")
        self.smoothness = smoothness
        self.evaluate = evaluate
        self.step_size = float(step_size)
        self.max_step = float(max_step)
        self.line_search = line_search
        self.project = project

    def objective(self, xi: NDArray[np.float64], ev: Evaluation) -> float:
        """U(ξ) given the evaluation of the other terms at ξ."""
        return ev.value + self.smoothness.value(xi)

    def direction(self, xi: NDArray[np.float64], ev: Evaluation) -> NDArray[np.float64]:
        """−α·A⁻¹∇U, limited to the trust region."""
        grad = ev.gradient + self.smoothness.gradient(xi)
        step = -self.step_size * self.smoothness.precondition(grad)
        size = float(np.max(np.abs(step) * np.sqrt(self.smoothness.metric))) if step.size else 0.0
        if size > self.max_step:
            step *= self.max_step / size
        return step

    def optimize(
        self, xi: NDArray[np.float64], iterations: int, stop_when_feasible: bool = True
    ) -> ChompResult:
        """Run at most ``iterations`` updates from ξ (n, m)."""
        x = np.array(xi, dtype=float)
        ev = self.evaluate(x)
        u = self.objective(x, ev)
        history = [u]
        halvings: list[int] = []
        status = ChompStatus.ITERATION_LIMIT
        done = 0
        # The line search remembers how far it had to halve, and grows back
        # when steps are accepted at once, so it rarely evaluates in vain.
        scale = 1.0
        for _ in range(iterations):
            if stop_when_feasible and ev.feasible:
                status = ChompStatus.VALID
                break
            step = self.direction(x, ev) * scale
            accepted = False
            for h in range(_HALVINGS + 1 if self.line_search else 1):
                candidate = x + step
                if self.project is not None:
                    candidate = self.project(candidate)
                ev_new = self.evaluate(candidate)
                u_new = self.objective(candidate, ev_new)
                allowed = ev_new.violation <= ev.violation + 1e-12
                if not self.line_search or (u_new < u and allowed):
                    x, ev, u = candidate, ev_new, u_new
                    halvings.append(h)
                    accepted = True
                    scale = min(1.0, scale * 2.0) if h == 0 else scale * 0.5**h
                    break
                step = 0.5 * step
            if not accepted:
                status = ChompStatus.CONVERGED
                break
            done += 1
            history.append(u)
        else:
            if stop_when_feasible and ev.feasible:
                status = ChompStatus.VALID
        return ChompResult(x, status, done, history, halvings, ev)
