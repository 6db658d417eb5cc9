"""The trajectory optimiser's configuration: frozen dataclasses whose fields state their units.

Two presets cover the papers:

* :func:`melon_config` (the default): TOWR's constraints plus Melon et al.'s
  additions (base above the feet, swing height and apex), the legs' reach
  ball, and analytic costs
  (Melon 2020, §III-A);
* :func:`towr_config`: TOWR 1.4's default problem, a pure feasibility problem
  with its constraints only and its ANYmal parameters, so that timings can be
  compared with TOWR's on the identical problem.

Change any field with :func:`roughwalk.config.override` and dotted keys
(``costs.force.weight=0``, ``solver.hessian=limited-memory``).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

from roughwalk.errors import ConfigError

__all__ = [
    "IntegralCost",
    "CostWeights",
    "TerrainModelConfig",
    "SolverOptions",
    "GuessProjection",
    "TrajoptConfig",
    "TOWR_CONSTRAINTS",
    "MELON_CONSTRAINTS",
    "MELON_REACH_CONSTRAINTS",
    "melon_config",
    "towr_config",
]

TOWR_CONSTRAINTS: tuple[str, ...] = (
    "terrain",
    "dynamics",
    "base_acceleration",
    "range_of_motion",
    "force",
    "total_duration",
    "initial_state",
    "goal_state",
)
"""TOWR 1.4's default constraint set (``Parameters()`` plus the start and goal bounds)."""

MELON_CONSTRAINTS: tuple[str, ...] = (
    *TOWR_CONSTRAINTS,
    "base_above_feet",
    "swing_height",
    "swing_apex",
)
"""TOWR's constraints plus Melon et al.'s base-above-feet and swing-height ones and a swing apex."""

MELON_REACH_CONSTRAINTS: tuple[str, ...] = (*MELON_CONSTRAINTS, "leg_reach")
_COMPILED_MODES = ("off", "on", "auto")
""":data:`MELON_CONSTRAINTS` plus the legs' real reach (a ball per leg, for bodies that know it).

The default set of :func:`melon_config`: plans made with it keep every
stance foot within reach of the planned base (single pallet: 0.1 % of 10 ms
samples out of reach against 39 % with the box alone), and the shipped
learned initialisers are trained on it. ``melon_config(constraints=
MELON_CONSTRAINTS)`` gives the box alone.
"""


@dataclass(frozen=True)
class IntegralCost:
    """Weights of one of Melon et al.'s integral costs (Eq. 1).

    J = ω ∫₀ᵀ ((x(t) − x_ref)² + ω_d ẋ(t)²) dt. A weight of 0 removes the cost.

    Attributes
    ----------
    weight:
        ω: how much the cost counts in the objective. Larger values make the
        motion smoother in this quantity at the price of more iterations.
    derivative_weight:
        ω_d [s²]: weight of the squared time derivative relative to the value;
        larger values penalise short, sharp changes.

    """

    weight: float = 0.0
    derivative_weight: float = 0.0

    def __post_init__(self) -> None:
        if not (self.weight >= 0 and self.derivative_weight >= 0):
            raise ConfigError(
                f"cost weights must be ≥ 0, got weight={self.weight}, "
                f"derivative_weight={self.derivative_weight}"
            )


@dataclass(frozen=True)
class CostWeights:
    """Melon et al.'s analytic costs (§III-A); forces enter divided by m·g.

    Attributes
    ----------
    base_vertical_velocity:
        On ż [m/s] and z̈: damps bouncing of the base.
    base_angular_velocity:
        On the Euler rates (roll, pitch, yaw) [rad/s] and their derivatives:
        damps rolling and pitching, which the tracking controller handles badly.
    force:
        On every contact force component f/(m·g) and its derivative: lowers
        peak forces and their rates.
    normal_force:
        On (f·n − f_ref)/(m·g) during stance, with f_ref = m·g / (feet in
        stance): keeps the weight shared evenly.
    step_edge:
        Weight of the Gaussian step-edge cost exp(−x_s²/2σ²) per foothold.
    step_edge_sigma:
        σ [m] of that Gaussian: how far from an edge a foothold is still pushed away.
    swing_height:
        Weight [1/m²] on (apex height − mean height of the two footholds)²:
        keeps steps low (the swing-height constraint keeps them high enough).
    force_between_nodes_penalty:
        Weight of the squared violation of the friction pyramid and force
        bounds at the force segments' inner control points, divided by m·g
        (:mod:`~roughwalk.trajopt.costs.force_between_nodes_penalty`): the
        soft form of the ``force_between_nodes`` rows. 0 (off) by default.

    """

    base_vertical_velocity: IntegralCost = field(default_factory=lambda: IntegralCost(1.0, 0.01))
    base_angular_velocity: IntegralCost = field(default_factory=lambda: IntegralCost(0.5, 0.01))
    force: IntegralCost = field(default_factory=lambda: IntegralCost(0.05, 0.001))
    normal_force: IntegralCost = field(default_factory=lambda: IntegralCost(0.05, 0.0))
    step_edge: float = 1.0
    step_edge_sigma: float = 0.05
    swing_height: float = 5.0
    force_between_nodes_penalty: float = 0.0

    def __post_init__(self) -> None:
        if self.step_edge < 0 or self.swing_height < 0 or self.force_between_nodes_penalty < 0:
            raise ConfigError(
                f"cost weights must be ≥ 0, got step_edge={self.step_edge}, "
                f"swing_height={self.swing_height}, "
                f"force_between_nodes_penalty={self.force_between_nodes_penalty}"
            )
        if not self.step_edge_sigma > 0:
            raise ConfigError(f"step_edge_sigma must be > 0 m, got {self.step_edge_sigma}")

    @classmethod
    def none(cls) -> CostWeights:
        """No cost at all: TOWR's pure feasibility problem."""
        zero = IntegralCost(0.0, 0.0)
        return cls(zero, zero, zero, zero, 0.0, 0.05, 0.0)


@dataclass(frozen=True)
class TerrainModelConfig:
    """How the terrain becomes a smooth, differentiable surface for the NLP.

    Attributes
    ----------
    resolution:
        Spacing [m] of the B-spline's control points. Finer follows the
        terrain more closely; coarser smooths steps into wider ramps.
    smoothing:
        σ [m] of the Gaussian blur applied before fitting; 0 keeps the raw
        resampled heights (steps then ring less than they would with an
        interpolating spline, since the control points are the heights).
    edge_slope:
        Slope (rise over run) above which a cell counts as part of an edge
        for the step-edge cost.

    """

    resolution: float = 0.02
    smoothing: float = 0.01
    edge_slope: float = 1.0

    def __post_init__(self) -> None:
        if not self.resolution > 0:
            raise ConfigError(f"terrain.resolution must be > 0 m, got {self.resolution}")
        if self.smoothing < 0:
            raise ConfigError(f"terrain.smoothing must be ≥ 0 m, got {self.smoothing}")
        if not self.edge_slope > 0:
            raise ConfigError(f"terrain.edge_slope must be > 0, got {self.edge_slope}")


WARM_START_OPTIONS: tuple[str, ...] = (
    "warm_start_init_point=yes",
    "mu_init=1e-6",
    "warm_start_bound_push=1e-9",
    "warm_start_bound_frac=1e-9",
    "warm_start_slack_bound_push=1e-9",
    "warm_start_slack_bound_frac=1e-9",
    "warm_start_mult_bound_push=1e-9",
)
"""IPOPT's options for a restart from a previous solution (see ``SolverOptions``)."""

GUESS_START_OPTIONS: tuple[str, ...] = (
    "warm_start_init_point=yes",
    "mu_oracle=quality-function",
    "warm_start_bound_push=1e-5",
    "warm_start_bound_frac=1e-5",
    "warm_start_slack_bound_push=1e-2",
    "warm_start_slack_bound_frac=1e-2",
    "warm_start_mult_bound_push=1e-5",
    "mumps_scaling=0",
    "mumps_permuting_scaling=0",
    "fast_step_computation=yes",
)
"""IPOPT's options for a start from predicted multipliers (see ``SolverOptions``)."""


@dataclass(frozen=True)
class SolverOptions:
    """IPOPT's settings and the solve's termination conditions.

    Attributes
    ----------
    max_iter:
        Iteration limit per solve; reaching it gives status ITERATION_LIMIT.
    time_limit_s:
        Wall-time limit [s] per solve (TOWR's ROS app uses 40 s of CPU time).
    hessian:
        "exact" (second derivatives), "limited-memory" (L-BFGS, as TOWR's
        ifopt) or "auto": exact when the NLP has costs, L-BFGS otherwise.
        L-BFGS solves TOWR's feasibility problems in fewer, cheaper
        iterations (exact takes 2–5× as many: block 1.5 m 195 against 67,
        gap trot 112–132 against 25).
        With costs it converges slowly or not at all: on flat ground (trot)
        it stops at the 40 s limit after ~500 iterations where exact takes
        25, and with optimised
        durations on the single pallet it leaves the dynamics violated by
        0.02 after 400 iterations where exact converges in 93, after a
        build of ~10 s of CPU (the durations make the Hessian dense).
    tol:
        IPOPT's convergence tolerance on the scaled NLP error.
    acceptable_tol:
        IPOPT's "acceptable" tolerance; a solve stuck there for a few
        iterations ends with status APPROXIMATE.
    constr_viol_tol:
        Largest constraint violation a converged solution may have (in the
        constraints' own units: m, m/s², N, ...).
    linear_solver:
        IPOPT's linear solver ("mumps" ships with CasADi).
    mumps_pivot_order:
        MUMPS's fill-reducing ordering (its ICNTL(7): 0 AMD, 2 AMF, 4 PORD,
        5 METIS, 6 QAMD, 7 automatic). None picks AMD with the exact
        Hessian (Melon's costs). With optimised durations the linear solves
        on the single pallet took 113 ms an iteration with AMD, 165 with
        METIS and 242 with the automatic choice (12.1, 15.7 and 23.5 s of
        CPU in all, 107, 95 and 97 iterations); with fixed durations, from
        the heuristic guess, the same iterations and costs took 0.71–0.73 s
        of CPU against 0.78–0.79 on the single pallet 1.0 m before its edge
        (41 iterations), 2.80–2.98 against 3.11–3.52 on the double pallet
        (88), 0.70–0.73 against 0.72–0.73 from 1.5 m before (31); three
        interleaved pairs, load 10–12. With L-BFGS (TOWR's problems) it
        picks METIS when phase durations are optimised — their columns are
        dense, and METIS factorises those KKT systems in about half the time
        of MUMPS's automatic choice — and the automatic choice otherwise,
        where no ordering was faster and the ordering changes the
        iterations (below).
    mumps_scaling:
        Whether MUMPS scales the KKT system's rows and columns (IPOPT's
        ``mumps_scaling`` and ``mumps_permuting_scaling``). None: off with
        the exact Hessian, on with L-BFGS. Measured from the heuristic guess
        (CPU time, warm solves): with Melon's costs and the exact Hessian,
        scaling off takes the same iterations on flat ground and the single
        pallet, 8–18 % less CPU, and the double pallet in 88 iterations
        instead of 156; on TOWR's cost-free problems with L-BFGS, scaling off
        takes the 1.0 m block from 51 to 283 iterations and the 1.5 m one
        from 67 to 1394.
    print_level:
        IPOPT's verbosity (0 silent, 5 per iteration).
    ipopt_options:
        Further IPOPT options as "name=value" strings (numbers are converted),
        e.g. ("mu_strategy=adaptive",).
    fixed_durations_ipopt_options:
        IPOPT options, on top of ``ipopt_options``, of a problem whose phase
        durations are fixed (``optimize_durations`` false); chosen when the
        solver is built, so a config changed to optimise durations after it
        was made does not carry them (see :func:`towr_config`).
    warm_ipopt_options:
        IPOPT options, on top of the others, of a solve restarted from a
        previous solution and its multipliers (``warm_start=``): IPOPT's warm
        start, with the point and multipliers barely pushed off their bounds,
        so that a solution is recognised in one or two iterations.
    guess_ipopt_options:
        IPOPT options, on top of the others, of a solve from a predicted guess
        with predicted multipliers (the learned initialiser). Measured on
        held-out single-pallet tasks from the learned guess: with the warm
        options above the median was 19.5 iterations, with these (pushes
        1e-5, quality-function barrier oracle) 14–16; larger pushes (1e-2)
        on everything double it. The slacks of the inequality rows alone
        start 1e-2 inside their bounds: on 50 held-out single-pallet tasks
        (exact Hessian) the iterations went from 876 (median 16) with 1e-5 to
        789 (14) with 1e-3, 762 (13) with 1e-2, 785 with 3e-2 and 823 with
        1e-1, every task to the same cost; the variables' push made no
        difference at 1e-3 and the multipliers' (1e-3) cost 15 % more.
        From an exact solution they take 2–5 iterations (2 with the slacks'
        push at 1e-5, on 5 single-pallet tasks) where the warm options
        take 1, and on TOWR's cost-free problem (L-BFGS) 12 where
        those take 1: a guess is not a solution. MUMPS's row/column scaling
        is off in them: on 30 held-out tasks the iterations were identical and
        the CPU time per iteration 13 % lower (interleaved runs). Their MUMPS
        ordering is ``mumps_pivot_order``'s: on 12 held-out single-pallet
        tasks (exact Hessian, fixed durations, same 177 iterations) AMD took
        21.0–21.6 ms of CPU an iteration against 22.2–23.9 for the
        automatic choice (four interleaved pairs), QAMD 22.5, AMF 23.4,
        PORD 23.5, METIS 33.4. With L-BFGS the ordering changes the
        iterations: TOWR's walk from its own solution took 18 with AMD and
        3 with the automatic choice, which L-BFGS keeps.
        ``fast_step_computation=yes`` (no residual check of the KKT solve) is
        on: the same iterations and costs on every task measured (50 held-out
        single-pallet tasks: 626 iterations either way, median CPU 0.276 s
        against 0.296; 8 double-pallet: 625, 2.74 against 2.93; 20 flat with
        the option below as well: 200, 0.196 against 0.213; paired per task,
        interleaved in one process).
        ``adaptive_mu_globalization=never-monotone-mode`` (the adaptive
        barrier update never falls back to the monotone one) is not: alone
        it took the 50 single-pallet tasks in 609 iterations, with the
        option above 200 of them in 2781 (median 12) against 2855 (13),
        median CPU 0.275 s against 0.307, the same
        196 converged to the same costs, but on the double pallet the solves
        that fail either way (5 of 8, the weak model) took 86 ms an
        iteration against 39, one stopped by the 40 s limit; from the
        heuristic guess the pair saved iterations (626 against 686 on 12
        tasks) with one ending 1 % dearer. Measured and not kept (30 tasks,
        same order, median iterations / ms of CPU an iteration; base
        11.5 / 24.8): the monotone update with ``mu_init`` 1e-3…1e-6 18 / 22.7 … 12.5 / 24.6
        with one task unconverged below 1e-4; ``mu_oracle`` loqo 15 / 23.1,
        probing 13 / 24.1; ``quality_function_max_section_steps`` 2 and 0
        12 / 24.6 and 14 / 24.2; ``min_refinement_steps=0`` on top 11 / 23.5
        (no gain). The barrier update's share of IPOPT's time is the KKT
        factorisation done there first, not the oracle: other oracles
        move it, they do not remove it. SPRAL (linked in CasADi's IPOPT,
        ``linear_solver=spral``, one thread) took 172 ms an iteration.

    Neither set applies to a solve from a guess without multipliers (the
    heuristic's cold solves).
    guess_fallback_after:
        Iterations a solve from a learned guess gets before it falls back
        to the initialiser's second guess (the model's network guess where
        the first was its solution library's pick): a solve not converged by
        then, or ended unconverged before (infeasible, failed), is restarted
        from the fallback with what is left of ``max_iter`` and
        ``time_limit_s``; the result reports both solves' iterations and
        time. None never restarts. A library pick can sit in a basin IPOPT
        does not leave: on 200 held-out single-pallet tasks two stopped at
        100 iterations where the network's guess converged in 12 and 37,
        while 196 of the 197 that converged did so within 30 iterations
        (the last in 63). Lower, a slow but converging pick is cut short;
        higher, a stuck one costs more before the restart. Measured at 40
        on those 200 (limit 100, same code with None): 199 converged
        against 197 (104 in 52 iterations at cost 1.332, 142 in 84 at
        5.682), 6 beyond their task's g_max against 7, 26 beyond the global
        one against 27, 2849 iterations in all against 2850 (median 13
        both): two slow picks restarted, one sooner (59 → 54), one later
        (43 → 95, same cost); 189 ends infeasible either way. The 12 timed
        tasks never restart: median 0.220–0.221 s of CPU, 10 iterations,
        against 0.218–0.227 without the fallback (main, interleaved).
        Raised from 40 to 50 with ``dear_guess_restarts``: a pick cut while
        converging leaves the further starts no iterations. Held-out task
        102's pick converges in 43 iterations (3.306, above its g_max
        2.995); cut at 40, the network's guess took 55 more to the same
        cost; at 50 a further start reaches 2.508 (62 in all). Only solves
        not converged by 40 change (4 of the 200: 100, 102, 104, 142); the
        stuck picks 104 and 142 pay 10 iterations more before restarting.
    dear_guess_restarts:
        Further starts a converged solve from a learned guess gets when its
        cost lies above the initialiser's cost limit (a learned model's
        per-task g_max, where the poor local minima begin), each with what
        is left of ``max_iter`` and ``time_limit_s``; it stops at the first
        start that ends below the limit, and the cheapest converged solve
        is kept. The starts are the model's other library candidates,
        nearest task first. 0 never restarts. Neighbouring tasks'
        solutions lie in different basins: held-out single-pallet tasks
        58, 72 and 102 end 32–36 % above the best cost found from the
        library's pick (and from the network's own guess), and the 4th,
        2nd and 3rd nearest task's solution reach it in 18, 8 and 18
        iterations. Solves below their limit (the median task) never
        restart; more starts cost iterations on the few that do. Measured
        on the 200 held-out tasks (limit 100, with ``guess_fallback_after``
        50): beyond the per-task g_max 5 → 2 of 199 (task 189 aside, now
        refused; 58, 72 and 102 mended; 45 and 142 not: no candidate gets
        below their limits), 2849 → 2915 iterations in all, median 13
        both; the 12 timed tasks never restart. The mended tasks used 1–2
        further starts.

    """

    max_iter: int = 3000
    time_limit_s: float = 40.0
    hessian: str = "auto"
    tol: float = 1e-6
    acceptable_tol: float = 1e-4
    constr_viol_tol: float = 1e-4
    linear_solver: str = "mumps"
    mumps_pivot_order: int | None = None
    mumps_scaling: bool | None = None
    print_level: int = 0
    ipopt_options: tuple[str, ...] = ()
    fixed_durations_ipopt_options: tuple[str, ...] = ()
    warm_ipopt_options: tuple[str, ...] = WARM_START_OPTIONS
    guess_ipopt_options: tuple[str, ...] = GUESS_START_OPTIONS
    guess_fallback_after: int | None = 50
    dear_guess_restarts: int = 3

    def __post_init__(self) -> None:
        for field_name in (
            "ipopt_options",
            "fixed_durations_ipopt_options",
            "warm_ipopt_options",
            "guess_ipopt_options",
        ):
            for item in getattr(self, field_name):
                if "=" not in item:
                    raise ConfigError(f"solver.{field_name} entries are name=value, got {item!r}")
        if self.hessian not in ("auto", "exact", "limited-memory"):
            raise ConfigError(
                f"solver.hessian must be 'auto', 'exact' or 'limited-memory', got {self.hessian!r}"
            )
        if self.max_iter < 0:
            raise ConfigError(f"solver.max_iter must be ≥ 0, got {self.max_iter}")
        if self.guess_fallback_after is not None and self.guess_fallback_after < 1:
            raise ConfigError(
                "solver.guess_fallback_after must be ≥ 1 or None (never restart), "
                f"got {self.guess_fallback_after}"
            )
        if self.dear_guess_restarts < 0:
            raise ConfigError(
                f"solver.dear_guess_restarts must be ≥ 0 (0: never), got {self.dear_guess_restarts}"
            )
        if self.mumps_pivot_order not in (None, 0, 2, 4, 5, 6, 7):
            raise ConfigError(
                "solver.mumps_pivot_order must be None, 0, 2, 4, 5, 6 or 7, "
                f"got {self.mumps_pivot_order!r}"
            )
        if not self.time_limit_s > 0:
            raise ConfigError(f"solver.time_limit_s must be > 0 s, got {self.time_limit_s}")


@dataclass(frozen=True)
class GuessProjection:
    """Moving the initial guess onto the linearised rows before IPOPT (:mod:`.guess_projection`).

    Attributes
    ----------
    steps:
        Gauss–Newton projection steps (0: IPOPT starts from the guess as
        made). Each costs one constraint Jacobian and one sparse QP (on the
        16-step double-pallet walk 1.5–2.7 s of CPU, mostly proxqp's). 0 by default:
        on 30 held-out double-pallet tasks it tracked no more often (session
        12, docs/measurements.md).
    between_nodes:
        Also keep the forces unilateral and inside the friction pyramid at
        the inner Bézier control points of every stance force segment (the
        rows of ``force_between_nodes``), whether or not the NLP has them.
    base_position_m, base_velocity_m_s, base_angle_rad, base_rate_rad_s,
    foot_position_m, foot_velocity_m_s, force_n, force_rate_n_s, duration_s:
        σ of each kind of variable: how far [its unit] it moves for one unit
        of cost. Small σ keeps that part of the guess; large σ lets it give
        way. The forces, the guess's worst part, give way most.
    row_weight:
        ρ: the cost of a unit of violation of a row (in the step's σ units)
        against one unit of step. Large is nearly hard; the slack only keeps
        the programme feasible where linearised rows contradict each other.
    left_out:
        Names of the NLP's constraints the projection does not move onto
        (their rows are left as the guess has them).
    tolerance:
        The QP solver's absolute tolerance (in σ units): coarser is faster;
        the next IPOPT iteration (or the controller) needs no more.
    """

    steps: int = 0
    between_nodes: bool = True
    base_position_m: float = 0.01
    base_velocity_m_s: float = 0.05
    base_angle_rad: float = 0.01
    base_rate_rad_s: float = 0.05
    foot_position_m: float = 0.005
    foot_velocity_m_s: float = 0.05
    force_n: float = 50.0
    force_rate_n_s: float = 500.0
    duration_s: float = 0.01
    row_weight: float = 1e4
    tolerance: float = 1e-4
    left_out: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        if not (isinstance(self.steps, int) and self.steps >= 0):
            raise ConfigError(f"guess_projection.steps must be an integer ≥ 0, got {self.steps!r}")
        for name in tuple(self.__dataclass_fields__)[2:-1]:
            v = getattr(self, name)
            if not v > 0:
                raise ConfigError(f"guess_projection.{name} must be > 0, got {v!r}")


@dataclass(frozen=True)
class TrajoptConfig:
    """Everything that defines the NLP and its solve (TOWR's ``Parameters`` and more).

    Attributes
    ----------
    gait:
        Contact schedule: "walk", "trot", "pace", "bound" or "gallop".
    steps:
        Number of swings of all feet together (16 is TOWR's walk, 14 Melon's trot).
    duration:
        Total duration T [s]. Longer gives slower, easier motions.
    optimize_durations:
        Optimise the phase durations (adds one variable per phase and foot
        but the last): more freedom, but every sample may fall in any
        polynomial, which makes the NLP dense — slower iterations and, with
        costs, a costly exact Hessian: on the single pallet with Melon's
        costs it takes ~10 s of CPU to build and the solve 93 iterations
        (L-BFGS does not converge there). Off by default, as in TOWR; Melon
        et al. found fixed durations more reliable too (Fig. 8).
    phase_duration_bounds:
        (min, max) [s] of an optimised phase (TOWR's 0.2–1.0 s).
    phase_bounds_admit_gait:
        Widen each optimised phase's bounds to admit its own duration in the
        gait: [min(min, max(d − 0.01 s, d / 2)), min(max(max, d + 0.01 s), T)]
        with d that phase's gait duration and T the total (others keep
        ``phase_duration_bounds``; the
        0.01 s keeps IPOPT's bound push from moving a phase that would sit
        on its bound). The 16-step walk in 5.5 s
        and the double pallet's 20 steps in 6.875 s give the front-right
        foot a first stance of 1.079 / 1.098 s, beyond TOWR's 1.0 s: without
        this option the NLP starts from a schedule fitted into the bounds (and
        ``learned_fixed_durations`` clamps that stance), so a
        fixed-duration guess no longer holds its nodes at their times;
        here the gait itself is a feasible schedule and no other phase's
        bound moves (unlike a wider ``phase_duration_bounds``); at 0
        iterations the plan is then the fixed-duration one to 1e-12. On by
        default since session 26, with the double pallet's torque-feasible
        model (its corner-grown retraining): from ``learned_fixed_durations``
        on held-out seeds 0–3 it tracks 120/120 at 0 iterations and 118/120
        at 5 (off: 115/120 at 5 with that model; the former model 117/120
        either way), single pallet seeds 0–2 90/90 at 0 and at 5 (sessions
        20–21); Melon's single pallet 1.0 m before with optimised durations
        (``bench_trajopt.py``) solves in 112 iterations to cost 1.125 (off:
        101, 1.143); the single pallet's optimised-duration model
        (trained under TOWR's bounds) tracks 5/30 and 10/30 on seed 0 at 0
        and 5 iterations (off: 6/30, 10/30). It changes nothing with fixed
        durations. Off in
        :func:`towr_config` (TOWR's own bounds): the 16-step walk in 3.5 s
        has phases of 0.157 and 0.199 s, whose lowered bounds took TOWR's
        block 1.5 m with optimised durations from 49 to 635 iterations (2.5 →
        30.6 s CPU) and the stairs 1.0 m from 40 to 231 (both still solved).
    body_model:
        "robot" (single rigid body from the Robot's model) or "towr_anymal"
        (TOWR's published ANYmal values).
    base_poly_duration:
        Duration [s] of one polynomial of the base splines; shorter means more
        variables and a finer dynamics check.
    foot_polys_per_swing:
        Polynomials per swing phase of a foot's motion (2: lift and land).
    force_polys_per_stance:
        Polynomials per stance phase of a foot's force (3).
    dt_dynamics:
        Interval [s] between the samples where the dynamics are enforced.
    dt_range_of_motion:
        Interval [s] between the samples of the range-of-motion and
        base-above-feet constraints.
    constraints:
        Names of the constraints to use (see :mod:`roughwalk.trajopt.constraints`).
        ``force_between_nodes`` (opt-in, appended last) keeps the forces
        unilateral and inside the friction pyramid between the force nodes too.
        ``joint_torques`` (opt-in) bounds the joint torques the stance
        forces ask of the legs (:mod:`~roughwalk.trajopt.constraints.joint_torques`).
    joint_torque_margin:
        Share of each joint's torque limit the ``joint_torques`` rows allow
        (1 the full limit). Below 1 leaves the tracking controller torque
        for the legs' own weight and its feedback, at the price of plans
        that lean on fewer, more evenly loaded legs (or none at all).
    dt_joint_torques:
        Interval [s] between the samples of the ``joint_torques`` rows
        (12 rows per sample). Shorter bounds the torques between samples
        more tightly at the price of more rows.
    costs:
        Cost weights (:class:`CostWeights`).
    swing_clearance:
        Height [m] of a swing's apex above both of its footholds (Melon's
        swing-height constraint).
    base_clearance:
        Least height of the base above every foot (Melon's base-above-feet
        constraint), as a fraction of the nominal base height.
    swing_base_clearance:
        The same least height above a foot while it swings (None: as
        ``base_clearance``), as a fraction of the nominal base height; with
        optimised durations every foot counts as in stance. Lower lets the
        trunk stay low while a front foot swings up a step and the hind feet
        still stand below it, at the price of a swing foot nearer the trunk.
        With the ``joint_torques`` rows on the double pallet it decides
        whether they converge (see
        :mod:`~roughwalk.trajopt.constraints.joint_torques`): at 0.7 none of
        18 near held-out tasks did, at 0.5 15 of 18. Without the rows, from
        the learned guess (≤ 700 iterations), the same 18 tasks converge 17
        times at 0.5 against 10 at 0.7 (median 90 against 48 iterations
        where converged; 2.5 against 5.6 s of CPU a solve) and their plans
        track 18 against 8 times,
        asking 108–196 N·m of a joint (0.7: 261–592 where converged). The
        double pallet's walk (its task space) uses 0.5, and its 20-step model
        is trained there. None by default: the single-pallet and flat models
        were trained at 0.7 and a model is refused at another clearance (at
        0.5 with their weights they track as at 0.7: 8/10 and 10/10 at 0 and
        5 iterations on the single pallet, 10/10 and 10/10 on flat ground).
    init:
        Initial guess: "heuristic", "footsteps:PLAN.json" or "learned"
        ("heuristic:even" keeps Melon's evenly spaced footholds on level
        ground too; see :class:`~roughwalk.trajopt.HeuristicInitializer`).
    terrain:
        Terrain smoothing (:class:`TerrainModelConfig`).
    solver:
        IPOPT settings and limits (:class:`SolverOptions`).
    guess_projection:
        Whether and how the initial guess is moved onto the linearised
        constraints before IPOPT starts (:class:`GuessProjection`).
    sample_rate_hz:
        Rate [Hz] at which results sample the trajectories for JSON output.
    compiled:
        Where the NLP's functions come from (the on-disk cache,
        ``roughwalk cache``): "off" builds CasADi expressions in every
        process and stores nothing; "auto" loads them from the cache —
        compiled to C (:mod:`.compiled_nlp`) or in CasADi's serialised form
        (:mod:`.serialized_nlp`) — and on a miss builds them and stores the
        serialised form (no compiler; 0.13–1.2 s of writing, 15–95 MB an
        entry); "on" compiles a miss with gcc instead (seconds to minutes; a
        structure gcc cannot compile is serialised). A compiled hit skips
        the whole build (TOWR's flat trot: 0.3 s of CPU), a serialised one
        a fifth to two fifths of it; the solve is the same. "off" is the
        default because a miss costs more than a build.

    """

    gait: str = "walk"
    steps: int = 16
    duration: float = 5.5
    optimize_durations: bool = False
    phase_duration_bounds: tuple[float, float] = (0.2, 1.0)
    phase_bounds_admit_gait: bool = True
    body_model: str = "robot"
    base_poly_duration: float = 0.1
    foot_polys_per_swing: int = 2
    force_polys_per_stance: int = 3
    dt_dynamics: float = 0.1
    dt_range_of_motion: float = 0.08
    constraints: tuple[str, ...] = MELON_REACH_CONSTRAINTS
    joint_torque_margin: float = 1.0
    dt_joint_torques: float = 0.04
    costs: CostWeights = field(default_factory=CostWeights)
    swing_clearance: float = 0.08
    base_clearance: float = 0.7
    swing_base_clearance: float | None = None
    init: str = "heuristic"
    terrain: TerrainModelConfig = field(default_factory=TerrainModelConfig)
    solver: SolverOptions = field(default_factory=SolverOptions)
    guess_projection: GuessProjection = field(default_factory=GuessProjection)
    sample_rate_hz: float = 100.0
    compiled: str = "off"

    def __post_init__(self) -> None:
        if self.compiled not in _COMPILED_MODES:
            raise ConfigError(
                f"compiled must be one of {', '.join(_COMPILED_MODES)}, got {self.compiled!r}"
            )
        lo, hi = self.phase_duration_bounds
        if not 0 < lo < hi:
            raise ConfigError(
                f"phase_duration_bounds must be 0 < min < max [s], got {self.phase_duration_bounds}"
            )
        for name in (
            "base_poly_duration",
            "dt_dynamics",
            "dt_range_of_motion",
            "dt_joint_torques",
            "sample_rate_hz",
            "joint_torque_margin",
        ):
            if not getattr(self, name) > 0:
                raise ConfigError(f"{name} must be > 0, got {getattr(self, name)}")
        for name in ("foot_polys_per_swing", "force_polys_per_stance"):
            if getattr(self, name) < 1:
                raise ConfigError(f"{name} must be ≥ 1, got {getattr(self, name)}")
        if self.swing_clearance < 0 or self.base_clearance < 0:
            raise ConfigError(
                f"swing_clearance and base_clearance must be ≥ 0 m, got "
                f"{self.swing_clearance}, {self.base_clearance}"
            )
        if self.swing_base_clearance is not None and self.swing_base_clearance < 0:
            raise ConfigError(
                f"swing_base_clearance must be ≥ 0 or None, got {self.swing_base_clearance}"
            )
        if len(set(self.constraints)) != len(self.constraints):
            raise ConfigError(f"constraints are listed twice: {self.constraints}")

    def structure_key(self) -> tuple[object, ...]:
        """The fields that change the NLP's structure (not the task, guess or solve limits)."""
        return tuple(
            getattr(self, f)
            for f in (
                "optimize_durations",
                "phase_duration_bounds",
                "phase_bounds_admit_gait",
                "body_model",
                "base_poly_duration",
                "foot_polys_per_swing",
                "force_polys_per_stance",
                "dt_dynamics",
                "dt_range_of_motion",
                "constraints",
                "joint_torque_margin",
                "dt_joint_torques",
                "costs",
                "swing_clearance",
                "base_clearance",
                "swing_base_clearance",
                "terrain",
                "guess_projection",
            )
        ) + (
            self.solver.hessian,
            self.solver.tol,
            self.solver.acceptable_tol,
            self.solver.constr_viol_tol,
            self.solver.linear_solver,
            self.solver.mumps_pivot_order,
            self.solver.mumps_scaling,
            self.solver.print_level,
            # IPOPT's options are fixed when the solver is built, so a cached problem
            # built with other options must not be reused.
            self.solver.ipopt_options,
            self.solver.warm_ipopt_options,
            self.solver.guess_ipopt_options,
        )


def melon_config(**changes: object) -> TrajoptConfig:
    """Melon et al.'s formulation: TOWR's constraints, their additions and analytic costs.

    IPOPT's adaptive barrier update solves the pallet climbs in a third of
    the iterations of its default monotone one.
    """
    base = TrajoptConfig(solver=SolverOptions(ipopt_options=("mu_strategy=adaptive",)))
    return replace(base, **changes)  # type: ignore[arg-type]


def towr_config(**changes: object) -> TrajoptConfig:
    """TOWR 1.4's default problem: its constraints, no cost, its ANYmal parameters.

    IPOPT's tolerances are TOWR's (IPOPT's defaults: tol 1e-8, acceptable_tol
    1e-6, constr_viol_tol 1e-4), so that timings compare like with like.

    Compared with TOWR's problem element by element (session 7): the same
    variables (848 at T = 3.4 s), rows in the same units (N, N·m, m, m/s²),
    no variable bounds besides TOWR's on the start and goal, IPOPT's options alike (with
    L-BFGS IPOPT switches both to its adaptive barrier update). Kept on
    purpose: the start and goal are rows reading the task parameters, not
    variable bounds, so that one NLP serves every task; TOWR's duplicate
    rows (each stance's terrain row twice, a second dynamics sample at T)
    are left out; the initial guess is Melon's heuristic, not TOWR's
    node-index interpolation (feet straight from start to goal, through a
    block; m·g/4 on every stance force node). Neither TOWR's guess nor the
    bounds reduce the iterations over TOWR's tasks: with the goals moved
    by −0.1 to +0.1 m (5 solves a task, medians) the heuristic with rows
    took 11 (flat walk), 20 (flat trot), 75 (block 1.5 m), 17 and 43
    (stairs 1.5 and 1.0 m), 27 (gap trot) and 38 (slope) iterations; TOWR's
    guess with bounds 14, 17, 26, 26, 34, 56 and 23; either change alone
    won on some tasks and lost on others. One task's count is a sample of
    that spread (flat trot 11–29, block 1.5 m 60–106), which holds TOWR's
    13 and 22–64. Since session 11 the heuristic puts each foothold on
    level ground under the base at the middle of its stance (see
    :class:`~roughwalk.trajopt.HeuristicInitializer`): the flat trot over
    the goals 1.4–1.6 m took 8, 11, 11, 8, 12 iterations (was 15, 11, 22,
    21, 12); the tasks on uneven ground are unchanged.

    One IPOPT option differs from TOWR's: no NLP scaling
    (``nlp_scaling_method=none``; IPOPT's default divides rows whose gradient
    exceeds 100 — the dynamics rows in N and N·m — and that shrinks the
    steps IPOPT takes on them). It tightens, not loosens, convergence: the
    tolerances then hold on the unscaled rows. Over the five goals 1.4–1.6 m
    (session 8) it took the flat trot from 20 to 15 iterations (median; 99
    to 81 in total) and block 1.5 m from 75 to 42 (383 to 214); the monotone
    barrier update, ``bound_relax_factor=0``, ``nlp_scaling_max_gradient=1000``,
    a 20-pair L-BFGS history and the quality-function oracle did not win on both.
    The LOQO oracle (``mu_oracle=loqo``, session 11) is not kept either: with
    optimised durations it took the block 1.0/1.4/1.5/1.6 m from 177 and 293
    iterations (both stopped by the 40 s limit), 49 and 94 to 62, 61, 30 and
    67, and the stairs 1.0/1.5 m from 40/27 to 24/14, but the stairs 0.9/1.1 m
    from 16/185 to 25/329 (stopped by the limit) and the flat walk 1.3–1.7 m
    from 11, 11, 12, 13, 13 to 12, 12, 11, 13, 15; with fixed durations the
    block 1.0 m from 18 to 45, the gap walk from 55 to 155 and the bound from
    28 to 71.

    With fixed durations IPOPT's adaptive barrier update never falls back
    to its monotone mode (``adaptive_mu_globalization=never-monotone-mode``,
    session 11): the fallback came near convergence (the flat trot at
    barrier 4e-10 jumped back to 5e-7 and spent 4 dear iterations, 2–3× the
    cost of the first ones). Iterations of the benchmark rows, fixed
    durations, from the level-ground guess: flat walk 10 → 10, flat trot
    11 → 8, block 1.0/1.5 m 18/41 → 18/33, stairs 1.0/1.5/2.0 m 23/14/16 →
    20/14/19, gap walk 55 → 52, gap trot 183 → 33, bound 28 → 28, slope
    25 → 21; goals moved ±0.1 m: flat trot 1.4–1.6 m 8, 11, 11, 8, 12 → 8,
    8, 8, 8, 12, block 1.4/1.6 m 48/42 → 39/34, gap walk 1.9 m 66 → 49,
    bound 1.9/2.1 m 858/456 → 734/252, stairs 1.9/2.1 m 44/17 → 20/17,
    slope 1.9/2.1 m 41/28 → 37/28, gap trot 2.4/2.6 m 24/27 both (the gap
    walk at 2.1 m stops at the time limit either way). With optimised
    durations it is not set: stairs 1.0 m 40 → 52 and 1.1 m 185 → stopped
    by the limit, though block 1.4/1.5/1.6 m went 298 (limit)/49/94 →
    47/31/26. ``kkt-error`` did as well on the flat trot but took the
    block 1.5 m to 64 and the bound to 72.
    """
    base = TrajoptConfig(
        constraints=TOWR_CONSTRAINTS,
        costs=CostWeights.none(),
        body_model="towr_anymal",
        phase_bounds_admit_gait=False,
        solver=SolverOptions(
            tol=1e-8,
            acceptable_tol=1e-6,
            ipopt_options=("nlp_scaling_method=none",),
            fixed_durations_ipopt_options=("adaptive_mu_globalization=never-monotone-mode",),
        ),
    )
    return replace(base, **changes)  # type: ignore[arg-type]
