"""Settings of the simulated runs (Zucker 2011, §6), with units and what each trades off.

Override any field by dotted key: ``roughwalk.run(..., **{"reflex.body_position_m":
0.05})`` or ``roughwalk run --set reflex.body_position_m=0.05``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from roughwalk.errors import ConfigError

__all__ = [
    "SimConfig",
    "WorldConfig",
    "ContactConfig",
    "ControllerConfig",
    "IntegratorConfig",
    "TouchdownConfig",
    "LiftGateConfig",
    "StabilizerConfig",
    "ReflexConfig",
    "OutcomeConfig",
    "ExecutorConfig",
]


RECOVERY_SLIDE_RESPONSES = ("lower", "hold", "replant")
"""What ``reflex.recovery_slide_m`` does with a foot that slid during a recovery."""


def _positive(obj: object, names: tuple[str, ...], prefix: str) -> None:
    for name in names:
        v = getattr(obj, name)
        if not (isinstance(v, int | float) and math.isfinite(v) and v > 0):
            raise ConfigError(f"{prefix}.{name} must be a positive number, got {v!r}")


def _nonnegative(obj: object, names: tuple[str, ...], prefix: str) -> None:
    for name in names:
        v = getattr(obj, name)
        if not (isinstance(v, int | float) and math.isfinite(v) and v >= 0):
            raise ConfigError(f"{prefix}.{name} must be a number ≥ 0, got {v!r}")


@dataclass(frozen=True)
class ContactConfig:
    """Foot–terrain contact of a small robot with rubber feet.

    Attributes
    ----------
    friction:
        Sliding friction coefficient μ. Rubber on wood, rock or plastic boards
        is about 0.8–1.0; lower values make the feet slip on slopes.
    torsional_friction, rolling_friction:
        MuJoCo's torsional [m] and rolling [m] friction; used only with
        ``condim`` 4 or 6.
    condim:
        Contact dimensionality: 3 (normal + tangential friction) suits a
        point-like spherical foot; 4 adds torsion, 6 rolling.
    timeconst:
        Contact stiffness as MuJoCo's ``solref`` time constant [s]: how fast a
        penetration is pushed out. Must be at least twice the physics step;
        smaller is stiffer (a hard board under a rubber sole sinks ~1 mm).
    dampratio:
        Contact damping ratio (``solref``'s second value); 1 is critical.
    solimp:
        MuJoCo's ``solimp`` (d0, d_width, width [m], midpoint, power): the
        impedance rising from d0 to d_width over ``width`` of penetration.
    cone:
        MuJoCo's friction cone, for every contact of the model; None (the
        default) keeps the robot file's (LittleDog's: MuJoCo's default
        pyramid; ANYmal C's: elliptic). "pyramidal" bounds the tangential
        force by μ only along the contact frame's two tangent axes, by μ/√2
        between them; "elliptic" is Coulomb's cone, μ in every direction. A
        1 cm sphere held on a plane (μ = 1, the feet's ``solref`` and
        ``solimp``, 2 kHz) tilted 40° stays within 12 mm over 2 s when the
        slope falls along a tangent axis, and slides 0.7 m (22.5° off it) or
        2.1 m (45° off) with the pyramid; with the elliptic cone it stays
        within 3.3 mm every way. On board AE (large rocks, session 21) the
        elliptic cone with ``impratio`` 10 walked 1 of seeds 0–7, 10, 11,
        15 against the pyramid's 5, and 3 of seeds 1, 4, 7, 10, 13 with
        ``impratio`` 1 (the pyramid's 1): the walk's settings were tuned on
        the pyramid, and LittleDog keeps it.
    impratio:
        MuJoCo's ``impratio``: the frictional constraints' impedance over the
        normal one's; None (the default) keeps the robot file's (LittleDog:
        1, ANYmal C: 100). At 1 a loaded foot creeps (the sphere above on
        20°: 3.5 mm over 2 s with the pyramid, 1.8 mm elliptic); at 10 with
        the elliptic cone 0.2–0.3 mm up to 40°. MuJoCo's documentation
        advises values above 1 only with the elliptic cone.
    """

    friction: float = 1.0
    torsional_friction: float = 0.005
    rolling_friction: float = 0.0001
    condim: int = 3
    timeconst: float = 0.005
    dampratio: float = 1.0
    solimp: tuple[float, ...] = (0.9, 0.95, 0.001, 0.5, 2.0)
    cone: str | None = None
    impratio: float | None = None

    def __post_init__(self) -> None:
        _positive(self, ("timeconst", "dampratio"), "world.contact")
        if self.impratio is not None:
            _positive(self, ("impratio",), "world.contact")
        if self.cone is not None and self.cone not in ("pyramidal", "elliptic"):
            raise ConfigError(
                f"world.contact.cone must be pyramidal or elliptic, got {self.cone!r}"
            )
        _nonnegative(self, ("friction", "torsional_friction", "rolling_friction"), "world.contact")
        if self.condim not in (1, 3, 4, 6):
            raise ConfigError(f"world.contact.condim must be 1, 3, 4 or 6, got {self.condim}")
        if len(self.solimp) != 5:
            raise ConfigError(f"world.contact.solimp needs 5 numbers, got {self.solimp}")


@dataclass(frozen=True)
class WorldConfig:
    """The MuJoCo model and its clocks.

    Attributes
    ----------
    physics_hz:
        Physics rate [Hz]; must be an integer multiple of ``control_hz``.
        2 kHz keeps the 10 mm feet and the 10⁻⁵ kg·m² links of LittleDog
        stable with stiff contacts; higher costs time linearly.
    control_hz:
        Controller rate [Hz]: the executor reads the state and sets the
        servo targets this often (LittleDog's onboard loop ran at 500 Hz).
    hfield_base:
        Thickness [m] of the solid slab MuJoCo puts under the height field.
    contact:
        Foot–terrain contact (:class:`ContactConfig`).
    integrator:
        MuJoCo integrator: "implicitfast" (stable with the servos' damping)
        or "euler", "rk4", "implicit".
    """

    physics_hz: float = 2000.0
    control_hz: float = 500.0
    hfield_base: float = 0.05
    contact: ContactConfig = field(default_factory=ContactConfig)
    integrator: str = "implicitfast"

    def __post_init__(self) -> None:
        _positive(self, ("physics_hz", "control_hz", "hfield_base"), "world")
        ratio = self.physics_hz / self.control_hz
        if abs(ratio - round(ratio)) > 1e-9 or round(ratio) < 1:
            raise ConfigError(
                f"world.physics_hz ({self.physics_hz}) must be an integer multiple of "
                f"world.control_hz ({self.control_hz})"
            )
        if self.integrator not in ("euler", "rk4", "implicit", "implicitfast"):
            raise ConfigError(
                f"world.integrator must be euler, rk4, implicit or implicitfast, "
                f"got {self.integrator!r}"
            )
        if 2.0 / self.physics_hz > self.contact.timeconst:
            raise ConfigError(
                f"world.contact.timeconst ({self.contact.timeconst} s) must be at least two "
                f"physics steps ({2.0 / self.physics_hz} s)"
            )

    @property
    def substeps(self) -> int:
        """Physics steps per control tick."""
        return int(round(self.physics_hz / self.control_hz))


@dataclass(frozen=True)
class ControllerConfig:
    """Joint-level control (Zucker 2011, §6: PD servos, force control to soften impacts).

    Attributes
    ----------
    gravity_compensation:
        Add the torques that hold the planned ground forces and the legs'
        own weight as a feed-forward (shifted into the position servos'
        targets). Without it every joint sags by τ/kp.
    velocity_feedforward:
        Track the planned joint velocities (the servo damps relative to them)
        instead of damping towards rest.
    touchdown_stiffness:
        Servo stiffness scale (0–1] of a swing leg near and just after
        touchdown, and of any leg whose measured force jumps above plan.
        Softer absorbs the impact; too soft lets the leg fold.
    touchdown_window_s:
        How long before the planned touchdown the leg softens [s].
    recover_s:
        Time [s] over which a softened leg returns to full stiffness once it
        bears weight.
    impact_force_n:
        A swing foot touching the terrain with more than this force [N]
        counts as an early touchdown and softens its leg.
    """

    gravity_compensation: bool = True
    velocity_feedforward: bool = True
    touchdown_stiffness: float = 0.4
    touchdown_window_s: float = 0.06
    recover_s: float = 0.08
    impact_force_n: float = 2.0

    def __post_init__(self) -> None:
        if not (0 < self.touchdown_stiffness <= 1):
            raise ConfigError(
                f"controller.touchdown_stiffness must be in (0, 1], got {self.touchdown_stiffness}"
            )
        _nonnegative(self, ("touchdown_window_s", "recover_s", "impact_force_n"), "controller")


@dataclass(frozen=True)
class IntegratorConfig:
    """The per-leg integrator of Zucker 2011, §6: Δ ← Δ + γ(f_B − f̄_B), q ← IK_B(f_B + Δ).

    Attributes
    ----------
    enabled:
        Run the integrators at all.
    gain:
        γ per control tick (dimensionless). The body error closes with a
        time constant of about 1/(γ·control_hz): 0.004 at 500 Hz is ~0.5 s,
        "slow-moving" as the paper says; larger corrects faster but fights
        the planned motion and can oscillate.
    max_offset_m:
        Largest |Δ| per leg [m]; the integrator cannot correct more.
    flight_decay_s:
        Time constant [s] with which Δ decays to zero while the foot is in
        flight, so the foot lands where planned.
    min_load_n:
        A supporting foot integrates only while its measured vertical force
        is at least this [N]; below it Δ holds (anti-windup: an unloaded leg
        cannot move the trunk). 0 integrates on every planned support.
    """

    enabled: bool = True
    gain: float = 0.004
    max_offset_m: float = 0.03
    flight_decay_s: float = 0.05
    min_load_n: float = 1.0

    def __post_init__(self) -> None:
        _nonnegative(self, ("gain", "min_load_n"), "integrator")
        _positive(self, ("max_offset_m", "flight_decay_s"), "integrator")


@dataclass(frozen=True)
class TouchdownConfig:
    """Feet that meet the ground before or after their plan (the ``TouchdownAdapter``).

    Attributes
    ----------
    enabled:
        Adapt the feet's heights at all.
    early_force_n:
        A swing foot with a measured vertical force above this [N] has landed
        early: its target stops at the height where it stands, for the rest
        of its swing and its stance.
    early_window_s:
        Only this close [s] to its planned touchdown does a swing foot's
        contact count as an early landing (earlier, the foot is still
        leaving the ground or scraping past something).
    search_rate_m_s:
        A foot planned to support that bears less than ``loaded_n`` is
        lowered at this speed [m/s] until it does (the ground is lower than
        planned: a rock's edge, a slope). Faster finds the ground sooner but
        lands harder.
    search_max_m:
        The deepest [m] a foot searches below its planned foothold.
    loaded_n:
        The vertical force [N] at which a supporting foot counts as loaded.
    max_tilt_rad:
        A foot searches only while the trunk's orientation error stays below
        this [rad]: a foot in the air because the trunk rocks (a push) must
        not be lengthened, it would kick the trunk back when it lands.
    release_s:
        Time constant [s] with which a lifted foot's correction fades in
        flight, so that it lands where planned.

    Measured (``roughwalk bench littledog --seeds 2 --classes sloped_rocks
    --set executor.compute_time_scale=0`` with the fast opt-in timing):
    ``enabled=false`` 0/2, on 2/2 (4.37 and 4.57 cm/s in two sweeps). The
    push sweep with the default timing is unchanged by it (``roughwalk
    bench push_recovery --direction 90`` / ``-90``: 16/17 and 15/17).
    """

    enabled: bool = True
    early_force_n: float = 2.0
    early_window_s: float = 0.1
    search_rate_m_s: float = 0.05
    search_max_m: float = 0.015
    loaded_n: float = 1.0
    max_tilt_rad: float = 0.05
    release_s: float = 0.05

    def __post_init__(self) -> None:
        _nonnegative(
            self,
            (
                "early_force_n",
                "early_window_s",
                "search_rate_m_s",
                "search_max_m",
                "loaded_n",
                "max_tilt_rad",
            ),
            "touchdown",
        )
        _positive(self, ("release_s",), "touchdown")


@dataclass(frozen=True)
class LiftGateConfig:
    """Hold a footstep at lift-off until the feet that stay down bear (the ``LiftGate``).

    The plan lifts a foot on time; on a rock the foot that landed last can
    still hang a few millimetres over its foothold (the touchdown search is
    lowering it) or slide down a flank, and the three feet the swing stands
    on are then two. On board AE (large rocks, seed 4, the walk's
    defaults) LH bore nothing from its touchdown at 0.70 s until 0.85 s,
    LF lifted at 0.82 s with the planned CoM 1.2 cm inside the RF–LH–RH
    triangle, and the robot tipped over the RF–LH diagonal: the foot-force
    reflex fired at 0.93 s and the run rolled over. The gate holds the
    plan (its clock stops and the plan's joint targets stand still) at the
    tick before a foot lifts while a foot that stays down bears less than
    ``least_n`` or ``fraction`` of the load the swing plans on it,
    whichever is smaller; for at most ``max_hold_s``, then the step goes
    on. The hold counts against the run's speed (the ``gate`` share of
    the time breakdown). Seed 4 then walks without a reflex (7.24 cm/s),
    but over seeds 0–31 of that bench (``--expansions 40000``, one process
    per seed, session 21) the gate walks 22 at 6.39 cm/s against 21 at 6.34
    (seeds 4, 6, 15, 16 gained; 12, 14, 24 lost), and with
    ``reflex.recentre_steps`` 2 the other classes' 4 seeds as main except
    logs seed 1 (2/4 against 3/4): the runs diverge after any change, so
    it stays off.

    Attributes
    ----------
    enabled:
        Gate lift-offs at all (off by default).
    least_n:
        The load [N] at which a staying foot counts as bearing.
    fraction:
        Or this share of the vertical load the swing's first sample plans
        on it, if that is less (a foot planned light).
    max_hold_s:
        The longest hold [s] of one lift-off.
    """

    enabled: bool = False
    least_n: float = 2.0
    fraction: float = 0.5
    max_hold_s: float = 0.3

    def __post_init__(self) -> None:
        _nonnegative(self, ("least_n", "fraction", "max_hold_s"), "lift_gate")


@dataclass(frozen=True)
class StabilizerConfig:
    """The CoP stabiliser: the trunk shifts to bring the measured CoP onto the planned ZMP.

    Attributes
    ----------
    enabled:
        Run the stabiliser at all.
    estimate_s:
        Time constant [s] of the low-pass that estimates the CoP offset the
        plan does not explain (foot impacts last a few milliseconds, a rock
        settling under a foot a few tenths of a second). Shorter reacts
        faster and lets more of the footfalls' noise move the trunk.
    follow_s:
        1/ω [s] of the critically damped motion by which the trunk shift
        follows the estimate. Shorter moves the trunk harder, and a trunk
        accelerating sideways moves its own ZMP the other way.
    max_shift_m:
        Largest trunk shift |s| [m]; beyond it the error is the reflexes' business.
    leak_s:
        Time constant [s] with which the shift fades while nothing is
        measured (all feet unloaded, or a reflex's recovery).
    min_load_n:
        Total vertical foot force [N] below which the CoP is not read.
    min_foot_n:
        A foot bears load above this vertical force [N]. The CoP is read
        only while exactly the planned supporting feet do.
    holdoff_s:
        After the contacts last differed from the plan (a foot strike, a
        touchdown early or late, a foot letting go), wait this long [s] before
        reading the CoP again, so the transient is not taken for an offset.
    """

    enabled: bool = True
    estimate_s: float = 0.15
    follow_s: float = 0.1
    max_shift_m: float = 0.02
    leak_s: float = 1.0
    min_load_n: float = 5.0
    min_foot_n: float = 0.5
    holdoff_s: float = 0.15

    def __post_init__(self) -> None:
        _nonnegative(self, ("min_load_n", "min_foot_n", "holdoff_s"), "stabilizer")
        _positive(self, ("estimate_s", "follow_s", "max_shift_m", "leak_s"), "stabilizer")


@dataclass(frozen=True)
class ReflexConfig:
    """Errors that trigger the reflex, and what it does (Zucker 2011, §6 and §4.5).

    Attributes
    ----------
    enabled:
        Watch for execution errors at all (off: the robot walks on blindly).
    body_position_m:
        Trunk position error [m] beyond which the reflex fires.
    body_orientation_rad:
        Trunk orientation error [rad] (angle of R̄Rᵀ) beyond which it fires.
    foot_position_m:
        A supporting foot this far [m] from where it should be (a slip).
        0.02 since session 16 (0.035 before): a foot sliding down a rock
        is caught before the trunk tips. Board AE (bench large rocks seed
        3, ``--expansions 40000``): LF slid 2.2–2.8 cm while RF swung; at
        0.035 the orientation reflex fired 0.1 s later, at 0.21 rad, and
        the recovery's stance had no plan; at 0.02 the foot-position
        reflex fires at 2.5 cm and the run reaches the goal (5.36 cm/s).
        ``bench_littledog.py``'s runs with ``--expansions 40000``, main and
        0.02 one process each: large rocks seeds 0–7 4/8 at 5.56 cm/s →
        5/8 at 5.30 (seed 3 gained; seed 5 slower, 3.79 → 2.67, after 5
        reflexes, not 2), logs seeds 0–5 4/6 at 7.52 → 4/6 at 7.71 (seed
        1 2.92 → 3.69, 3 reflexes, not 4); round rocks, sloped rocks, gap,
        barrier and steps seeds 0–1 walk every run as at 0.035 (no reflex
        more); held-out large rocks seeds 8–15 5/8 at 5.47 → 4/8 at 6.40
        (seed 15 lost: a re-plan after the earlier reflex found no plan;
        seed 14 3.73 → 5.76): over 16 large-rocks seeds 9 either way. With
        ``executor.start_max_slope`` 40° as well: large rocks 0–7 5/8 at
        6.48, 8–15 5/8 at 7.41, logs 4/6 at 7.22. Of main's 31 reflexes
        on those large-rocks and logs runs 25 were foot-force ones and none
        a foot-position one: the slides that end runs mostly happen inside
        recoveries, where no reflex watches.
    foot_force_n:
        While three feet support the robot, one planned to bear at least this
        much [N] that measures less than ``foot_force_fraction`` of its plan
        has lost its footing (with four down the load sharing is statically
        indeterminate, so an unloaded foot is no error).
    foot_force_fraction:
        See ``foot_force_n``.
    foot_force_tilt_rad:
        A lost load counts only once the trunk's orientation error exceeds
        this [rad]: a robot balanced on a diagonal with one foot unloaded is
        not falling, one that tilts while a foot lets go is. 0.03 since
        session 10 (0.05 before): a side push while a front foot swings
        (LF, pushed left at 2.0 s with ``swing.time_law`` "joint" and
        ``timing.min_swing_s`` 0.2) unloads the hind foot of the other side
        (RH) 0.02 s after it lands, and the trunk rolls over the RF–LH
        diagonal; at 0.05 the reflex fired 0.11 s after the push, the trunk
        already moving sideways at 0.22 m/s and rolled 5°, and the lowered
        LF (moved out by the capture offset computed then) did not stop the
        roll (35° at 2.9 s); at 0.03 (or 0.02) it fires ~0.03 s sooner and
        one reflex rescues it. The 1 N·s side push (``roughwalk bench
        push_recovery --from 1.6 --to 3.2``, 9 push times) with the default
        gait survives 8 of 9 to the left (7 at 0.05: the 2.2 s push, also
        LF's swing, is rescued now; 3.0 s still falls) and 8 of 9 to the
        right (the same: 2.2 s, LF's lift-off, falls with both; see
        ``TimingConfig`` in :mod:`roughwalk.trajectories.config` for why no
        trigger mends that one). The repeatable bench (``roughwalk bench
        littledog --classes barrier,steps,round_rocks,sloped_rocks,gap,logs,large_rocks
        --expansions 40000 --seeds 2 --set executor.compute_time_scale=0
        --set reflex.replan_budget_s=300``) walks every run as at 0.05, to
        the millisecond and reflex (none fires sooner or more often there),
        and the demo course stays at 5.64 cm/s.
    foot_force_descent_m_s, foot_force_descent_n:
        While the planned trunk descends faster than ``foot_force_descent_m_s``
        [m/s], only a foot planned to bear at least ``foot_force_descent_n``
        [N] (not ``foot_force_n``) is judged by its load. A planned descent
        tilts the trunk and leaves a lightly planned foot light without any
        tip: on the gap course (bench gap seed 1, ``--expansions 40000``)
        the trunk lowers 5–7 cm as LF swings down to the trench floor
        (0.14 m/s when the reflex fired), RH, planned to carry 3.3 N,
        unloads, the trunk tilts 0.04–0.05 rad from its plan, and the
        reflex fired though nothing was falling (with ``foot_force_n`` 100
        the run walks on). Raising ``foot_force_n`` to 4 N everywhere drops that
        alarm but also the rescues on flat ground, where a side push
        unloads a foot planned ~3 N with the trunk level (pushed right at
        2.0 and 2.2 s). With 0.05 m/s and 4 N (session 16, ``bench_littledog.py
        --expansions 40000 --classes gap --seeds 6``) gap walks 6/6 at 7.18 →
        7.33 cm/s (only seed 1 changes, 6.64 → 7.55, no reflex), and the 1 N·s
        side pushes (``bench_push_recovery.py --from 1.6 --to 3.2``) survive
        as before: 7/9 right, 8/9 left, the same push times. That descent
        slows to 0.08 m/s while RH is still unloaded: at 0.1 m/s the alarm
        fires at 8.14 s and seed 1 walks 6.64 cm/s, as on main. It was
        off in session 16 (``foot_force_descent_n`` 0, i.e. no more than
        ``foot_force_n``; 0 still turns it off): on board AE (bench large rocks seed 2) LF,
        planned 2.3 N, unloads at 1.50 s as the planned trunk sinks
        0.125 m/s, tilted 0.05 rad, and there the reflex (1.53 s) is a
        rescue: with the condition at 0.05 m/s and 4 N it does not fire,
        the robot walks on, a reflex fires at 2.96 s and the re-plan finds
        no certificate (fails; 6.20 cm/s without the condition). The load,
        descent rate and tilt there are those of the gap's false alarm; the
        centre of mass is not (``foot_force_descent_lean_m``). With that
        lean asked, 4 N by default since session 17 (``bench_littledog.py
        --expansions 40000 --seeds 6 --jobs 1``, main and the branch back to
        back): gap 6/6 at 7.18 → 7.33 cm/s (seed 1 6.64 → 7.55, no reflex),
        large rocks 5/6 at 5.30 and logs 4/6 at 7.71, every run at the same
        speed (logs seed 2 still rolls over, after 3 reflexes, not 2);
        round rocks, sloped rocks, barrier, steps (``--seeds 2``) the same
        runs. Without the lean, large rocks seed 2 walked 6.20 → 3.14 cm/s.
    foot_force_descent_lean_m:
        The descent's exemption holds for a light foot only while the
        measured centre of mass leans at least this far [m] onto it: past
        the line through the two other supporting feet, on its side
        (:func:`~roughwalk.sim.reflexes.lean_toward`). Leaning onto a foot
        presses it down (it bears again when it touches); a robot balanced
        on the other two, or leaning away, tips off it. Recorded in the two
        runs (``bench_littledog.py --expansions 40000``, session 17): gap
        seed 1's false alarm (7.90–7.98 s, RH light, planned 3.3 N, the
        trunk sinking 0.14 m/s) leaned 0.8–1.3 cm onto RH; large rocks
        seed 2's rescue (1.45–1.52 s, LF planned 2.1–2.4 N, on a rock face:
        its contact force mostly sideways, sinking 0.10–0.13 m/s) 0.1–0.2
        cm. A negative value asks for no lean (the exemption of session 16).
        The 1 N·s side pushes keep their rescues: their trunk is planned
        level, so no exemption applies (as measured with session 16's).
    one_sided:
        Watch for the one-sided state (off by default): every loaded foot
        on one side, a foot of the other side planned down and bearing
        nothing, and the trunk rolling over the loaded side's line, lifting
        the other side, faster than
        ``one_sided_rate_rad_s`` [rad/s] for ``one_sided_persist_s`` [s]
        (:func:`~roughwalk.sim.reflexes.tipping_off`). Neither foot check
        sees this state with four feet planned down. Trade-off: it fires
        sooner (0.14 s on the 1 N·s right push at 1.8 s), but the recovery
        it starts saves no run: the 1 N·s side-push sweeps keep 7/9 right
        and 8/9 left, large rocks seeds 0–11 7/12 at 5.50 cm/s, as without;
        the responses tried with it (pressing the unloaded feet down,
        stepping a loaded foot out, watching diagonals too) lose runs.
        Session 19's figures and the why: ``docs/measurements.md``.
    one_sided_rate_rad_s, one_sided_persist_s, one_sided_loaded_n:
        See ``one_sided``; a foot bearing more than ``one_sided_loaded_n``
        [N] counts as loaded.
    persist_s:
        An error must last this long [s] to count, so impact transients do not.
    settle_s:
        After all four feet are down, hold still this long [s] before re-planning.
    settled_rate_rad_s:
        After ``settle_s`` the hold goes on while the trunk turns faster than
        this [rad/s] or a foot bears no load (a trunk still rocking from its
        left feet to its right ones): lifting a foot then tips it over.
    foot_force_per_leg:
        The foot-force error persists only while the same foot stays short
        of load (off: while any foot is). Board AE (bench large
        rocks seed 0, ``--expansions 40000``) with ``timing.measured_speed``
        0.9 and ``timing.min_swing_s`` 0.2: as LH landed (0.77–0.79 s) RH
        chattered on a rock face (0 N every other 2 ms tick) and LF let go
        for a few ticks at a time; no foot lost its load for 0.03 s, but
        the reflex fired, the recovery lowered three feet onto RF alone and
        the robot rolled over (34° at 1.41 s). With this, ``standing_bear``
        and ``replan_nudge_m`` 0.02 that run reaches the goal (2.78 cm/s,
        three reflexes later in the course). The three together on the
        repeatable bench (``roughwalk bench littledog --expansions 40000
        --seeds 2``; only runs with a reflex can change): with that timing
        large rocks 1/2 → 2/2 at 3.80 cm/s (seed 0 2.78, 3 reflexes),
        barrier 2/2 at 5.62 → 5.61, sloped rocks 1/2 at 6.90 (seed 1 still
        fails: its nudged re-plan finds no certificate within 2 cm); with
        the default timing no run lost, but large rocks seed 0 2.79 → 2.25
        (3 reflexes, not 2) and logs seed 1 4.01 → 3.52 (barrier 4.73 and
        sloped rocks 1/2 at 5.90 unchanged). On by default since session
        12, with ``standing_bear``, ``replan_nudge_m`` 0.02 and the
        measured timing (``timing.measured_speed`` 0.95, ``min_swing_s``
        0.2; figures in :class:`~roughwalk.trajectories.config.TimingConfig`):
        13 of 14 runs as before, large rocks 2/2 at 4.40 cm/s (3.80 with
        ``measured_speed`` 0.9).
    settle_max_s:
        Longest extension [s] of the hold for that; then the re-plan starts anyway.
    settled_loaded_feet:
        How many feet (3 or 4) must bear load for the robot to count as
        settled (with the trunk turning slower than ``settled_rate_rad_s``).
        Four feet down share the load indeterminately: one a millimetre
        high carries nothing, however still the robot stands. On the
        LittleDog logs board (AD, bench seed 1, ``--expansions 40000``, the
        joint swing options) RF rested unloaded after the recovery and the
        hold ran its whole ``settle_max_s``: the reflex took 2.32 s of the
        run's 6.78. 3 counts a still trunk on three loaded feet as settled;
        rocking from the left feet to the right ones still loads only two
        at its ends. Session 13 (``roughwalk bench littledog --expansions
        40000 --seeds 2``; only runs with a reflex can change, and each of
        those was run again): with the joint swing options
        (``trajectory.swing.time_law=joint``, ``swing.path=joint``,
        ``swing.ramp_fraction=0.1``) logs 5.00 → 5.64 cm/s (seed 1 4.35 →
        5.61), barrier 6.94 → 7.37 (seed 0 6.13 → 6.99), every other run
        the same (large rocks seed 0 and sloped rocks seed 1 fail with
        both); with the defaults barrier 5.83 → 6.14 (seed 0 5.17 → 5.79)
        but large rocks 4.40 → 4.17 (seed 0 3.84 → 3.37: re-planned 0.04 s
        sooner, from a stance a hair different, it met a second
        foot-force reflex). 1 N·s side-push sweeps (``roughwalk bench
        push_recovery --from 1.6 --to 3.2 --direction ±90``): 8/9 and 8/9,
        the same push times, with 3 and 4. 3 by default since session 15,
        with the fast swing options (see
        :class:`~roughwalk.trajectories.config.SwingConfig`'s ``path``).
    lower_s:
        Time [s] to put all four feet down and centre the trunk over them.
    capture_max_m:
        Largest capture step [m]: a lifted foot on the side the trunk is
        moving towards goes down v·√(h/g) further that way (0: straight
        down). Longer catches harder pushes and may ask for a foot beyond
        the leg's reach (it then lands as near as the leg gets).
    catch_nearer:
        A lifted foot the recovery puts down lands on the flat ground
        nearest to it between straight below and its planned foothold,
        where that is nearer than straight below and the arched way there
        clears the ground (:func:`~roughwalk.sim.recovery.nearer_catch`):
        a hind foot caught over a trench as it climbs out lands on the lip,
        not 10 cm down at the bottom. On (session 26): with
        ``swing.law_trunk`` "moving" the 1.5 m gap course (``bench
        littledog --full``, seeds 0–9, ``--expansions 40000``) walks 10/10
        at 8.09 cm/s, against 8/10 with it off (seeds 5 and 6 rolled over
        as RH went back down into the trench); of the other courses' runs
        with a reflex (large rocks seeds 4, 20, 22, 48; logs 6, 7; steps
        2, 6) none lands otherwise.
    replan_budget_s:
        Time the anytime planner gets to re-plan [s] (the paper's target: walk
        again within 2 s).
    standing_bear:
        While the recovery puts the unloaded feet down, the supporting feet
        still on the ground (:func:`~roughwalk.sim.recovery.standing_feet`)
        keep bearing the trunk, loaded at that instant or not. Off:
        only the feet loaded at that instant bear it, the others are
        unweighted and softened as for a touchdown. Board AE (bench large
        rocks seed 0, ``--expansions 40000``), with ``timing.measured_speed``
        0.9 and ``timing.min_swing_s`` 0.2: at the first reflex (0.79 s,
        LH's swing) only RF measured load (RH chattered on a rock face, LF
        had let go), the whole 26.6 N went to RF and the robot rolled over
        (34° at 1.41 s); on, that reflex is survived and re-planned, but the
        run falls at 4.14 s after two more. With the default timing the
        same course, won after two reflexes with it off, ends after four
        in a failed re-plan with it on: the reflexes' outcomes on that board
        are chaotic, and two seeds do not tell the better setting. On by
        default since session 12, with the measured timing (see
        ``foot_force_per_leg``).
    loaded_window_s:
        A foot that bore load (over 1 N) at any tick within this long [s]
        before the reflex, and is still within 1 cm of the ground, counts
        as loaded for the recovery: it stays where it is rather than being
        put down on its planned foothold like a lifted foot (0: only the
        load at the reflex's tick counts). Feet on rock faces chatter: on
        board AE (bench large rocks seed 6, ``--expansions 40000`` with
        ``executor.start_max_slope`` 40°) RH bore 6.4 N at 0.912 s and
        nothing for the 34 ms to the foot-force reflex (0.946 s, LF
        swinging, RH 2.6 mm over the ground). It bore the trunk either way
        (``standing_bear``); put down, it moved the few millimetres to its
        planned foothold, the trunk rolled −13° → −20° over the RF–LH
        diagonal, LF struck at 78 N and the robot bounced over to the right
        (34° at 1.43 s); held, the run reaches the goal (3.95 cm/s, 2
        reflexes). A difference of millimetres: the outcome there is
        chaotic rather than this option's doing. Off: at 0.05 bench logs
        seed 1 (``--expansions 40000``) falls (main reaches the goal at
        3.69 cm/s after 3 reflexes): without the ground check its RF,
        lifting off 2 cm up after a bounce, was held in the air (pitched
        35° at 3.72 s); with it the trunk touches the terrain at 6.32 s
        after 5 reflexes. Large rocks seeds 0–11 (``bench_littledog.py
        --expansions 40000 --seeds 12 --classes large_rocks``, session 18):
        7/12 at 5.50 cm/s → 9/12 at 5.34 (6 and 11 rescued, 9 4.21 → 5.41,
        3 5.36 → 3.86); the 1 N·s side pushes the same push times as main.
    replan_nudge_m:
        Where the stance the feet stand on after a recovery has no pose
        certificate (nor, within 2.5 cm, the one they were headed for), the
        re-plan starts from the nearest stance with one foot moved 1 cm at a
        time up to this far [m] that has one; the integrators absorb the
        difference. 0: no such search, and the run ends there. 0.02 by
        default since session 12 (0 before), with the measured timing (see
        ``foot_force_per_leg``).
    replan_from_trunk:
        A re-plan gives the planner the measured trunk pose with the feet:
        where the pose guessed from the feet gives the stance no
        certificate, the start's is searched from the trunk, its body kept
        only ``footstep.certificate.start_clearance`` off the terrain (the
        robot already stands there; every planned stance keeps the full
        clearance). If the leg due to lift cannot start the plan, the others
        are tried in walking order (a leg whose shin settled against a rock
        must step first: no stance keeping it there has a certificate).
        Only then the planned footholds and ``replan_nudge_m``.
    replan_nudge_any_leg:
        Each stance ``replan_nudge_m`` tries may start with any leg, the one
        due to lift first and then the others in walking order, as the
        measured stance may with ``replan_from_trunk``. Off: only the leg
        due. Board AE (bench large rocks seed 4, ``--expansions 40000``,
        the fast options and the rim check): LF slid 3.9 cm off a flank,
        the recovery settled on four loaded feet, the stance was certified
        for LF, RF or LH to lift but no footstep left it, and no stance
        within 2 cm let RH (the leg due) lift; LF moved 1 cm left with LH
        first has a plan. On by default since session 15: large rocks
        seeds 0–7 (``roughwalk bench littledog --classes large_rocks
        --expansions 40000 --seeds 8`` with the fast options and
        ``footstep.edge_drop=0.03``) 4/8 at 5.46 cm/s → 6/8 at 4.93 (seeds
        4 and 5 rescued, at 4.79 and 2.93 cm/s; every other run the same);
        held-out seeds 8–15 3/8 → 4/8 (seed 15 rescued at 3.83 cm/s; seeds
        9–12 roll over in their first recovery either way); seeds 0–1 of
        the other six classes the same runs but logs seed 1, which still
        fails, two reflexes later.
    replant_max_slope, replant_snap_m, replant_min_m, replant_s, replant_margin_m:
        After a recovery settles and before the re-plan, a foot standing on
        a slope steeper than ``replant_max_slope`` [rad] (the mean over the
        foot's disc, as ``executor.start_max_slope`` judges a start foot)
        is lifted and put down on the nearest foothold within
        ``replant_snap_m`` [m] no steeper than that, if that is at least
        ``replant_min_m`` [m] away
        (:func:`~roughwalk.sim.recovery.replant_segments`): the trunk moves
        until its centre of mass is ``replant_margin_m`` [m] inside the
        other three feet, the foot steps, the trunk returns over the four,
        each motion taking ``replant_s`` [s], and the robot settles again.
        Each leg at most once per recovery; none where the other three
        cannot hold the trunk. Without it the re-plan starts on the foot
        where it slid (a 76° rock face after large rocks seed 4's first
        recovery). Each step costs about a second: re-planting feet
        merely off the footholds by millimetres (which the re-plan snaps)
        made large rocks seed 2 walk 1.93 cm/s with 4 reflexes (6.20 and
        1 without), so only feet on a face step. π/2: off. Session 17
        (``bench_littledog.py --expansions 40000``, one process per seed,
        main and the branch), 40° with ``recovery_slide_m`` 0.015: large
        rocks 0–7 5/8 at 5.30 → 5/8 at 5.63 cm/s, 14 → 9 reflexes (seed
        4 rescued at 4.33: RF steps 1.7 cm off a 76° face; seed 5 lost:
        LH stepped 1 cm down a flank and no stance within 2 cm of the new
        one has a certificate); logs 0–5 4/6 → 3/6 (seed 1 lost after 3
        reflexes). With ``executor.start_max_slope`` 40° as well: large
        rocks 0–7 5/8 at 6.47 cm/s with 5 reflexes; held-out 8–15 and
        logs in ``docs/measurements.md``. Success is not better: off.
    replant_certified:
        A foot is re-planted (``replant_max_slope``, and a slid foot put
        down again, ``recovery_slide_m``) only where the stance it makes
        has a pose certificate, as the re-plan after it will ask (the
        footstep planner's own routine, from the measured trunk with
        ``replan_from_trunk``); otherwise the foot stays where it is.
        Board AE (bench large rocks seed 5, ``--expansions 40000``, the
        re-plant options): LH stepped 1 cm down a flank onto a stance no
        certificate holds, nor any within ``replan_nudge_m``, and the
        re-plan failed. Acts only with one of those options on. Session 18
        (``bench_littledog.py --expansions 40000``, both re-plant options):
        large rocks 0–7 5/8 at 5.63 cm/s as before, seed 5 now re-planned
        from where LH stood (solved) but two reflexes later the trunk
        touches the rocks at 5.65 s (main walks it at 2.67 after 5
        reflexes); logs 0–5 3/6 (seeds 1, 2 roll over, 5's re-plan has no
        certificate). The re-plant options stay off.
    recovery_slide_m, recovery_slides:
        During a recovery, no reflex watches the feet; with this, a foot
        the recovery holds on its foothold that slides more than
        ``recovery_slide_m`` [m] off it for ``persist_s``, while the other
        three bear load, is put down again: the recovery starts over from
        where the robot is, that foot lowered like a lifted one onto the
        nearest gentle foothold (``replant_max_slope``) or where it is, at
        most ``recovery_slides`` times per reflex. 0: off. In session 17's
        runs (see ``replant_max_slope``) it fired once, on large rocks seed
        7 (LF, 3.0 s), and that run still fell as on main. In the two
        traced recoveries where a slide ended the run, fewer than three
        other feet bore load, where putting a foot down again cannot help:
        large rocks seed 4's second recovery on main (RF slid 0.17 s in,
        LF and RH still being lowered) and, with ``executor.start_max_slope``
        40°, its first (at the reflex only LF bore load, 1 N).
    recovery_slide_bearing:
        How many of the other three feet (0–3) must bear load for
        ``recovery_slide_m`` to act on a slide. 3: only where they can
        carry the trunk while the slid foot is put down again (session 17).
        Fewer watches the recoveries that stand on a diagonal or one side,
        where the slides that end runs happen: board AE, bench large rocks
        seed 4's second recovery (2.44 s) stands on LF and RH while RF, bearing
        nothing, slides 5.5 cm down its flank and the trunk rolls over the
        diagonal (35° at 3.06 s); seed 10's first (1.39 s) as RF and RH slide.
        A foot loaded within the last 50 ms counts as bearing (RH chattered
        to 0 N every 30 ms there, restarting the watch's persistence).
        Session 20 (``bench_littledog.py --expansions 40000 --classes
        large_rocks --seeds 16`` on board AE; ``bench_push_recovery.py
        --from 1.6 --to 3.2 --direction ±90``): with ``recovery_slide_m``
        0.01, 2 and "replant", seed 4 reaches the goal (3.43 cm/s) but the
        right push sweep is 5/9 (main 7/9) and logs seed 1 falls (main 3.69
        cm/s); with ``recovery_slide_drop_m`` 0.003 too, the pushes are
        main's (8/9, 7/9) but large rocks 0–15 walk 8/16 at 5.92 cm/s
        against main's 9/16 at 5.79 (6 gained; 1 and 5 lost; 4 falls) and
        logs seed 1 still falls; restarting the recovery where the slid
        foot has nowhere 5 mm away to step: 8/16 at 5.67 (15 gained, 1 and
        3 lost), logs seed 1 falls. So 3 stays the default.
    recovery_slide_response:
        What a slide caught by ``recovery_slide_m`` does. "lower": the
        recovery starts over, the slid foot put down again like a lifted
        one (unweighted, onto ``replant_max_slope``'s nearest gentle
        foothold or straight down); "hold": the recovery starts over with the
        slid foot bearing where it now is, the trunk centred over the
        measured stance; "replant": the trunk moves over the other three
        feet, the slid foot steps onto the nearest gentle foothold (or on
        along its slide onto the first flat ground within 2 cm) and the
        trunk is centred again (:func:`~roughwalk.sim.recovery.replant_segments`;
        "hold" where the other three cannot hold the trunk).
    recovery_slide_drop_m:
        With this [m] > 0, only a foot that has dropped at least this below
        its recovery foothold counts as sliding: one going down a rock's
        face. 0: any motion along the
        ground or down. On flat ground a side push drags feet along the
        ground or leaves a lowered foot short of its foothold, and re-planting
        them there lost pushes main survives (1 N·s right push at 2.0 s: LF
        1.5 cm up and 2.6 cm off, then LH dragged 3 cm; rolled 35° at 3.25 s).
    recentre_steps, recentre_radius_m:
        When the re-plan after a reflex finds no plan from where the feet
        stand (no pose certificate, or no step out of the stance), the
        settled robot steps one foot toward its nominal place under the
        measured trunk and re-plans again, instead of ending the run: the
        foot farthest from its place first, to the foothold within
        ``recentre_radius_m`` [m] of it, at least 1 cm nearer that place,
        from which the planner finds a plan; at most ``recentre_steps``
        such steps per reflex (0: off, the default). On board AE (large
        rocks, the walk's defaults) 2 of the 7 failures of seeds 0–15 end
        with a re-plan that finds no plan (seeds 6, 15), with feet spread
        where a recovery left them. With 2 steps seed 16 walks (1.82 cm/s:
        RH and later LF stepped 4.5 cm toward their places); seeds 6 and
        15 still find no plan from any stance one step makes (session 21).
    max_reflexes:
        Give up (a failed run) after this many reflexes.
    end_at_goal:
        A recovery that settles with the feet's centroid within
        ``outcome.goal_radius_m`` of a goal already reached ends the run
        there instead of re-planning. Off, the robot re-plans from the goal
        and walks on: on board AE (bench large rocks seed 5, ``--expansions
        40000``) a reflex fired 0.1 s before the goal was reached, the
        re-plan stepped on and the next one found RF on no foothold, and
        the run that had reached the goal failed.
    """

    enabled: bool = True
    body_position_m: float = 0.04
    body_orientation_rad: float = 0.15
    foot_position_m: float = 0.02
    foot_force_n: float = 2.0
    foot_force_fraction: float = 0.05
    foot_force_tilt_rad: float = 0.03
    foot_force_per_leg: bool = True
    foot_force_descent_m_s: float = 0.05
    foot_force_descent_n: float = 4.0
    foot_force_descent_lean_m: float = 0.005
    one_sided: bool = False
    one_sided_rate_rad_s: float = 0.2
    one_sided_persist_s: float = 0.01
    one_sided_loaded_n: float = 1.0
    persist_s: float = 0.03
    settle_s: float = 0.3
    settled_rate_rad_s: float = 0.2
    settle_max_s: float = 1.5
    settled_loaded_feet: int = 3
    lower_s: float = 0.5
    capture_max_m: float = 0.04
    catch_nearer: bool = True
    replan_budget_s: float = 2.0
    standing_bear: bool = True
    loaded_window_s: float = 0.0
    replan_nudge_m: float = 0.02
    replan_from_trunk: bool = True
    replan_nudge_any_leg: bool = True
    replant_max_slope: float = 0.5 * math.pi
    replant_snap_m: float = 0.025
    replant_min_m: float = 0.01
    replant_s: float = 0.25
    replant_margin_m: float = 0.015
    replant_certified: bool = True
    recovery_slide_m: float = 0.0
    recovery_slides: int = 2
    recovery_slide_bearing: int = 3
    recovery_slide_response: str = "lower"
    recovery_slide_drop_m: float = 0.0
    recentre_steps: int = 0
    recentre_radius_m: float = 0.05
    max_reflexes: int = 6
    end_at_goal: bool = True

    def __post_init__(self) -> None:
        _positive(
            self,
            (
                "body_position_m",
                "body_orientation_rad",
                "foot_position_m",
                "foot_force_n",
                "lower_s",
                "replan_budget_s",
                "settled_rate_rad_s",
                "replant_max_slope",
                "replant_s",
            ),
            "reflex",
        )
        _nonnegative(
            self,
            (
                "foot_force_fraction",
                "foot_force_tilt_rad",
                "foot_force_descent_m_s",
                "foot_force_descent_n",
                "persist_s",
                "settle_s",
                "capture_max_m",
                "loaded_window_s",
                "one_sided_rate_rad_s",
                "one_sided_persist_s",
                "one_sided_loaded_n",
                "replan_nudge_m",
                "settle_max_s",
                "replant_snap_m",
                "replant_min_m",
                "replant_margin_m",
                "recovery_slide_m",
                "recovery_slide_drop_m",
                "recentre_radius_m",
            ),
            "reflex",
        )
        if not (
            isinstance(self.recentre_steps, int)
            and not isinstance(self.recentre_steps, bool)
            and self.recentre_steps >= 0
        ):
            raise ConfigError(
                f"reflex.recentre_steps must be an integer ≥ 0, got {self.recentre_steps!r}"
            )
        if self.settled_loaded_feet not in (3, 4) or isinstance(self.settled_loaded_feet, bool):
            raise ConfigError(
                f"reflex.settled_loaded_feet must be 3 or 4, got {self.settled_loaded_feet!r}"
            )
        if self.recovery_slide_bearing not in (0, 1, 2, 3) or isinstance(
            self.recovery_slide_bearing, bool
        ):
            raise ConfigError(
                "reflex.recovery_slide_bearing must be 0, 1, 2 or 3, "
                f"got {self.recovery_slide_bearing!r}"
            )
        if self.recovery_slide_response not in RECOVERY_SLIDE_RESPONSES:
            raise ConfigError(
                f"unknown reflex.recovery_slide_response {self.recovery_slide_response!r}; "
                f"known: {', '.join(RECOVERY_SLIDE_RESPONSES)}"
            )
        if not (isinstance(self.recovery_slides, int) and self.recovery_slides >= 0):
            raise ConfigError(
                f"reflex.recovery_slides must be an integer ≥ 0, got {self.recovery_slides}"
            )
        if not (isinstance(self.max_reflexes, int) and self.max_reflexes >= 0):
            raise ConfigError(
                f"reflex.max_reflexes must be an integer ≥ 0, got {self.max_reflexes}"
            )


@dataclass(frozen=True)
class OutcomeConfig:
    """What counts as success and as a fall.

    Attributes
    ----------
    goal_radius_m:
        The run succeeds when the feet's centroid comes within this distance
        [m] (in x–y) of the goal.
    max_roll_rad, max_pitch_rad:
        Trunk roll and pitch beyond these [rad] count as a fall.
    slip_m:
        A supporting foot sliding this far [m] from where it touched down
        counts as one foot slip.
    time_limit_s:
        Simulated time [s] after which an unfinished run fails.
    """

    goal_radius_m: float = 0.06
    max_roll_rad: float = 0.6
    max_pitch_rad: float = 0.6
    slip_m: float = 0.01
    time_limit_s: float = 120.0

    def __post_init__(self) -> None:
        _positive(
            self,
            ("goal_radius_m", "max_roll_rad", "max_pitch_rad", "slip_m", "time_limit_s"),
            "outcome",
        )


RELAX_EDGE_MARGIN = ("all", "replans", "none")
"""Values of :attr:`ExecutorConfig.relax_edge_margin`."""


@dataclass(frozen=True)
class ExecutorConfig:
    """The execution pipeline (Zucker 2011, §6).

    Attributes
    ----------
    compute_time_scale:
        Simulated seconds charged per wall-clock second of on-line planning
        and trajectory optimisation. 1 is real time on this machine (the
        paper's setting: optimisation runs in parallel with execution and a
        late step makes the robot wait); 0 pretends computing is free
        (reproducible runs, independent of the machine's load).
    initial_plan_s:
        Planning time [s] before the clock starts (the trials allowed 90 s;
        the anytime planner improves its plan until then).
    plan_expansions:
        A budget of expanded states for every plan and re-plan, on top of
        the time limits; 0: none. With ``compute_time_scale`` 0 and time
        limits the budget reaches first, a run no longer depends on how
        fast the machine is at the moment (the planner's deterministic
        mode).
    longest_step:
        The footstep planner's longest forward action, as a fraction of the
        robot's hip-to-hip length L; 0 keeps the planner's own action set
        (longest 0.3 L). A value above that adds forward actions of this
        length (sideways −0.1, 0, 0.1 L). In a steady crawl the stride is
        1.6 times the longest action (9.6 cm at 0.3 L on LittleDog, whose
        swings are joint-speed limited at 0.28–0.32 s: longer strides carry
        the feet farther per swing); ``footstep.max_foot_travel`` (0.6 L)
        then grows to 0.88 of the fore–aft span a foot reaches
        (:mod:`roughwalk.sim.stride_reach`; 0.159 m, so 0.14 m on LittleDog;
        to the steady stride, 0.129 m at 0.4 L, before session 24). 0.4 by
        default since session 15, with the fast swing
        options and ``swing.lift_off_reach`` (see
        :class:`~roughwalk.trajectories.config.SwingConfig`'s ``path``); with
        the former "even" swings longer strides lengthened the
        joint-speed-bound swings more than in proportion (demo course, 0.3 → 0.42 L: stride
        9.4 → 11.5 cm, mean swing 0.36 → 0.50 s, 4.67 → 4.50 cm/s), and
        barrier seed 0 fell at 0.42 L (RF's foot-force reflex stepping
        onto the barrier, then a roll over the right feet in the re-plan's
        first swing).
    start_snap_m:
        Where the nominal stance at the start pose puts a foot on no
        foothold (a rock's rim, ``footstep.edge_drop``), that foot is put
        on the nearest foothold within this distance [m] and the plan
        starts from those feet (as a re-plan's feet are snapped); 0: the
        start is refused. Larger puts the robot down farther from its
        nominal stance.
    start_max_slope:
        Steepest slope [rad] (the mean over the foot's disc, as
        ``footstep.max_foothold_slope`` measures it) a foot of the start
        stance may stand on: a steeper one moves onto the nearest foothold
        within ``start_snap_m`` that is not, and the plan starts from
        there. ≥ π/2: only the footstep settings' limit counts. A start
        foot bears load through the first shifts and swings and, as no
        re-plan moves a standing foot, through every recovery after them.
        Board AE, bench large rocks seeds 4 and 6 (``--expansions 40000``):
        RF started on a 41–42° flank beside a 6 cm rim and both runs fell.
        Session 16, 40° against off (``bench_littledog.py``'s runs, one
        process each): large rocks seeds 0–7 4/8 at 5.56 cm/s (14 reflexes)
        → 4/8 at 7.30 (7); seeds 8–15 5/8 at 5.47 → 5/8 at 7.23; logs seeds
        0–5 4/6 at 7.52 → 4/6 at 7.22 (seed 1 lost, 5 gained); round rocks,
        sloped rocks, gap, barrier, steps seeds 0–1 the same runs. Seeds 4
        and 6 still fall: RF, moved 5 mm up the rock, slides off it. With
        ``reflex.foot_position_m`` 0.02: large rocks 10/16 (9 without),
        logs 4/6. Off by default: it buys speed, not yet success.
    refuse_colliding_m:
        When the trajectory generator returns the next footstep colliding
        (its report not collision-free: no timing it tried keeps the legs
        off the terrain), the executor does not walk it: it re-plans from
        the stance the current footstep ends in, with that foothold and
        everything within this radius [m] of it refused to the leg's end
        (``PlanStart.refused``), and blends into the new plan's first
        footstep. 0: the step is walked as it came. On the gap (bench
        seed 0, ``--expansions 40000``) RF's step onto the trench floor 3
        cm past the near wall had its shank 1.6 cm inside the rim at
        touchdown; walked, the shank rested on the rim and a foot-force
        reflex cost 1.1 s (6.51 cm/s); with 3 cm refused the re-planned step
        is valid (7.64 cm/s). 0.03 by default since session 17
        (``bench_littledog.py --expansions 40000 --seeds 6 --jobs 1`` with
        ``reflex.foot_force_descent_n`` 4, main and the branch back to
        back): gap 6/6 at 7.33 → 7.52 cm/s, logs and large rocks every run
        the same, round rocks, sloped rocks, barrier, steps (``--seeds 2``)
        the same runs. The re-plan starts a planner with the refused cells
        and a cold certificate cache: where computing is charged
        (``compute_time_scale``) the robot waits for it at the end of the
        current footstep, up to ``reflex.replan_budget_s`` and the rebuild
        (~0.5 s).
    relax_edge_margin:
        Where the walk's footstep planner, keeping feet
        ``footstep.edge_margin`` > 0 beyond their radius from a rim, finds
        no plan, a second planner with the margin 0 plans from the same
        start (:class:`~roughwalk.sim.footstep_source.PlannerSource`'s
        ``fallback``; the ``plan`` and ``replan`` events say ``relaxed``):
        "all", for the first plan (no start stance it certifies) and for
        re-plans (from where the feet stand, nowhere to step); "replans",
        for re-plans only, where a run's start, like a trial's, is put
        where the walk's own checks find a plan (``roughwalk bench
        littledog`` tries its start nudges so first); "none".
        The margin keeps feet off rims they would land on by a
        touchdown's few millimetres of error, but near rocks it can leave
        a stance no step out of (figures in
        :data:`~roughwalk.sim.footstep_source.EXECUTION_FOOTHOLD_SAFETY`).
    """

    compute_time_scale: float = 1.0
    initial_plan_s: float = 10.0
    plan_expansions: int = 0
    longest_step: float = 0.4
    start_snap_m: float = 0.015
    start_max_slope: float = 0.5 * math.pi
    refuse_colliding_m: float = 0.03
    relax_edge_margin: str = "all"

    def __post_init__(self) -> None:
        _nonnegative(
            self,
            (
                "refuse_colliding_m",
                "compute_time_scale",
                "plan_expansions",
                "longest_step",
                "start_snap_m",
                "start_max_slope",
            ),
            "executor",
        )
        _positive(self, ("initial_plan_s",), "executor")
        if self.relax_edge_margin not in RELAX_EDGE_MARGIN:
            raise ConfigError(
                f"executor.relax_edge_margin must be one of {', '.join(RELAX_EDGE_MARGIN)}, "
                f"got {self.relax_edge_margin!r}"
            )


@dataclass(frozen=True)
class SimConfig:
    """Everything a simulated run takes; see each part's documentation."""

    world: WorldConfig = field(default_factory=WorldConfig)
    controller: ControllerConfig = field(default_factory=ControllerConfig)
    integrator: IntegratorConfig = field(default_factory=IntegratorConfig)
    touchdown: TouchdownConfig = field(default_factory=TouchdownConfig)
    lift_gate: LiftGateConfig = field(default_factory=LiftGateConfig)
    stabilizer: StabilizerConfig = field(default_factory=StabilizerConfig)
    reflex: ReflexConfig = field(default_factory=ReflexConfig)
    outcome: OutcomeConfig = field(default_factory=OutcomeConfig)
    executor: ExecutorConfig = field(default_factory=ExecutorConfig)
