"""Segments the executor makes itself: the reflex's recovery, holds and blends.

The reflex (Zucker 2011, §6) must "restore the robot's balance and place
all four feet firmly on the ground". :func:`recovery_segment` does it in
three parts, from the measured state:

1. every foot off the ground goes down, fast: straight below where it is
   (to its planned foothold if that is within 2 cm; towards it, off a step's
   edge, :func:`off_edge`); the trunk holds still.
   A trunk moving towards a lifted foot's side (a push) moves that foot's
   target by the capture offset v·√(h/g) (the linear inverted pendulum's
   capture point), so the support polygon reaches where the trunk is going;
2. the trunk moves over the four feet, to the nominal stance fitted to them
   with its centre of mass over the feet's centroid (:func:`centred_fit`);
3. it holds still so the robot settles before re-planning.

Settled, a foot may still stand where no walk should start: slid onto a
rock's face steeper than the friction cone, or off every foothold the
planner allows. :func:`replant_segments` lifts such a foot and puts it
down on the nearest foothold (the trunk first over the other three feet,
then back over all four), as the start of a run moves a foot put down on
a flank (:func:`~roughwalk.sim.foothold_snap.snap_to_footholds`).

Motions are minimum-jerk in joint angles and trunk pose, long enough that
no joint exceeds half its velocity limit.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from roughwalk.robots._rotations import quat_to_matrix
from roughwalk.sim.trajectory_buffer import DesiredState, Segment
from roughwalk.trajectories.body_keyframes import nominal_fit, pose_over_support
from roughwalk.trajectories.contact_forces import static_contact_forces
from roughwalk.trajectories.euler import matrix_to_rpy, rpy_to_quat
from roughwalk.trajectories.whole_body import WholeBody

if TYPE_CHECKING:
    from roughwalk.robots.robot import Robot
    from roughwalk.sim.measured_state import MeasuredState
    from roughwalk.terrain.terrain import Terrain

__all__ = [
    "recovery_segment",
    "replant_segments",
    "sliding_leg",
    "centred_fit",
    "hold_segment",
    "blend_segment",
    "pose_segment",
    "min_jerk",
    "off_edge",
    "nearer_catch",
    "standing_feet",
    "near_ground",
    "recently_loaded",
    "settled",
]

_RATE_HZ = 100.0
_GRAVITY = 9.81
EDGE_RISE_M = 0.01
"""Height change [m] of the ground under a foot (half its radius either side
of its centre, about one radius across) beyond which a lowered foot stands on
an edge: LittleDog's 1 cm across is steeper than 45°, where no foot holds
with μ = 1. At 0.5 cm, a catch on a rock's flank (board AC, seed 0 of the
bench's round rocks: 5.6 mm) moved too, and that run fell."""
STANDING_M = 0.01
"""Height [m] of a supporting foot's centre over the ground under it, less
its radius, within which :func:`standing_feet` takes it to stand."""
EDGE_STEP_M = 0.0025
"""Step [m] of :func:`off_edge`'s search towards the planned foothold."""
EDGE_REACH_M = 0.02
"""Farthest [m] :func:`off_edge` moves a lowered foot."""


def min_jerk(s: NDArray[np.float64]) -> NDArray[np.float64]:
    """The minimum-jerk profile 10s³ − 15s⁴ + 6s⁵ on [0, 1] (peak slope 1.875)."""
    return s**3 * (10.0 - 15.0 * s + 6.0 * s**2)


def _duration(robot: Robot, q: NDArray[np.float64], at_least: float, speed: float) -> float:
    """Time [s] for the joint path q (n, 12), min-jerk, at ≤ ``speed`` × the velocity limits."""
    travel = np.abs(np.diff(q, axis=0)).sum(axis=0)
    need = float(np.max(1.875 * travel / (speed * np.asarray(robot.joint_velocity_limit))))
    return max(at_least, need)


def _forces(
    robot: Robot,
    q: NDArray[np.float64],
    base_pos: NDArray[np.float64],
    base_quat: NDArray[np.float64],
    feet: NDArray[np.float64],
    support: NDArray[np.bool_],
) -> NDArray[np.float64]:
    """Static ground forces (n, 4, 3) [N] holding the robot's weight over its CoM."""
    com = np.array([robot.center_of_mass(q[k], base_pos[k], base_quat[k]) for k in range(len(q))])
    zero = np.zeros((len(q), 3))
    return static_contact_forces(feet, support, com[:, :2], zero, robot.mass, _GRAVITY)


def pose_segment(
    robot: Robot,
    base_pos: NDArray[np.float64],
    base_rpy: NDArray[np.float64],
    feet: NDArray[np.float64],
    support: NDArray[np.bool_],
    duration: float,
    kind: str,
    ready_at: float,
    speed: float = 0.5,
) -> Segment:
    """A segment through trunk poses (n, 3)+(n, 3) [m, rad] and feet (n, 4, 3) [m], timed by IK.

    The samples are spread over ``duration`` [s] (or longer if a joint would
    pass ``speed`` × its velocity limit) with minimum-jerk timing; q comes
    from IK at every sample.
    """
    n = len(base_pos)
    quats = np.array([rpy_to_quat(a) for a in base_rpy])
    q = np.array([robot.inverse_kinematics(feet[k], base_pos[k], quats[k])[0] for k in range(n)])
    total = _duration(robot, q, duration, speed)
    m = max(int(np.ceil(total * _RATE_HZ)), 1)
    t = np.linspace(0.0, total, m + 1)
    s = min_jerk(t / total) * (n - 1)
    lo = np.clip(np.floor(s).astype(int), 0, max(n - 2, 0))
    a = (s - lo)[:, None]
    hi = np.minimum(lo + 1, n - 1)

    def lerp(x: NDArray[np.float64]) -> NDArray[np.float64]:
        flat = x.reshape(n, -1)
        return ((1.0 - a) * flat[lo] + a * flat[hi]).reshape((m + 1, *x.shape[1:]))

    qs = lerp(q)
    pos = lerp(base_pos)
    rpy = lerp(base_rpy)
    quat = np.array([rpy_to_quat(r) for r in rpy])
    fs = lerp(feet)
    sup = np.repeat(np.asarray(support, dtype=bool)[None], m + 1, axis=0)
    qd = np.gradient(qs, t, axis=0) if m > 1 else np.zeros_like(qs)
    return Segment(
        t=t,
        q=qs,
        qd=qd,
        base_pos=pos,
        base_quat=quat,
        feet=fs,
        support=sup,
        forces=_forces(robot, qs, pos, quat, fs, sup),
        phase=np.zeros(m + 1, dtype=np.int64),
        kind=kind,
        ready_at=ready_at,
    )


def hold_segment(
    state: DesiredState, duration: float, ready_at: float, kind: str = "hold"
) -> Segment:
    """Hold ``state`` for ``duration`` [s]."""
    m = max(int(np.ceil(duration * _RATE_HZ)), 1)
    t = np.linspace(0.0, max(duration, 1e-3), m + 1)

    def rep(x: NDArray[Any]) -> NDArray[Any]:
        return np.repeat(np.asarray(x)[None], m + 1, axis=0)

    return Segment(
        t=t,
        q=rep(state.q),
        qd=np.zeros((m + 1, 12)),
        base_pos=rep(state.base_pos),
        base_quat=rep(state.base_quat),
        feet=rep(state.feet),
        support=rep(state.support),
        forces=rep(state.forces),
        phase=np.zeros(m + 1, dtype=np.int64),
        kind=kind,
        step=state.step,
        ready_at=ready_at,
    )


def blend_segment(
    robot: Robot,
    start: DesiredState,
    end: DesiredState,
    at_least: float,
    ready_at: float,
) -> Segment:
    """Move from ``start`` to ``end`` (both with four feet down) in trunk pose, feet following.

    Used where a new plan begins from a pose that differs slightly from the
    one the robot holds.
    """
    k = 11
    s = np.linspace(0.0, 1.0, k)[:, None]
    rpy0 = matrix_to_rpy(quat_to_matrix(start.base_quat))
    rpy1 = matrix_to_rpy(quat_to_matrix(end.base_quat))
    rpy1 = rpy0 + (rpy1 - rpy0 + np.pi) % (2 * np.pi) - np.pi
    feet = (1.0 - s[:, :, None]) * start.feet[None] + s[:, :, None] * end.feet[None]
    return pose_segment(
        robot,
        (1.0 - s) * start.base_pos + s * end.base_pos,
        (1.0 - s) * rpy0 + s * rpy1,
        feet,
        np.ones(4, dtype=bool),
        at_least,
        "blend",
        ready_at,
    )


def _capture_offset(
    measured: MeasuredState, feet: NDArray[np.float64], limit: float
) -> NDArray[np.float64]:
    """The capture offset v·√(h/g) (2,) [m] of the trunk, at most ``limit`` [m] long.

    The linear inverted pendulum's capture point (Pratt et al. 2006): where a
    foot must be for a trunk at height h over the feet, moving at v, to come
    to rest over it.
    """
    if limit <= 0.0:
        return np.zeros(2)
    height = max(float(measured.base_pos[2] - feet[:, 2].mean()), 0.0)
    offset = np.asarray(measured.base_vel[:2], dtype=float) * np.sqrt(height / _GRAVITY)
    norm = float(np.linalg.norm(offset))
    return offset * (limit / norm) if norm > limit else offset


def centred_fit(
    robot: Robot, feet: NDArray[np.float64], iterations: int = 3
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The nominal stance's trunk pose fitted to ``feet`` (4, 3), its CoM over their centroid.

    Returns (base_pos [m], rpy [rad]): :func:`nominal_fit`'s, slid
    horizontally until the centre of mass is over the feet's centroid.

    The fit alone tilts the trunk with the feet and keeps it square above
    them, which moves the centre of mass h·sin(tilt) towards the low feet:
    4.7 cm at the 15° roll of a stance across the barrier's edge, next to
    the support polygon's low edge, where the robot rolled over (bench
    barrier seed 1). Where sliding all the way leaves a foot the fit
    reached out of reach, it slides part of the way.
    """
    fit, rpy = nominal_fit(WholeBody(robot), feet)
    quat = rpy_to_quat(rpy)
    centre = feet[:, :2].mean(axis=0)
    pos = fit.copy()
    for _ in range(iterations):
        q, _ = robot.inverse_kinematics(feet, pos, quat)
        pos[:2] += centre - robot.center_of_mass(q, pos, quat)[:2]
    # Slide less where the whole slide leaves a foot the fit reached out of reach.
    reached = robot.inverse_kinematics(feet, fit, quat)[1]
    for share in (1.0, 0.75, 0.5, 0.25):
        slid = fit + share * (pos - fit)
        if np.all(robot.inverse_kinematics(feet, slid, quat)[1] >= reached):
            return slid, rpy
    return fit, rpy


def _ring(radius: float) -> NDArray[np.float64]:
    """Offsets (9, 2) [m]: a centre and eight points ``radius`` around it."""
    a = np.linspace(0.0, 2.0 * np.pi, 8, endpoint=False)
    return np.vstack([[0.0, 0.0], radius * np.column_stack([np.cos(a), np.sin(a)])])


def _under_foot(foot_radius: float) -> NDArray[np.float64]:
    """Offsets (5, 2) [m] of the ground under a foot: its centre, half a radius around."""
    return (
        0.5 * foot_radius * np.array([[0.0, 0.0], [1.0, 0.0], [-1.0, 0.0], [0.0, 1.0], [0.0, -1.0]])
    )


def off_edge(
    terrain: Terrain,
    catch: NDArray[np.float64],
    toward: NDArray[np.float64],
    foot_radius: float,
    reach: float,
) -> NDArray[np.float64]:
    """A lowered foot's catch (3,) [m] moved off a step's edge, towards ``toward`` (3,).

    A foot put down where the ground under it changes height (a step's
    corner: within half a foot radius of the foot's centre by more than
    :data:`EDGE_RISE_M`) rolls off the corner as it presses. A swing
    caught just over a step's edge did so on the LittleDog steps course
    (seed 1 of ``bench littledog --classes steps --expansions 40000``): RF
    went down 2 mm past the 5.4 cm step's edge, onto the corner, slipped,
    and the robot rolled over. The catch moves on towards where the foot
    was headed (its planned foothold, on ground the planner accepted),
    2.5 mm at a time up to ``reach`` [m], to the first flat ground; if
    there is none, it stays.
    """
    start = np.asarray(catch, dtype=float)
    way = np.asarray(toward, dtype=float)[:2] - start[:2]
    length = float(np.linalg.norm(way))
    ring = _under_foot(foot_radius)
    steps = int(np.floor(min(reach, length) / EDGE_STEP_M + 1e-9))
    for k in range(steps + 1):
        xy = start[:2] + (k * EDGE_STEP_M / length) * way if k else start[:2]
        z = np.asarray(terrain.height(xy[None] + ring), dtype=float)
        if float(np.ptp(z)) <= EDGE_RISE_M:
            out = start.copy()
            out[:2] = xy
            return out
    return start


def standing_feet(
    robot: Robot,
    terrain: Terrain,
    measured: MeasuredState,
    support: NDArray[np.bool_],
    loaded_n: float,
) -> NDArray[np.bool_]:
    """The feet that bear the trunk while a reflex puts the others down.

    Those loaded, and those supporting and on the ground.

    A foot's measured force alone misses standing feet: on a steep rock
    face a loaded hind foot chatters (LittleDog board AE, the bench's large
    rocks seed 0: RH's vertical force alternated 0 and 15–20 N every 8 ms
    while LH swung), and a trunk sagging onto the other diagonal unloads a
    front foot (LF) for the instant the reflex fires. Counted as lifted,
    both were put down with the trunk's whole weight planned on the one
    loaded foot (RF, 26.6 N), the others unweighted and softened as for a
    touchdown, and the robot rolled over (34° at 1.41 s, with
    ``timing.measured_speed`` 0.9). A foot the
    plan has in ``support`` whose centre is within :data:`STANDING_M` of
    the ground under it counts as standing, as does any foot bearing more
    than ``loaded_n`` [N].
    """
    loaded = measured.foot_forces[:, 2] > loaded_n
    low = near_ground(robot, terrain, measured.feet)
    return np.asarray(loaded | (np.asarray(support, dtype=bool) & low), dtype=bool)


def near_ground(robot: Robot, terrain: Terrain, feet: NDArray[np.float64]) -> NDArray[np.bool_]:
    """The feet (4, 3) [m] less :data:`STANDING_M` above the ground (centre less radius)."""
    ground = terrain.height(feet[:, :2])
    return np.asarray(feet[:, 2] - ground - robot.foot_radius < STANDING_M, dtype=bool)


def recently_loaded(
    last_loaded_s: NDArray[np.float64], now: float, window_s: float
) -> NDArray[np.bool_]:
    """The feet (4,) that bore load within ``window_s`` [s] before ``now`` [s].

    ``last_loaded_s`` (4,) [s]: when each foot last bore load (−∞: never).
    A foot chattering on a rock face bears load every few ticks and none
    in between (board AE: RH alternated 0 and 15–20 N every 8 ms, bench
    large rocks seed 0; RH bore nothing for the 34 ms before seed 6's
    reflex); at a reflex it stands as much as a foot loaded at that tick.
    ``window_s`` 0: only a foot loaded at ``now``.
    """
    age = now - np.asarray(last_loaded_s, dtype=float)
    return np.asarray(age <= window_s + 1e-9, dtype=bool)


def settled(measured: MeasuredState, rate_rad_s: float, loaded_feet: int, loaded_n: float) -> bool:
    """Whether a recovered robot stands still on ``loaded_feet`` loaded feet.

    The trunk turns slower than ``rate_rad_s`` [rad/s] with at least
    ``loaded_feet`` feet pressing down by over ``loaded_n`` [N]
    (:attr:`~roughwalk.sim.config.ReflexConfig.settled_loaded_feet`: four
    feet down share the load indeterminately, so a still robot can stand on
    three.)
    """
    turning = float(np.linalg.norm(measured.base_angvel))
    loaded = int(np.sum(np.asarray(measured.foot_forces)[:, 2] > loaded_n))
    return turning < rate_rad_s and loaded >= loaded_feet


CATCH_STEP_M = 0.005
"""Spacing [m] of :func:`nearer_catch`'s candidate landings."""
CATCH_EDGE_M = 0.01
"""Flat ground [m] beyond the foot's radius a :func:`nearer_catch` landing
needs around it (the walk's ``footstep.edge_margin``)."""
CATCH_CLEAR_M = 0.002
"""Least height [m] of a lowered foot's sole over the ground along its way
to the planned foothold, for :func:`nearer_catch` to send it there."""
ARCH_M = 0.015
"""Height [m] of the arch a lowered foot moving across makes (part 1 of
:func:`recovery_segment`)."""


def _arched_way(
    start: NDArray[np.float64], goal: NDArray[np.float64], k: int
) -> NDArray[np.float64]:
    """``k`` points (k, 3) from ``start`` to ``goal``, a lowered foot's way.

    Straight, arched by :data:`ARCH_M` where it moves across: part 1 of
    :func:`recovery_segment` moves the foot so, and :func:`nearer_catch`
    checks that way against the ground.
    """
    s = np.linspace(0.0, 1.0, k)
    way = (1.0 - s)[:, None] * start[None] + s[:, None] * goal[None]
    if np.linalg.norm(goal[:2] - start[:2]) > 0.02:
        way[:, 2] += ARCH_M * np.sin(np.pi * s)
    return way


def nearer_catch(
    terrain: Terrain,
    foot: NDArray[np.float64],
    catch: NDArray[np.float64],
    planned: NDArray[np.float64],
    foot_radius: float,
) -> NDArray[np.float64] | None:
    """A landing (3,) [m] for a lifted foot at ``foot`` (3,) nearer than ``catch``, else None.

    ``catch`` is where the recovery would put the foot down (straight
    below, :func:`off_edge`), ``planned`` its planned foothold, both (3,)
    foot centres; only their ground heights count. The candidates lie on
    the line from the catch to the planned foothold, every
    :data:`CATCH_STEP_M`: each on ground flat (within
    :data:`EDGE_RISE_M`) out to :data:`CATCH_EDGE_M` beyond the foot's
    radius, and reached along the foot's arched straight way with its sole
    :data:`CATCH_CLEAR_M` over the ground (sampled at the foot's centre
    and half a radius around it), and higher than the catch's ground by
    more than :data:`EDGE_RISE_M`, so only a drop is avoided (on level
    ground the catch keeps its capture offset). The nearest to the foot
    wins if it is nearer than the catch. On the LittleDog 1.5 m gap course (``bench
    littledog --full``, seed 6, ``swing.law_trunk`` "moving") the
    foot-force reflex fired as RH, 3 cm over the trench's lip and still
    over the trench floor, climbed out of the 10 cm deep trench; the
    recovery put RH back down on the floor, 12 cm below, and the trunk
    rolled over towards it.
    """
    foot = np.asarray(foot, dtype=float)
    start = np.asarray(catch, dtype=float)
    way = np.asarray(planned, dtype=float)[:2] - start[:2]
    length = float(np.linalg.norm(way))
    ground = float(np.asarray(terrain.height(start[None, :2]), dtype=float)[0])
    best = float(np.linalg.norm(foot - np.array([start[0], start[1], ground + foot_radius])))
    if length < CATCH_STEP_M:
        return None
    rim = _ring(foot_radius + CATCH_EDGE_M)
    under = _under_foot(foot_radius)
    found = None
    for k in range(1, int(np.floor(length / CATCH_STEP_M + 1e-9)) + 1):
        xy = start[:2] + min(1.0, k * CATCH_STEP_M / length) * way
        z = np.asarray(terrain.height(xy[None] + rim), dtype=float)
        if float(np.ptp(z)) > EDGE_RISE_M:
            continue
        land = np.array([xy[0], xy[1], float(terrain.height(xy[None])[0]) + foot_radius])
        if land[2] - foot_radius - ground <= EDGE_RISE_M:
            continue  # no drop avoided (on level ground the catch keeps its capture offset)
        distance = float(np.linalg.norm(land - foot))
        if distance >= best:
            continue
        path = _arched_way(foot, land, 17)[1:-1]
        heights = terrain.height((path[:, None, :2] + under[None]).reshape(-1, 2))
        top = np.asarray(heights, dtype=float).reshape(len(path), len(under)).max(axis=1)
        if np.all(path[:, 2] - foot_radius - top >= CATCH_CLEAR_M):
            best, found = distance, land
    return found


def recovery_segment(
    robot: Robot,
    terrain: Terrain,
    measured: MeasuredState,
    planned_feet: NDArray[np.float64],
    in_contact: NDArray[np.bool_],
    lower_s: float,
    settle_s: float,
    ready_at: float,
    press_m: float = 0.0,
    capture_max_m: float = 0.0,
    bearing: NDArray[np.bool_] | None = None,
    catch_nearer: bool = False,
) -> tuple[list[Segment], NDArray[np.float64]]:
    """The reflex's motion from ``measured``: feet down, trunk over them, hold.

    Parameters
    ----------
    planned_feet:
        (4, 3) [m] where each foot was headed (its planned foothold).
    in_contact:
        (4,) which feet bear weight now; the others are put down.
    lower_s:
        Time [s] for the first two parts together (stretched if a joint needs it).
    settle_s:
        Hold time [s] at the end.
    press_m:
        How far [m] below the terrain surface the lowered feet aim.
    capture_max_m:
        Largest capture offset [m] of a lowered foot (0: straight down).
    bearing:
        (4,) the feet that carry the trunk while the others go down
        (:func:`standing_feet`; default ``in_contact``). A foot both put
        down and bearing keeps its load as it moves the few millimetres to
        the ground.
    catch_nearer:
        A lifted foot goes down on the flat ground nearest to it on the way
        to its planned foothold instead of straight down, where that is
        nearer and the way there clears the ground (:func:`nearer_catch`):
        a foot climbing out of a trench, caught over its floor, lands on
        the lip rather than back at the bottom.

    Returns the segments and the four footholds (4, 3) [m] the robot ends on.
    """
    r = robot.foot_radius
    base = measured.base_pos
    rpy = matrix_to_rpy(measured.rotation)
    start_feet = measured.feet.copy()
    target = start_feet.copy()
    capture = _capture_offset(measured, start_feet, capture_max_m)
    centre = start_feet[:, :2].mean(axis=0)
    for leg in np.flatnonzero(~np.asarray(in_contact, dtype=bool)):
        # Straight down is the quickest catch, moved out by the capture offset
        # when the trunk heads for this foot's side; the planned foothold only
        # when the foot is nearly over that point already.
        catch = start_feet[leg].copy()
        if float(capture @ (start_feet[leg, :2] - centre)) > 0.0:
            catch[:2] += capture
        planned = np.asarray(planned_feet[leg], dtype=float)
        goal = planned.copy()
        if np.linalg.norm(goal[:2] - catch[:2]) > 0.02:
            goal = off_edge(terrain, catch, planned, r, EDGE_REACH_M)
            nearer = (
                nearer_catch(terrain, start_feet[leg], goal, planned, r) if catch_nearer else None
            )
            if nearer is not None:
                goal = nearer
        # "Firmly on the ground": aim a little into it, so the servo presses
        # the foot down and the pressing legs stop the trunk tipping.
        goal[2] = float(terrain.height(goal[None, :2])[0]) + r - press_m
        target[leg] = goal
    # Part 1, fast: the lifted feet down (with a 1.5 cm arch if they move
    # across), trunk still; the robot may be tipping towards them.
    k = 9
    feet = np.stack([_arched_way(start_feet[j], target[j], k) for j in range(4)], axis=1)
    support = np.asarray(in_contact if bearing is None else bearing, dtype=bool)
    segments = []
    if not np.all(in_contact):
        segments.append(
            pose_segment(
                robot,
                np.repeat(base[None], k, axis=0),
                np.repeat(rpy[None], k, axis=0),
                feet,
                support,
                0.25 * lower_s,
                "recovery",
                ready_at,
                speed=1.0,
            )
        )
    # Part 2: the trunk over the four feet, nominal stance fitted to them.
    fit_pos, fit_rpy = centred_fit(robot, target)
    fit_rpy = rpy + (fit_rpy - rpy + np.pi) % (2 * np.pi) - np.pi
    s2 = np.linspace(0.0, 1.0, k)[:, None]
    segments.append(
        pose_segment(
            robot,
            (1.0 - s2) * base + s2 * fit_pos,
            (1.0 - s2) * rpy + s2 * fit_rpy,
            np.repeat(target[None], k, axis=0),
            np.ones(4, dtype=bool),
            0.75 * lower_s,
            "recovery",
            ready_at,
        )
    )
    segments.append(hold_segment(segments[-1].last(), settle_s, ready_at, kind="recovery"))
    return segments, target


HELD_M = 0.002
"""How near [m] a foot's desired position must be to its recovery foothold
for :func:`sliding_leg` to watch it (a foot still being put down is not)."""


def sliding_leg(
    measured: MeasuredState,
    desired: DesiredState,
    footholds: NDArray[np.float64],
    limit: float,
    loaded_n: float,
    others_bearing: int = 3,
    loaded: NDArray[np.bool_] | None = None,
    drop_m: float = 0.0,
) -> int | None:
    """A foot sliding off its recovery foothold while the others bear load, else None.

    Watched: the feet the recovery holds on their ``footholds`` (4, 3) [m]
    (desired supporting, within :data:`HELD_M` of them). The one farthest
    beyond ``limit`` [m] counts (with ``others_bearing`` below 3 or
    ``drop_m`` > 0 only along the ground or down: a foot rising off its
    foothold does not count, since on flat ground a side push's roll lifts
    one) if at least ``others_bearing`` (0–3) of the
    other three each bear more than ``loaded_n`` [N]: with 3 they can carry
    the trunk while it is put down again; with fewer the slide is caught
    where the recovery stands on a diagonal or on one side (see
    ``ReflexConfig.recovery_slide_bearing``). ``loaded`` (4,): the feet
    that count as bearing instead (a foot chattering on a rock face bears
    every few ticks, :func:`recently_loaded`). ``drop_m`` [m] > 0: only a
    foot that has dropped at least that below its foothold counts, one
    sliding down a face; a foot dragged along level ground by a push, or one
    that never reached its foothold, does not. (Not "on the ground" too: a
    foot on a 60° face rests a radius above the ground under its centre.)
    """
    held = np.asarray(desired.support, dtype=bool) & (
        np.linalg.norm(np.asarray(desired.feet) - footholds, axis=1) < HELD_M
    )
    # A slide moves the foot along the ground or down a face; a foot rising
    # off its foothold (the trunk rolling away from it) is no slide. Only in
    # session 20's modes (fewer bearing feet, or a drop gate): the original
    # watch (3 bearing, no gate) stays as measured in session 17.
    moved = np.asarray(measured.feet, dtype=float) - footholds
    if others_bearing < 3 or drop_m > 0.0:
        moved[:, 2] = np.minimum(moved[:, 2], 0.0)
    if drop_m > 0.0:
        held = held & (moved[:, 2] <= -drop_m)
    off = np.where(held, np.linalg.norm(moved, axis=1), 0.0)
    leg = int(np.argmax(off))
    if off[leg] <= limit:
        return None
    bears = np.asarray(measured.foot_forces)[:, 2] > loaded_n if loaded is None else loaded
    others = np.delete(np.asarray(bears, dtype=bool), leg)
    return leg if int(np.sum(others)) >= others_bearing else None


REPLANT_LIFT_M = 0.02
"""Height [m] of the arch a re-planted foot swings through, over the higher
of its two ends: enough to clear the rim of the face it slid down."""


def replant_segments(
    robot: Robot,
    measured: MeasuredState,
    leg: int,
    target: NDArray[np.float64],
    move_s: float,
    settle_s: float,
    ready_at: float,
    margin: float,
) -> list[Segment] | None:
    """Lift foot ``leg`` where it stands and put it down on ``target`` (3,) [m]: a short step.

    From the measured stance: the trunk moves until the centre of mass is
    ``margin`` [m] inside the other three feet's triangle
    (:func:`~roughwalk.trajectories.body_keyframes.pose_over_support`), the
    foot swings to ``target`` through a :data:`REPLANT_LIFT_M` arch, the
    trunk returns over the four feet (:func:`centred_fit`), and the robot
    holds ``settle_s`` [s]. Each of the three motions takes ``move_s`` [s]
    (longer if a joint needs it). None where the triangle cannot hold the
    centre of mass with half that margin: lifting the foot would tip the
    robot.
    """
    wb = WholeBody(robot)
    feet = np.array(measured.feet, dtype=float)
    others = [i for i in range(4) if i != leg]
    rpy = matrix_to_rpy(measured.rotation)
    shift = pose_over_support(wb, feet, others, margin, start=(measured.base_pos, rpy))
    tri = feet[others, :2]
    com = shift.com[:2]
    inside = []
    for k in range(3):
        a, b = tri[k], tri[(k + 1) % 3]
        c = tri[(k + 2) % 3]
        edge = b - a
        normal = np.array([-edge[1], edge[0]]) / max(float(np.linalg.norm(edge)), 1e-9)
        if normal @ (c - a) < 0.0:
            normal = -normal
        inside.append(float(normal @ (com - a)))
    if min(inside) < 0.5 * margin or not np.all(shift.reachable):
        return None
    k = 9
    s2 = np.linspace(0.0, 1.0, k)[:, None]
    four = np.ones(4, dtype=bool)
    three = four.copy()
    three[leg] = False
    rpy1 = rpy + (shift.rpy - rpy + np.pi) % (2 * np.pi) - np.pi
    segments = [
        pose_segment(
            robot,
            (1.0 - s2) * measured.base_pos + s2 * shift.base_pos,
            (1.0 - s2) * rpy + s2 * rpy1,
            np.repeat(feet[None], k, axis=0),
            four,
            move_s,
            "recovery",
            ready_at,
        )
    ]
    s1 = np.linspace(0.0, 1.0, k)
    swing = np.repeat(feet[None], k, axis=0)
    swing[:, leg] = (1.0 - s1)[:, None] * feet[leg] + s1[:, None] * np.asarray(target, dtype=float)
    top = max(float(feet[leg, 2]), float(target[2])) + REPLANT_LIFT_M
    lift = np.sin(np.pi * s1) * (top - ((1.0 - s1) * feet[leg, 2] + s1 * target[2]))
    swing[:, leg, 2] += lift
    segments.append(
        pose_segment(
            robot,
            np.repeat(shift.base_pos[None], k, axis=0),
            np.repeat(rpy1[None], k, axis=0),
            swing,
            three,
            move_s,
            "recovery",
            ready_at,
        )
    )
    after = swing[-1]
    fit_pos, fit_rpy = centred_fit(robot, after)
    fit_rpy = rpy1 + (fit_rpy - rpy1 + np.pi) % (2 * np.pi) - np.pi
    segments.append(
        pose_segment(
            robot,
            (1.0 - s2) * shift.base_pos + s2 * fit_pos,
            (1.0 - s2) * rpy1 + s2 * fit_rpy,
            np.repeat(after[None], k, axis=0),
            four,
            move_s,
            "recovery",
            ready_at,
        )
    )
    segments.append(hold_segment(segments[-1].last(), settle_s, ready_at, kind="recovery"))
    return segments
