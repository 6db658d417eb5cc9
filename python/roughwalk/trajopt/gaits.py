"""Contact schedules: which foot touches the ground when, from a named gait.

A gait is a stride — a cycle of whole-body contact states, each held for a
nominal time — repeated between two stand phases, as TOWR's quadruped gait
generator does (Winkler et al. 2018; the strides and their nominal times are
TOWR's): ``walk`` is TOWR's overlapping walk, ``trot`` its flying trot, then
``pace``, ``bound`` and ``gallop``. The last stride is an *end* stride that
brings the feet back into a stand.

A **step** is one foot's swing. The number of steps fixes how many strides
are used; gaits whose stride count cannot give the requested steps are
refused, naming the counts that work (the walk: 4, 8, 12, 16, ...). The
two-beat gaits (trot, pace, bound) end either on their first support pair,
as TOWR's end strides do (2, 6, 10, 14, ... steps), or after a whole stride
without its last flight (4, 8, 12, 16, ...), so that they make any even
count; the short ending is tried first, which keeps the counts TOWR makes
exactly TOWR's schedules.

Each foot's schedule is then its alternating stance and swing phase durations
[s], scaled so that the whole motion lasts the requested duration.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from roughwalk.errors import InvalidArgumentError

__all__ = [
    "ContactSchedule",
    "GAIT_NAMES",
    "make_gait",
    "valid_step_counts",
    "schedule_from_swings",
]

# Whole-body contact states, feet in the canonical order LF, RF, LH, RH (1 = stance).
_STAND = (1, 1, 1, 1)
_FLIGHT = (0, 0, 0, 0)

Phase = tuple[float, tuple[int, int, int, int]]

# TOWR's stride for each gait: (nominal time [s], contact state) per phase.
_STRIDES: dict[str, list[Phase]] = {
    # Overlapping walk: three-leg support phases joined by two-leg ones.
    "walk": [
        (0.25, (1, 1, 0, 1)),
        (0.13, (0, 1, 0, 1)),
        (0.25, (0, 1, 1, 1)),
        (0.13, (0, 1, 1, 0)),
        (0.25, (1, 1, 1, 0)),
        (0.13, (1, 0, 1, 0)),
        (0.25, (1, 0, 1, 1)),
        (0.13, (1, 0, 0, 1)),
    ],
    # Flying trot: diagonal pairs with a flight phase between them.
    "trot": [
        (0.4, (1, 0, 0, 1)),
        (0.1, _FLIGHT),
        (0.4, (0, 1, 1, 0)),
        (0.1, _FLIGHT),
    ],
    "pace": [
        (0.3, (1, 0, 1, 0)),
        (0.1, _FLIGHT),
        (0.3, (0, 1, 0, 1)),
        (0.1, _FLIGHT),
    ],
    "bound": [
        (0.3, (0, 0, 1, 1)),
        (0.1, _FLIGHT),
        (0.3, (1, 1, 0, 0)),
        (0.1, _FLIGHT),
    ],
    "gallop": [
        (0.2, (0, 1, 1, 1)),
        (0.3, (0, 0, 1, 1)),
        (0.2, (1, 0, 1, 1)),
        (0.2, (1, 0, 0, 1)),
        (0.2, (1, 1, 0, 1)),
        (0.3, (1, 1, 0, 0)),
        (0.2, (1, 1, 1, 0)),
        (0.2, (0, 1, 1, 0)),
    ],
}


def _drop_transition(stride: list[Phase]) -> list[Phase]:
    """The stride without its final transition phase, whose time goes to the phase before."""
    body = stride[:-1]
    last_time, last_state = body[-1]
    return [*body[:-1], (last_time + stride[-1][0], last_state)]


# The end strides of each gait, tried in this order: each lands every foot so
# that the final stand can follow. TOWR's own end stride comes first.
_END_STRIDES: dict[str, list[list[Phase]]] = {
    "walk": [_drop_transition(_STRIDES["walk"])],
    "trot": [[(0.4, (1, 0, 0, 1))], _drop_transition(_STRIDES["trot"])],
    "pace": [[(0.3, (1, 0, 1, 0))], _drop_transition(_STRIDES["pace"])],
    "bound": [[(0.3, (0, 0, 1, 1))], _drop_transition(_STRIDES["bound"])],
    "gallop": [_drop_transition(_STRIDES["gallop"])],
}

_STAND_TIME = 0.3  # [s], TOWR's stand phase

GAIT_NAMES: tuple[str, ...] = tuple(_STRIDES)
"""The named gaits, in TOWR's combo order (walk, trot, pace, bound, gallop)."""

_MAX_STRIDES = 64


@dataclass(frozen=True)
class ContactSchedule:
    """Per foot, alternating stance and swing phase durations [s] from t = 0.

    Attributes
    ----------
    name:
        The gait's name ("walk", "trot", ... or "footsteps").
    durations:
        Per foot (LF, RF, LH, RH), its phase durations [s]; they sum to
        :attr:`total_duration` for every foot.
    in_contact_at_start:
        Per foot, whether its first phase is a stance phase.

    """

    name: str
    durations: tuple[tuple[float, ...], ...]
    in_contact_at_start: tuple[bool, ...]

    @property
    def n_feet(self) -> int:
        """Number of feet (4)."""
        return len(self.durations)

    @property
    def total_duration(self) -> float:
        """Duration of the motion [s]."""
        return float(sum(self.durations[0]))

    @property
    def steps(self) -> int:
        """Number of swings of all feet together."""
        return sum(self.swing_count(foot) for foot in range(self.n_feet))

    def is_stance(self, foot: int, phase: int) -> bool:
        """Whether phase ``phase`` of foot ``foot`` is a stance phase."""
        return self.in_contact_at_start[foot] == (phase % 2 == 0)

    def swing_count(self, foot: int) -> int:
        """Number of swing phases of ``foot``."""
        return sum(not self.is_stance(foot, k) for k in range(len(self.durations[foot])))

    def phase_times(self, foot: int) -> NDArray[np.float64]:
        """Phase boundaries [s] of ``foot``: 0, end of phase 0, ..., total duration."""
        return np.concatenate([[0.0], np.cumsum(self.durations[foot])])

    def in_contact(self, foot: int, t: float | NDArray[np.float64]) -> NDArray[np.bool_]:
        """Whether ``foot`` is in stance at time(s) ``t`` [s] (a boundary: the earlier phase)."""
        times = np.atleast_1d(np.asarray(t, dtype=float))
        bounds = self.phase_times(foot)
        phase = np.clip(np.searchsorted(bounds, times, side="left") - 1, 0, len(bounds) - 2)
        stance = np.array([self.is_stance(foot, int(k)) for k in range(len(bounds) - 1)])
        return stance[phase]

    def scaled(self, total_duration: float) -> ContactSchedule:
        """The same schedule stretched to last ``total_duration`` [s]."""
        factor = total_duration / self.total_duration
        return ContactSchedule(
            self.name,
            tuple(tuple(d * factor for d in foot) for foot in self.durations),
            self.in_contact_at_start,
        )

    def with_durations(
        self, durations: Sequence[Sequence[float] | NDArray[np.float64]]
    ) -> ContactSchedule:
        """The same phase pattern with other durations [s] (for instance optimised ones)."""
        return ContactSchedule(
            self.name,
            tuple(tuple(float(d) for d in foot) for foot in durations),
            self.in_contact_at_start,
        )

    def fitted(self, bounds: tuple[float, float]) -> ContactSchedule:
        """The same schedule with every phase moved into ``bounds`` = (min, max) [s].

        Each foot's phases keep their total: phases outside the bounds are
        clamped, and the difference is shared by the others in proportion to
        their length. Optimised durations start here: a nominal phase outside
        its bounds would be clamped by IPOPT alone, and the polynomials would
        then no longer hold the times the initial guess put them at. A foot
        whose phases cannot fit (too many or too few for the duration) is
        left as it is; callers check that case themselves.
        """
        lo, hi = bounds
        fitted = []
        for durations in self.durations:
            d = np.asarray(durations, dtype=float)
            total = float(d.sum())
            if not len(d) * lo <= total <= len(d) * hi:
                fitted.append(tuple(float(v) for v in d))
                continue
            for _ in range(len(d) + 1):
                d = np.clip(d, lo, hi)
                excess = total - float(d.sum())
                if abs(excess) < 1e-12:
                    break
                free = d < hi if excess > 0 else d > lo
                d[free] += excess * d[free] / d[free].sum()
            fitted.append(tuple(float(v) for v in d))
        return self.with_durations(fitted)

    def structure_key(self) -> tuple[object, ...]:
        """What fixes the NLP's structure: phase counts and first contacts (not durations)."""
        return (tuple(len(d) for d in self.durations), self.in_contact_at_start)


def _schedule(name: str, phases: Sequence[Phase]) -> ContactSchedule:
    """Split a whole-body phase sequence into per-foot alternating phase durations."""
    n_feet = len(phases[0][1])
    durations: list[list[float]] = [[] for _ in range(n_feet)]
    for foot in range(n_feet):
        current = phases[0][1][foot]
        acc = 0.0
        for time, state in phases:
            if state[foot] != current:
                durations[foot].append(acc)
                acc, current = 0.0, state[foot]
            acc += time
        durations[foot].append(acc)
    first = tuple(bool(phases[0][1][foot]) for foot in range(n_feet))
    return ContactSchedule(name, tuple(tuple(d) for d in durations), first)


def _gait_schedules(name: str, strides: int) -> list[ContactSchedule]:
    """The schedules of ``strides`` strides (the last one an end stride), one per end stride."""
    return [
        _schedule(name, [(_STAND_TIME, _STAND), *_STRIDES[name] * (strides - 1), *end,
                         (_STAND_TIME, _STAND)])
        for end in _END_STRIDES[name]
    ]  # fmt: skip


def valid_step_counts(gait: str, limit: int = 6) -> list[int]:
    """The first ``limit`` step counts that ``gait`` can make, in increasing order."""
    _check_gait(gait)
    counts = {s.steps for n in range(1, limit + 1) for s in _gait_schedules(gait, n)}
    return sorted(counts)[:limit]


def _check_gait(gait: str) -> None:
    if gait not in _STRIDES:
        raise InvalidArgumentError(f"unknown gait '{gait}'; known: {', '.join(GAIT_NAMES)}")


def make_gait(gait: str, steps: int, duration: float) -> ContactSchedule:
    """The contact schedule of ``gait`` with ``steps`` swings, lasting ``duration`` [s].

    Raises :class:`InvalidArgumentError` for an unknown gait, a step count the
    gait cannot make (naming those it can) or a non-positive duration.
    """
    _check_gait(gait)
    if not (isinstance(duration, int | float) and np.isfinite(duration) and duration > 0):
        raise InvalidArgumentError(
            f"duration must be a positive number of seconds, got {duration!r}"
        )
    if isinstance(steps, bool) or not isinstance(steps, int | np.integer) or steps < 1:
        raise InvalidArgumentError(f"steps must be a positive integer, got {steps!r}")
    for strides in range(1, _MAX_STRIDES + 1):
        schedules = _gait_schedules(gait, strides)
        for schedule in schedules:
            if schedule.steps == steps:
                return schedule.scaled(float(duration))
        if min(s.steps for s in schedules) > steps:
            break
    counts = ", ".join(str(c) for c in valid_step_counts(gait))
    raise InvalidArgumentError(
        f"the {gait} gait cannot make {steps} steps; it makes {counts}, ... steps"
    )


def schedule_from_swings(
    swing_order: Sequence[int], duration: float, stand_fraction: float = 0.1
) -> ContactSchedule:
    """A one-foot-at-a-time schedule swinging the feet in ``swing_order``, over ``duration`` [s].

    The motion opens and closes with a stand phase of ``stand_fraction`` of the
    duration each; the swings share the rest evenly. This is the schedule of
    a footstep plan, whose feet move one at a time; a foot that steps twice in
    a row lands for half a swing time in between.
    """
    order = [int(f) for f in swing_order]
    if not order:
        raise InvalidArgumentError("a footstep schedule needs at least one swing")
    if any(f not in range(4) for f in order):
        raise InvalidArgumentError(f"feet are numbered 0..3 (LF, RF, LH, RH), got {order}")
    repeats = sum(a == b for a, b in zip(order, order[1:], strict=False))
    stand = duration * stand_fraction
    swing = (duration - 2 * stand) / (len(order) + 0.5 * repeats)
    phases: list[Phase] = [(stand, _STAND)]
    for i, foot in enumerate(order):
        if i and order[i - 1] == foot:
            phases.append((0.5 * swing, _STAND))
        state = [1, 1, 1, 1]
        state[foot] = 0
        phases.append((swing, (state[0], state[1], state[2], state[3])))
    phases.append((stand, _STAND))
    return _schedule("footsteps", phases)
