"""Settings of the whole-body tracking controller, with units and what each trades off.

Override any field by dotted key: ``roughwalk.track(..., **{"gains.base_kp": 150})``
or ``roughwalk track --set gains.base_kp=150``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from roughwalk.errors import ConfigError

__all__ = ["TrackingConfig", "TrackingGains", "TaskWeights", "ContactStateConfig"]


def _positive(obj: object, names: tuple[str, ...], prefix: str) -> None:
    for name in names:
        v = getattr(obj, name)
        if not (isinstance(v, int | float) and math.isfinite(v) and v > 0):
            raise ConfigError(f"{prefix}.{name} must be a positive number, got {v!r}")


@dataclass(frozen=True)
class TrackingGains:
    """PD gains of the task-space accelerations (Bellicoso et al. 2016 style).

    Attributes
    ----------
    base_kp, base_kd:
        Base position feedback [1/s²] and [1/s]: a 10 rad/s natural
        frequency (100, 20) corrects centimetre errors within a step without
        fighting the planned accelerations.
    orientation_kp, orientation_kd:
        Base orientation feedback [1/s²], [1/s].
    swing_kp, swing_kd:
        Swing-foot feedback [1/s²], [1/s]: stiffer than the base, a swing leg
        is light and must land where planned.
    slip_gain_scale:
        Factor on a slipping foot's stance weight (with soft contacts):
        holding the foot harder is what stops a slip.
    slip_friction_scale:
        Factor on μ in a slipping foot's friction pyramid: ask it for less
        tangential force. (Raising the base gains on a slip, tried first,
        turned each slip into a jolt.)
    foothold_velocity_gain:
        Swing feet land this many seconds [s] of base velocity error further
        along (the capture point's √(h/g) ≈ 0.22 s for ANYmal C): the one
        correction a trotting base has in the direction its two feet cannot
        push. 0 lands exactly on the plan.
    foothold_position_gain:
        Fraction of the base position error added to the footholds. 1 lands
        a swing foot where the plan puts it relative to the trunk as it is;
        less keeps it nearer the planned spot in the world. On the double
        pallet's far-corner tasks the trunk drifts sideways over the climb
        (two right feet carry it while both left feet swing): at 0.5 the
        left feet land at the edge of their reach, carry nothing, and the
        robot rolls off the pallet's side. Session 17, ``bench_tracking
        --tasks 30 --env double_pallet --init learned --durations fixed``,
        1.0 against 0.5: seed 0 29/30 and 29/30 at 0 and 5 iterations
        against 28/30 and 29/30, seed 1 27/30 and 29/30 against 27/30 and
        27/30, seed 2 30/30 at 5 (as before); 0.5 with a 0.2 m shift limit
        tracked none of two of the failing plans.
    max_foothold_shift_m:
        Largest foothold correction [m].
    max_base_feedback:
        Largest base (or CoM) feedback acceleration [m/s²]: a big error is
        closed over several steps, not with a lunge that makes the feet slide.
    max_orientation_feedback:
        Largest base orientation feedback acceleration [rad/s²].
    max_swing_feedback:
        Largest swing-foot feedback acceleration [m/s²]: a far-off foot must
        not whip its leg, whose reaction spins a trunk in flight.
    """

    base_kp: float = 100.0
    base_kd: float = 20.0
    orientation_kp: float = 100.0
    orientation_kd: float = 20.0
    swing_kp: float = 400.0
    swing_kd: float = 40.0
    slip_gain_scale: float = 3.0
    slip_friction_scale: float = 0.5
    foothold_velocity_gain: float = 0.22
    foothold_position_gain: float = 1.0
    max_foothold_shift_m: float = 0.12
    max_swing_feedback: float = 25.0
    max_base_feedback: float = 50.0
    max_orientation_feedback: float = 100.0

    def __post_init__(self) -> None:
        _positive(
            self,
            tuple(self.__dataclass_fields__)[:8]
            + (
                "max_foothold_shift_m",
                "max_swing_feedback",
                "max_base_feedback",
                "max_orientation_feedback",
            ),
            "gains",
        )
        if not (self.foothold_velocity_gain >= 0 and self.foothold_position_gain >= 0):
            raise ConfigError(
                "gains.foothold_velocity_gain and gains.foothold_position_gain must be ≥ 0, got "
                f"{self.foothold_velocity_gain}, {self.foothold_position_gain}"
            )


@dataclass(frozen=True)
class TaskWeights:
    """Weights of the QP's least-squares tasks (each task's residual is in m/s², rad/s² or N).

    Attributes
    ----------
    base_linear, base_angular:
        Base acceleration tasks. The orientation weighs less than the
        position: where a plan asks the impossible (the double pallet's climb
        asks the feet for net forces beyond friction) the trunk may tilt
        rather than lose its support. Learned initialiser, held-out tasks,
        0.3 against 1.0 (session 11): double pallet 0 iterations 21/30
        against 16/30, 5 iterations 7/10 against 4/10; single pallet 8/10
        and 9/10 against 9/10 and 9/10 (10 tasks gained, 3 lost). Not
        monotone: on five hard double-pallet tasks 0.15 and 0.5 tracked
        none, 0.3 and 1.0 two each.
    swing_foot:
        Swing-foot acceleration task.
    stance_foot:
        Stance feet do not accelerate (J q̈ + J̇ q̇ = 0); heavy, a soft contact constraint.
    flight_base_angular:
        Base angular task weight while no foot bears load: the trunk can only
        be turned by swinging the legs then, so keep it small (0: let it spin).
    force:
        Contact force tracking [1/N²]: the planned forces are a preference, the
        base tasks decide.
    joint_acceleration, torque:
        Regularisation of q̈ [1/(rad/s²)²] and τ [1/(N·m)²] that keeps the QP strictly convex.
    """

    base_linear: float = 1.0
    base_angular: float = 0.3
    swing_foot: float = 1.0
    stance_foot: float = 100.0
    flight_base_angular: float = 0.0
    force: float = 1e-4
    joint_acceleration: float = 1e-4
    torque: float = 1e-6

    def __post_init__(self) -> None:
        names = tuple(n for n in self.__dataclass_fields__ if n != "flight_base_angular")
        _positive(self, names, "weights")
        if not self.flight_base_angular >= 0:
            raise ConfigError(
                f"weights.flight_base_angular must be ≥ 0, got {self.flight_base_angular}"
            )


@dataclass(frozen=True)
class ContactStateConfig:
    """When a foot counts as touching, early, late or slipping.

    Attributes
    ----------
    contact_force_n:
        A foot touches when its measured normal force exceeds this [N].
    release_force_n:
        A loaded foot stays loaded until its normal force drops under this [N].
    early_touchdown_phase:
        A swing foot that touches after this fraction of its swing is treated
        as in stance (an early touchdown); before it, the touch is a scuff.
    search_speed_m_s:
        A foot planned in stance but not touching (a late touchdown) keeps
        moving down at this speed [m/s] until it finds the ground.
    search_depth_m:
        It stops reaching down this far [m] below the planned foothold.
    slip_speed_m_s:
        A stance foot moving faster than this [m/s] slips.
    ground_contact:
        A foot planned in stance that touches the terrain at all (any
        contact, whatever its force) is in stance, not late: a lightly
        loaded foot on the ground otherwise flickers between the two.
    """

    contact_force_n: float = 5.0
    release_force_n: float = 1.0
    early_touchdown_phase: float = 0.5
    search_speed_m_s: float = 0.3
    search_depth_m: float = 0.1
    slip_speed_m_s: float = 0.1
    ground_contact: bool = True

    def __post_init__(self) -> None:
        _positive(
            self, tuple(n for n in self.__dataclass_fields__ if n != "ground_contact"), "contact"
        )


@dataclass(frozen=True)
class TrackingConfig:
    """Everything :func:`roughwalk.track` takes; see each part's documentation.

    Attributes
    ----------
    control_hz:
        Controller rate [Hz]; the paper's controller runs at 400 Hz.
    physics_hz:
        Physics rate [Hz], an integer multiple of ``control_hz``.
    stand_after_s:
        Time [s] the robot keeps standing at the final pose after the motion.
    max_roll_pitch_rad:
        Roll or pitch beyond this [rad] is a fall (45°).
    final_position_tolerance_m:
        Success needs the base this close [m] to the planned final position.
    friction:
        Friction coefficient μ of the QP's pyramids (below the simulated
        ground's, so planned forces do not slide).
    min_normal_force_n, max_normal_force_n:
        Bounds [N] on a stance foot's normal force.
    qp_solver:
        qpsolvers' name of the QP solver ("proxqp", "osqp", ...).
    qp_max_iter:
        The QP solver's iteration limit (None: the solver's default in
        :class:`~roughwalk.tracking.whole_body_qp.WholeBodyQP`). A tick that
        hits it stalls, and a stalled tick ends the run as a failure: a
        400 Hz controller has no minutes to spend on one solve.
    hard_contacts:
        Stance feet do not accelerate as a hard constraint of the QP
        (Bellicoso et al.'s highest priority) instead of a heavy task.
    track_com:
        Track the planned centre of mass with the whole robot's (the single
        rigid body's linear dynamics hold for it exactly) instead of the
        trunk's position.
    reach_aware:
        Lower the planned base where the planned stance feet are beyond the
        legs' reach (:mod:`roughwalk.tracking.reach`); success and tracking
        errors are still judged against the plan itself. Session 10 found it
        worse alone (10 double-pallet tasks: 5 and 3 tracked at 0 and 5
        iterations against 7 and 5; the lowered base folded a front leg onto
        the upper step). Session 13, with ``swing_keep_level``, the same
        bench plans tracked with each setting: double pallet tasks 0–29 at 0
        and 5 iterations 23/30 and 24/30 against 21/30 and 17/30 (11 gained,
        2 lost; alone 22/30 and 21/30, 8 gained, 3 lost); single pallet 8/10
        and 10/10 against 8/10 and 9/10; flat 10/10 both.
    reach_smoothing_s:
        Window [s] over which that lowering is widened and smoothed: longer
        is gentler, shorter keeps closer to the plan.
    min_knee_bend_rad, max_knee_bend_rad:
        Knee bend [rad] (0 = straight) the controller keeps: the least also
        sets the reach above; the knee limits and the HAA limits become
        bounds on q̈ so a stretched leg cannot snap through to the other
        knee branch.
    joint_limit_horizon_s:
        Horizon h [s] of those bounds: q + q̇h + ½q̈h² stays in range. Shorter
        brakes later and harder.
    terrain_swings:
        Swing the feet along the controller's own terrain-clearing paths to
        edge-safe footholds (:mod:`roughwalk.tracking.swing`) instead of
        along the planned swing splines, which were planned over a smoothed
        terrain.
    swing_clearance_m:
        Height [m] a swinging foot keeps above the highest terrain between
        lift-off and touchdown.
    touchdown_depth_m:
        A swing aims this far [m] below the ground, so the foot touches down
        by the planned time instead of hovering.
    swing_keep_level:
        Drop the Raibert correction of a foothold where it would land the
        foot on another terrain level than the planned foothold's (over a
        pallet's side edge, 0.3 m down). Alone: double pallet 23/30 and 22/30
        against 21/30 and 17/30 (10 gained, 3 lost); with ``reach_aware``
        see there.
    """

    control_hz: float = 400.0
    physics_hz: float = 2000.0
    stand_after_s: float = 1.0
    max_roll_pitch_rad: float = math.pi / 4
    final_position_tolerance_m: float = 0.10
    friction: float = 0.6
    min_normal_force_n: float = 2.0
    max_normal_force_n: float = 1500.0
    qp_solver: str = "proxqp"
    qp_max_iter: int | None = None
    track_com: bool = False
    hard_contacts: bool = True
    reach_aware: bool = True
    reach_smoothing_s: float = 0.15
    min_knee_bend_rad: float = 0.35
    max_knee_bend_rad: float = 2.4
    joint_limit_horizon_s: float = 0.05
    terrain_swings: bool = True
    swing_clearance_m: float = 0.08
    touchdown_depth_m: float = 0.01
    swing_keep_level: bool = True
    gains: TrackingGains = field(default_factory=TrackingGains)
    weights: TaskWeights = field(default_factory=TaskWeights)
    contact: ContactStateConfig = field(default_factory=ContactStateConfig)

    def __post_init__(self) -> None:
        _positive(
            self,
            (
                "control_hz",
                "physics_hz",
                "max_roll_pitch_rad",
                "final_position_tolerance_m",
                "friction",
                "max_normal_force_n",
                "reach_smoothing_s",
                "max_knee_bend_rad",
                "joint_limit_horizon_s",
                "swing_clearance_m",
            ),
            "tracking",
        )
        if not self.touchdown_depth_m >= 0:
            raise ConfigError(
                f"tracking.touchdown_depth_m must be ≥ 0, got {self.touchdown_depth_m}"
            )
        if not 0 <= self.min_knee_bend_rad < self.max_knee_bend_rad:
            raise ConfigError(
                "tracking.min_knee_bend_rad must be ≥ 0 and below max_knee_bend_rad, got "
                f"{self.min_knee_bend_rad}, {self.max_knee_bend_rad}"
            )
        if not (self.stand_after_s >= 0 and self.min_normal_force_n >= 0):
            raise ConfigError(
                "tracking.stand_after_s and tracking.min_normal_force_n must be ≥ 0, got "
                f"{self.stand_after_s}, {self.min_normal_force_n}"
            )
        ratio = self.physics_hz / self.control_hz
        if abs(ratio - round(ratio)) > 1e-9 or round(ratio) < 1:
            raise ConfigError(
                f"tracking.physics_hz ({self.physics_hz}) must be an integer multiple of "
                f"tracking.control_hz ({self.control_hz})"
            )
