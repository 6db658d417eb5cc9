"""A footstep plan read into what trajectory generation needs: steps and keyframes.

Accepts the footstep planner's :class:`FootstepPlan` or its JSON (``roughwalk
plan``): ``footsteps`` [{leg, x, y, z}] in execution order starting with the
four feet of the initial stance, each the foot's contact point on the
terrain; ``certificates`` [{step, base_pos, base_quat, q}], one per footstep
after the initial stance: the pose holding the stance that step reaches with
the CoM inside the support triangle of the next step (Zucker 2011, §4.3);
and optionally ``initial_pose``, the initial stance's certificate.

Trajectories need foot-sphere centres: a contact point plus the foot radius
along the terrain's normal, or, where a certificate places that foot within
a centimetre of it, exactly where the certificate's joint angles put it (the
centre the planner checked). With ``foot_centre="disc"`` the normal is the
mean slope's over the foot's disc instead, the planner's own with
``footstep.normal_radius`` the foot radius (the two go together: a
certificate's foot within a centimetre wins either way). With
``foot_centre="resting"`` the centre is
instead where the sphere rests when lowered straight onto the contact's
(x, y) (:func:`~roughwalk.planning.foothold_safety.resting_centres`): the
normal is that of the one grid point under the contact, and on a scanned
rock it is not the foot's. Missing pieces are filled as a certificate
search would start them (:func:`pose_over_support`): the initial pose, the
pose for the first step, certificates of a bare footstep list.
"""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from roughwalk.errors import InvalidArgumentError, PlanningError
from roughwalk.planning.foothold_safety import resting_centres
from roughwalk.robots.canonical_frame import LEG_NAMES
from roughwalk.trajectories.body_keyframes import (
    BodyKeyframe,
    keyframe_at,
    pose_over_support,
    rpy_of,
)
from roughwalk.trajectories.euler import rpy_to_matrix
from roughwalk.trajectories.whole_body import WholeBody

if TYPE_CHECKING:
    from roughwalk.terrain.terrain import Terrain

__all__ = ["FOOT_CENTRES", "StepSpec", "StepSequence", "plan_fields"]

FOOT_CENTRES = ("normal", "disc", "resting")
"""How a contact point becomes a foot-sphere centre (:func:`_foot_centres`)."""


@dataclass(frozen=True)
class StepSpec:
    """One footstep: leg ``leg`` (canonical index) moves from ``start`` to ``target`` [m].

    ``index`` counts footsteps from 1; ``stance_before`` and ``stance_after``
    are the four feet (4, 3) [m] around it; ``swing_pose`` is the keyframe
    held through its swing (CoM inside the triangle of the other three
    feet) and ``end_pose`` the certificate reached after it.
    """

    index: int
    leg: int
    start: NDArray[np.float64]
    target: NDArray[np.float64]
    stance_before: NDArray[np.float64]
    stance_after: NDArray[np.float64]
    swing_pose: BodyKeyframe
    end_pose: BodyKeyframe

    @property
    def leg_name(self) -> str:
        """The swing leg's name: LF, RF, LH or RH."""
        return LEG_NAMES[self.leg]

    @property
    def support_legs(self) -> tuple[int, ...]:
        """The three legs that stay down."""
        return tuple(i for i in range(4) if i != self.leg)

    @property
    def support_triangle(self) -> NDArray[np.float64]:
        """(3, 3) feet of the support legs [m]."""
        return self.stance_before[list(self.support_legs)]


def _get(obj: Any, name: str, default: Any = None) -> Any:
    if isinstance(obj, Mapping):
        return obj.get(name, default)
    return getattr(obj, name, default)


def plan_fields(plan: Any) -> dict[str, Any]:
    """The plan's robot, terrain, footsteps, certificates and initial pose, from any form.

    ``plan`` is a :class:`FootstepPlan`-like object, its JSON dict (the
    fields may be nested under ``"plan"``), or a path to that JSON.
    """
    if isinstance(plan, str | Path):
        p = Path(plan)
        try:
            plan = json.loads(p.read_text())
        except (OSError, json.JSONDecodeError) as e:
            raise PlanningError(f"cannot read footstep plan '{p}': {e}") from None
    if (
        isinstance(plan, Mapping)
        and "footsteps" not in plan
        and isinstance(plan.get("plan"), Mapping)
    ):
        inner = dict(plan["plan"])
        for key in ("robot", "terrain"):
            inner.setdefault(key, plan.get(key))
        plan = inner
    footsteps = _get(plan, "footsteps")
    if footsteps is None:
        raise PlanningError(
            "a footstep plan needs 'footsteps' ([{leg, x, y, z}], initial stance first); "
            f"got {type(plan).__name__} without them"
        )
    robot = _get(plan, "robot")
    terrain = _get(plan, "terrain")
    return {
        "robot": robot if isinstance(robot, str) or robot is None else _get(robot, "name", robot),
        "terrain": terrain
        if isinstance(terrain, str) or terrain is None
        else _get(terrain, "spec", terrain),
        "footsteps": list(footsteps),
        "certificates": list(_get(plan, "certificates", None) or []),
        "initial_pose": _get(plan, "initial_pose", None),
        "status": _get(plan, "status", None),
        "reason": _get(plan, "reason", None),
    }


def contacts_at(leg: int, contact: NDArray[np.float64]) -> NDArray[np.float64]:
    """A (4, 3) array with ``contact`` in row ``leg`` (the others unused)."""
    out = np.zeros((4, 3))
    out[leg] = contact
    return out


def _foot_centres(
    wb: WholeBody,
    terrain: Terrain | None,
    contacts: NDArray[np.float64],
    legs: Any,
    certificate: Any,
    foot_centre: str = "normal",
) -> NDArray[np.float64]:
    """Foot-sphere centres (4, 3) [m] of the ``legs`` rows of ``contacts`` (others copied).

    ``foot_centre`` "normal": contact plus radius along the normal; or the
    certificate's own foot centre where its joint angles put the foot
    within 1 cm of that. "disc": the same along the normal of the mean
    slope over the foot's disc (:meth:`Terrain.disc_normal`), as the
    planner places it with ``footstep.normal_radius`` the foot radius.
    "resting": the sphere lowered straight onto the contact's (x, y)
    rests there (needs ``terrain``; without it, "normal").

    For "normal", the normal is the bilinear one at the contact point,
    over one grid cell (1.2 mm on the LittleDog boards), while the planner
    judges a foothold's slope over the foot's disc. Of the board cells whose disc
    slopes less than 45°, 11–12 % have a point normal steeper than 45°,
    and there the centre along it sinks into the rock beside the contact
    (AE: by over 2 mm at 14 % of them, by 25 mm at the 99th percentile;
    AD: 25 %, 48 mm): the swing aims the foot into a face it then lands on
    early, off its planned foothold.
    """
    out = np.array(contacts, dtype=float)
    legs = list(legs)
    xy = out[legs, :2]
    if foot_centre == "resting" and terrain is not None:
        radius = np.array([wb.robot.leg_descriptions[i].foot_radius for i in legs])
        for k, leg in enumerate(legs):
            out[leg] = resting_centres(terrain, xy[k : k + 1], float(radius[k]))[0]
        return out
    radius = np.array([wb.robot.leg_descriptions[i].foot_radius for i in legs])
    if terrain is None:
        normals = np.tile([0.0, 0.0, 1.0], (len(legs), 1))
    elif foot_centre == "disc":
        normals = np.vstack(
            [terrain.disc_normal(xy[k : k + 1], float(radius[k])) for k in range(len(legs))]
        )
    else:
        normals = terrain.normal(xy)
    out[legs] = out[legs] + radius[:, None] * normals
    q = None if certificate is None else _get(certificate, "q")
    if q is not None:
        try:
            q12 = np.asarray(q, dtype=float)
            pos, rpy = _pose(certificate, "certificate")
        except PlanningError:
            return out
        if q12.shape == (12,) and np.all(np.isfinite(q12)):
            rot = rpy_to_matrix(rpy)
            feet = pos + wb.foot_positions(wb.robot.to_canonical(q12).reshape(1, 4, 3))[0] @ rot.T
            for i in legs:
                if np.linalg.norm(feet[i] - out[i]) < 0.01:
                    out[i] = feet[i]
    return out


def _leg_index(value: Any, where: str) -> int:
    if isinstance(value, str) and value.upper() in LEG_NAMES:
        return LEG_NAMES.index(value.upper())
    if isinstance(value, int | np.integer) and 0 <= int(value) < 4:
        return int(value)
    raise PlanningError(f"{where}: leg {value!r} is not one of {', '.join(LEG_NAMES)} (or 0–3)")


def _footstep(entry: Any, where: str) -> tuple[int, NDArray[np.float64]]:
    leg = _leg_index(_get(entry, "leg"), where)
    pos = _get(entry, "position")
    if pos is None:
        pos = [_get(entry, k) for k in ("x", "y", "z")]
    try:
        p = np.asarray(pos, dtype=float)
    except (TypeError, ValueError):
        raise PlanningError(f"{where}: position must be three numbers [m], got {pos!r}") from None
    if p.shape != (3,) or not np.all(np.isfinite(p)):
        raise PlanningError(f"{where}: position must be three finite numbers [m], got {pos!r}")
    return leg, p


def _pose(entry: Any, where: str) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    try:
        pos = np.asarray(_get(entry, "base_pos"), dtype=float)
        quat = np.asarray(_get(entry, "base_quat"), dtype=float)
    except (TypeError, ValueError):
        raise PlanningError(f"{where}: base_pos and base_quat must be numbers") from None
    if (
        pos.shape != (3,)
        or quat.shape != (4,)
        or not np.all(np.isfinite(pos))
        or not (np.all(np.isfinite(quat)) and np.linalg.norm(quat) > 1e-9)
    ):
        raise PlanningError(
            f"{where}: needs base_pos [x, y, z] and a nonzero base_quat [w, x, y, z], "
            f"got {pos.tolist()} and {quat.tolist()}"
        )
    return pos, rpy_of(quat)


class StepSequence:
    """The footsteps of a plan with a keyframe for every swing and every step's end.

    Build with :meth:`from_plan`.
    """

    def __init__(
        self,
        wb: WholeBody,
        initial_stance: NDArray[np.float64],
        initial_pose: BodyKeyframe,
        steps: Sequence[StepSpec],
    ) -> None:
        self.wb = wb
        self.initial_stance = initial_stance
        self.initial_pose = initial_pose
        self.steps = list(steps)

    def __len__(self) -> int:
        return len(self.steps)

    @classmethod
    def from_plan(
        cls,
        plan: Any,
        wb: WholeBody,
        support_margin: float = 0.015,
        terrain: Terrain | None = None,
        foot_centre: str = "normal",
    ) -> StepSequence:
        """Read ``plan`` (see :func:`plan_fields`) for the robot of ``wb``.

        ``support_margin`` [m] is the CoM margin of the keyframes made here
        (the initial stance's swing pose and missing certificates);
        ``terrain`` gives the normals that turn contact points into foot
        centres (vertical without it); ``foot_centre`` is one of
        :data:`FOOT_CENTRES` (see :func:`_foot_centres`).
        """
        if foot_centre not in FOOT_CENTRES:
            raise InvalidArgumentError(
                f"foot_centre must be one of {', '.join(FOOT_CENTRES)}, got {foot_centre!r}"
            )
        fields = plan_fields(plan)
        entries = fields["footsteps"]
        if len(entries) < 5:
            status = fields["status"]
            why = f" (the planner's status: {status}: {fields['reason']})" if status else ""
            raise PlanningError(
                f"a footstep plan needs the 4 feet of its initial stance and at least one step; "
                f"got {len(entries)} footsteps{why}"
            )
        contacts = np.full((4, 3), np.nan)
        for i, entry in enumerate(entries[:4]):
            leg, pos = _footstep(entry, f"footsteps[{i}]")
            if np.all(np.isfinite(contacts[leg])):
                raise PlanningError(
                    f"footsteps[{i}]: leg {LEG_NAMES[leg]} appears twice in the initial stance"
                )
            contacts[leg] = pos
        moves = [_footstep(e, f"footsteps[{i}]") for i, e in enumerate(entries[4:], start=4)]
        certs = fields["certificates"]
        if certs and len(certs) != len(moves):
            raise PlanningError(
                f"the plan has {len(moves)} steps but {len(certs)} certificates; "
                "expected one per step after the initial stance"
            )
        if certs and all(_get(c, "step") is not None for c in certs):
            certs = sorted(certs, key=lambda c: int(_get(c, "step")))

        init = fields["initial_pose"]
        stance = _foot_centres(wb, terrain, contacts, range(4), init, foot_centre)
        if init is not None:
            pos, rpy = _pose(init, "initial_pose")
            initial = keyframe_at(wb, stance, pos, rpy)
        else:
            # The fitted pose alone may hang the CoM outside the feet on a slope.
            initial = pose_over_support(wb, stance, [0, 1, 2, 3], support_margin)
        moves = [
            (
                leg,
                _foot_centres(
                    wb,
                    terrain,
                    contacts_at(leg, c),
                    [leg],
                    certs[k] if certs else None,
                    foot_centre,
                )[leg],
            )
            for k, (leg, c) in enumerate(moves)
        ]

        steps: list[StepSpec] = []
        before = stance
        swing_pose: BodyKeyframe | None = None
        for k, (leg, target) in enumerate(moves):
            after = before.copy()
            after[leg] = target
            support = [i for i in range(4) if i != leg]
            if swing_pose is None:
                swing_pose = pose_over_support(
                    wb, before, support, support_margin, start=(initial.base_pos, initial.rpy)
                )
            if certs:
                pos, rpy = _pose(certs[k], f"certificates[{k}]")
                end = keyframe_at(wb, after, pos, rpy)
            else:
                following = (
                    [i for i in range(4) if i != moves[k + 1][0]]
                    if k + 1 < len(moves)
                    else list(range(4))
                )
                end = pose_over_support(
                    wb,
                    after,
                    following,
                    support_margin,
                    start=(swing_pose.base_pos, swing_pose.rpy),
                )
            steps.append(
                StepSpec(
                    index=k + 1,
                    leg=leg,
                    start=before[leg].copy(),
                    target=target,
                    stance_before=before,
                    stance_after=after,
                    swing_pose=swing_pose,
                    end_pose=end,
                )
            )
            before = after
            swing_pose = end
        return cls(wb, stance, initial, steps)

    def anchors(self) -> NDArray[np.float64]:
        """ZMP anchors (S + 2, 2) [m]: initial CoM, each swing pose's CoM, the final CoM."""
        pts = [self.initial_pose.com[:2]]
        pts += [s.swing_pose.com[:2] for s in self.steps]
        pts.append(self.steps[-1].end_pose.com[:2])
        return np.array(pts)


def check_step_range(sequence: StepSequence, first: int, count: int | None) -> range:
    """Step indices (0-based) from ``first``, ``count`` of them (all when None)."""
    n = len(sequence)
    if not (0 <= first < n):
        raise InvalidArgumentError(f"first step {first} is outside the plan's steps 0…{n - 1}")
    stop = n if count is None else min(n, first + max(int(count), 0))
    return range(first, stop)
