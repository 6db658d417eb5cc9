"""The swing foot's initial path (Zucker 2011, §5.2).

"For the swing leg, a spline is constructed to move smoothly from initial
foot position, up to a heuristically determined 'liftoff' position, over to a
'dropoff' position, and down to the footstep target." Here the pieces are
quintic Hermite segments through the four waypoints with zero acceleration at
every waypoint (so the path is C², and starts and ends at rest), velocities
at the interior waypoints chosen per coordinate as Fritsch–Carlson do for
monotone cubics (zero where the path turns) and capped at twice the slope of
either neighbouring segment, which keeps these quintics monotone too, and
waypoint times proportional to segment lengths.

That path's own timing stops the foot vertically at lift-off and drop-off
and dashes through the short lift and drop segments: its peak joint speeds
are 2.5–3.5 times their means, and the swing's duration is set by the peak
against the velocity limits (§5.2). With ``SwingConfig.time_law = "even"``
the same path is re-timed so the foot moves at a steady speed in a metric
that weights vertical motion by ``vertical_weight`` (lifting the foot costs
LittleDog's hip and knee more than moving it forward), with smooth
start-up and slow-down over ``ramp_fraction`` of the time at each end.
With ``time_law = "joint"`` and the swing leg's inverse kinematics at hand,
the metric is the leg's own: at each point the largest joint speed over its
limit, max_j |dq_j/du| / v_j, so the limiting joint runs near its limit along
the whole path instead of only where the Cartesian metric peaks (the
velocity-only time-optimal law, smoothed at its ends by the same ramps).

The heuristic path lifts the foot straight up, which on LittleDog swings the
hip (HFE, 7.5 rad/s) back and forth again while the knee (14 rad/s) bends:
two thirds of the hip's 1.0–1.8 rad per swing. With ``SwingConfig.path =
"joint"`` the path is instead shaped in the leg's joint space for the
``"joint"`` time law: the hip and knee bend by a few sine modes on top of
the straight move from the start's angles to the target's, chosen to lower
the joints' speed over their limits along the path while the foot keeps
``lift_height`` above the line from start to target and ``clearance`` above
the ground actually under it (not one apex over the whole stride).
"""

from __future__ import annotations

import weakref
from collections import OrderedDict
from collections.abc import Callable
from dataclasses import astuple, replace
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.interpolate import CubicSpline

from roughwalk.errors import InvalidArgumentError
from roughwalk.trajectories.config import SwingConfig

if TYPE_CHECKING:
    from roughwalk.terrain.terrain import Terrain

__all__ = ["LegAngles", "LegFeet", "SwingSpline", "ground_clearance", "ramp_profile"]

LegAngles = Callable[[NDArray[np.float64]], NDArray[np.float64]]
"""The swing leg's angles (n, 3) [rad] with its foot at world positions (n, 3) [m]."""
LegFeet = Callable[[NDArray[np.float64]], NDArray[np.float64]]
"""The swing leg's foot at world positions (n, 3) [m] for its angles (n, 3) [rad]."""

_TABLE = 2001
"""Samples of the path parameter used to invert its arc length."""
_NODES = 121
"""Nodes of the cubic time law u(t)."""
_STOP_SHARE = 0.1
"""Share of the mean weighted speed added to it everywhere (see ``_even_law``)."""
_JOINT_TABLE = 201
"""Samples of the path at which the "joint" time law evaluates the leg's IK."""
_REACH_TOLERANCE = 0.002
"""Miss [m] of the leg's IK beyond which the "joint" law does not trust its rate."""
_PATH_WAYPOINTS = 17
"""Waypoints of a ``path = "joint"`` swing (about 8 mm apart on a 10 cm stride)."""
_CHECKS = 33
"""Samples of the path (ends included) at which a ``path = "joint"`` swing's optimiser
asks for the clearances (each one constraint: SLSQP's cost grows fast with their number)."""
_FINE = 97
"""Samples at which the optimised swing's clearances are checked afterwards."""
_FOOTPRINT = 4
"""Points on the foot's rim (plus its centre) at which the ground under it is read."""
_SHAPES_KEPT = 256
"""Joint-space swing shapes remembered per terrain (see ``_remembered_shape``)."""
_MODES = 6
"""Sine modes of the hip's and the knee's bend along a ``path = "joint"`` swing."""
_POWER = 8
"""p of the p-norm over joints that stands in for the largest joint speed over its limit."""
_ITERATIONS = 60
"""SLSQP iterations for a ``path = "joint"`` swing's shape."""
_CUSHION = 0.0015
"""Margin [m] the optimiser adds to the clearances at its samples, for the path between them."""
_TOLERANCE = 0.001
"""Shortfall [m] of a clearance that a ``path = "joint"`` swing may keep between the samples."""


def ramp_profile(tau: ArrayLike, ramp: float) -> NDArray[np.float64]:
    """Fraction of the way (0 → 1) at time fractions ``tau`` ∈ [0, 1], ramp fraction ``ramp``.

    The speed rises from rest as a smoothstep over the first ``ramp`` of the
    time, holds, and falls symmetrically over the last: peak over mean speed
    1 / (1 − ramp), zero speed and acceleration at both ends.
    """
    x = np.clip(np.asarray(tau, dtype=float), 0.0, 1.0)
    if ramp <= 0:
        return x
    scale = 1.0 / (1.0 - ramp)

    def rise(t: NDArray[np.float64]) -> NDArray[np.float64]:
        y = np.clip(t / ramp, 0.0, 1.0)
        return ramp * (y**3 - 0.5 * y**4) + np.maximum(t - ramp, 0.0)

    first = np.minimum(x, 0.5)
    out = rise(first)
    late = x > 0.5
    out[late] = 2 * rise(np.array(0.5)) - rise(1.0 - x[late])
    return out * scale


def ground_clearance(
    terrain: Terrain, points: ArrayLike, foot_radius: float
) -> NDArray[np.float64]:
    """Height [m] of the foot sphere's bottom above the highest ground under its disc.

    ``points`` (n, 3): foot centres [m]. The ground is read at the centre and
    ``_FOOTPRINT`` points on the rim (radius ``foot_radius``), a conservative
    stand-in for the sphere's distance to the terrain.
    """
    p = np.asarray(points, dtype=float).reshape(-1, 3)
    angle = np.linspace(0.0, 2 * np.pi, _FOOTPRINT, endpoint=False)
    rim = foot_radius * np.stack([np.cos(angle), np.sin(angle)], axis=1)
    offsets = np.concatenate([np.zeros((1, 2)), rim])
    xy = (p[:, None, :2] + offsets[None]).reshape(-1, 2)
    ground = np.asarray(terrain.height(xy), dtype=float).reshape(len(p), -1).max(axis=1)
    return p[:, 2] - foot_radius - ground


def _lift_profile(s: NDArray[np.float64], fraction: float) -> NDArray[np.float64]:
    """Share (0 → 1 → 0) of the full lift asked for at path fractions ``s``.

    Linear from the ends to ``fraction`` of the path in (the foot leaves and
    meets the ground at an angle, not sliding along it), 1 between.
    """
    f = max(fraction, 0.05)
    return np.clip(np.minimum(s, 1.0 - s) / f, 0.0, 1.0)


def _joint_path_waypoints(
    start: NDArray[np.float64],
    target: NDArray[np.float64],
    config: SwingConfig,
    terrain: Terrain | None,
    foot_radius: float,
    leg_angles: LegAngles,
    leg_feet: LegFeet,
    velocity_limit: NDArray[np.float64],
    joint_range: tuple[NDArray[np.float64], NDArray[np.float64]] | None,
) -> NDArray[np.float64] | None:
    """Waypoints (K, 3) [m] of a swing shaped in joint space; or None.

    The leg's angles are q(s) = q₀ + s·(q₁ − q₀) + Σₖ cₖ·sin(kπs), s ∈ [0, 1],
    the hip (HFE) and knee (KFE) bent by ``_MODES`` sine modes each, the
    abduction (HAA) straight. The coefficients minimise ∫ ‖q′ / v‖_p ds, a
    smooth stand-in (p = ``_POWER``) for the largest joint speed over its
    limit that sets the ``"joint"`` time law's pace (so LittleDog's slow hip
    moves less and its fast knee lifts), subject to, at ``_CHECKS`` points,
    the foot being ``lift_height`` above the straight line from start to
    target and its sphere ``clearance`` above the ground under it
    (``scan_terrain``), each times :func:`_lift_profile`. The foot is read
    by FK at the swing pose, its ends shifted onto start and target. None
    where the optimiser ends short of those clearances by over
    ``_TOLERANCE`` at ``_FINE`` samples, the angles leave ``joint_range``
    (lower, upper), or the leg's IK misses the ends by over 2 mm.
    """
    from scipy.optimize import minimize

    q0, q1 = np.asarray(leg_angles(np.array([start, target])), dtype=float)
    ends = np.asarray(leg_feet(np.array([q0, q1])), dtype=float)
    if np.max(np.linalg.norm(ends - np.array([start, target]), axis=1)) > 0.002:
        return None
    modes = np.arange(1, _MODES + 1)
    at_ends = None
    if config.scan_terrain and terrain is not None:
        at_ends = ground_clearance(terrain, np.array([start, target]), foot_radius)

    def margins(s: NDArray[np.float64], cs: NDArray[np.float64]) -> NDArray[np.float64]:
        """(len(cs), len(s)): the smaller margin [m] of lift and clearance, one FK call."""
        q = np.repeat((q0 + s[:, None] * (q1 - q0))[None], len(cs), axis=0)
        basis = np.sin(np.pi * s[:, None] * modes)
        q[:, :, 1:] += np.einsum("nm,bjm->bnj", basis, cs.reshape(-1, 2, _MODES))
        p = np.asarray(leg_feet(q.reshape(-1, 3)), dtype=float).reshape(len(cs), len(s), 3)
        p += (1.0 - s)[:, None] * (start - ends[0]) + s[:, None] * (target - ends[1])
        share = _lift_profile(s, config.lift_fraction)
        chord = start[2] + s * (target[2] - start[2])
        out = p[:, :, 2] - chord - config.lift_height * share
        if at_ends is not None and terrain is not None:
            clear = ground_clearance(terrain, p.reshape(-1, 3), foot_radius).reshape(out.shape)
            # A foot standing on a slope reads its disc's uphill rim above its
            # sphere's bottom: that shortfall at the ends fades as it lifts.
            slope = np.minimum(0.0, at_ends[0] + s * (at_ends[1] - at_ends[0]))
            out = np.minimum(out, clear - slope * (1.0 - share) - config.clearance * share)
        return out

    s = np.linspace(0.0, 1.0, _CHECKS)[1:-1]
    rate_basis = np.pi * modes * np.cos(np.pi * s[:, None] * modes)
    w = 1.0 / np.asarray(velocity_limit, dtype=float).reshape(3)[1:]
    steady = (q1 - q0)[1:]
    step = 1e-5

    def cost(c: NDArray[np.float64]) -> tuple[float, NDArray[np.float64]]:
        r = (steady + rate_basis @ c.reshape(2, _MODES).T) * w  # (n, 2)
        a = np.abs(r) + 1e-12
        norm = np.sum(a**_POWER, axis=1) ** (1.0 / _POWER)
        # d‖r‖_p / d r_j = sign(r_j)·(|r_j| / ‖r‖_p)^(p−1)
        d = np.sign(r) * (a / norm[:, None]) ** (_POWER - 1) * w
        return float(norm.mean()), (d.T @ rate_basis).ravel() / len(s)

    memo: dict[bytes, NDArray[np.float64]] = {}

    def with_steps(c: NDArray[np.float64]) -> NDArray[np.float64]:
        """Margins at c and at c plus ``step`` along each coefficient (one FK call)."""
        key = c.tobytes()
        if key not in memo:
            memo.clear()
            memo[key] = margins(s, np.vstack([c, c + step * np.eye(len(c))]))
        return memo[key]

    constraints = {
        "type": "ineq",
        "fun": lambda c: with_steps(c)[0] - _CUSHION,
        "jac": lambda c: ((with_steps(c)[1:] - with_steps(c)[0]) / step).T,
    }
    # Start from a knee bend that lifts the foot (its sign from FK).
    mid = 0.5 * (q0 + q1)
    probe = np.asarray(leg_feet(np.array([mid, mid + [0.0, 0.0, 1e-3]])), dtype=float)
    guess = np.zeros(2 * _MODES)
    guess[_MODES] = 0.5 if probe[1, 2] > probe[0, 2] else -0.5
    result = minimize(
        cost,
        guess,
        jac=True,
        method="SLSQP",
        constraints=constraints,
        options={"maxiter": _ITERATIONS, "ftol": 1e-6},
    )
    c = np.asarray(result.x, dtype=float)
    fine = np.linspace(0.0, 1.0, _FINE)
    if not np.all(np.isfinite(c)) or np.min(margins(fine[1:-1], c[None])) < -_TOLERANCE:
        return None
    q = q0 + fine[:, None] * (q1 - q0)
    q[:, 1:] += np.sin(np.pi * fine[:, None] * modes) @ c.reshape(2, _MODES).T
    if joint_range is not None and (
        np.any(q < joint_range[0] - 1e-9) or np.any(q > joint_range[1] + 1e-9)
    ):
        return None
    p = np.asarray(leg_feet(q), dtype=float)
    p += (1.0 - fine)[:, None] * (start - ends[0]) + fine[:, None] * (target - ends[1])
    return p[:: (_FINE - 1) // (_PATH_WAYPOINTS - 1)]


_shapes: weakref.WeakKeyDictionary[object, OrderedDict[bytes, NDArray[np.float64] | None]] = (
    weakref.WeakKeyDictionary()
)
_flat_shapes: OrderedDict[bytes, NDArray[np.float64] | None] = OrderedDict()


def _remembered_shape(
    start: NDArray[np.float64],
    target: NDArray[np.float64],
    config: SwingConfig,
    terrain: Terrain | None,
    foot_radius: float,
    leg_angles: LegAngles,
    leg_feet: LegFeet,
    velocity_limit: NDArray[np.float64],
    joint_range: tuple[NDArray[np.float64], NDArray[np.float64]] | None,
) -> NDArray[np.float64] | None:
    """:func:`_joint_path_waypoints`, remembered: a footstep's swing is shaped several times.

    The same swing is planned for the nominal timing, the fitted timing and
    each attempt of its trajectory; the shape depends on the ends, the
    settings, the terrain and the trunk pose, which the leg's FK at three
    fixed angles pins down. At most ``_SHAPES_KEPT`` shapes per terrain.
    """
    probes = np.asarray(leg_feet(np.array([[0.0, 0.0, 0.0], [0.3, 0.5, -0.5], [-0.3, -0.5, 0.5]])))
    parts = [start, target, probes.ravel(), velocity_limit, [foot_radius]]
    if joint_range is not None:
        parts += [joint_range[0], joint_range[1]]
    key = np.concatenate([np.asarray(x, dtype=float).ravel() for x in parts]).tobytes()
    key += repr(astuple(config)).encode()
    if terrain is None:
        store = _flat_shapes
    else:
        store = _shapes.setdefault(terrain, OrderedDict())
    if key in store:
        store.move_to_end(key)
        found = store[key]
        return None if found is None else found.copy()
    shape = _joint_path_waypoints(
        start,
        target,
        config,
        terrain,
        foot_radius,
        leg_angles,
        leg_feet,
        velocity_limit,
        joint_range,
    )
    store[key] = shape
    if len(store) > _SHAPES_KEPT:
        store.popitem(last=False)
    return None if shape is None else shape.copy()


def _interior_slopes(
    points: NDArray[np.float64], times: NDArray[np.float64]
) -> NDArray[np.float64]:
    """Velocities (K, 3) at the waypoints: zero at the ends, monotone-preserving inside."""
    h = np.diff(times)
    delta = np.diff(points, axis=0) / h[:, None]
    v = np.zeros_like(points)
    for i in range(1, len(points) - 1):
        d0, d1 = delta[i - 1], delta[i]
        w1 = 2 * h[i] + h[i - 1]
        w2 = h[i] + 2 * h[i - 1]
        same = d0 * d1 > 0
        with np.errstate(divide="ignore", invalid="ignore"):
            harmonic = (w1 + w2) / (w1 / d0 + w2 / d1)
        # A zero-acceleration quintic stays monotone while |v| ≤ 2·|slope|.
        cap = 2.0 * np.minimum(np.abs(d0), np.abs(d1))
        v[i] = np.where(same, np.clip(harmonic, -cap, cap), 0.0)
    return v


# The ramps of the fast swing options (``time_law`` and ``path`` "joint").
FAST_RAMP_FRACTION = 0.1


def _path_corridor(
    s: NDArray[np.float64], t: NDArray[np.float64], foot_radius: float
) -> NDArray[np.float64]:
    """(N, 2) points [m] under the straight path from ``s`` to ``t``, a foot radius either side."""
    stride = float(np.linalg.norm(t[:2] - s[:2]))
    n = max(8, int(np.ceil(stride / 0.005)) + 1)
    along = np.linspace(0.0, 1.0, n)[:, None] * (t[:2] - s[:2]) + s[:2]
    if stride > 1e-9:
        side = np.array([-(t[1] - s[1]), t[0] - s[0]]) / stride
    else:
        side = np.array([0.0, 1.0])
    return np.concatenate([along + k * foot_radius * side for k in (-1.0, 0.0, 1.0)])


def _ground_relief(
    s: NDArray[np.float64], t: NDArray[np.float64], terrain: Terrain, foot_radius: float
) -> float:
    """Highest minus lowest ground [m] under the foot's straight path (:func:`_path_corridor`)."""
    ground = np.asarray(terrain.height(_path_corridor(s, t, foot_radius)), dtype=float)
    return float(np.max(ground) - np.min(ground))


class SwingSpline:
    """A C² foot path through start, lift-off, drop-off and target, at rest at both ends.

    Parameters
    ----------
    waypoints:
        (K, 3) positions [m], K ≥ 2: start, ..., target.
    duration:
        Time [s] from start to target.
    config:
        With ``time_law == "even"`` or ``"joint"``, the path is re-timed to a
        steady speed (see the module notes); otherwise (or without it) each
        segment takes time in proportion to its length.
    leg_angles, velocity_limit:
        The swing leg's IK (:data:`LegAngles`) and its joints' limits (3,)
        [rad/s], for ``time_law == "joint"``; without them that law falls
        back to ``"even"``.
    leg_feet:
        The leg's FK at the same trunk pose (:data:`LegFeet`). With it, the
        ``"joint"`` law is ``"even"`` where the IK misses the path by over
        ``_REACH_TOLERANCE`` (a target below the leg's reach from the swing
        pose): the clamped angles stop there, the leg's rate reads zero and
        the law dashed through that stretch, which the trunk's later pose
        then has to follow at up to 1.5 times the joints' limits (LittleDog
        board AC, the last fifth of a downhill swing).

    Attributes
    ----------
    times:
        When the foot passes each waypoint [s].
    """

    def __init__(
        self,
        waypoints: ArrayLike,
        duration: float,
        config: SwingConfig | None = None,
        leg_angles: LegAngles | None = None,
        velocity_limit: ArrayLike | None = None,
        leg_feet: LegFeet | None = None,
    ) -> None:
        p = np.asarray(waypoints, dtype=float)
        if p.ndim != 2 or p.shape[1] != 3 or p.shape[0] < 2 or not np.all(np.isfinite(p)):
            raise InvalidArgumentError(f"swing waypoints must be finite (K ≥ 2, 3), got {p.shape}")
        if not (np.isfinite(duration) and duration > 0):
            raise InvalidArgumentError(f"swing duration must be positive [s], got {duration}")
        seg = np.linalg.norm(np.diff(p, axis=0), axis=1)
        # Chord-length timing, but no segment gets less than a tenth of the
        # average, so a short one (a tiny stride) is not a dash.
        seg = np.maximum(seg, 0.1 * seg.mean() + 1e-9)
        self.waypoints = p
        self.duration = float(duration)
        self.knots = np.concatenate([[0.0], np.cumsum(seg) / seg.sum() * duration])
        self.velocities = _interior_slopes(p, self.knots)
        self._law: CubicSpline | None = None
        self.times = self.knots
        joint_metric = None
        if leg_angles is not None and velocity_limit is not None:
            joint_metric = (leg_angles, np.asarray(velocity_limit, dtype=float).reshape(3))
        if (
            joint_metric is not None
            and leg_feet is not None
            and not self._reached(joint_metric[0], leg_feet)
        ):
            joint_metric = None
        if config is not None and config.time_law in ("even", "joint"):
            self._law = self._even_law(
                config.vertical_weight,
                config.ramp_fraction,
                joint_metric if config.time_law == "joint" else None,
            )
            if self._law is not None:
                self.times = self._pass_times()

    def _reached(self, leg_angles: LegAngles, leg_feet: LegFeet) -> bool:
        """Whether the leg's IK puts its foot on the path (within ``_REACH_TOLERANCE``)."""
        points, _, _ = self._evaluate_path(np.linspace(0.0, self.duration, _JOINT_TABLE))
        feet = np.asarray(leg_feet(np.asarray(leg_angles(points), dtype=float)), dtype=float)
        return bool(np.max(np.linalg.norm(feet - points, axis=1)) <= _REACH_TOLERANCE)

    def _even_law(
        self,
        vertical_weight: float,
        ramp: float,
        joint_metric: tuple[LegAngles, NDArray[np.float64]] | None = None,
    ) -> CubicSpline | None:
        """The path parameter u(t) [s] for a steady weighted speed, or None (keep the knots).

        The weight: the foot's speed with vertical motion counted
        ``vertical_weight`` times, or with ``joint_metric`` (IK, limits) the
        largest joint speed over its limit.
        """
        u = np.linspace(0.0, self.duration, _TABLE)
        if joint_metric is None:
            _, du, _ = self._evaluate_path(u)
            speed = np.linalg.norm(du * [1.0, 1.0, vertical_weight], axis=1)
        else:
            leg_angles, limit = joint_metric
            coarse = np.linspace(0.0, self.duration, _JOINT_TABLE)
            q = np.asarray(leg_angles(self._evaluate_path(coarse)[0]), dtype=float)
            rate = np.max(np.abs(np.gradient(q, coarse, axis=0)) / limit, axis=1)
            speed = np.interp(u, coarse, rate)
        if not np.all(np.isfinite(speed)) or speed.max() <= 0:
            return None
        # A share of the mean keeps the arc length strictly increasing and makes
        # the foot slow down where its path stops (stepping in place, a corner
        # with lift_fraction 0): there u′ stays finite, so the velocity p′·u′
        # goes to zero instead of flipping at once.
        speed = speed + _STOP_SHARE * speed.mean()
        arc = np.concatenate([[0.0], np.cumsum(0.5 * (speed[1:] + speed[:-1]) * np.diff(u))])
        t = np.linspace(0.0, self.duration, _NODES)
        nodes = np.interp(ramp_profile(t / self.duration, ramp) * arc[-1], arc, u)
        nodes[0], nodes[-1] = 0.0, self.duration
        # The path's rate does not vanish at its ends, so the ramp's start from
        # rest is u′ = 0 there.
        law = CubicSpline(t, nodes, bc_type=((1, 0.0), (1, 0.0)))
        dense = np.linspace(0.0, self.duration, 4 * _NODES)
        if np.any(np.diff(law(dense)) < 0) or np.any(law(dense, 1) < -1e-9):
            return None
        return law

    def _pass_times(self) -> NDArray[np.float64]:
        """Times [s] at which the re-timed foot passes the path's knots."""
        assert self._law is not None
        t = np.linspace(0.0, self.duration, _TABLE)
        out = np.interp(self.knots, self._law(t), t)
        out[0], out[-1] = 0.0, self.duration
        return out

    @classmethod
    def plan(
        cls,
        start: ArrayLike,
        target: ArrayLike,
        duration: float,
        config: SwingConfig,
        terrain: Terrain | None = None,
        foot_radius: float = 0.0,
        leg_angles: LegAngles | None = None,
        velocity_limit: ArrayLike | None = None,
        leg_feet: LegFeet | None = None,
        joint_range: tuple[ArrayLike, ArrayLike] | None = None,
        law_legs: tuple[LegAngles, LegFeet] | None = None,
    ) -> SwingSpline:
        """The heuristic lift-off and drop-off points, then the spline.

        Both sit at one height: ``lift_height`` above the higher of start and
        target, and with ``scan_terrain``, ``clearance`` above the highest
        terrain under the straight path (foot sphere included, sampled across
        the foot's width). They are ``lift_fraction`` of the stride in from
        start and target. ``leg_angles`` and ``velocity_limit``: for the
        ``"joint"`` time law (see the class).

        With ``config.path == "joint"`` under the ``"joint"`` time law, and
        ``leg_angles``, ``velocity_limit`` and ``leg_feet`` (the leg's FK at
        the same trunk pose) given, the path is
        instead shaped in joint space (:func:`_joint_path_waypoints`;
        ``joint_range``: the leg's (lower, upper) angles [rad]), and kept
        where it allows a shorter swing than the heuristic one.

        ``law_legs``: the leg's IK and FK to time the ``"joint"`` law by
        (and to compare paths and laws by) instead of ``leg_angles`` and
        ``leg_feet``, where they differ: with ``SwingConfig.law_trunk``
        "moving", under the trunk as it moves through the swing; those take
        points (angles) in the order the foot passes them, from lift-off to
        touchdown. The path's shape is still made at the fixed pose.
        """
        s = np.asarray(start, dtype=float)
        t = np.asarray(target, dtype=float)
        if config.fast_swing_relief > 0 and terrain is not None:
            relief = _ground_relief(s, t, terrain, foot_radius)
            if relief <= config.fast_swing_relief:
                config = replace(
                    config, time_law="joint", path="joint", ramp_fraction=FAST_RAMP_FRACTION
                )
            config = replace(config, fast_swing_relief=0.0)
        if (
            config.path == "joint"
            and config.time_law == "joint"
            and leg_angles is not None
            and leg_feet is not None
            and velocity_limit is not None
        ):
            limit = np.asarray(velocity_limit, dtype=float).reshape(3)
            limits = None
            if joint_range is not None:
                limits = (
                    np.asarray(joint_range[0], dtype=float).reshape(3),
                    np.asarray(joint_range[1], dtype=float).reshape(3),
                )
            heuristic = cls.plan(
                s,
                t,
                duration,
                replace(config, path="cartesian"),
                terrain,
                foot_radius,
                leg_angles,
                limit,
                leg_feet=leg_feet,
                law_legs=law_legs,
            )
            waypoints = _remembered_shape(
                s, t, config, terrain, foot_radius, leg_angles, leg_feet, limit, limits
            )
            if waypoints is None:
                return heuristic
            timed_by, timed_feet = law_legs if law_legs is not None else (leg_angles, leg_feet)
            shaped = cls._timed(waypoints, duration, config, timed_by, limit, timed_feet)
            # The shape's cost stands in for the time law's pace: keep
            # whichever path the joints' peak speeds allow the shorter swing.
            return min((shaped, heuristic), key=lambda c: c.least_time(timed_by, limit))
        if law_legs is not None:
            leg_angles, leg_feet = law_legs
        top = max(s[2], t[2]) + config.lift_height
        if config.scan_terrain and terrain is not None:
            ground = float(np.max(terrain.height(_path_corridor(s, t, foot_radius))))
            top = max(top, ground + foot_radius + config.clearance)
        f = config.lift_fraction
        lift = s + f * (t - s)
        drop = t - f * (t - s)
        lift[2] = drop[2] = top
        waypoints = np.array([s, lift, drop, t])
        return cls._timed(waypoints, duration, config, leg_angles, velocity_limit, leg_feet)

    @classmethod
    def _timed(
        cls,
        waypoints: NDArray[np.float64],
        duration: float,
        config: SwingConfig,
        leg_angles: LegAngles | None,
        velocity_limit: ArrayLike | None,
        leg_feet: LegFeet | None = None,
    ) -> SwingSpline:
        """The spline through ``waypoints`` under ``config``'s time law."""
        spline = cls(waypoints, duration, config, leg_angles, velocity_limit, leg_feet)
        if config.time_law != "joint" or leg_angles is None or velocity_limit is None:
            return spline
        # Where the leg's IK is nearly singular along the path (a high swing
        # over rocks at the edge of the workspace) its rate is a poor metric:
        # keep whichever law lets the joints' peak speeds allow the shorter swing.
        even = cls(waypoints, duration, replace(config, time_law="even"))
        return min((spline, even), key=lambda c: c.least_time(leg_angles, velocity_limit))

    def least_time(self, leg_angles: LegAngles, velocity_limit: ArrayLike) -> float:
        """Least duration [s] at which this path and time law keep the leg within its limits.

        The peak of |q̇_j| / v_j over 41 samples, times the current duration.
        """
        q = np.asarray(leg_angles(self.position(np.linspace(0.0, self.duration, 41))))
        v = np.asarray(velocity_limit, dtype=float).reshape(3)
        peak = np.abs(np.diff(q, axis=0)).max(axis=0) * 40 / self.duration
        return float(np.max(peak / v)) * self.duration

    def _segments(
        self, t: ArrayLike
    ) -> tuple[NDArray[np.int64], NDArray[np.float64], NDArray[np.float64]]:
        tt = np.clip(np.asarray(t, dtype=float), 0.0, self.duration)
        i = np.clip(np.searchsorted(self.knots, tt, side="right") - 1, 0, len(self.knots) - 2)
        h = self.knots[i + 1] - self.knots[i]
        return i, (tt - self.knots[i]) / h, h

    def evaluate(
        self, t: ArrayLike
    ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
        """Position [m], velocity [m/s] and acceleration [m/s²], each (n, 3), at times t [s].

        Times outside [0, duration] are clamped (the foot rests at its ends).
        """
        if self._law is None:
            return self._evaluate_path(t)
        tt = np.clip(np.atleast_1d(np.asarray(t, dtype=float)), 0.0, self.duration)
        u = np.clip(self._law(tt), 0.0, self.duration)
        du = self._law(tt, 1)[:, None]
        ddu = self._law(tt, 2)[:, None]
        pos, vel, acc = self._evaluate_path(u)
        return pos, vel * du, acc * du * du + vel * ddu

    def _evaluate_path(
        self, t: ArrayLike
    ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
        """The path and its derivatives at path parameters ``t`` (its own chord timing)."""
        i, s, h = self._segments(t)
        s = s[:, None]
        h = h[:, None]
        p0, p1 = self.waypoints[i], self.waypoints[i + 1]
        v0, v1 = self.velocities[i] * h, self.velocities[i + 1] * h
        s2, s3 = s * s, s * s * s
        # Quintic Hermite basis with zero end accelerations.
        h00 = 1 - 10 * s3 + 15 * s3 * s - 6 * s3 * s2
        h10 = s - 6 * s3 + 8 * s3 * s - 3 * s3 * s2
        h11 = -4 * s3 + 7 * s3 * s - 3 * s3 * s2
        h01 = 10 * s3 - 15 * s3 * s + 6 * s3 * s2
        d00 = -30 * s2 + 60 * s3 - 30 * s3 * s
        d10 = 1 - 18 * s2 + 32 * s3 - 15 * s3 * s
        d11 = -12 * s2 + 28 * s3 - 15 * s3 * s
        a00 = -60 * s + 180 * s2 - 120 * s3
        a10 = -36 * s + 96 * s2 - 60 * s3
        a11 = -24 * s + 84 * s2 - 60 * s3
        pos = h00 * p0 + h10 * v0 + h11 * v1 + h01 * p1
        vel = (d00 * p0 + d10 * v0 + d11 * v1 - d00 * p1) / h
        acc = (a00 * p0 + a10 * v0 + a11 * v1 - a00 * p1) / (h * h)
        return pos, vel, acc

    def position(self, t: ArrayLike) -> NDArray[np.float64]:
        """Foot positions (n, 3) [m] at times t [s]."""
        return self.evaluate(t)[0]
