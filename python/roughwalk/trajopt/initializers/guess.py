"""Helpers shared by initial guesses: node times and base poses along a straight line."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from roughwalk.trajopt.formulation import Formulation
from roughwalk.trajopt.task import ResolvedTask, nominal_feet
from roughwalk.trajopt.variables import NodeVariableSet

__all__ = [
    "node_times",
    "straight_base",
    "feet_guess",
    "forces_guess",
    "pack_guess",
    "off_edges",
    "level_goal_stance",
    "EDGE_COST",
]

_FLAT_SLOPE = 0.3  # steeper ground than this is no place for a guessed foothold
EDGE_COST = 0.2
"""Guessed footholds keep off ground whose step-edge cost exp(−x_s²/2σ²) exceeds this."""


def node_times(
    nodes: NodeVariableSet, durations: list[float] | NDArray[np.float64]
) -> NDArray[np.float64]:
    """Times [s] of a spline's nodes for numeric polynomial ``durations``."""
    return np.concatenate([[0.0], np.cumsum(np.asarray(durations, dtype=float))])


def poly_durations(
    nlp: Formulation, foot: int, phase_durations: NDArray[np.float64], force: bool
) -> list[float]:
    """Numeric polynomial durations [s] of a foot's motion (or force) spline."""
    nodes = nlp.forces[foot] if force else nlp.feet[foot]
    return [phase_durations[p.phase] / p.polys_in_phase for p in nodes.polys]


def straight_base(
    nlp: Formulation,
    task: ResolvedTask,
    times: NDArray[np.float64],
    goal_z: float | None = None,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """CoM positions (n, 3) and Euler angles (n, 3) on the straight line from start to goal.

    The height follows the terrain under the nominal feet at each pose, and
    the base pitches and rolls with the plane through them, so that a guess
    over a pallet climbs it with the feet within their reach. ``goal_z`` [m]
    (the CoM height over guessed goal footholds) shifts the heights towards
    it over the last quarter of the way, when the feet take their last
    steps to those footholds (spread over the whole way, the block 0.95 m
    took 347 iterations instead of 26).
    """
    schedule = nlp.schedule
    first_lift = min(schedule.durations[f][0] for f in range(schedule.n_feet))
    last_touch = max(
        schedule.total_duration - schedule.durations[f][-1] for f in range(schedule.n_feet)
    )
    span = max(last_touch - first_lift, 1e-6)
    s = np.clip((np.asarray(times) - first_lift) / span, 0.0, 1.0)[:, None]
    start_xy = task.base_position[:2]
    xy = start_xy + s * (task.goal_xy - start_xy)
    yaw = task.base_euler[2] + s[:, 0] * (task.goal_euler[2] - task.base_euler[2])
    z = np.zeros(len(xy))
    roll = np.zeros(len(xy))
    pitch = np.zeros(len(xy))
    stance = nlp.body.stance
    for i, (p, a) in enumerate(zip(xy, yaw, strict=True)):
        feet, z[i] = nominal_feet(nlp.body, nlp.terrain, float(p[0]), float(p[1]), float(a))
        # Least-squares plane h ≈ h₀ + gx·x_b + gy·y_b through the feet (base axes).
        design = np.column_stack([np.ones(len(stance)), stance[:, 0], stance[:, 1]])
        _, gx, gy = np.linalg.lstsq(design, feet[:, 2], rcond=None)[0]
        pitch[i] = -np.arctan(gx)
        roll[i] = np.arctan(gy)
    if goal_z is not None:
        z += np.clip(4 * s[:, 0] - 3, 0, 1) * (goal_z - z[-1])
    z[0] = task.base_position[2]
    roll[0] = pitch[0] = roll[-1] = pitch[-1] = 0.0
    positions = np.column_stack([xy, z])
    euler = np.column_stack([roll, pitch, yaw])
    return positions, euler


def off_edges(
    nlp: Formulation, foothold: NDArray[np.float64], direction: NDArray[np.float64]
) -> NDArray[np.float64]:
    """Move a guessed foothold along ``direction`` (2,) off steep ground and step edges.

    The nearest point within the range-of-motion box's x half-size that is
    flat and away from edges, on the terrain; the foothold itself (on the
    terrain) when there is none. A guess on a step's edge, where the
    smoothed surface is nearly vertical, turns the friction pyramid on its
    side and is a poor start.
    """
    reach = nlp.body.max_deviation[0]
    offsets = np.linspace(-reach, reach, 31)
    offsets = offsets[np.argsort(np.abs(offsets), kind="stable")]
    unit = np.asarray(direction, dtype=float) / max(float(np.linalg.norm(direction)), 1e-9)
    points = foothold[None, :2] + offsets[:, None] * unit[None, :]
    values = nlp.terrain.evaluate(points)
    slope = np.hypot(values[:, 1], values[:, 2])
    good = np.flatnonzero((slope < _FLAT_SLOPE) & (values[:, 3] < EDGE_COST))
    best = int(good[0]) if good.size else 0
    return np.array([points[best, 0], points[best, 1], values[best, 0]])


def level_goal_stance(
    nlp: Formulation, feet: NDArray[np.float64], direction: NDArray[np.float64]
) -> NDArray[np.float64]:
    """Goal footholds (4, 3) [m] moved along ``direction`` (2,) so that a level base reaches them.

    The goal's base is level (TOWR's goal orientation), so its feet must
    stand within the range-of-motion box's height 2·Δz of one another. The
    nominal stance astride a step does not (block 1.0 m: hind feet on the
    ground, front feet 0.5 m up on the block) and the solver spends hundreds
    of iterations leaving that guess. For each level c (a nominal foothold's
    height, or ±Δz from it) every foot takes, within its x reach, ground
    whose height lies within Δz of c: the nearest flat ground off edges, or
    else the least steep; the level that leaves the fewest feet without
    such ground and moves them least wins. Feet already level stay put.
    """
    reach, dz = nlp.body.max_deviation[0], nlp.body.max_deviation[2]
    if np.ptp(feet[:, 2]) <= 2 * dz:
        return feet
    offsets = np.linspace(-reach, reach, 31)
    unit = np.asarray(direction, dtype=float) / max(float(np.linalg.norm(direction)), 1e-9)
    points = feet[:, None, :2] + offsets[None, :, None] * unit[None, None, :]
    values = nlp.terrain.evaluate(points.reshape(-1, 2)).reshape(len(feet), len(offsets), 4)
    heights = values[:, :, 0]
    slope = np.hypot(values[:, :, 1], values[:, :, 2])
    good = (slope < _FLAT_SLOPE) & (values[:, :, 3] < EDGE_COST)
    best: tuple[tuple[int, float], NDArray[np.float64]] | None = None
    for level in np.unique(np.concatenate([feet[:, 2] - dz, feet[:, 2], feet[:, 2] + dz])):
        chosen = feet.copy()
        missing, moved = 0, 0.0
        for foot in range(len(feet)):
            inside = np.abs(heights[foot] - level) <= dz
            if not inside.any():
                missing += 1
                continue
            # Flat ground off edges first, nearest; otherwise the least steep.
            key = np.where(good[foot], np.abs(offsets), 10.0 + slope[foot])
            k = int(np.argmin(np.where(inside, key, np.inf)))
            chosen[foot] = [*points[foot, k], heights[foot, k]]
            moved += abs(float(offsets[k]))
        score = (missing, moved)
        if best is None or score < best[0]:
            best = (score, chosen)
    assert best is not None
    return best[1]


def finite_difference(
    values: NDArray[np.float64], times: NDArray[np.float64]
) -> NDArray[np.float64]:
    """Velocities at nodes from values at node times (zero at both ends: start and goal at rest)."""
    vel = np.gradient(values, times, axis=0) if len(times) > 2 else np.zeros_like(values)
    vel[0] = 0.0
    vel[-1] = 0.0
    return vel


def feet_guess(
    nlp: Formulation,
    task: ResolvedTask,
    foot: int,
    phase_durations: NDArray[np.float64],
    footholds: dict[int, NDArray[np.float64]],
) -> NDArray[np.float64]:
    """Foot ``foot``'s motion variables from its stance ``footholds`` (phase → (3,) [m]).

    Swing nodes go on the straight line between the swing's footholds, the
    apex ``swing_clearance`` above the higher one, moving at the step's mean
    horizontal velocity.
    """
    motion = nlp.feet[foot]
    n_nodes = motion.n_nodes
    pos = np.zeros((n_nodes, 3))
    vel = np.zeros((n_nodes, 3))
    for phase, stance in enumerate(motion.stance_phases):
        nodes = motion.phase_nodes(phase)
        if stance:
            pos[nodes[0]] = pos[nodes[-1]] = footholds[phase]
            continue
        before = footholds.get(phase - 1, footholds.get(phase + 1))
        after = footholds.get(phase + 1, before)
        assert before is not None and after is not None
        n = len(nodes) - 1
        for j, node in enumerate(nodes[1:-1], start=1):
            frac = j / n
            pos[node] = before + frac * (after - before)
            lift = np.sin(np.pi * frac)
            pos[node, 2] = max(before[2], after[2]) * lift + pos[node, 2] * (1 - lift)
            pos[node, 2] += nlp.config.swing_clearance * lift
            vel[node, :2] = (after[:2] - before[:2]) / phase_durations[phase]
    return motion.pack(pos, vel)


def forces_guess(
    nlp: Formulation,
    foot: int,
    phase_durations: NDArray[np.float64],
    schedule_durations: list[NDArray[np.float64]],
) -> NDArray[np.float64]:
    """Foot ``foot``'s force variables: the weight shared by the feet in stance at each node."""
    force = nlp.forces[foot]
    times = node_times(force, poly_durations(nlp, foot, phase_durations, force=True))
    schedule = nlp.schedule.with_durations(schedule_durations)
    count = sum(schedule.in_contact(f, times).astype(float) for f in range(nlp.n_feet))
    mine = schedule.in_contact(foot, times)
    pos = np.zeros((force.n_nodes, 3))
    pos[:, 2] = np.where(mine, nlp.body.weight / np.maximum(count, 1.0), 0.0)
    # Nodes at the ends of a stance phase touch the swing: their force is held at zero.
    return force.pack(pos, np.zeros_like(pos))


def pack_guess(nlp: Formulation, parts: dict[str, NDArray[np.float64]]) -> NDArray[np.float64]:
    """The full variable vector from per-set values."""
    return nlp.join(parts)
