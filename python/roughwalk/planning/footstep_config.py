"""Settings of the footstep planner, scaled to the robot (Zucker 2011, §4).

Every length is a multiple of the robot's hip-to-hip length L (front to
hind hip joints along x; 0.202 m for LittleDog, 0.60 m for ANYmal C), so
one set of numbers serves every registered robot. The LittleDog values
are given in brackets.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from roughwalk.errors import ConfigError

if TYPE_CHECKING:
    from roughwalk.robots.robot import Robot

__all__ = [
    "CertificateConfig",
    "FootstepConfig",
    "WALKING_ORDERS",
    "hip_to_hip_length",
    "nominal_body_clearance",
]

# Canonical leg indices: 0 LF, 1 RF, 2 LH, 3 RH.
LEG_INDEX = {"LF": 0, "RF": 1, "LH": 2, "RH": 3}
# The statically stable crawl: each hind leg is followed by the front leg on its side.
WALKING_ORDERS = {"crawl": ("LH", "LF", "RH", "RF")}


def nominal_body_clearance(robot: Robot) -> float:
    """Least clearance [m] of the body, feet excluded, at the nominal stance on flat ground.

    LittleDog's is 21 mm (its shins' lower ends), ANYmal C's 17 mm.
    """
    from roughwalk.robots.collision_model import CollisionModel

    model = CollisionModel.from_robot(robot)
    height = robot.nominal_stance.base_height
    a, b = model.world_segments(robot, robot.nominal_q, (0.0, 0.0, height))
    clear = np.minimum(a[:, 2], b[:, 2]) - model.radius
    body = ~model.is_foot
    return float(clear[body].min()) if body.any() else math.inf


def hip_to_hip_length(robot: Robot) -> float:
    """Distance L [m] along x between the front and hind hip (HAA) joints."""
    hips = robot.hip_positions
    return float(0.5 * (hips[0, 0] + hips[1, 0]) - 0.5 * (hips[2, 0] + hips[3, 0]))


def _check(name: str, value: float, low: float = 0.0, strict: bool = False) -> None:
    ok = math.isfinite(value) and (value > low if strict else value >= low)
    if not ok:
        relation = ">" if strict else ">="
        raise ConfigError(f"footstep.{name} must be a finite number {relation} {low}, got {value}")


@dataclass(frozen=True)
class CertificateConfig:
    """The pose-certificate search (Zucker 2011, §4.4) and the pose penalties of §4.3.

    Attributes
    ----------
    max_iterations:
        Most correction rounds (the paper's 25). More rescues harder stances
        at the price of slower rejections.
    stall_rounds:
        The search also gives up after this many rounds without cutting its
        total violation (foot errors, CoM and clearance deficits) by a tenth:
        stuck, typically a shin against a rock no trunk motion frees, or the
        obstacle step lifting the trunk and the reachability step pulling it
        back down in turn (most rejections on the logs). Larger keeps a few
        more stances (2-3 % on the LittleDog boards from 3 to 4) at a large
        cost in time. Measured from 3 to 2 on the five bench courses (20,000
        expansions): first plan on the logs 0.18 -> 0.10 s CPU, actions per
        CPU second +3-17 %, final costs equal or lower on every course, first
        costs equal except large rocks (+6 %, found in half the time) and
        logs (+0.7 %).
    alpha_reach, beta_reach:
        Translation [1] and rotation [rad/m²] step sizes of the reachability
        correction (§3.2). Larger converges in fewer rounds but may overshoot.
    reach_overshoot:
        How far past the closest reachable point the correction aims [m]
        (0.01 L [2 mm]), so that it lands inside the workspace.
    alpha_obstacle, beta_obstacle:
        Weights of translation [1] and rotation [rad²/m²] in the obstacle-avoidance
        correction (§3.4): its direction is the paper's (α·J_xᵀg, β·J_Rᵀg), its
        length makes the point's linearised motion along g cover the clearance
        deficit. A larger β/α turns the trunk more and shifts it less.
    com_margin:
        The CoM must lie this far inside the next step's support triangle [m]
        (0.05 L [1 cm]). Larger is more robust to CoM errors but prunes more
        stances.
    max_step, max_turn:
        Longest trunk translation [m] (0.1 L) and rotation [rad] per round,
        all corrections together.
    max_drift:
        The search gives up once the trunk is this far from its guessed
        position [m] (0.5 L): near a singular leg the obstacle step's
        Jacobians blow up and would fling the trunk away.
    clearance:
        Least body clearance, feet excluded [m] (0.2 c0 [4 mm], with c0 the
        body's clearance standing on flat ground, see
        :func:`nominal_body_clearance`). The SDF's
        interpolation error bound is added on top of it, so the true
        clearance is at least this.
    start_clearance:
        Least body clearance [m] of a re-plan's start certificate when the
        re-plan gives the measured trunk pose and no certificate keeps
        ``clearance``: searched from the measured trunk, as the distance
        field reads it (its error bound not added, the robot already stands
        there). Only the start stance: every stance the plan reaches keeps
        ``clearance``. 0 (no body point inside the terrain) lets the robot
        walk on from a shin settled against a rock (board Y, sloped rocks
        seed 1: the RF shin 3.6 mm from the rock face, a certificate needs
        8.4 mm); larger than ``clearance`` plus the field's error, the
        measured trunk only seeds the full search.
    clearance_overshoot:
        How far past ``clearance`` the obstacle correction aims [m].
    preferred_clearance:
        Clearance below which the pose cost rises [m] (0.5 c0 [1 cm]).
    clearance_penalty:
        Pose cost at ``clearance``, falling linearly to 0 at ``preferred_clearance``.
    singularity_margin:
        Legs whose normalised Jacobian volume |det J|/Π|J_k| (1 far from
        singular, 0 singular) is below this pay a penalty.
    singularity_penalty:
        Pose cost per leg at a singularity, falling linearly to 0 at the margin.
    max_tilt:
        Largest roll and pitch of the starting trunk pose guessed from the feet
        [rad] (0.15, 8.6°). The guess tilts the trunk like the feet, and the
        search keeps the guess when it already holds: at 0.5 rad, a LittleDog
        front foot on the floor of the 10 cm gap trench gave certificates
        rolled 19-23° and pitched 15-29° with the trunk 5 cm lower, in which
        a hind thigh sank up to 9 mm into the trunk and the diagonal foot
        carried 2 N of the robot's 27 N; walked in MuJoCo, a hind swing
        stalled against the trunk or the robot tipped over its diagonal
        (bench gap seeds 0 and 1, and a foot-force reflex on large rocks at a
        planned 28.6° roll). Smaller leaves the tilt to the reach correction,
        which turns the trunk only as far as a foot needs.

    """

    max_iterations: int = 25
    stall_rounds: int = 2
    alpha_reach: float = 0.7
    beta_reach: float = 50.0
    reach_overshoot: float = 0.002
    alpha_obstacle: float = 0.7
    beta_obstacle: float = 30.0
    com_margin: float = 0.01
    max_step: float = 0.02
    max_turn: float = 0.15
    max_drift: float = 0.1
    clearance: float = 0.004
    start_clearance: float = 0.0
    clearance_overshoot: float = 0.002
    preferred_clearance: float = 0.01
    clearance_penalty: float = 0.5
    singularity_margin: float = 0.25
    singularity_penalty: float = 0.5
    max_tilt: float = 0.15

    def __post_init__(self) -> None:
        for name in ("max_iterations", "stall_rounds"):
            if getattr(self, name) < 1:
                raise ConfigError(
                    f"footstep.certificate.{name} must be >= 1, got {getattr(self, name)}"
                )
        for f in dataclasses.fields(self):
            if f.name not in ("max_iterations", "stall_rounds"):
                _check(f"certificate.{f.name}", float(getattr(self, f.name)))
        for name in ("max_step", "max_turn", "max_drift"):
            _check(f"certificate.{name}", float(getattr(self, name)), strict=True)
        if self.preferred_clearance < self.clearance:
            raise ConfigError(
                f"footstep.certificate.preferred_clearance ({self.preferred_clearance}) must be "
                f">= clearance ({self.clearance})"
            )
        if self.singularity_margin > 1:
            raise ConfigError(
                "footstep.certificate.singularity_margin is a fraction in [0, 1], "
                f"got {self.singularity_margin}"
            )


@dataclass(frozen=True)
class FootstepConfig:
    """Everything the footstep planner needs to know; build it with :meth:`for_robot`.

    Attributes
    ----------
    resolution:
        Foothold lattice spacing [m] (L/40 [5 mm], the paper's grid). Finer
        finds better footholds but multiplies the states.
    normal_radius:
        Radius [m] of the disc over which a foothold's normal is the mean
        slope (:meth:`~roughwalk.terrain.terrain.Terrain.disc_normal`): the
        foot centre the pose certificates place sits the foot radius along
        it. 0 (default) takes the bilinear normal at the contact point,
        over one grid cell, which on a scanned rock can lean 20° more than
        the disc the slope checks judge; with the foot radius, the centre
        is the one ``trajectory.foot_centre="disc"`` aims at. Measured
        with both (session 23, ``bench_littledog.py --expansions 40000``,
        large rocks, one process per seed): seeds 0–22 walk 12 of 23
        against 20 with the point normal. Along the point normal the
        sphere touches the terrain at the contact point itself; along the
        disc's it meets the rock beside it first, wherever the two lean
        apart, and lands off its foothold. So 0 stays. Its precomputation
        grows with (r / grid spacing)²: about 300 gradients per lattice
        cell at the foot radius on the 1.2 mm boards.
    actions:
        Footstep displacements (dx, dy, dθ) [m, m, rad] of the moving leg in
        the heading frame, added to its nominal place around the feet's
        centroid (12–25 in the paper). Default: dx ∈ {−0.1, 0, 0.1, 0.2, 0.3}·L
        × dy ∈ {−0.1, 0, 0.1}·L, and turns of ±0.15 rad with dx ∈ {0, 0.15 L}:
        19 actions.
    walking_order:
        Leg names in stepping order (the crawl LH, LF, RH, RF).
    local_search_radius:
        Radius of the search for a cheaper foothold around each action's
        target [m] (L/20 [1 cm]; footnote 1 of the paper); 0 turns it off.
    local_search_penalty:
        Cost per ``local_search_radius`` of distance from the target, so that
        among equal footholds the action's own wins.
    max_foot_travel:
        Longest horizontal move of a foot in one step [m] (0.6 L). It also
        bounds the centroid's progress per step (a quarter of it), which makes
        the Euclidean heuristic admissible.
    min_foot_separation:
        Least horizontal distance between two feet [m] (0.2 L).
    crossing_margin:
        Left feet stay this far left of right feet and front feet this far
        ahead of hind feet [m] (0.05 L).
    step_cost:
        Cost of every step on top of terrain and pose costs (1: a flat
        foothold costs as much as taking a step). Larger prefers fewer steps.
    incircle_preferred, incircle_min:
        Support triangles with a smaller incircle radius [m] pay a pose cost
        (0.18 L), or are refused (0.08 L) (§4.3).
    incircle_penalty:
        Pose cost at ``incircle_min``, falling linearly to 0 at ``incircle_preferred``.
    certificate:
        The pose-certificate search (:class:`CertificateConfig`).
    goal_radius:
        The goal is reached when the feet's centroid is this close to it [m] (L/4).
    heuristic:
        ``"dubins"`` (the paper's, informed but not admissible) or
        ``"euclidean"`` (admissible: the plan's bound ε′ is then guaranteed).
    turning_radius:
        Turning radius of the Dubins car [m] (L).
    dubins_cost_per_metre:
        Cost per metre of the Dubins heuristic; 0 takes the cost of a flat
        step over the centroid's progress per step at the longest forward action.
    epsilon0, epsilon_decrement:
        ARA*'s initial heuristic inflation ε₀ and its decrement per iteration.
        A larger ε₀ finds a first plan sooner, a worse one.
    max_tree_edges:
        Search-tree edges kept for pictures (0 keeps none).
    cache_capacity:
        Certificate outcomes cached across plans and re-plans (about 40 bytes
        each); when full, the half least recently used is dropped.
    sdf_resolution:
        Voxel size of the terrain's signed distance field [m] (the smaller of
        L/40 and 0.3 c0 [5 mm]).
        Its interpolation error bound (0.87 × this) is added to the clearance.
    sdf_z_margin:
        Free space the SDF covers above the terrain [m] (1.4 × the nominal
        trunk height); the body above it is checked by a slower exact fall-back.
    cost_heading:
        Heading [rad] of the terrain cost map for a cost learned on oriented
        features (the map is computed once per terrain); ignored otherwise.
    edge_drop:
        A cell is no foothold where a foot resting on it has terrain more
        than this [m] below its sole within ``edge_margin`` beyond its
        radius: a rock's rim, off which a round foot slides
        (:func:`~roughwalk.planning.foothold_safety.edge_footholds`). 0 turns
        the check off. Smaller also refuses steep slopes (a drop d within
        r + margin is a slope of atan(d / (r + margin))); larger lets feet
        onto the rims of lower rocks. At 3 cm it refuses 16 % of the learned
        cost's footholds on the LittleDog board AE, 2 % on AC, 11 % on Y and
        31 % on AD; at 4 cm none on Y, 26 % on AD. Most of AD's are the
        cracks between touching logs (2–10 mm wide, down to the floor) and
        the logs' ends. Counting no drop into a crack narrower than the
        foot (a grey closing of the heights) refuses 18 % of AD, and logs
        with the fast options then fall in all 4 seeds (1/4 with this
        check, session 15). On AE (``bench_littledog.py
        --expansions 40000``, large rocks) the start put RF on a 7.5 cm
        rock's rim in seeds 2 and 3, which fell in the first swings;
        refused, and the foot moved onto the rock's top
        (``executor.start_snap_m``), both walk without a reflex. Off for a
        plan alone; a walk in physics plans with 3 cm (and
        ``max_foothold_slope`` 45°) unless told otherwise
        (:data:`roughwalk.sim.footstep_source.EXECUTION_FOOTHOLD_SAFETY`,
        session 15). Alone (session 14, ``--expansions 40000``, seeds 0–5): sloped rocks 4/6
        → 6/6 (mean 5.66 → 7.05 cm/s, no reflex), large rocks 3/6 → 3/6
        (seeds 2, 3, 4 against 0, 1, 4: new plans put LF on a 52° flank,
        seed 1, and let LF slip 4.3 cm, seed 0), and on the 2-seed board
        bench logs seed 1 falls at 1.33 s.
    edge_margin:
        How far beyond the foot's radius [m] a drop still counts. Larger keeps
        feet farther from rims, at the price of footholds near rocks. 0 for
        a plan alone; a walk in physics plans with 1 cm
        (:data:`~roughwalk.sim.footstep_source.EXECUTION_FOOTHOLD_SAFETY`,
        session 23): a touchdown lands a median 3 mm (90th percentile
        6 mm, worst 11 mm) from its planned foot centre (224 touchdowns of
        large rocks seeds 0–31), and the foot centre sits downhill of the
        contact the check judges. Large rocks seed 9 (with the opt-in
        ``normal_radius``) put RF 8 mm off its plan on the rim of a 5 cm
        rock, where it hung by its edge and slid as the trunk shifted. In
        five of the seven runs that failed without the margin (seeds 13,
        16, 24, 27, 28), when the first reflex fired a standing foot's
        planned centre was 6–12 mm from ground 3 cm below its sole, and the
        foot itself 1–6 mm. With the walk's 3 cm ``edge_drop`` and 45°
        ``max_foothold_slope``, 1 cm leaves no foothold on 49 % of board
        AE's cells (41 % with 0), AC 36 % (29), Y 37 % (28), AD 59 % (48).
    max_foothold_slope:
        A cell is no foothold where the terrain's mean slope over the foot's
        disc is steeper than this [rad]
        (:func:`~roughwalk.planning.foothold_safety.steep_footholds`): a foot
        pressed down vertically slides beyond the friction cone, atan μ
        (45° at μ = 1). π/2 turns the check off. Smaller keeps a margin to
        the cone and refuses more of a rocky board. Off for a plan alone; 45°
        in a walk in physics (with ``edge_drop`` 3 cm; figures below). Alone
        at 45° it refuses 37 % of board AE's footholds, and large rocks seed 1
        then finds no start in 18 (``--expansions 40000``); at 50° seed 1
        walks (4.98 cm/s; off, its plan put LF on a 52° flank, off which
        it slid), but seeds 0–5 still give 3 of 6 (1, 2, 3 against 2, 3,
        4), after 4 reflexes against 1. With ``edge_drop`` 3 cm alone, the
        logs' (AD) starts put RF and RH on 51–59° flanks with less than
        3 cm of drop beside them, off which they slid; at 45° with
        ``edge_drop`` 3 cm and the fast options (session 15, 4 seeds)
        26 of 28 runs against 24: logs go 1/4 → 3/4 (seed 1 at 2.9 cm/s
        after 4 reflexes), round rocks 4/4 at 7.72 → 8.14 cm/s and sloped
        rocks 4/4 at 7.89 → 8.41 without a reflex, large rocks stay 3/4
        (5.77 → 6.15), gap, barrier and steps are unchanged; together they
        refuse 17 % of AC's footholds, 41 % of AD's, 38 % of AE's and 23 %
        of Y's, 2–4 % of gap, barrier and steps. At 50° logs are 2/4 and
        large rocks 3/4 at 4.52 cm/s. The contact
        normal's tilt instead (the gradient of the resting height, which
        bridges cracks) at 45° gave logs 2/4: the flanks' contact tilts
        (45–56°) lie nearer the cone than their slopes.
    max_contact_slope:
        A cell is no foothold where the contact a foot lowered onto it makes
        leans more than this [rad] from vertical
        (:func:`~roughwalk.planning.foothold_safety.contact_slopes`), on top
        of ``max_foothold_slope``'s mean over the disc. Of board AE's cells
        the walk's 45° disc limit and 3 cm rim check accept, 14 % rest the
        foot on a contact leaning beyond 45° (AD: 4 %); of 56 touchdowns in
        session 17's large-rocks runs, all within 0.9 cm of their plan, the
        5 that came down on such a contact were 4 planned on one. π/2
        turns the check off, as by default: at 45° (``bench_littledog.py
        --expansions 40000``, one process per seed) large rocks 0–7 5/8 at
        5.30 → 5/8 at 5.95 cm/s (seed 7 rescued, seed 2 lost), logs 0–5
        4/6 at 7.71 → 4/6 at 8.26 (seed 5 rescued, seed 1 lost), held-out
        large rocks 8–15 4/8 at 6.40 → 5/8 at 6.16. Session 18, 4 seeds
        of the other five classes: every run kept (round rocks 4/4 at 8.14
        → 8.21, sloped rocks 8.41 → 8.31, barrier 8.37, steps 8.02, gap
        7.65 cm/s). Large rocks seed 2, which main rescues with one reflex
        (6.20 cm/s), rolls over in its first recovery at 45° and at 50°,
        with ``executor.start_max_slope`` 40° or without, and at 55° finds
        no certificate for its re-plan (figures in
        ``docs/measurements.md``): so it stays off.
    wall_reach:
        A cell is no foothold for the front legs where the terrain rises more
        than ``wall_height`` above the sole of a foot resting there within
        this [m] behind it (along ``cost_heading``), nor for the hind legs
        within this ahead of it: there the leg's knee, which points back on
        the front legs and forwards on the hind ones, meets the wall's rim
        (:func:`~roughwalk.planning.foothold_safety.wall_footholds`). 0
        turns the check off. Larger keeps feet farther from walls (a trench
        narrower than this leaves the front feet no foothold on its floor).
        Off, in a walk too. 7.5 cm is the measured setting: in the gap runs
        a front knee stood up to 6.5 cm behind its foot at touchdown (seed
        1's LF, 6.5 cm past the trench's near wall, cleared the rim by 0.1 mm
        in its trajectory), plus 1 cm; it refuses 3.2 % of the gap course
        (its trench floor but a 3.5 cm band for each end), 0.5 % / 0.9 %
        (front / hind) of board AE, 0.8 % / 1.0 % of AD, none of AC, Y,
        barrier or steps. On the gap (``bench_littledog.py --expansions
        40000 --classes gap``, session-15 defaults, session 16) it ends
        seed 0's hooked shank: 6.51 → 7.98 cm/s, no reflex, and seed 1
        6.64 → 7.96, so seeds 0–3 walk 7.14 → 7.24 cm/s; but over seeds
        0–5 7.18 → 7.11 cm/s (6/6 both): seeds 2, 4 and 5 (7.79, 7.27,
        7.26 → 5.36, 6.81, 6.86) put their front feet deeper into the
        trench, and as LF swings down to it the lowered, tilted trunk tips
        over the RF–LH diagonal, unloading RH (the foot-force reflex; the
        mode of seed 1 without the check). At 6.5 cm seed 5 rolls over, and
        a recovery that leaves a front foot on a refused trench cell (seed 2
        with ``zmp.min_support_load`` 5 N) has no re-plan start.
    wall_height:
        How far above a foot's sole [m] a wall within ``wall_reach`` may rise
        (9 cm: the knee stands 10–11 cm above the sole, less its 1 cm
        radius). Smaller also refuses footholds beside lower walls, which the
        knee clears.

    """

    resolution: float = 0.005
    normal_radius: float = 0.0
    actions: tuple[tuple[float, float, float], ...] = ()
    walking_order: tuple[str, str, str, str] = WALKING_ORDERS["crawl"]
    local_search_radius: float = 0.01
    local_search_penalty: float = 0.1
    max_foot_travel: float = 0.12
    min_foot_separation: float = 0.04
    crossing_margin: float = 0.01
    step_cost: float = 1.0
    incircle_preferred: float = 0.036
    incircle_min: float = 0.016
    incircle_penalty: float = 1.0
    certificate: CertificateConfig = field(default_factory=CertificateConfig)
    goal_radius: float = 0.05
    heuristic: str = "dubins"
    turning_radius: float = 0.2
    dubins_cost_per_metre: float = 0.0
    epsilon0: float = 3.0
    epsilon_decrement: float = 0.5
    max_tree_edges: int = 20_000
    cache_capacity: int = 4_000_000
    sdf_resolution: float = 0.005
    sdf_z_margin: float = 0.25
    cost_heading: float = 0.0
    edge_drop: float = 0.0
    edge_margin: float = 0.0
    max_foothold_slope: float = math.pi / 2
    max_contact_slope: float = math.pi / 2
    wall_reach: float = 0.0
    wall_height: float = 0.09

    def __post_init__(self) -> None:
        _check("resolution", self.resolution, strict=True)
        _check("normal_radius", self.normal_radius)
        if not self.actions:
            raise ConfigError(
                "footstep.actions must hold at least one (dx, dy, dtheta); "
                "use FootstepConfig.for_robot(robot) for the defaults"
            )
        try:
            acts = np.asarray(self.actions, dtype=float)
        except (TypeError, ValueError):
            raise ConfigError(
                f"footstep.actions must be (dx, dy, dtheta) triples, got {self.actions!r}"
            ) from None
        if acts.ndim != 2 or acts.shape[1] != 3 or not np.all(np.isfinite(acts)):
            raise ConfigError(
                f"footstep.actions must be finite (dx, dy, dtheta) triples, got shape {acts.shape}"
            )
        object.__setattr__(self, "actions", tuple(tuple(float(v) for v in a) for a in acts))
        order = tuple(self.walking_order)
        if sorted(order) != sorted(LEG_INDEX):
            raise ConfigError(
                f"footstep.walking_order must name each of LF, RF, LH, RH once, got {order}"
            )
        object.__setattr__(self, "walking_order", order)
        for name in (
            "local_search_radius",
            "local_search_penalty",
            "min_foot_separation",
            "incircle_min",
            "incircle_penalty",
            "turning_radius",
            "dubins_cost_per_metre",
        ):
            _check(name, float(getattr(self, name)))
        for name in (
            "max_foot_travel",
            "step_cost",
            "goal_radius",
            "epsilon_decrement",
            "sdf_resolution",
        ):
            _check(name, float(getattr(self, name)), strict=True)
        _check("sdf_z_margin", self.sdf_z_margin)
        _check("edge_drop", self.edge_drop)
        _check("edge_margin", self.edge_margin)
        _check("max_foothold_slope", self.max_foothold_slope)
        _check("max_contact_slope", self.max_contact_slope)
        _check("wall_reach", self.wall_reach)
        _check("wall_height", self.wall_height)
        if not math.isfinite(self.crossing_margin) or not math.isfinite(self.cost_heading):
            raise ConfigError("footstep.crossing_margin and footstep.cost_heading must be finite")
        if self.incircle_preferred < self.incircle_min:
            raise ConfigError(
                f"footstep.incircle_preferred ({self.incircle_preferred}) must be >= "
                f"incircle_min ({self.incircle_min})"
            )
        if self.heuristic not in ("dubins", "euclidean"):
            raise ConfigError(
                f"unknown footstep.heuristic '{self.heuristic}'; known: dubins, euclidean"
            )
        if not (math.isfinite(self.epsilon0) and self.epsilon0 >= 1):
            raise ConfigError(f"footstep.epsilon0 must be >= 1, got {self.epsilon0}")
        if self.max_tree_edges < 0 or self.cache_capacity < 0:
            raise ConfigError("footstep.max_tree_edges and cache_capacity must be >= 0")

    @classmethod
    def for_robot(cls, robot: Robot, **overrides: Any) -> FootstepConfig:
        """The defaults scaled to ``robot``'s hip-to-hip length, then ``overrides``.

        ``overrides`` are field names (``heuristic="euclidean"``) or, for the
        certificate, ``certificate=CertificateConfig(...)`` or dotted-free
        ``certificate_<field>=...`` keys (``certificate_clearance=0.006``).
        """
        length = hip_to_hip_length(robot)
        if not (math.isfinite(length) and length > 0):
            raise ConfigError(
                f"robot '{robot.name}' has front and hind hips {length} m apart; "
                "the footstep planner needs front hips ahead of hind hips"
            )
        half = 0.5 * length
        # Clearances scale with how close the robot's own shins come to flat
        # ground (c0), not with its length: ANYmal's shins sit 17 mm up, 3 % of L.
        c0 = min(nominal_body_clearance(robot), 0.1 * length)
        if not c0 > 0:
            c0 = 0.1 * length
        cert_over = {
            k.removeprefix("certificate_"): v
            for k, v in overrides.items()
            if k.startswith("certificate_")
        }
        scaled: dict[str, Any] = {
            "beta_reach": 0.5 / half**2,
            "reach_overshoot": 0.01 * length,
            "beta_obstacle": 0.3 / half**2,
            "com_margin": 0.05 * length,
            "max_step": 0.1 * length,
            "max_drift": 0.5 * length,
            "clearance": 0.2 * c0,
            "clearance_overshoot": 0.1 * c0,
            "preferred_clearance": 0.5 * c0,
        }
        cert_names = {f.name for f in dataclasses.fields(CertificateConfig)}
        unknown_cert = sorted(set(cert_over) - cert_names)
        if unknown_cert:
            known = ", ".join(sorted(cert_names))
            raise ConfigError(f"unknown certificate field(s) {unknown_cert}; known: {known}")
        certificate = CertificateConfig(**{**scaled, **cert_over})
        actions = [
            (dx * length, dy * length, 0.0)
            for dx in (-0.1, 0.0, 0.1, 0.2, 0.3)
            for dy in (-0.1, 0.0, 0.1)
        ]
        actions += [(dx * length, 0.0, dth) for dth in (-0.15, 0.15) for dx in (0.0, 0.15)]
        defaults: dict[str, Any] = {
            "resolution": length / 40,
            "actions": tuple(actions),
            "local_search_radius": length / 20,
            "max_foot_travel": 0.6 * length,
            "min_foot_separation": 0.2 * length,
            "crossing_margin": 0.05 * length,
            "incircle_preferred": 0.18 * length,
            "incircle_min": 0.08 * length,
            "certificate": certificate,
            "goal_radius": 0.25 * length,
            "turning_radius": length,
            # Its interpolation error (0.87 × this) stays below 0.26 c0.
            "sdf_resolution": min(length / 40, 0.3 * c0),
            "sdf_z_margin": 1.4 * robot.nominal_stance.base_height,
        }
        defaults.update({k: v for k, v in overrides.items() if not k.startswith("certificate_")})
        names = {f.name for f in dataclasses.fields(cls)}
        unknown = sorted(set(defaults) - names)
        if unknown:
            raise ConfigError(
                f"unknown footstep config field(s) {unknown}; known: {', '.join(sorted(names))}"
            )
        return cls(**defaults)

    def to_core(self) -> dict[str, Any]:
        """The dict the Rust planner reads: leg names become canonical indices."""
        d = dataclasses.asdict(self)
        d["walking_order"] = [LEG_INDEX[name] for name in self.walking_order]
        d["actions"] = [tuple(a) for a in self.actions]
        for key in (
            "sdf_resolution",
            "sdf_z_margin",
            "cost_heading",
            "edge_drop",
            "edge_margin",
            "max_foothold_slope",
            "max_contact_slope",
            "wall_reach",
            "wall_height",
        ):
            d.pop(key)
        return d
