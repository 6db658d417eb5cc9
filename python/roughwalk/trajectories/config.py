"""Settings of footstep trajectory generation (Zucker 2011, §5), with units and trade-offs.

Override any field by dotted key: ``footstep_trajectories(plan,
**{"chomp.max_iterations": 30})`` or ``roughwalk trajectory --set
chomp.max_iterations=30``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from roughwalk.errors import ConfigError

__all__ = [
    "TrajectoryConfig",
    "TimingConfig",
    "ZmpConfig",
    "SwingConfig",
    "ChompConfig",
    "ValidityConfig",
]


def _check_positive(obj: object, names: tuple[str, ...], prefix: str) -> None:
    for name in names:
        v = getattr(obj, name)
        if not (isinstance(v, int | float) and math.isfinite(v) and v > 0):
            raise ConfigError(f"{prefix}.{name} must be a positive number, got {v!r}")


def _check_nonnegative(obj: object, names: tuple[str, ...], prefix: str) -> None:
    for name in names:
        v = getattr(obj, name)
        if not (isinstance(v, int | float) and math.isfinite(v) and v >= 0):
            raise ConfigError(f"{prefix}.{name} must be a number ≥ 0, got {v!r}")


@dataclass(frozen=True)
class TimingConfig:
    """How long each footstep takes (Zucker 2011, §5.2).

    Attributes
    ----------
    velocity_margin:
        Factor (≥ 1) on the shift phase's minimum time, the largest joint
        travel over its velocity limit (§5.2). The CoM's smooth motion peaks
        near twice its mean speed, but most LittleDog shifts are short and
        take ``min_shift_s``. 1.3 since session 10 (1.6 before; timed by
        the ends' travel, 1.3 restarted every other barrier step): with the
        shift timed by its legs' peak joint rate along the trunk's path the
        few long shifts (0.3–0.5 s on the demo course) shrink by a fifth,
        and a step whose joints would still outrun a limit is lengthened
        by the generator's re-timing and restarts. Larger values walk
        slower. See "Session 10" below.
    swing_velocity_margin:
        Factor (≥ 1) on the swing's minimum time, the duration at which the
        foot spline's peak joint speeds reach the limits. The trunk moves
        during the swing too, hence a little slack. The swing is most of a
        LittleDog footstep (0.45–0.6 s of ~0.75 s), so this sets the speed.
    min_shift_s:
        Shortest shift phase [s] (four feet down, centre of pressure moved
        into the next support triangle) for a ZMP travel of
        ``shift_travel_m`` or more. The cart-table needs time to move
        its ZMP: shorter shifts swing the trunk harder. The preview
        controller starts the move ahead, so 0.1 s holds on the
        benchmark courses after a 0.2 s first shift (``first_shift_s``;
        0.3 s walked 20 % slower than 0.2). The fast timing
        (0.1 here, ``min_swing_s`` 0.2, ``swing.time_law`` "joint")
        against the defaults, the planner's budget fixed so that runs
        repeat (``roughwalk bench littledog --classes
        barrier,steps,round_rocks,sloped_rocks --expansions 40000 --seeds
        2``, since the bench counts a fall mid-course as a failure instead
        of walking again from a nudged start, and with ``swing_trunk``
        "still"): barrier 1/2 at 4.20 → 1/2 at 5.70 cm/s, steps 2/2 at 3.76
        → 5.21, round rocks 1/2 at 3.12 → 1/2 at 4.23, sloped rocks 1/2 at
        4.16 → 1/2 at 5.09 (the same seeds fail); the 1 N·s side push
        (``roughwalk bench push_recovery --direction 90`` / ``-90``) 16 and
        16 of 17. 0.1 is the default since session 10, with
        ``first_shift_s`` 0.2 (see "Session 10" below); the rest of the
        fast timing is not, and before that none of it was, because:
        with 0.1 here the ZMP leaves the support polygon in the first step
        of a flat straight crawl and in the Figure 8 barrier step (both
        invalid after CHOMP's restarts; ``first_shift_s`` 0.2 mends both
        but loses pushes: it delays the gait by 0.1 s, so three push times
        to the right instead of one land in the gait's weak phase, a push
        towards the right feet while LF swings, where the trunk rolls over
        RF–RH faster than the recovery puts the left feet down; without it
        the fast timing falls there too, at 2.0 s), and the rest of the fast
        timing alone (0.2 here) falls under the side push at 2 of the first
        11 times to the left and 3 of the first 12 to the right.
    shift_travel_m:
        ZMP travel [m] of a shift that takes the whole ``min_shift_s``; a
        shorter one takes proportionally less, down to ``min_hold_s``. In a
        crawl the swing already carries the ZMP into the next support
        triangle before every front swing (the swings of one side share
        two feet), so only the shifts that change sides travel (~25 mm
        on LittleDog) and the others need next to none. 0 gives every
        shift ``min_shift_s``. Measured with the fast opt-in timing
        (``min_shift_s`` 0.1, ``min_swing_s`` 0.2, ``swing.time_law``
        "joint"; ``roughwalk bench littledog --seeds 2 --set
        executor.compute_time_scale=0``), 0 → 0.02: the runs that reach the
        goal in both walk 3–5 % faster (barrier 5.67/5.72 → 5.92/6.01 cm/s,
        steps 5.57 → 5.80, sloped rocks 5.48 → 5.66, round rocks 4.42 →
        4.55); which other runs fail changes with the anytime planner's
        plans (2 seeds cannot tell). The default 0.02 goes with
        ``swing_trunk`` "moving" (see the figures there); a shift that
        travels little is still timed by its legs' peak joint rate along the
        trunk's path (``velocity_margin``), which keeps the joint speeds.
    min_hold_s:
        Shortest shift phase [s] whatever the travel (at most
        ``min_shift_s``): the landed foot's touchdown settles before the
        next foot lifts.
    first_shift_s:
        Shortest shift phase [s] of a plan's first step, which starts from
        rest (0.2 since session 10; 0, no floor of its own, before).
        The cart-table moves its ZMP only by accelerating the CoM, and from
        rest the preview controller has no earlier motion to start the move
        in: with the fast timing's 0.1 s the ZMP left the support polygon
        in the first of six steps of a flat straight crawl and in the
        Figure 8 barrier step (0.15 s: the latter too); 0.2 s keeps both
        valid. With the fast timing and 0.2 here the repeatable bench
        walks all 8 runs, sloped rocks at 5.00 cm/s (4.37 without), steps
        5.16 (5.21), barrier 5.67 (5.71), but round rocks at 2.99 with 3
        reflexes (4.17, none), and the side push survives 16 of 17 to the
        left and only 13 to the right (16 without: falls at 2.0–2.4 s and
        4.4 s), so it stayed 0 until session 10 made it 0.2 with
        ``min_shift_s`` 0.1 (see "Session 10" below).
    min_swing_s:
        Shortest swing phase [s]. 0.2 since session 12 (0.3 before), with
        ``measured_speed`` 0.95: the measured timing shortens swings only down
        to this floor, and at 0.3 the floor, not the joints, timed most of
        them (see ``measured_speed`` for the figures).
    swing_trunk:
        The trunk under which the swing's joint speeds are estimated:
        ``"still"`` holds the swing pose throughout; ``"landing"``
        carries its height and tilt on to the landing certificate's, as the
        initial trajectory does; ``"shorter"``: the shorter of the
        two; ``"moving"`` (default, with ``shift_travel_m`` 0.02): the
        shortest of those and one whose trunk also moves on horizontally
        to where the swing takes the ZMP (its exit), as the preview
        controller moves it (the measured swing still
        lengthens a step that would outrun the limits). "shorter" with
        ``shift_travel_m`` 0 → "moving" with 0.02 (the trunk moves on
        during the swings and the shifts that then carry the ZMP only a
        little shrink to ``min_hold_s``) on the repeatable bench
        (``roughwalk bench littledog --classes
        barrier,steps,round_rocks,sloped_rocks --expansions 40000 --seeds
        2``): barrier 2/2 at 4.10 → 5.31 cm/s, steps 2/2 at 3.86 → 4.22
        (seed 1: 3 reflexes), round rocks 1/2 at 3.85 → 2/2 at 4.15, sloped
        rocks 1/2 at 4.92 → 1/2 at 5.82 (the same seed falls at 1 s); the
        demo course 4.67 → 5.56 cm/s (shifts 0.20 → 0.13 s, swings 0.36 →
        0.34 s). With the fast timing on top (``min_shift_s`` 0.1,
        ``min_swing_s`` 0.2, ``swing.time_law`` "joint"): barrier 5.75,
        steps 5.26, round rocks 2/2 at 4.21, sloped rocks 1/2 at 6.86, demo
        6.65 cm/s. Those figures predate timing the shift by its legs'
        peak joint rate along the trunk's path, which lengthens some of
        the shifts "moving" and 0.02 shrink. The default since session 9,
        measured with that timing against the old defaults ("shorter",
        0) on the same repeatable bench (``--classes
        barrier,steps,round_rocks,sloped_rocks`` and ``--classes
        gap,logs,large_rocks``, both ``--expansions 40000 --seeds 2``):
        barrier 2/2 at 4.10 → 4.68 cm/s, steps 2/2 at 3.86 → 1/2 at 4.71
        (seed 0 4.29 → 4.71; seed 1 rolls over at 8.75 s, LH's foot-force
        reflex firing while RF swings up the step, as with the old timing
        at 9.49 s, but the recovery put RF down on the step's corner; since
        the recovery moves such a catch off the edge, steps 2/2 at 4.21,
        seed 1 3.72 with 2 reflexes, the other classes unchanged), round rocks 1/2 at
        3.85 → 2/2 at 3.60 (the seed both reach 3.85 → 4.02), sloped rocks
        1/2 at 4.92 → 5.36 (the other seed falls at 1 s), logs 2/2 at
        4.41 → 4.82, gap and large rocks 0/2 with both; the demo
        course (:func:`roughwalk.demo.run_demo`'s terrain, start and goal,
        ``executor.plan_expansions`` 40000, no computing time charged)
        4.67 → 5.14 cm/s (shifts 0.20 → 0.17 s, swings 0.36 → 0.34 s). The
        old push test's right push (``test_one_reflex_rescues_a_push_to_the_right_mid_stride``,
        "even", 2.2 s) rolls this gait over at 3.0 s instead of one reflex
        and a re-plan (the test now pins the old timing for that case).
        The faster gait, not the recovery, moves the push: the
        same-side shift before LF shrinks to ``min_hold_s`` (0.2 → 0.06
        s), so LF lifts as the push lands, the CoM 4.0 cm inside the RF–RH
        edge (5.1 cm with the old defaults, whose push lands in the shift
        before LH with four feet down). Its capture point crosses that
        edge 0.09 s later, before the foot-force reflex fires (0.13 s);
        the recovery then lowers LF and LH, which can only push, never
        pull, so the left feet do not touch again and the roll grows 5° →
        35°. The old defaults fall the same way (the same reflex, 34° 0.39 s
        later) when pushed at LF's lift-off, 2.78 s: that phase needs a
        wider stance or a sideways capture step of a right foot, not a
        change of this setting nor a faster trigger (a reflex fired as the
        capture point leaves the support triangle fires first, and the
        robot rolls over all the same). The 1 N·s side push sweep
        (``roughwalk bench push_recovery --direction 90`` / ``-90``)
        survives 16 and 15 of 17 (16 and 15 with the old defaults, at
        other times): falls at 3.2 s (mid RF swing) to the left, 2.2 s
        (LF's lift-off) and 2.4 s (mid LF swing) to the right; by 0.05 s,
        to the right, RH's lift-off (2.70, 2.75 s) falls too, mid RF
        swing (3.05–3.25 s) and mid LH swing (1.85–2.15 s) one reflex
        rescues.
        ``zmp.support_margin`` 0.02 on top was no fix (measured before the
        peak-rate shift timing), though both sweeps then survived 16 of 17
        (falls at 3.2 s left, 2.4 s right) and the 2.2 s push one reflex
        rescued: it landed 0.04 s before LF lifts, the CoM again
        4.0 cm inside, the capture point 0.1 cm past the edge at worst
        (demo 5.46 cm/s). A straight 10 cm crawl's last
        step (RF) is invalid with either setting: its swing pose, over LF
        10 cm ahead, does not reach RF's start at lift-off (with "moving"
        and 0.02 its 0.06 s shift also broke a joint speed limit until the
        shift was timed by its peak joint rate: 0.22 s now); a 9 cm crawl
        is valid throughout with both.
        Stepping down from the barrier (8 cm), the swing pose leaves the
        landing foot at the edge of its reach, where the knee's rate per
        metre soars: "still" timed that swing 1.12 s, "landing" 0.64 s (both
        valid); stepping over it, "landing" lowers the trunk while the foot
        is at its highest and timed 1.4 s against 0.7 s. Either estimate is
        only the first guess: the initial trajectory's measured swing
        (``_retimed``) lengthens any step whose joints would outrun their
        limits, and never shortens one, hence "shorter". "still" → "shorter"
        on the repeatable bench (``roughwalk bench littledog --classes
        barrier,steps,round_rocks,sloped_rocks --expansions 40000 --seeds
        2``): the same runs succeed and fail for the same reasons, barrier
        1/2 at 4.20 → 4.42 cm/s, steps 2/2 at 3.76 → 4.03, round rocks 1/2
        at 3.12 → 3.85, sloped rocks 1/2 at 4.16 → 4.92; with the fast
        timing barrier 5.70 → 5.92, steps 5.21 → 5.26, round rocks 4.23 →
        4.23. Flat-ground swings do not change: the 1 N·s side push
        (``roughwalk bench push_recovery --direction 90`` / ``-90``)
        survives 16 and 15 of 17 with both, at the same push times.
    measured_speed:
        Fraction (0 < · ≤ 1) of its velocity limit that each phase's
        fastest joint reaches on the initial trajectory: the nominal timing
        is shortened until it does (never lengthened: that is the re-timing
        on a broken limit, and restarts). 0 keeps the nominal timing.
        0.95 (with ``min_swing_s`` 0.2 and the three ``reflex`` options
        ``standing_bear``, ``replan_nudge_m`` 0.02 and ``foot_force_per_leg``)
        since session 12; 0 (and 0.3, the options off) before. Session 11,
        on the demo course (:func:`roughwalk.demo.run_demo`'s
        terrain, start and goal, ``executor.plan_expansions`` 40000, no
        computing time charged) with the defaults the swings' fastest joints
        reach 0.72–0.91 of their limits, the shifts' 0.02–0.17, and the
        swings take 1.90 times the least time their own joint paths allow
        with every joint at its limit (mostly the hip HFE, whose swing
        travel, 1.0–1.8 rad, is two thirds lifting and setting down the
        foot). 0.9 with ``min_swing_s`` 0.2: demo 5.64 → 6.49 cm/s (shifts
        0.122 → 0.085 s, at their floors; swings 0.340 → 0.317 s); with
        ``swing.time_law`` "joint" and ``swing.ramp_fraction`` 0.1 on top
        7.27 cm/s (swings 0.268 s, 1.51 times that least time), with
        ``chomp.rate_hz`` 100 too (phases quantised to 10 ms, not 20)
        7.61. The repeatable bench (``roughwalk bench littledog --classes
        barrier,steps,round_rocks,sloped_rocks,gap,logs,large_rocks
        --expansions 40000 --seeds 2``), defaults → 0.9 with ``min_swing_s``
        0.2 → also "joint" and ramp 0.1: barrier 2/2 at 4.73 → 5.62 → 5.77
        cm/s, steps 4.95 → 5.73 → 6.45, round rocks 4.34 → 5.76 → 4.66,
        sloped rocks 1/2 at 5.90 → 6.90 → 7.21 (the same seed fails),
        gap 4.89 → 5.64 → 5.97, logs 4.80 → 6.08 → 5.00, large rocks 2/2
        at 3.10 → 1/2 at 4.82 → 1/2 at 3.73. Not the default in session 11
        because of that lost run: large rocks seed 0 (board AE), which the
        defaults survive after two reflexes at 30° of roll, rolls past 34°
        (at 1.4 s after one reflex; with ``min_swing_s`` 0.3 kept, at 4.6 s
        after two; with the "joint" law its re-plan finds no start
        certificate). The three reflex options win it back (see
        :class:`~roughwalk.sim.config.ReflexConfig`). Session 12, the old
        defaults → 0.9 with ``min_swing_s`` 0.2 and the three options
        (the repeatable bench as above): barrier 2/2 at 4.73 → 5.61 cm/s,
        steps 4.95 → 5.73, round rocks 4.34 → 5.76, sloped rocks 1/2 at
        5.90 → 6.90 (seed 1 still ends in a re-plan without a certified
        start), gap 4.89 → 5.64, logs 4.80 → 6.08, large rocks 2/2 at 3.10
        → 3.80 (seed 0 2.78 cm/s after three reflexes): 13 of 14 runs with
        both, every class faster; flat ground 0.5 m (``roughwalk run``,
        2000 expansions) 7.04 cm/s; the 1 N·s side push from 1.6 to 3.2 s
        (``roughwalk bench push_recovery --from 1.6 --to 3.2 --direction
        90`` / ``-90``) survives 9 of 9 to the left (8 before) and 7 of 9
        to the right (8 before, where 2.2 s, LF's lift-off, fell): LF now
        swings 2.05–2.32 s after the first motion, and the pushes 0.15 s
        into that swing (2.2 s) and 0.08 s after it lands (2.4 s) roll the
        trunk over the right feet after one reflex each. 0.9 → 0.95 (same
        settings otherwise, same commands): 13 of 14 runs, barrier 5.61 →
        5.83, steps 5.73 → 5.95, round rocks 5.76 → 6.02, sloped rocks 1/2
        at 6.90 → 7.06, gap 5.64 → 5.86, logs 6.08 → 5.92 (seed 1 after one
        reflex), large rocks 2/2 at 3.80 → 4.40 (seed 0 after one reflex,
        not three); demo course 6.49 → 6.81 cm/s (swings 0.317 → 0.299 s);
        flat 0.5 m 7.04 → 7.38; side push left 9 → 8 of 9, right 7 → 8 of
        9 (both fall at 2.0 s, 0.07 s into LF's swing; 8 and 8 with the
        old defaults), hence 0.95. 1.0: demo 6.99 cm/s, large rocks 2/2 at
        4.56, round rocks 6.13, but the right push survives only 6 of 9
        (1.8, 2.0, 2.4 s fall) and the left 8.
    max_step_s:
        Longest a step may be made by restarts [s].
    settle_s:
        After the last step, four feet down while the centre of mass comes to
        rest over the final pose [s].
    stretch_shift:
        Whether the re-timing of a swing whose initial trajectory breaks a
        joint's velocity limit (the generator's ``_retimed``: the step
        lengthened by the swing leg's peak speed over its limit) lengthens
        the shift as well (True, default), or only the swing (False). Only
        the swing leg's airborne speed is measured there, so the shift's
        share of the stretch is time the limit does not ask for (large
        rocks seed 0: 0.06 s of its 0.30 s stretch); a longer shift gives
        the preview controller more time to move the ZMP, though. Off
        (``bench_littledog.py --expansions 40000 --classes large_rocks``):
        seed 0 7.15 → 7.30 cm/s, but seed 3 (5.36 cm/s after one reflex)
        fails (its re-plan after the reflex finds no start certificate);
        with ``swing.law_trunk`` "moving" as well, large rocks seeds 0–7
        6/8 at 6.42 cm/s (main 5/8 at 5.30; seed 3 lost, 4 and 6 gained)
        and the 1 N·s right push (``bench_push_recovery.py --from 1.6 --to
        3.2 --direction -90``) 6/9 (main 7/9: 2.0 s falls too), left 8/9
        as main. Hence on.

    Session 10: where a run's clock goes, and the shift defaults
    (``min_shift_s`` 0.2 → 0.1, ``first_shift_s`` 0 → 0.2,
    ``velocity_margin`` 1.6 → 1.3). With session 9's defaults the demo
    course (:func:`roughwalk.demo.run_demo`'s terrain, start and goal,
    ``executor.plan_expansions`` 40000, no computing time charged) took
    11.68 s: swings 7.84 s (0.34 s each), shifts 3.84 s (0.17 s each; every
    side-changing one at the 0.2 s floor), no waits for optimisation (none
    either with the computing time charged, ``compute_time_scale`` 1),
    no reflexes; 23 footsteps of 9.4 cm strides, the feet's centroid
    2.4 cm on per footstep (LittleDog board AD, bench logs seed 0: 4.49 s,
    63 % swings, 37 % shifts, 8.1 cm strides). Longer strides
    (``executor.longest_step`` 0.4) lengthen both phases more than the
    stride (11.4 cm: swings 0.40 s, shifts 0.28 s, since the supporting
    legs then sit near the edge of their reach, where their joints turn
    fastest per metre; 4.62 cm/s). With the new shift defaults the demo
    walks 5.14 → 5.64 cm/s (shifts 0.17 → 0.12 s), and the repeatable
    bench (``roughwalk bench littledog --classes
    barrier,steps,round_rocks,sloped_rocks,gap,logs,large_rocks
    --expansions 40000 --seeds 2``) gives barrier 2/2 at 4.18 → 4.73
    cm/s, steps 2/2 at 4.48 → 4.95, round rocks 2/2 at 4.06 → 4.34,
    sloped rocks 1/2 at 5.36 → 5.90, gap 2/2 at 4.49 → 4.89, logs 2/2
    at 4.77 → 4.80 (seed 0 5.15 → 5.60; seed 1 4.39 → 4.01, one reflex),
    large rocks 1/2 at 3.23 → 2/2 at 3.21 (the seed both reach 3.23 →
    3.41): every run the old defaults win still wins.
    The fast timing's swing part on top (``swing.time_law`` "joint",
    ``min_swing_s`` 0.2) is an option, not the default. The robot fell
    under the 1 N·s left push at 2.0 s that each part alone survives: the
    push lands 0.09 s into LF's swing, the CoM 1.5 cm inside the RF–LH
    diagonal, RH lets go 0.02 s later and the trunk rolls over that
    diagonal; the foot-force reflex, gated at 0.05 rad of tilt, fired
    0.11 s after the push (0.22 m/s sideways, 5° of roll), too late for
    the lowered LF. Since ``reflex.foot_force_tilt_rad`` 0.03 one reflex
    rescues it. With that, against the defaults (same commands as above,
    the defaults' figures just above): demo 5.64 → 6.00 cm/s (swings
    0.34 → 0.30 s); barrier 2/2 at 4.73 → 5.29, steps 2/2 at 4.95 → 5.51,
    round rocks 2/2 at 4.34 → 4.17, sloped rocks 1/2 at 5.90 → 3.91 (seed
    0, 2 reflexes; seed 1 falls at 1.8 s instead of failing its re-plan),
    gap 2/2 at 4.89 → 5.59, logs 2/2 at 4.80 → 4.84, large rocks 2/2 at
    3.21 → 1/2 at 2.48 (seed 0's re-plan fails after 3 reflexes): a run
    lost. The side push from 1.6 to 3.2 s: to the left 9 of 9 (8 with the
    defaults), to the right 7 (8): 1.8 and 2.0 s fall, the push just before
    or after LF lifts, as the defaults' 2.2 s; the trunk rolls over the
    RF–RH edge onto the right feet (see ``min_shift_s`` on that phase).
    """

    velocity_margin: float = 1.3
    swing_velocity_margin: float = 1.1
    min_shift_s: float = 0.1
    shift_travel_m: float = 0.02
    min_hold_s: float = 0.06
    first_shift_s: float = 0.2
    min_swing_s: float = 0.2
    measured_speed: float = 0.95
    max_step_s: float = 4.0
    settle_s: float = 0.8
    swing_trunk: str = "moving"
    stretch_shift: bool = True

    def shift_floor(self, travel: float) -> float:
        """Shortest shift phase [s] for a ZMP travel of ``travel`` [m]."""
        if self.shift_travel_m <= 0:
            return self.min_shift_s
        part = min(1.0, max(travel, 0.0) / self.shift_travel_m)
        return max(min(self.min_hold_s, self.min_shift_s), self.min_shift_s * part)

    def __post_init__(self) -> None:
        _check_positive(self, ("min_shift_s", "min_swing_s", "max_step_s"), "timing")
        _check_nonnegative(
            self, ("settle_s", "shift_travel_m", "min_hold_s", "first_shift_s"), "timing"
        )
        for name in ("velocity_margin", "swing_velocity_margin"):
            v = getattr(self, name)
            if not (math.isfinite(v) and v >= 1):
                raise ConfigError(f"timing.{name} must be ≥ 1, got {v}")
        if not (math.isfinite(self.measured_speed) and 0 <= self.measured_speed <= 1):
            raise ConfigError(f"timing.measured_speed must be in [0, 1], got {self.measured_speed}")
        if self.swing_trunk not in ("still", "landing", "shorter", "moving"):
            raise ConfigError(
                "timing.swing_trunk must be 'still', 'landing', 'shorter' or 'moving', "
                f"got {self.swing_trunk!r}"
            )


@dataclass(frozen=True)
class ZmpConfig:
    """The ZMP reference and its preview controller (Kajita et al. 2003; Zucker 2011, §5.2).

    Attributes
    ----------
    tracking_weight:
        Weight Q on the squared ZMP error [1/m²]. Only its ratio to
        ``jerk_weight`` matters.
    jerk_weight:
        Weight R on the squared CoM jerk [s⁶/m²]. Smaller tracks the
        reference more tightly with more trunk motion.
    preview_steps:
        The preview window spans this many footsteps from the current one
        (the paper: three). Beyond the window the reference is held.
    shortcut:
        Try the "shortcut" ZMP of the paper's footnote 2 first: the point of
        the support triangle (shrunk by ``support_margin``) nearest to the
        straight line between the neighbouring anchors, so the trunk sways
        less. Falls back to the certificate when it collides or fails.
    support_margin:
        Distance [m] the shortcut point keeps inside its support triangle.
        A larger margin plans more load on the third support foot (the
        reflexes seen on the rock courses were a foot planned at ~3 N that
        unloaded). With the fast opt-in timing (``timing.min_shift_s`` 0.1,
        ``timing.min_swing_s`` 0.2, ``swing.time_law`` "joint"), 0.025
        walked all 8 bench littledog runs of barrier, steps, round and
        sloped rocks (2 seeds; 0.015: 6 of 8) but slower (steps 5.57 →
        5.03 cm/s), and under the 1 N·s side push on flat ground 3 of the
        first 12 runs fell (0.015: 2 of 34).
    min_support_load:
        Least static load [N] the shortcut ZMP and each swing's exit point
        plan on every foot of the support triangle (on top of
        ``support_margin``; 0: none). The static loads are the ZMP's
        barycentric coordinates times the weight: each edge moves in by
        that share of the opposite foot's height over it, where this is more
        than the margin. The shortcut presses the ZMP against the diagonal
        edge, where the margin leaves the third foot ~3 N on LittleDog.
        Measured with the fast timing (``timing.min_shift_s`` 0.1,
        ``timing.min_swing_s`` 0.2, ``swing.time_law`` "joint"; ``roughwalk
        bench littledog --classes barrier,steps,round_rocks,sloped_rocks
        --expansions 40000 --seeds 2``), 0 → 5 N: all 8 runs still walk, but
        steps seed 1 still fires its reflex (LH, planned 4.7 N instead of
        3.1 N, carries nothing at 7.0 s while RF swings onto the 11.8 cm
        step: the trunk tips over the diagonal by more than the load moves
        the ZMP), and the rock runs get slower with more reflexes (round
        rocks 4.17 → 3.34 cm/s, 0 → 2 reflexes; sloped rocks 4.37 → 3.97;
        barrier 5.71 → 5.61, steps 5.21 → 5.35), so it stays 0.
    com_margin:
        Least distance [m] the planned CoM keeps inside each swing's support
        triangle, from lift-off to touchdown (0: no check, the default). The
        preview controller's CoM leads its ZMP: toward the next anchor
        before a short shift, so the CoM of a swing ends nearer the
        triangle's edge than the ZMP exit (``EXIT_MARGIN_FACTOR`` ×
        ``chomp.zmp_margin``), and it lags into a triangle at lift-off. On
        board AE (large rocks, seeds 0–15, the walk's defaults) the planned
        CoM came within a median 0.7 cm of the edge over the first plans'
        swings, a quarter within 0.25 cm; the swings the 13 runs' first
        reflexes fired in or after were no nearer (median 0.76 cm). Where
        the CoM comes nearer than this, the step's initial trajectory is
        built again: its swing's exit moves in
        by the shortfall, and where the CoM is short at lift-off the shift
        lengthens by a quarter (within ``timing.max_step_s``), up to four
        times (``generator.COM_LIMIT``); the best is kept. Above the
        shortcut's ``support_margin`` the lift-off shortfall cannot close.
        On a short swing the CoM moves in about a quarter of the exit's
        inset (a 0.2 s swing before a 0.06 s shift, flat ground: 2 cm of
        inset, 0.5 cm of margin). At 0.01 (session 21, one process per seed,
        ``--expansions 40000``) large rocks 0–23 walk 15 of 22 as main, at
        5.57 cm/s against 6.53 (seeds 10, 15 gained, 0, 20 lost; the longer
        shifts cost the clean runs 8 %); with the lift gate 15 of 23 at
        5.94: off by default.
    gravity:
        Gravitational acceleration [m/s²].
    """

    tracking_weight: float = 1.0
    jerk_weight: float = 1e-6
    preview_steps: int = 3
    shortcut: bool = True
    support_margin: float = 0.015
    min_support_load: float = 0.0
    com_margin: float = 0.0
    gravity: float = 9.81

    def __post_init__(self) -> None:
        _check_positive(self, ("tracking_weight", "jerk_weight", "gravity"), "zmp")
        _check_nonnegative(self, ("support_margin", "min_support_load", "com_margin"), "zmp")
        if not (isinstance(self.preview_steps, int) and self.preview_steps >= 1):
            raise ConfigError(f"zmp.preview_steps must be an integer ≥ 1, got {self.preview_steps}")


@dataclass(frozen=True)
class SwingConfig:
    """The swing foot's initial spline: start → lift-off → drop-off → target (§5.2).

    Attributes
    ----------
    lift_height:
        Lift-off and drop-off points are at least this high [m] above the
        higher of start and target.
    clearance:
        With ``scan_terrain``, the path between lift-off and drop-off also
        clears the highest terrain under the straight foot path by this much
        [m] (foot sphere included). More clearance avoids collisions that
        CHOMP would have to fix, at the price of longer, faster swings.
    scan_terrain:
        Look at the terrain under the foot path (else only ``lift_height``).
    lift_fraction:
        Where lift-off and drop-off sit along the stride (0: straight above
        start and target; 0.5: both at the middle). Small values lift
        vertically first; larger ones round the corners (with the ``"even"``
        time law, 0.3 (default): the foot sweeps its corners at speed, and
        rounder ones keep that gentle, ~25 m/s² peak on a 10 cm stride in
        0.33 s against ~150 m/s² at 0.1, and need less joint speed).
    time_law:
        ``"even"``: the foot moves along its path at a steady speed
        (in the metric below) with smooth ramps at both ends, so its joints'
        peak speeds sit nearer their means and the velocity limits allow a
        shorter swing (§5.2's timing rule is then less pessimistic).
        ``"knots"``: each spline segment takes time in proportion to its
        length (the foot halts vertically at lift-off and drop-off and
        dashes through the short lift and drop; peak joint speeds 2.3–3.8
        times their means on LittleDog; use it with ``lift_fraction`` 0.1).
        Measured in MuJoCo (``roughwalk bench littledog --set
        executor.compute_time_scale=0``, seeds 0–1), "knots" → "even":
        swings 0.42–0.64 → 0.30–0.36 s; barrier 3.07 → 4.16 cm/s, steps
        3.01 → 3.98, round rocks 2.60 → 3.21 (the same runs succeed: 2/2,
        2/2, 1/2; sloped rocks 2/2 at 2.64 → 3.57; gap 0/2 → 1/2 at 3.71;
        large rocks and logs 0/2 with both). Under a 1 N·s side push on
        flat ground (``roughwalk bench push_recovery``, 17 push times from
        1.6 to 4.8 s) "knots" survives 16 to the left and 12 to the right,
        "even" 16 and 15; the falls
        looked at are of one kind with both (pushed while a foot of the
        other side swings, the trunk rolls over the feet it is pushed
        towards), and the sweep's default 1.6–3.2 s window misses those of
        "knots" (9/9 both ways; "even" 9/9 and 7/9).
        ``"joint"`` (default): as ``"even"``, but the pace along the path is the swing
        leg's own, the largest joint speed over its limit (the
        velocity-limited time-optimal law with the same end ramps), where the
        leg's inverse kinematics is given; else it is ``"even"``, and so
        where that IK misses the path (a downhill target out of the swing
        pose's reach: the clamped angles read no rate and the law dashed,
        round rocks 4.93 → 6.94 cm/s with the ``"joint"`` path). On a flat
        LittleDog stride of 6–10 cm the least swing drops by ~16 %
        (0.274 → 0.231 s at 9.4 cm).
    vertical_weight:
        With ``"even"``: one metre of vertical foot motion counts like this
        many metres of horizontal motion (LittleDog's hip and knee turn about
        faster per metre lifted than per metre forward; 1.5 gave the shortest
        LittleDog swings, 2.0 let the hip limit them).
    ramp_fraction:
        With ``"even"``: fraction of the swing at each end over which the foot
        speeds up from rest and slows down to rest (peak over mean speed
        1 / (1 − ramp_fraction)). Shorter ramps accelerate harder. 0.1 by
        default since session 15 (0.2 before; see ``path``).
    path:
        ``"cartesian"``: the heuristic path above, its lift-off and
        drop-off at one height over the whole stride. ``"joint"``: the path
        is shaped in the swing leg's joint space (for the ``"joint"`` time
        law): the hip (HFE) and knee (KFE) bend by six sine modes each on
        top of the straight move from the start's angles to the target's,
        chosen by SLSQP to lower the joints' speed over their limits along
        the path while the foot keeps ``lift_height`` above the line from
        start to target and its sphere ``clearance`` above the ground
        actually under it (both from ``lift_fraction`` of the path in, a
        share of them on the ramps). The heuristic path lifts the foot
        straight up, which swings LittleDog's hip (7.5 rad/s against the
        knee's 14) back and forth: two thirds of its 1.0–1.8 rad per swing.
        The heuristic path is kept where the shaped one would not allow a
        shorter swing, or where the leg's kinematics are not given. On a
        flat 9.5 cm stride: hip travel 1.28 → 0.96 rad, least swing 0.207
        → 0.172 s (``"joint"`` law, ramps 0.1). Demo (``timing.measured_speed``
        0.9, ``timing.min_swing_s`` 0.2, ``time_law`` "joint",
        ``ramp_fraction`` 0.1): 7.27 → 8.19 cm/s, swings 0.278 → 0.241 s,
        hip travel per swing 1.31 → 0.94 rad (knee 1.76 → 1.82 rad; apex
        3.3 → 3.9 cm); the shapes cost ~1 s CPU per run (remembered, so a
        footstep is shaped once per trunk pose). With the ``"even"`` law it
        does not pay (demo 6.49 → 6.23 cm/s, one reflex), so under other
        time laws the heuristic path is kept. Boards (``bench_littledog.py
        --expansions 40000 --seeds 2``; ``timing.measured_speed`` 0.9,
        ``timing.min_swing_s`` 0.2, ``reflex.standing_bear``,
        ``reflex.replan_nudge_m`` 0.02, ``reflex.foot_force_per_leg``,
        ``time_law`` "joint", ``ramp_fraction`` 0.1), "cartesian" →
        "joint": barrier 5.77 → 6.19 cm/s, steps 6.45 → 7.33, round rocks
        4.66 → 4.88, sloped rocks 1/2 7.21 → 8.16, gap 5.97 → 6.49, logs
        4.27 → 5.64, large rocks 3.31 → 3.71; 13 of 14 runs with both; 1 N·s
        side pushes at 1.6–3.2 s survived right / left 6 / 7 → 7 / 8 of 9. The
        ``"joint"`` law alone, against ``"even"`` with the same settings, is
        slower on round rocks (5.76), logs (6.08) and large rocks (3.80); with
        the rest of the fast options below it is faster everywhere.
        The fast options together (``time_law`` and ``path`` "joint",
        ``ramp_fraction`` 0.1, ``lift_off_reach``, ``executor.longest_step``
        0.4, ``reflex.settled_loaded_feet`` 3, ``footstep.edge_drop`` 0.03 and
        ``footstep.max_foothold_slope`` 45°) are the defaults since session 15:
        board bench over 4 seeds of every class 26 of 28 runs, round rocks 8.14,
        sloped rocks 8.41, barrier 8.37, steps 7.96, gap 7.14 cm/s (4/4 each),
        logs 3/4, large rocks 3/4. The former defaults ("even", "cartesian",
        ramps 0.2, 0.3 L steps): 14 of 14 runs over 2 seeds at 4.4–6.0 cm/s,
        sloped rocks 4/6 and large rocks 3/6 over 6 seeds.
    lift_off_reach:
        Where the foot about to lift is out of the leg's reach under the
        trunk the preview controller planned for lift-off, lower and tilt
        the trunk there until it is reached (as at touchdown for the
        landing foot; Zucker 2011, §3.2 without the horizontal push). The
        preview leads the trunk ahead of the swing pose the planner
        certified (1.1 cm at a 12.6 cm stride), which the trailing foot of
        a long stride's last crawl step (RF) then misses: that step was
        invalid at its fitted timing and fell back to its nominal one,
        stretched (0.08 + 0.24 s → 0.62 + 0.44 s). Flat 0.8 m, joint swing
        options (``time_law`` and ``path`` "joint", ``ramp_fraction`` 0.1),
        ``executor.longest_step`` 0.4 / 0.45: 7.40 → 9.02 / 6.59 → 9.18
        cm/s (stretch 2.5 → 0.5 s / 3.8 → 0.5 s); at the default 0.3 L
        9.25 either way (only a straight crawl's last step, or one with
        10 cm strides and more, needs it). On by default, with
        ``executor.longest_step`` 0.4 (see ``path``).
    fast_swing_relief:
        Swings whose ground, under the foot's straight path and a foot
        radius either side, varies by at most this [m] take the fast swing
        options: ``time_law`` and ``path`` "joint", ``ramp_fraction`` 0.1;
        the others keep the settings above. 0 (default): off. The fast
        options shorten flat swings most (flat 0.8 m: 7.23 → 9.25 cm/s,
        swings 0.27 → 0.20 s) and lose runs on rough boards. Board bench
        (``bench_littledog.py --expansions 40000 --seeds 2``), 0 → 0.005:
        14/14 runs both, the four boards unchanged (the gate never opens on
        them), gap 5.86 → 7.02 cm/s, barrier 5.83 → 6.76, steps 5.95 → 6.70;
        at 0.01 large rocks seed 0 rolls over. 1 N·s side pushes
        (``bench_push_recovery.py --from 1.6 --to 3.2``) at 0.005: left 8/9,
        right 7/9 (8/9, 8/9 off), hence still off. With the defaults since
        session 15 (the fast options everywhere) it changes nothing.
    law_trunk:
        The trunk under which the ``"joint"`` time law paces a step's swing
        (and picks its path and law by the least time): ``"swing_pose"``
        (the default until session 26), the pose held through the swing, where a step down a
        rock misses its target by 3–6 cm (the trunk reaches it only by
        lowering into the landing pose) and the law falls back to
        ``"even"``; ``"moving"`` (the default), the initial trajectory's trunk from
        lift-off to touchdown (:func:`~roughwalk.trajectories.initial_trajectory.moving_trunk_leg`),
        so the limiting joint runs near its limit along the whole swing
        rather than at one point of it. Only the initial trajectory's swing
        changes; the nominal timing still uses the swing pose. Large rocks
        seeds 0–7 (``bench_littledog.py --expansions 40000 --classes
        large_rocks``), main 5/8 at 5.30 cm/s → "moving" 7/8 at 6.21 (seed
        0 7.15 → 7.91 with no reflex either way, seed 1 5.10 → 7.23 with
        its reflex gone, seed 3 5.36 → 4.81 with two); but the 1 N·s right
        push (``bench_push_recovery.py --from 1.6 --to 3.2 --direction
        -90``) survives 6 of 9 against 7 (2.0 s, in LF's swing on level
        ground, rolls over), hence off; see ``law_trunk_rise``.
        Session 25 (``docs/measurements.md``; one process per seed through
        ``bench_littledog.py --expansions 40000``'s run, every class against
        the defaults on the same seeds): under the swing pose a step into
        or out of the gap course's trench ran its hip at 0.9 of its limit
        only at lift-off and drop-off (0.3 between; 0.58–0.94 s swings),
        under the moving trunk at 0.6–0.9 throughout (0.46–0.64 s). Large
        rocks seeds 0–63 63/64 at 7.18 cm/s → 64/64 at 7.91, round rocks
        seeds 0–7 7.90 → 9.14, the 0.8 m gap 7.79 → 9.00 (the other six
        classes' seeds 0–7 48/48 either way); but the 1.5 m
        gap course (``--full``) 10/10 at 7.14 → 8/10 at 8.25: as a hind
        foot climbs out of the trench the planned trunk sits on the
        diagonal of the other three feet, the front foot off it unloads,
        and two runs roll over; the right push 7/9 → 6/9. Still off until
        that trench exit keeps its support.
        Session 26: those two falls were the reflex's recovery putting the
        climbing hind foot back down on the trench floor, 12 cm below;
        with ``reflex.catch_nearer`` (on since then) it lands on the lip and
        the 1.5 m gap course walks 10/10 at 8.09 cm/s (the other classes'
        runs are the same as "moving" alone: the option acts only in a
        recovery, and theirs land the same). Hence "moving" is the default.
    law_trunk_rise:
        With ``law_trunk`` "moving", only swings whose target lies at least
        this far [m] above or below their start are paced under the moving
        trunk (the steps up and down rocks it is for); the others keep the
        swing pose. 0: every swing. On level ground nothing changes then.
        At 0.01 with "moving" (``bench_littledog.py --expansions 40000``):
        large rocks seeds 0–7 6/8 at 5.93 cm/s (main 5/8 at 5.30; seed 6
        gained), the other five classes 2/2 each and faster on seeds 0–1
        (round rocks 7.54 → 8.41, sloped rocks 8.50 → 9.31, gap 7.60 →
        7.62, barrier 8.52 → 8.64, steps 8.63 → 8.98), but logs seeds 0–5
        lose seed 1 (main 3.69 cm/s after its reflexes; 6 reflexes, given
        up) and gain seed 5: 4/6 at 8.08 against 7.71. Hence off.
    """

    lift_height: float = 0.03
    clearance: float = 0.025
    scan_terrain: bool = True
    lift_fraction: float = 0.3
    time_law: str = "joint"
    vertical_weight: float = 1.5
    ramp_fraction: float = 0.1
    path: str = "joint"
    lift_off_reach: bool = True
    fast_swing_relief: float = 0.0
    law_trunk: str = "moving"
    law_trunk_rise: float = 0.0

    def __post_init__(self) -> None:
        _check_nonnegative(
            self, ("lift_height", "clearance", "fast_swing_relief", "law_trunk_rise"), "swing"
        )
        if self.law_trunk not in ("swing_pose", "moving"):
            raise ConfigError(
                f"swing.law_trunk must be 'swing_pose' or 'moving', got {self.law_trunk!r}"
            )
        if self.path not in ("cartesian", "joint"):
            raise ConfigError(f"swing.path must be 'cartesian' or 'joint', got {self.path!r}")
        if not (math.isfinite(self.lift_fraction) and 0 <= self.lift_fraction < 0.5):
            raise ConfigError(f"swing.lift_fraction must be in [0, 0.5), got {self.lift_fraction}")
        if self.time_law not in ("even", "joint", "knots"):
            raise ConfigError(
                f"swing.time_law must be 'even', 'joint' or 'knots', got {self.time_law!r}"
            )
        _check_positive(self, ("vertical_weight",), "swing")
        if not (math.isfinite(self.ramp_fraction) and 0 < self.ramp_fraction <= 0.5):
            raise ConfigError(f"swing.ramp_fraction must be in (0, 0.5], got {self.ramp_fraction}")


@dataclass(frozen=True)
class ChompConfig:
    """The CHOMP optimiser (Ratliff et al. 2009; Zucker 2011, §5.1 and §5.3).

    Attributes
    ----------
    rate_hz:
        Sample rate of ξ [Hz] (the paper: half the control rate). Thanks to
        the covariant update the result hardly depends on it; the cost is
        linear in it.
    max_iterations:
        Iteration limit per attempt (body and swing iterations together).
    body_iterations, swing_iterations:
        Iterations of each coordinate-descent block: first the trunk with the
        supporting legs by IK, then the swing leg's joints.
    smoothness_order:
        1 penalises squared velocities, 2 squared accelerations of the change
        ξ − ξ₀ from the initial trajectory (so the ZMP-planned motion is kept
        where nothing pushes it). 2 spreads corrections more smoothly.
    smoothness_weight:
        λ in U = f_obs + λ·f_smooth + ... Larger keeps closer to the initial
        trajectory, smaller lets the obstacles push further.
    obstacle_weight:
        Weight of the workspace obstacle cost [1/m²].
    obstacle_epsilon:
        ε [m]: the obstacle potential is zero beyond this clearance and
        quadratic inside it (Ratliff 2009). It is the clearance CHOMP aims for.
    reachability_weight:
        Weight of ½Σ‖f′ − FK(IK(f′))‖² over the supporting legs [1/m²] (§3.2),
        f′ the foot target pushed ``reach_margin`` away from its hip.
    reach_margin:
        [m] how far inside the leg's workspace the reachability term starts
        to act, so that its optimum keeps the feet reachable.
    support_weight:
        Weight of the squared shortfall of the ZMP margin to the support
        polygon below ``zmp_margin`` [1/m²] (the static-stability term, with
        the cart-table's ZMP in place of the CoM).
    zmp_margin:
        Margin [m] inside the support polygon the support term asks for.
    speed_weight:
        Weight of ½Σ max(0, |q̇| − ρ·v)² over the swing leg's joints [s²/rad²]
        (not in the paper, which only lengthens steps that break the limits).
    speed_fraction:
        ρ: the fraction of each joint's velocity limit above which that term acts.
    step_size:
        α in ξ ← ξ − α·A⁻¹∇U.
    max_step:
        Trust region: an update moving any sample by more than this [m] (or
        its rotation by more than max_step / rotation_scale [rad]) is scaled
        down.
    rotation_scale:
        [m/rad]: one radian of trunk rotation counts like this much trunk
        displacement in the metric.
    joint_scale:
        [m/rad]: one radian of a swing joint counts like this much foot
        displacement in the metric.
    point_spacing:
        Spacing [m] of the body points along the collision capsules.
    gradient:
        ``"functional"``: Ratliff 2009's functional gradient of the
        arc-length-weighted potential, ‖ẋ‖·[(I − x̂′x̂′ᵀ)∇c − c·κ], projected
        orthogonally to each body point's path. ``"exact"``: the Euclidean
        gradient of the discretised objective (the same in the limit).
    line_search:
        Halve a step that would raise the objective (up to 6 times) instead of
        taking it; stop when no halving helps.
    max_restarts:
        If the result collides or breaks a velocity limit, lengthen the step,
        regenerate the initial trajectory and restart, at most this often.
    restart_duration_factor:
        Factor (> 1) on the step duration at each restart.
    """

    rate_hz: float = 50.0
    max_iterations: int = 40
    body_iterations: int = 10
    swing_iterations: int = 10
    smoothness_order: int = 2
    smoothness_weight: float = 1.0
    obstacle_weight: float = 400.0
    obstacle_epsilon: float = 0.015
    reachability_weight: float = 2000.0
    reach_margin: float = 0.005
    support_weight: float = 200.0
    zmp_margin: float = 0.005
    speed_weight: float = 0.05
    speed_fraction: float = 0.8
    step_size: float = 0.2
    max_step: float = 0.01
    rotation_scale: float = 0.1
    joint_scale: float = 0.08
    point_spacing: float = 0.02
    gradient: str = "functional"
    line_search: bool = True
    max_restarts: int = 3
    restart_duration_factor: float = 1.3

    def __post_init__(self) -> None:
        _check_positive(
            self,
            (
                "rate_hz",
                "smoothness_weight",
                "obstacle_epsilon",
                "step_size",
                "max_step",
                "rotation_scale",
                "joint_scale",
                "point_spacing",
            ),
            "chomp",
        )
        _check_nonnegative(
            self,
            (
                "obstacle_weight",
                "reachability_weight",
                "reach_margin",
                "support_weight",
                "zmp_margin",
                "speed_weight",
            ),
            "chomp",
        )
        for name in ("max_iterations", "body_iterations", "swing_iterations", "max_restarts"):
            v = getattr(self, name)
            if not (isinstance(v, int) and v >= 0):
                raise ConfigError(f"chomp.{name} must be an integer ≥ 0, got {v!r}")
        if self.body_iterations + self.swing_iterations == 0 and self.max_iterations > 0:
            raise ConfigError("chomp.body_iterations and chomp.swing_iterations are both 0")
        if not (math.isfinite(self.speed_fraction) and 0 < self.speed_fraction <= 1):
            raise ConfigError(f"chomp.speed_fraction must be in (0, 1], got {self.speed_fraction}")
        if self.smoothness_order not in (1, 2):
            raise ConfigError(
                f"chomp.smoothness_order must be 1 (velocity) or 2 (acceleration), "
                f"got {self.smoothness_order!r}"
            )
        if self.gradient not in ("functional", "exact"):
            raise ConfigError(
                f"chomp.gradient must be 'functional' or 'exact', got {self.gradient!r}"
            )
        if not (math.isfinite(self.restart_duration_factor) and self.restart_duration_factor > 1):
            raise ConfigError(
                f"chomp.restart_duration_factor must be > 1, got {self.restart_duration_factor}"
            )


@dataclass(frozen=True)
class ValidityConfig:
    """When a footstep trajectory counts as valid (and when CHOMP may stop early).

    Attributes
    ----------
    min_clearance:
        Every collision capsule except the supporting feet must keep this
        distance [m] from the terrain (0: touching is allowed).
    foot_tolerance:
        The swing foot may dip this far [m] into the terrain's distance field
        (it starts and ends touching the ground; the paper allows light foot
        contact).
    zmp_tolerance:
        The ZMP may leave the support polygon by at most this much [m].
    contact_zone:
        A lifted foot within this distance [m] of its start or target may
        touch the ground (down to ``foot_tolerance``); farther away it must
        keep ``min_clearance`` like the rest of the body, so that grazing an
        obstacle is not mistaken for landing.
    """

    min_clearance: float = 0.0
    foot_tolerance: float = 0.001
    zmp_tolerance: float = 0.0
    contact_zone: float = 0.02

    def required_clearance(
        self,
        points: NDArray[np.float64],
        is_foot: NDArray[np.bool_],
        footholds: NDArray[np.float64],
        contact_clearance: float = 0.0,
    ) -> NDArray[np.float64]:
        """The clearance [m] each point (T, U, 3) must keep.

        ``min_clearance``, or the foot floor for a foot point within
        ``contact_zone`` of a foothold (K, 3).
        """
        near = np.zeros(points.shape[:2], dtype=bool)
        if np.any(is_foot):
            feet = points[:, is_foot]
            dist = np.linalg.norm(feet[:, :, None, :] - footholds[None, None], axis=-1).min(axis=-1)
            near[:, is_foot] = dist < self.contact_zone
        return np.where(near, self.foot_floor(contact_clearance), self.min_clearance)

    def foot_floor(self, contact_clearance: float = 0.0) -> float:
        """The least clearance [m] a lifted foot may have.

        ``-foot_tolerance``, or that much below the foot's clearance on its
        own footholds when the plan put one slightly into the field (a foot
        cannot do better than the ground it stands on).
        """
        return min(-self.foot_tolerance, contact_clearance - self.foot_tolerance)

    def __post_init__(self) -> None:
        if not math.isfinite(self.min_clearance):
            raise ConfigError(f"validity.min_clearance must be finite, got {self.min_clearance}")
        _check_nonnegative(self, ("foot_tolerance", "zmp_tolerance", "contact_zone"), "validity")


@dataclass(frozen=True)
class TrajectoryConfig:
    """Everything :func:`roughwalk.footstep_trajectories` can be told.

    Attributes
    ----------
    control_rate_hz:
        Rate [Hz] of the output joint angles and velocities. The checks of
        clearance and velocity limits run at this rate.
    sdf_resolution:
        Voxel size [m] of the terrain's signed distance field when one has to
        be built (5 mm as in the paper).
    foot_centre:
        How a planned contact point becomes the foot-sphere centre the
        swing aims at and the stance holds: "normal", the contact plus the
        foot radius along the terrain's normal at that one point (the
        planner's own centre); "disc", the contact plus the foot radius
        along the normal of the mean slope over the foot's disc
        (:meth:`~roughwalk.terrain.terrain.Terrain.disc_normal`; the
        planner's centre with ``footstep.normal_radius`` the foot radius,
        which it needs: a certificate's foot within 1 cm wins;
        large rocks walk worse with both, figures there);
        "resting", where the sphere rests lowered
        straight onto the contact's (x, y), over the whole foot's disc as
        the planner's slope and rim checks judge it
        (:func:`~roughwalk.trajectories.step_sequence._foot_centres`).
        Session 17 (``bench_littledog.py --expansions 40000``): large rocks
        seed 2 falls with "resting" (main 6.20 cm/s), seed 3 walks 6.06
        (5.36). Touchdowns land within 0.9 cm of their plan with either,
        so the aim is not what puts feet on steep faces (see
        ``footstep.max_contact_slope``): "normal" stays.
    timing, zmp, swing, chomp, validity:
        The stages' settings.
    """

    control_rate_hz: float = 100.0
    sdf_resolution: float = 0.005
    foot_centre: str = "normal"
    timing: TimingConfig = field(default_factory=TimingConfig)
    zmp: ZmpConfig = field(default_factory=ZmpConfig)
    swing: SwingConfig = field(default_factory=SwingConfig)
    chomp: ChompConfig = field(default_factory=ChompConfig)
    validity: ValidityConfig = field(default_factory=ValidityConfig)

    def __post_init__(self) -> None:
        _check_positive(self, ("control_rate_hz", "sdf_resolution"), "trajectory")
        if self.foot_centre not in ("normal", "disc", "resting"):
            raise ConfigError(
                "trajectory.foot_centre must be 'normal', 'disc' or 'resting', "
                f"got {self.foot_centre!r}"
            )
        for name, kind in (
            ("timing", TimingConfig),
            ("zmp", ZmpConfig),
            ("swing", SwingConfig),
            ("chomp", ChompConfig),
            ("validity", ValidityConfig),
        ):
            if not isinstance(getattr(self, name), kind):
                raise ConfigError(f"{name} must be a {kind.__name__}")
