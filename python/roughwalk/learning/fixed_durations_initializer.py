"""The ``learned_fixed_durations`` initialiser: a fixed-duration model's guess, durations optimised.

Figure 8 of Melon et al. 2020 executes plans solved with fixed and with
optimised phase durations. A model trained on fixed-duration solves of an
environment predicts every variable of the optimised-duration NLP but the
phase durations: the two NLPs share their variable sets, in the same order
and of the same sizes, except ``durations_*``, empty when fixed. This
initialiser puts the model's prediction where the optimised layout expects
it and sets the phase durations to the gait's own, the values the fixed
NLP held them at, so that every spline of the guess is the one the model
predicted (the same nodes at the same times): a fixed-duration solution so
mapped meets the optimised NLP's rows as it met the fixed one's. The
optimised durations' bounds admit every gait phase by default
(``TrajoptConfig.phase_bounds_admit_gait``). Where a gait phase lies outside
bounds that do not (TOWR's 0.2–1.0 s as :func:`~roughwalk.trajopt.towr_config`
keeps them; the front-right foot's first stance of the 16-step walk in 5.5 s
lasts 1.079 s) it cannot be held; :func:`gait_durations` clamps it and lets the
next phase absorb the difference, and the guess violates the dynamics
where that foot's force moved (the single pallet's converged fixed solve
of held-out task 0, mapped: largest row violation 125 against 250 at the
NLP's own fitted start, which moves every phase of two feet).

Multipliers: the constraint blocks of the two NLPs are the same, in the same
order, except those with rows only when the durations are optimised
(:data:`DURATION_ROWS`, ``total_duration``); the model's constraint
multipliers fill their own blocks and those rows start at 0 (inactive: each
foot's free phases sum to well below T − 0.2 s). Bound multipliers of the
duration variables start at 0 too.

Why not the optimised-duration model alone: the single pallet's (session
18, 247 solves) starts IPOPT far from dynamic consistency, since an error in
a predicted duration moves every later node of that foot in time; the
fixed-duration model of the same environment was trained on 914 solves.

Registered as ``learned_fixed_durations`` (the shipped fixed-duration model
of the problem's robot, terrain, gait, steps, duration and clearance) and
``learned_fixed_durations:MODEL`` (a model file or shipped name); a problem
whose layout does not map (other steps, nodes, terrain, clearance or
constraint set) is refused naming what differs. :attr:`model` is the model
used.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from roughwalk.errors import ConfigError
from roughwalk.learning.initializer import LearnedInitializer, _pick, load_model
from roughwalk.learning.model_constraints import recorded_constraints
from roughwalk.learning.model_file import LearnedModel, problem_signature
from roughwalk.trajopt import Formulation, make_gait, register_initializer
from roughwalk.trajopt.task import ResolvedTask

__all__ = [
    "NAME",
    "DURATION_ROWS",
    "FixedDurationsInitializer",
    "fixed_signature",
    "fixed_durations_model",
    "gait_durations",
    "to_optimised_variables",
    "to_optimised_rows",
]

NAME = "learned_fixed_durations"

DURATION_ROWS = ("total_duration",)
"""Constraint blocks with rows only when the phase durations are optimised."""


def fixed_signature(signature: dict[str, Any]) -> dict[str, Any]:
    """``signature`` of the same problem with fixed phase durations (``durations_*`` empty)."""
    fixed = {**signature, "optimize_durations": False}
    if "layout" in signature:
        fixed["layout"] = [
            [name, 0 if str(name).startswith("durations") else size]
            for name, size in signature["layout"]
        ]
    return fixed


def fixed_durations_model(argument: str | None, signature: dict[str, Any]) -> LearnedModel:
    """The fixed-duration model for the problem of ``signature``, checked against it.

    ``argument`` is a model file or shipped name (None: the shipped model
    that fits). A model trained with optimised durations is refused: its
    durations are its own, not the gait's.
    """
    fixed = fixed_signature(signature)
    model = _pick(fixed) if argument is None else load_model(argument)
    if model.header["problem"].get("optimize_durations"):
        raise ConfigError(
            f"{NAME} needs a model trained with fixed phase durations; '{model.name}' "
            f"was trained with optimised ones (use --init learned:{model.name})"
        )
    model.check_signature(fixed)
    return model


def to_optimised_variables(nlp: Formulation, x: NDArray[np.float64]) -> NDArray[np.float64]:
    """The fixed-duration vector ``x`` in ``nlp``'s layout, the phase durations at the gait's.

    Every variable set but ``durations_*`` takes the next values of ``x``
    in order (the two layouts list the same sets); refused when ``x`` does
    not hold exactly those values.
    """
    x = np.asarray(x, dtype=float)
    kept = sum(v.size for v in nlp.variable_sets if not v.name.startswith("durations"))
    if x.size != kept:
        raise ConfigError(
            f"a fixed-duration guess of {x.size} values does not map into this NLP, whose "
            f"sets other than the phase durations hold {kept}"
        )
    timings = zip(nlp.durations, gait_durations(nlp), strict=True)
    durations = {d.name: (d, timed) for d, timed in timings}
    parts, at = [], 0
    for v in nlp.variable_sets:
        if v.name in durations:
            d, timed = durations[v.name]
            parts.append(d.pack(timed))
        else:
            parts.append(x[at : at + v.size])
            at += v.size
    return np.concatenate(parts)


def gait_durations(nlp: Formulation) -> list[NDArray[np.float64]]:
    """Per foot, the phase durations [s] of the fixed-duration NLP, within ``nlp``'s bounds.

    The gait's own durations (``make_gait``: the fixed NLP's schedule), not
    ``nlp``'s start (:meth:`~roughwalk.trajopt.ContactSchedule.fitted`
    rescales every phase of a foot that has one out of bounds, which moves
    all of its nodes in time). A free phase out of its bounds
    [min, max] is clamped and the next phase absorbs the difference, so that
    every later phase boundary keeps its time in the gait: on the 16-step
    walk in 5.5 s, the front-right foot's first stance (1.079 s) ends at
    1.0 s and its first swing starts that much earlier; every other phase
    boundary is the gait's. With ``phase_bounds_admit_gait`` every phase is
    in its own bounds and nothing is clamped: the gait's durations exactly.
    """
    gait = make_gait(nlp.config.gait, nlp.config.steps, nlp.config.duration)
    out = []
    for d, own in zip(nlp.durations, gait.durations, strict=True):
        ends = np.cumsum(own)
        timed, start = [], 0.0
        for end, lo, hi in zip(ends[: d.size], d.lower, d.upper, strict=True):
            timed.append(float(np.clip(end - start, lo, hi)))
            start += timed[-1]
        timed.append(float(d.total - start))
        out.append(np.asarray(timed))
    return out


def to_optimised_rows(nlp: Formulation, lam_g: NDArray[np.float64]) -> NDArray[np.float64] | None:
    """Constraint multipliers of the fixed-duration NLP in ``nlp``'s rows, or None.

    The fixed NLP's rows are ``nlp``'s blocks without :data:`DURATION_ROWS`,
    in order; those rows get 0, and so do blocks appended after the fixed
    NLP's (a constraint the model was not trained with). None when
    ``lam_g`` does not end on a block boundary (the rows do not correspond;
    no multiplier warm start).
    """
    lam_g = np.asarray(lam_g, dtype=float)
    if lam_g.size == 0:
        return None
    parts, at = [], 0
    for name, size in nlp.row_layout:
        if name in DURATION_ROWS or at == lam_g.size:
            parts.append(np.zeros(size))
            continue
        if at + size > lam_g.size:
            return None
        parts.append(lam_g[at : at + size])
        at += size
    if at != lam_g.size:
        return None
    return np.concatenate(parts)


class FixedDurationsInitializer(LearnedInitializer):
    """A fixed-duration model's guess and multipliers in the optimised-duration layout.

    Parameters
    ----------
    argument:
        A fixed-duration model file or shipped name; None picks the shipped
        one that fits the problem with fixed durations.

    """

    name = NAME

    def __init__(self, argument: str | None = None) -> None:
        super().__init__(None)
        self.argument = argument

    def _model(self, signature: dict[str, Any]) -> LearnedModel:
        if self.model is None:
            self.model = fixed_durations_model(self.argument, signature)
        return self.model

    def source(self) -> str | None:
        """The fixed-duration model the guess comes from, for the result's message."""
        if self.model is None:
            return None
        return f"fixed-duration learned model '{self.model.name}', phase durations at the gait's"

    def constraints(
        self, requested: tuple[str, ...], signature: dict[str, object]
    ) -> tuple[str, ...]:
        """The fixed-duration model's constraint set (see base), with :data:`DURATION_ROWS`.

        A fixed-duration model may have been trained without ``total_duration``
        (it has no rows then); the optimised NLP needs it, or each foot's
        last phase would be unbounded, so it is appended when missing.
        """
        chosen = super().constraints(requested, signature)
        if signature.get("optimize_durations"):
            chosen += tuple(n for n in DURATION_ROWS if n not in chosen)
        return chosen

    def guess(self, nlp: Formulation, task: ResolvedTask) -> NDArray[np.float64]:
        """The model's guess mapped into ``nlp``, within its bounds; refuses a mismatch."""
        signature = problem_signature(nlp)
        model = self._model(signature)
        model.check_signature(fixed_signature(signature))
        self._check_constraints(nlp, model)
        x = to_optimised_variables(nlp, model.predict(task.task))
        return np.clip(x, nlp.lbx, nlp.ubx)

    def multipliers(
        self, nlp: Formulation, task: ResolvedTask
    ) -> tuple[NDArray[np.float64] | None, NDArray[np.float64] | None]:
        """The model's (lam_x, lam_g) mapped into ``nlp``, 0 for the durations' own, or None."""
        model = self._model(problem_signature(nlp))
        lam_x, lam_g = model.predict_multipliers([task.task])
        if lam_x is None or lam_g is None:
            return None, None
        rows = to_optimised_rows(nlp, lam_g[0])
        if rows is None:
            return None, None
        # The durations' bound multipliers: 0 (inactive at the gait's durations; a
        # clamped phase sits on its bound, but the fixed NLP had no multiplier for it).
        bounds = to_optimised_variables(nlp, lam_x[0])
        at = 0
        for v in nlp.variable_sets:
            if v.name.startswith("durations"):
                bounds[at : at + v.size] = 0.0
            at += v.size
        return bounds, rows

    def fallback(
        self, nlp: Formulation, task: ResolvedTask
    ) -> tuple[NDArray[np.float64], NDArray[np.float64] | None, NDArray[np.float64] | None]:
        """The network's own guess (for a model with a library), mapped as :meth:`guess`."""
        model = self._model(problem_signature(nlp))
        network = model.network_only()
        x0 = to_optimised_variables(nlp, network.predict(task.task))
        saved, self.model = self.model, network
        try:
            lam_x, lam_g = self.multipliers(nlp, task)
        finally:
            self.model = saved
        return np.clip(x0, nlp.lbx, nlp.ubx), lam_x, lam_g

    def other_start(
        self, nlp: Formulation, task: ResolvedTask, visited: Any
    ) -> tuple[NDArray[np.float64], NDArray[np.float64] | None, NDArray[np.float64] | None] | None:
        """No further start: library candidates are not mapped (the shipped ones have none)."""
        return None

    @staticmethod
    def _check_constraints(nlp: Formulation, model: LearnedModel) -> None:
        """Refuse an NLP whose constraint set does not start with the model's.

        As for ``learned``, constraints appended after the model's set are
        taken (their multipliers start at 0); :data:`DURATION_ROWS` are left
        out of the comparison (the fixed NLP has no rows for them).
        """
        recorded = recorded_constraints(model)
        if recorded is None:
            return
        ours = [n for n in nlp.config.constraints if n not in DURATION_ROWS]
        theirs = [n for n in recorded if n not in DURATION_ROWS]
        if ours[: len(theirs)] != theirs:
            raise ConfigError(
                f"learned model '{model.name}' was trained on constraints {theirs}; this NLP "
                f"has {ours}: its guess does not map ({NAME} needs the model's set, "
                f"optionally followed by others)"
            )


register_initializer(NAME, FixedDurationsInitializer)
