"""A motion task: where the base starts and where it must end, and its checks.

A task gives the base's start and goal as (x [m], y [m], yaw [rad]). The
start state is completed as TOWR does: the feet at their nominal stance on
the terrain, the base at its nominal height above them, at rest; the goal
fixes the base's x, y and orientation and asks it to be at rest, its height
left free (Winkler 2018; TOWR's ``bounds_final_lin_pos_ = {X, Y}``).

The task reaches the NLP as its parameter vector p (:meth:`ResolvedTask.vector`),
so that one built NLP serves every task.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from roughwalk.errors import InvalidArgumentError
from roughwalk.trajopt.robot_model import SingleRigidBody
from roughwalk.trajopt.terrain_model import TerrainModel
from roughwalk.trajopt.variables.base_angular import euler_to_rotation

__all__ = [
    "Task",
    "ResolvedTask",
    "TASK_SIZE",
    "parse_pose",
    "level_stance_problems",
    "start_reach_problems",
    "task_problems",
]

# p = [start pos (3), start euler (3), start feet (12), goal xy (2), goal euler (3), goal z (1)]
TASK_SIZE = 24


def parse_pose(text: str, what: str = "pose") -> tuple[float, float, float]:
    """Read "X,Y,YAW" ([m], [m], [rad]) into a tuple; raise naming the bad text."""
    parts = [p.strip() for p in str(text).split(",")]
    if len(parts) != 3:
        raise InvalidArgumentError(
            f"{what} must be X,Y,YAW (metres, metres, radians), got {text!r}"
        )
    try:
        return (float(parts[0]), float(parts[1]), float(parts[2]))
    except ValueError:
        raise InvalidArgumentError(f"{what} must be three numbers X,Y,YAW, got {text!r}") from None


@dataclass(frozen=True)
class Task:
    """Move the base from ``start`` to ``goal``, both (x [m], y [m], yaw [rad])."""

    start: tuple[float, float, float]
    goal: tuple[float, float, float]

    @classmethod
    def from_any(cls, task: Any) -> Task:
        """A Task from a Task, a {"start", "goal"} mapping or a (start, goal) pair."""
        if isinstance(task, Task):
            return task
        if isinstance(task, dict):
            start, goal = task.get("start"), task.get("goal")
        else:
            try:
                start, goal = task
            except (TypeError, ValueError):
                raise InvalidArgumentError(
                    f"a task is a Task, {{'start', 'goal'}} or (start, goal), got {task!r}"
                ) from None
        return cls(_pose(start, "start"), _pose(goal, "goal"))

    def problems(self) -> list[str]:
        """What is wrong with the numbers themselves (NaN, infinity)."""
        out = []
        for what, pose in (("start", self.start), ("goal", self.goal)):
            if not all(math.isfinite(v) for v in pose):
                out.append(f"{what} {pose} is not finite")
        return out


def _pose(value: Any, what: str) -> tuple[float, float, float]:
    if isinstance(value, str):
        return parse_pose(value, what)
    try:
        x, y, yaw = (float(v) for v in value)
    except (TypeError, ValueError):
        raise InvalidArgumentError(f"{what} must be (x, y, yaw), got {value!r}") from None
    return (x, y, yaw)


@dataclass(frozen=True)
class ResolvedTask:
    """A task completed on a terrain for a body: the NLP's start and goal states.

    Attributes
    ----------
    base_position:
        (3,) start CoM position [m].
    base_euler:
        (3,) start Euler angles ZYX (roll, pitch, yaw) [rad].
    feet:
        (4, 3) start footholds [m] on the terrain.
    goal_xy:
        (2,) goal CoM x, y [m].
    goal_euler:
        (3,) goal Euler angles [rad] (level, with the goal yaw).
    goal_z:
        Goal CoM height [m] at the nominal stance (used by initial guesses only).

    """

    task: Task
    base_position: NDArray[np.float64]
    base_euler: NDArray[np.float64]
    feet: NDArray[np.float64]
    goal_xy: NDArray[np.float64]
    goal_euler: NDArray[np.float64]
    goal_z: float

    def vector(self) -> NDArray[np.float64]:
        """The NLP parameter vector p (TASK_SIZE,)."""
        return np.concatenate(
            [
                self.base_position,
                self.base_euler,
                self.feet.ravel(),
                self.goal_xy,
                self.goal_euler,
                [self.goal_z],
            ]
        )

    @property
    def goal_position(self) -> NDArray[np.float64]:
        """(3,) goal CoM position [m] at nominal height."""
        return np.array([self.goal_xy[0], self.goal_xy[1], self.goal_z])


def nominal_feet(
    body: SingleRigidBody, terrain: TerrainModel, x: float, y: float, yaw: float
) -> tuple[NDArray[np.float64], float]:
    """Footholds (4, 3) [m] of the nominal stance on the terrain, and the CoM height [m] there."""
    rot = euler_to_rotation(np.array([0.0, 0.0, yaw]))
    feet = np.array([x, y, 0.0]) + body.stance @ rot.T
    feet[:, 2] = terrain.height(feet[:, :2])
    return feet, float(feet[:, 2].mean() + body.nominal_height)


def resolve(task: Task, body: SingleRigidBody, terrain: TerrainModel) -> ResolvedTask:
    """Complete ``task`` on ``terrain`` for ``body`` (see the module docstring)."""
    sx, sy, syaw = task.start
    gx, gy, gyaw = task.goal
    feet, z = nominal_feet(body, terrain, sx, sy, syaw)
    _, goal_z = nominal_feet(body, terrain, gx, gy, gyaw)
    return ResolvedTask(
        task,
        np.array([sx, sy, z]),
        np.array([0.0, 0.0, syaw]),
        feet,
        np.array([gx, gy]),
        np.array([0.0, 0.0, gyaw]),
        goal_z,
    )


def stance_problems(
    body: SingleRigidBody, terrain: TerrainModel, pose: tuple[float, float, float], what: str
) -> list[str]:
    """Say why the nominal stance at ``pose`` cannot be stood in.

    Unknown ground, or ground too steep or more uneven than the legs reach
    (a pose inside an obstacle). Beyond the grid the terrain continues its border, as
    :class:`~roughwalk.terrain.Terrain` does.
    """
    x, y, yaw = pose
    feet, _ = nominal_feet(body, terrain, x, y, yaw)
    out = []
    x_min, x_max, y_min, y_max = terrain.extent
    inside = (
        (feet[:, 0] >= x_min)
        & (feet[:, 0] <= x_max)
        & (feet[:, 1] >= y_min)
        & (feet[:, 1] <= y_max)
    )
    known = terrain.terrain.is_known(feet[inside, :2]) if inside.any() else np.ones(0, bool)
    if not np.all(known):
        out.append(f"{what} ({x:g}, {y:g}): the feet would stand on unknown terrain")
    # The body may tilt with the ground, so only what no plane through the
    # footholds explains must fit in the legs' vertical reach, and the plane
    # itself must be walkable (at most 45°).
    design = np.column_stack([np.ones(4), body.stance[:, :2]])
    coeffs, *_ = np.linalg.lstsq(design, feet[:, 2], rcond=None)
    uneven = float(np.abs(feet[:, 2] - design @ coeffs).max())
    slope = float(np.hypot(coeffs[1], coeffs[2]))
    reach = body.max_deviation[2]
    if uneven > reach or slope > 1.0:
        out.append(
            f"{what} ({x:g}, {y:g}) is inside an obstacle: the nominal footholds lie "
            f"{uneven:.3f} m off their best plane (the legs reach {reach:.3f} m) on ground "
            f"sloping {np.degrees(np.arctan(slope)):.0f}° (at most 45°)"
        )
    return out


_LEVEL_SAMPLE = 0.01  # [m] spacing of the ground samples in a foot's reach
_LEVEL_TOLERANCE = 0.02  # [m] slack for ground between the samples


def level_stance_problems(
    body: SingleRigidBody, terrain: TerrainModel, pose: tuple[float, float, float], what: str
) -> list[str]:
    """Say why no level base at ``pose`` can stand: its feet reach no common ground level.

    The goal base is level (roll and pitch zero) and each foot must stand in
    its range-of-motion box around the nominal foothold (±Δx, ±Δy, ±Δz in the
    base frame), so some height window 2Δz high must hold ground within every
    foot's x-y reach. TOWR's block 0.9 m is such a goal: the hind feet reach
    x ≤ 0.71 m, where the smoothed edge is 0.2 m high, under front feet 0.5 m
    up on the block; IPOPT ran into its 40 s limit there.
    """
    x, y, yaw = pose
    rot = euler_to_rotation(np.array([0.0, 0.0, yaw]))
    dx, dy, dz = body.max_deviation
    ox = np.linspace(-dx, dx, 2 * math.ceil(dx / _LEVEL_SAMPLE) + 1)
    oy = np.linspace(-dy, dy, 2 * math.ceil(dy / _LEVEL_SAMPLE) + 1)
    offsets = np.array(np.meshgrid(ox, oy, indexing="ij")).reshape(2, -1).T
    local = body.stance[:, None, :2] + offsets[None, :, :]  # (4, m, 2) in the base frame
    points = np.array([x, y]) + local @ rot[:2, :2].T
    heights = terrain.height(points.reshape(-1, 2)).reshape(len(body.stance), -1)
    window = 2 * dz + _LEVEL_TOLERANCE
    levels = np.unique(np.floor(heights * 1000) / 1000)  # each sample lies in its own window
    inside = (heights[None, :, :] >= levels[:, None, None]) & (
        heights[None, :, :] <= levels[:, None, None] + window
    )
    if np.any(np.all(np.any(inside, axis=2), axis=1)):
        return []
    return [
        f"{what} ({x:g}, {y:g}): no level base can stand there: its feet's reach holds no "
        f"ground within {2 * dz:.2f} m of one height (the range-of-motion box)"
    ]


_LEGS = ("LF", "RF", "LH", "RH")  # the order of SingleRigidBody.stance


def start_reach_problems(
    body: SingleRigidBody,
    terrain: TerrainModel,
    pose: tuple[float, float, float],
    what: str,
    tolerance: float,
) -> list[str]:
    """Say which feet of the start stance at ``pose`` lie outside their range of motion.

    The start is fixed, not free (:func:`resolve`): a level base at the mean
    foot height plus the nominal height, the feet at their nominal footholds
    on the ground. Where the ground under the footholds is uneven (a foot on
    a pallet's smoothed edge, the others below it), a foot can sit further
    from the base than its range-of-motion box allows, and no solve can meet
    both the start and the box at t = 0. Held-out single-pallet task 189
    (start (0.495, 0.317, −0.387)) is such a task: its left front foot rests
    0.161 m up the edge, 0.121 m above its nominal height against a reach of
    0.102, and IPOPT ends locally infeasible from every guess, the start
    rows 0.0187 m off. ``tolerance`` [m] is the excess the solver itself
    accepts (its ``constr_viol_tol``).
    """
    x, y, yaw = pose
    feet, z = nominal_feet(body, terrain, x, y, yaw)
    rot = euler_to_rotation(np.array([0.0, 0.0, yaw]))
    off = (feet - np.array([x, y, z])) @ rot - body.stance  # (4, 3) in the base frame
    excess = np.abs(off) - np.asarray(body.max_deviation)
    out = []
    for foot in np.flatnonzero(excess.max(axis=1) > tolerance):
        axis = int(np.argmax(excess[foot]))
        out.append(
            f"{what} ({x:g}, {y:g}, yaw {yaw:g}): the {_LEGS[foot]} foot of its stance is "
            f"{abs(off[foot, axis]):.3f} m from its nominal position along "
            f"{'xyz'[axis]} (the range of motion allows {body.max_deviation[axis]:.3f} m): "
            "the ground under the start footholds is too uneven for a level base"
        )
    return out


def task_problems(
    body: SingleRigidBody,
    terrain: TerrainModel,
    task: Task,
    constraints: tuple[str, ...],
    tolerance: float,
) -> list[str]:
    """Every reason ``task`` cannot be solved on ``terrain`` under ``constraints`` (empty: none).

    The start's and the goal's stances (:func:`stance_problems`); with the
    start state and the range of motion both enforced, the start stance's
    reach (:func:`start_reach_problems`); with the goal state too, whether
    a level goal base can stand at all (:func:`level_stance_problems`).
    ``tolerance`` [m] is the solver's constraint tolerance.
    """
    problems = stance_problems(body, terrain, task.start, "start")
    problems += stance_problems(body, terrain, task.goal, "goal")
    if problems or "range_of_motion" not in constraints:
        return problems
    if "initial_state" in constraints:
        problems += start_reach_problems(body, terrain, task.start, "start", tolerance)
    if "goal_state" in constraints:
        problems += level_stance_problems(body, terrain, task.goal, "goal")
    return problems
