"""The single rigid body the NLP plans for: mass, inertia, nominal stance, range of motion.

TOWR (and Melon et al.) lump the whole robot into one rigid body whose
origin is its centre of mass, with massless legs whose feet must stay in a box
around their nominal position in the base frame. :func:`rigid_body_from_robot`
derives these numbers from a :class:`~roughwalk.robots.Robot`;
:data:`TOWR_ANYMAL` holds TOWR's published ANYmal values, so that comparisons
with TOWR solve the identical problem.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from roughwalk.errors import InvalidArgumentError
from roughwalk.trajopt.leg_statics import LegStatics, leg_statics_from_robot

if TYPE_CHECKING:
    from roughwalk.robots import Robot

__all__ = [
    "GRAVITY",
    "SingleRigidBody",
    "TOWR_ANYMAL",
    "rigid_body_from_robot",
    "rigid_body_model",
    "BODY_MODELS",
]

GRAVITY = 9.80665
"""Standard gravity [m/s²]."""

Vec3 = tuple[float, float, float]


@dataclass(frozen=True)
class SingleRigidBody:
    """A quadruped as one rigid body with four massless legs (Winkler 2018, §IV).

    Attributes
    ----------
    name:
        Where the numbers come from ("towr_anymal", "anymal_c", ...).
    mass:
        Total mass m [kg].
    inertia:
        (3, 3) inertia I_b about the centre of mass, base axes [kg·m²].
    nominal_stance:
        (4, 3) foot contact points in the base frame at the nominal pose [m],
        relative to the centre of mass, legs LF, RF, LH, RH.
    max_deviation:
        (3,) half-sizes [m] of each foot's range-of-motion box around its
        nominal position, base axes.
    force_limit:
        Largest normal contact force f_max [N] per foot.
    friction:
        Friction coefficient μ of the friction pyramid.
    com_in_base:
        (3,) the centre of mass in the robot's base frame [m]: add
        −R·com_in_base to a planned CoM to get the base frame's origin.
    reach_centres, reach_radius:
        The legs' reach, when known: each foot contact point i lies within
        ``reach_radius`` [m] of ``reach_centres[i]`` (4, 3) [m] (base axes,
        relative to the centre of mass). The box alone cannot say this: its
        lower corners lie beyond a real leg's stretch (see
        :func:`leg_reach_sphere`). None (TOWR's model) means the box only.
    legs:
        Each leg's geometry and torque limits (:class:`LegStatics`, canonical
        order), for the ``joint_torques`` constraint; None (TOWR's model, or
        legs of another kind) leaves that constraint without rows.

    """

    name: str
    mass: float
    inertia: tuple[Vec3, Vec3, Vec3]
    nominal_stance: tuple[Vec3, Vec3, Vec3, Vec3]
    max_deviation: Vec3
    force_limit: float = 1000.0
    friction: float = 0.5
    com_in_base: Vec3 = (0.0, 0.0, 0.0)
    reach_centres: tuple[Vec3, Vec3, Vec3, Vec3] | None = None
    reach_radius: float | None = None
    legs: tuple[LegStatics, LegStatics, LegStatics, LegStatics] | None = None

    def __post_init__(self) -> None:
        if not (np.isfinite(self.mass) and self.mass > 0):
            raise InvalidArgumentError(f"mass must be > 0 kg, got {self.mass}")
        inertia = np.asarray(self.inertia, dtype=float)
        if inertia.shape != (3, 3) or not np.allclose(inertia, inertia.T):
            raise InvalidArgumentError(
                f"inertia must be a symmetric 3×3 matrix, got {self.inertia}"
            )
        if np.linalg.eigvalsh(inertia).min() <= 0:
            raise InvalidArgumentError(f"inertia must be positive definite, got {self.inertia}")
        if np.asarray(self.nominal_stance).shape != (4, 3):
            raise InvalidArgumentError("nominal_stance must hold 4 feet of (x, y, z) [m]")
        if min(self.max_deviation) <= 0:
            raise InvalidArgumentError(
                f"max_deviation must be > 0 m on every axis, got {self.max_deviation}"
            )
        if not (self.force_limit > 0 and self.friction > 0):
            raise InvalidArgumentError(
                f"force_limit and friction must be > 0, got {self.force_limit}, {self.friction}"
            )
        if (self.reach_centres is None) != (self.reach_radius is None):
            raise InvalidArgumentError("reach_centres and reach_radius come together or not at all")
        if self.reach_centres is not None:
            if np.asarray(self.reach_centres).shape != (4, 3):
                raise InvalidArgumentError("reach_centres must hold 4 points of (x, y, z) [m]")
            radius = self.reach_radius
            if radius is None or not (np.isfinite(radius) and radius > 0):
                raise InvalidArgumentError(f"reach_radius must be > 0 m, got {radius}")

    @property
    def inertia_matrix(self) -> NDArray[np.float64]:
        """I_b as a (3, 3) array [kg·m²]."""
        return np.asarray(self.inertia, dtype=float)

    @property
    def stance(self) -> NDArray[np.float64]:
        """The nominal stance as a (4, 3) array [m]."""
        return np.asarray(self.nominal_stance, dtype=float)

    @property
    def nominal_height(self) -> float:
        """Height [m] of the centre of mass over flat ground at the nominal stance."""
        return float(-self.stance[:, 2].mean())

    @property
    def weight(self) -> float:
        """m·g [N]."""
        return self.mass * GRAVITY

    def with_changes(self, **changes: object) -> SingleRigidBody:
        """A copy with some fields replaced (for overriding the robot's numbers)."""
        return replace(self, **changes)  # type: ignore[arg-type]

    def to_dict(self) -> dict[str, object]:
        """JSON-ready fields."""
        return {
            "name": self.name,
            "mass": self.mass,
            "inertia": [list(r) for r in self.inertia],
            "nominal_stance": [list(r) for r in self.nominal_stance],
            "max_deviation": list(self.max_deviation),
            "force_limit": self.force_limit,
            "friction": self.friction,
            "com_in_base": list(self.com_in_base),
            "reach_centres": None
            if self.reach_centres is None
            else [list(r) for r in self.reach_centres],
            "reach_radius": self.reach_radius,
            "legs": None if self.legs is None else [leg.to_dict() for leg in self.legs],
        }


def _tuple3(v: NDArray[np.float64]) -> Vec3:
    return (float(v[0]), float(v[1]), float(v[2]))


# TOWR's models/examples/anymal_model.h: ANYmal (B) as TOWR publishes it.
TOWR_ANYMAL = SingleRigidBody(
    name="towr_anymal",
    mass=29.5,
    inertia=(
        (0.946438, -0.000938112, 0.00595386),
        (-0.000938112, 1.94478, 0.00146328),
        (0.00595386, 0.00146328, 2.01835),
    ),
    nominal_stance=(
        (0.34, 0.19, -0.42),
        (0.34, -0.19, -0.42),
        (-0.34, 0.19, -0.42),
        (-0.34, -0.19, -0.42),
    ),
    max_deviation=(0.15, 0.10, 0.10),
    force_limit=1000.0,
    friction=0.5,
)
"""TOWR's ANYmal: 29.5 kg, its inertia (Ixy, Ixz, Iyz entered as TOWR's products of
inertia, I = [[Ixx, −Ixy, −Ixz], ...]), nominal stance x ±0.34, y ±0.19, z −0.42 m,
box half-sizes 0.15, 0.10, 0.10 m, f_max 1000 N, μ 0.5."""

# TOWR's ANYmal box relative to its leg length (thigh + shank ≈ 0.6 m) and its
# force limit relative to its weight: used to scale other robots.
_BOX_PER_LEG_LENGTH = np.array([0.25, 1 / 6, 1 / 6])
_FORCE_LIMIT_PER_WEIGHT = 1000.0 / (29.5 * GRAVITY)


def _composite_inertia(robot: Robot) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Whole-robot CoM (3,) in the base frame [m] and inertia (3, 3) about it [kg·m²], nominal q."""
    from roughwalk.robots import reference_fk

    d = robot.description
    q = robot.to_canonical(robot.nominal_q).reshape(4, 3)
    masses = [d.base_mass]
    coms = [np.asarray(d.base_com, dtype=float)]
    inertias = [np.asarray(d.base_inertia, dtype=float)]
    for i, leg in enumerate(d.legs):
        positions, rotations = reference_fk.leg_link_frames(leg, q[i])
        for k in range(3):
            masses.append(float(d.link_mass[i, k]))
            coms.append(positions[k] + rotations[k] @ d.link_com[i, k])
            inertias.append(rotations[k] @ d.link_inertia[i, k] @ rotations[k].T)
    m = np.array(masses)
    c = np.array(coms)
    com = (m[:, None] * c).sum(axis=0) / m.sum()
    total = np.zeros((3, 3))
    for mass, pos, inertia in zip(m, c, inertias, strict=True):
        r = pos - com
        total += inertia + mass * (r @ r * np.eye(3) - np.outer(r, r))
    return com, 0.5 * (total + total.T)


def leg_reach_sphere(
    robot: Robot, min_knee_bend_rad: float = 0.35
) -> tuple[NDArray[np.float64], float] | None:
    """Sphere centres (4, 3) in the base frame [m] and radius [m] holding each leg's foot centres.

    For an abduction–flexion–knee leg (HAA about base x, HFE and KFE about
    base y), a foot centre lies at a fixed lateral offset l from the HAA axis
    and, in the thigh–shank plane, at r = √(a² + b² + 2ab cos φ) from the HFE
    joint (thigh a, shank b, knee bend φ; 0 is straight). With v the foot
    relative to the HAA anchor and h_x the HFE joint's offset along x,
    r² = (v_x − h_x)² + v_y² + v_z² − l², so r ≤ r(φ_min) is the ball
    |v − h_x e_x| ≤ √(r(φ_min)² + l²): a smooth constraint for the NLP.
    ``min_knee_bend_rad`` keeps the knee that far from straight, where a
    whole-body controller loses the leg (the tracking wing's ``LegReach``
    uses the same margin). None when a leg is not of that kind.
    """
    legs = robot.description.legs
    for leg in legs:
        axes = np.abs(np.asarray(leg.axis, dtype=float))
        turned = any(not np.allclose(np.abs(q), [1, 0, 0, 0]) for q in leg.body_quat)
        if turned or not np.allclose(axes, [[1, 0, 0], [0, 1, 0], [0, 1, 0]], atol=1e-6):
            return None
    haa = np.array([np.asarray(leg.body_pos[0]) + leg.anchor[0] for leg in legs])
    hfe_x = np.array([leg.body_pos[1][0] + leg.anchor[1][0] for leg in legs])
    lateral = np.array([leg.body_pos[1][1] + leg.body_pos[2][1] + leg.foot[1] for leg in legs])
    a, b = robot.leg_lengths[:, 0], robot.leg_lengths[:, 1]
    reach = np.sqrt(a * a + b * b + 2 * a * b * np.cos(min_knee_bend_rad))
    radius = np.sqrt(reach**2 + lateral**2)
    centres = haa + np.outer(hfe_x, [1.0, 0.0, 0.0])
    return centres, float(radius.min())


def rigid_body_from_robot(robot: Robot, **overrides: object) -> SingleRigidBody:
    """The single rigid body of ``robot`` at its nominal pose; ``overrides`` replace fields.

    Mass and inertia are the whole robot's (legs included) about its centre of
    mass; the nominal stance is the feet's contact points (foot centres
    lowered by the foot radius) relative to that centre of mass; the
    range-of-motion box and force limit scale TOWR's ANYmal values by leg
    length and weight, and the legs' reach ball (:func:`leg_reach_sphere`)
    cuts off the box's corners the legs cannot reach.
    """
    com, inertia = _composite_inertia(robot)
    feet = np.asarray(robot.nominal_stance.feet, dtype=float) - com
    feet[:, 2] -= robot.foot_radius
    leg_length = float(np.mean(robot.leg_lengths.sum(axis=1)))
    box = _BOX_PER_LEG_LENGTH * leg_length
    sphere = leg_reach_sphere(robot)
    centres: tuple[Vec3, Vec3, Vec3, Vec3] | None = None
    legs = leg_statics_from_robot(robot)
    if sphere is not None:
        # Centres for contact points relative to the CoM (foot centre = contact + r_foot e_z).
        o = sphere[0] - com - np.array([0.0, 0.0, robot.foot_radius])
        centres = (_tuple3(o[0]), _tuple3(o[1]), _tuple3(o[2]), _tuple3(o[3]))
    body = SingleRigidBody(
        name=robot.name,
        mass=float(robot.mass),
        inertia=(_tuple3(inertia[0]), _tuple3(inertia[1]), _tuple3(inertia[2])),
        nominal_stance=(_tuple3(feet[0]), _tuple3(feet[1]), _tuple3(feet[2]), _tuple3(feet[3])),
        max_deviation=_tuple3(box),
        force_limit=float(_FORCE_LIMIT_PER_WEIGHT * robot.mass * GRAVITY),
        friction=0.5,
        com_in_base=_tuple3(com),
        reach_centres=centres,
        reach_radius=None if sphere is None else sphere[1],
        legs=None if legs is None else (legs[0], legs[1], legs[2], legs[3]),
    )
    return body.with_changes(**overrides) if overrides else body


BODY_MODELS: tuple[str, ...] = ("robot", "towr_anymal")
"""Names accepted by :func:`rigid_body_model`."""


def rigid_body_model(name: str, robot: Robot | None) -> SingleRigidBody:
    """The body model called ``name``: "robot" (from ``robot``) or "towr_anymal"."""
    if name == "towr_anymal":
        return TOWR_ANYMAL
    if name == "robot":
        if robot is None:
            raise InvalidArgumentError("body_model 'robot' needs a robot")
        return rigid_body_from_robot(robot)
    raise InvalidArgumentError(f"unknown body model '{name}'; known: {', '.join(BODY_MODELS)}")
