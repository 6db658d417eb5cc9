"""A leg's joint torques holding a foot force, in closed form for the NLP.

The single rigid body has massless legs; :mod:`.implied_torques` checks a
finished plan by putting the robot's legs under it (analytic IK in the Rust
core, τ = −Jᵀ f with the foot Jacobian). The NLP needs the same torques as a
smooth symbolic function of its variables, so here the IK and the Jacobian
are folded into the geometry of an abduction–flexion–knee leg (HAA about the
base's x, HFE and KFE about the thigh's y, as :func:`leg_reach_sphere`
assumes). Joint k's column of J is a_k × (x − p_k) (axis a_k through p_k,
foot centre x), so

    τ_k = −a_k · ((x − p_k) × f),

the moment of the foot force about joint k's axis, which needs only where
the axes are, not the angles:

* HAA: the axis is fixed in the base, through the HAA anchor A;
* HFE: the foot centre keeps a fixed lateral offset l from A along the
  thigh's y axis, so with v = x − A the thigh's turn (cos θ, sin θ) about x
  solves (v_y, v_z) = l (cos θ, sin θ) + m (−sin θ, cos θ), m = −√(v_y² + v_z² − l²)
  (the foot below the hip); the HFE axis is (0, cos θ, sin θ) through
  A + R_x(θ) h (h the HFE anchor's offset from A);
* KFE: parallel to HFE, through the knee, which a planar two-link leg (thigh
  a, shank b, knee branch as the robot's ``knee_sign``) places at
  α d + β d⊥ from the HFE joint, d the foot seen from the HFE joint in the
  thigh's plane, α = (r² + a² − b²) / 2r², |β| r = √(a² − α² r²).

The two square roots are taken of a smooth positive part
½(s + √(s² + δ²)), δ = 1e-6 m², so that a stretched leg (at an infeasible
iterate) gives a finite value and derivative instead of NaN; at any pose the
legs can reach the values differ by < 1e-9 m².
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import TYPE_CHECKING, Any

import casadi as ca
import numpy as np
from numpy.typing import NDArray

from roughwalk.trajopt.variables import world_to_base

if TYPE_CHECKING:
    from roughwalk.robots import Robot

__all__ = ["LegStatics", "leg_statics_from_robot", "joint_torques_function", "PARAMETERS"]

Vec3 = tuple[float, float, float]

PARAMETERS = 13
"""Length of :meth:`LegStatics.vector`."""

_SMOOTHING = 1e-6  # δ [m²] of the smooth positive part under the square roots


@dataclass(frozen=True)
class LegStatics:
    """One abduction–flexion–knee leg's geometry, as its joint torques need it.

    Attributes
    ----------
    haa:
        The HAA axis' anchor A in the base frame [m] (relative to the base
        frame's origin, not the centre of mass).
    hfe_offset:
        (x, z) of the HFE anchor relative to A in the thigh's frame [m].
    lateral:
        l: the foot centre's fixed offset from A along the thigh's y axis [m].
    thigh, shank:
        a, b: HFE → KFE and KFE → foot centre across their axes [m].
    knee_sign:
        ±1: the knee branch, right-handed about the thigh's +y axis (the
        robot's ``knee_sign`` times the HFE axis' sign).
    axis_signs:
        ±1 per joint: its axis along +x, +y, +y of its body or against it.
    torque_limits:
        |τ| limits [N·m] of HAA, HFE, KFE (+inf when unlimited).
    foot_radius:
        The foot sphere's radius [m]: its centre sits that far above the
        contact point the NLP plans.

    """

    haa: Vec3
    hfe_offset: tuple[float, float]
    lateral: float
    thigh: float
    shank: float
    knee_sign: float
    axis_signs: Vec3
    torque_limits: Vec3
    foot_radius: float = 0.0

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready fields (an infinite torque limit as None)."""
        out = asdict(self)
        out["torque_limits"] = [v if math.isfinite(v) else None for v in self.torque_limits]
        return out

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> LegStatics:
        """The leg from :meth:`to_dict`'s fields."""
        return cls(
            haa=tuple(data["haa"]),
            hfe_offset=tuple(data["hfe_offset"]),
            lateral=float(data["lateral"]),
            thigh=float(data["thigh"]),
            shank=float(data["shank"]),
            knee_sign=float(data["knee_sign"]),
            axis_signs=tuple(data["axis_signs"]),
            torque_limits=tuple(  # type: ignore[arg-type]
                math.inf if v is None else float(v) for v in data["torque_limits"]
            ),
            foot_radius=float(data.get("foot_radius", 0.0)),
        )

    def vector(self) -> NDArray[np.float64]:
        """The numbers :func:`joint_torques_function` takes as its ``leg`` input (13,)."""
        return np.array(
            [
                *self.haa,
                *self.hfe_offset,
                self.lateral,
                self.thigh,
                self.shank,
                self.knee_sign,
                *self.axis_signs,
                self.foot_radius,
            ]
        )


def _signed_axis(axis: NDArray[np.float64], along: int) -> float | None:
    """+1 or −1 when the unit ``axis`` lies along base axis ``along``, None otherwise."""
    unit = np.zeros(3)
    unit[along] = 1.0
    for sign in (1.0, -1.0):
        if np.allclose(axis, sign * unit, atol=1e-6):
            return sign
    return None


def leg_statics_from_robot(robot: Robot) -> tuple[LegStatics, ...] | None:
    """Each leg's :class:`LegStatics` (canonical order), or None when a leg is not of that kind.

    The kind: no turned bodies, HAA along ±x, HFE and KFE along ±y (ANYmal C,
    LittleDog, Go1).
    """
    legs = robot.description.legs
    limits = np.asarray(robot.to_canonical(robot.joint_torque_limit), float).reshape(4, 3)
    out = []
    for i, leg in enumerate(legs):
        turned = any(not np.allclose(np.abs(q), [1, 0, 0, 0]) for q in leg.body_quat)
        signs = [_signed_axis(np.asarray(leg.axis[k], float), a) for k, a in enumerate((0, 1, 1))]
        if turned or any(s is None for s in signs):
            return None
        sx, sy, sz = (float(s) for s in signs if s is not None)
        body = np.asarray(leg.body_pos, float)
        haa = body[0] + leg.anchor[0]
        hfe = body[0] + body[1] + leg.anchor[1] - haa
        foot = body.sum(axis=0) + leg.foot - haa
        thigh, shank = robot.leg_lengths[i]
        out.append(
            LegStatics(
                haa=(float(haa[0]), float(haa[1]), float(haa[2])),
                hfe_offset=(float(hfe[0]), float(hfe[2])),
                lateral=float(foot[1]),
                thigh=float(thigh),
                shank=float(shank),
                knee_sign=float(leg.knee_sign) * sy,
                axis_signs=(sx, sy, sz),
                torque_limits=(float(limits[i, 0]), float(limits[i, 1]), float(limits[i, 2])),
                foot_radius=float(leg.foot_radius),
            )
        )
    return tuple(out)


def _positive(s: ca.SX) -> ca.SX:
    """Smooth max(s, 0) (see the module's notes)."""
    return 0.5 * (s + ca.sqrt(s * s + _SMOOTHING**2))


def joint_torques_function(com_in_base: Vec3) -> ca.Function:
    """SX function (c, η, p, f, leg) → τ (3,) [N·m] of the leg's HAA, HFE, KFE.

    c the centre of mass [m, world], η the base's Euler angles [rad], p the
    foot's contact point [m, world] (its centre the foot radius above),
    f the contact force [N, world], ``leg`` :meth:`LegStatics.vector`. The
    base frame's origin is c − R ``com_in_base``. τ = −Jᵀ f: what the
    motors hold against the ground's push (the leg's own weight aside).
    """
    c, eta, p, f = (ca.SX.sym(n, 3) for n in ("c", "eta", "p", "f"))
    leg = ca.SX.sym("leg", PARAMETERS)
    haa, hx, hz, lateral = leg[0:3], leg[3], leg[4], leg[5]
    thigh, shank, knee, signs = leg[6], leg[7], leg[8], leg[9:12]
    up = ca.vertcat(0.0, 0.0, leg[12])
    v = world_to_base(eta, p + up - c) + ca.DM(com_in_base) - haa
    f_b = world_to_base(eta, f)
    tau_haa = -signs[0] * (v[1] * f_b[2] - v[2] * f_b[1])
    # The thigh's turn about x, from the foot's fixed lateral offset.
    below = -ca.sqrt(_positive(v[1] * v[1] + v[2] * v[2] - lateral * lateral))
    spread = lateral * lateral + below * below
    cos_t = (lateral * v[1] + below * v[2]) / spread
    sin_t = (lateral * v[2] - below * v[1]) / spread
    # In the thigh's frame: the foot seen from the HFE joint (x, z) and the force.
    dx, dz = v[0] - hx, -sin_t * v[1] + cos_t * v[2] - hz
    fx, fz = f_b[0], -sin_t * f_b[1] + cos_t * f_b[2]
    tau_hfe = -signs[1] * (dz * fx - dx * fz)
    r2 = dx * dx + dz * dz
    along = (r2 + thigh * thigh - shank * shank) / (2 * r2)
    across = knee * ca.sqrt(_positive(thigh * thigh - along * along * r2) / r2)
    kx, kz = along * dx - across * dz, along * dz + across * dx
    tau_kfe = -signs[2] * ((dz - kz) * fx - (dx - kx) * fz)
    return ca.Function(
        "joint_torques", [c, eta, p, f, leg], [ca.vertcat(tau_haa, tau_hfe, tau_kfe)]
    )
