"""Type stubs for the compiled module ``roughwalk._core`` (the Rust core's bindings)."""

from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

__version__: str

class HeightField:
    """A regular-grid height field held in Rust (x-major heights [m])."""

    def __init__(
        self,
        x0: float,
        y0: float,
        dx: float,
        dy: float,
        heights: NDArray[np.float64],
        known: NDArray[np.bool_] | None = None,
    ) -> None: ...
    def height(
        self, xy: NDArray[np.float64], interpolation: str = "bilinear"
    ) -> NDArray[np.float64]: ...
    def height_and_gradient(
        self, xy: NDArray[np.float64], interpolation: str = "bilinear"
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]: ...
    def disc_normal(self, xy: NDArray[np.float64], radius: float) -> NDArray[np.float64]: ...
    def is_known(self, xy: NDArray[np.float64]) -> NDArray[np.bool_]: ...
    @property
    def shape(self) -> tuple[int, int]: ...

# ---- sdf (crates/roughwalk-py/src/sdf.rs) ----

class SdfBand:
    """A signed distance field half built: occupancy and exact band done."""

    @staticmethod
    def from_heightfield(
        heightfield: HeightField,
        origin: tuple[float, float, float],
        resolution: float,
        shape: tuple[int, int, int],
        band_cells: float,
    ) -> SdfBand: ...
    @staticmethod
    def from_mesh(
        heightfield: HeightField,
        vertices: NDArray[np.float64],
        faces: NDArray[np.int64],
        origin: tuple[float, float, float],
        resolution: float,
        shape: tuple[int, int, int],
        band_cells: float,
    ) -> SdfBand: ...
    def seed_mask(self, max_distance: float | None = None) -> NDArray[np.bool_]: ...
    @property
    def exact_count(self) -> int: ...
    def finish(self) -> SdfField: ...
    def finish_with_nearest_voxel(self, nearest: NDArray[np.int64]) -> SdfField: ...
    def finish_with_seed_distance(
        self, seed_distance: NDArray[np.float32], offset: float
    ) -> SdfField: ...

class SdfField:
    """A built signed distance field: lattice values [m] and the height-field fall-back."""

    def __init__(
        self,
        heightfield: HeightField,
        origin: tuple[float, ...],
        resolution: float,
        values: NDArray[np.float32],
    ) -> None: ...
    def query(
        self, points: NDArray[np.float64]
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]: ...
    def surface_query(
        self, points: NDArray[np.float64]
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]: ...
    def query_spheres(
        self, centers: NDArray[np.float64], radii: NDArray[np.float64]
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]: ...
    def query_capsules(
        self,
        a: NDArray[np.float64],
        b: NDArray[np.float64],
        radii: NDArray[np.float64],
        samples: int | None = None,
    ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]: ...
    def values(self) -> NDArray[np.float32]: ...
    @property
    def origin(self) -> tuple[float, float, float]: ...
    @property
    def resolution(self) -> float: ...
    @property
    def shape(self) -> tuple[int, int, int]: ...

def feature_transform(seeds: NDArray[np.bool_]) -> NDArray[np.int64]: ...

# ---- robot kinematics (crates/roughwalk-py/src/robot.rs) ----

class LegChain:
    """One leg: hinges HAA, HFE, KFE from the trunk (base) frame to a spherical foot.

    Body k's pose follows MuJoCo's hinge: T_k = T_{k-1} · [R(body_quat_k), body_pos_k] ·
    Trans(anchor_k) · Rot(axis_k, q_k) · Trans(-anchor_k); the foot centre is T_3 · foot.
    ``knee_sign`` (+1/-1) picks the IK knee branch: the sign of the angle, right-handed
    about the HFE axis, from the HFE→KFE segment to the KFE→foot segment (projected on
    the plane ⟂ that axis); for a leg straight at q_KFE = 0 with KFE and HFE axes
    pointing the same way, the sign of q_KFE. Raises ``RobotModelError`` when HFE ∦ KFE
    or HFE ∦⟂ HAA (the analytic IK's assumption).
    """

    def __init__(
        self,
        body_pos: ArrayLike,
        body_quat: ArrayLike,
        anchor: ArrayLike,
        axis: ArrayLike,
        lower: ArrayLike,
        upper: ArrayLike,
        velocity_limit: ArrayLike,
        foot: ArrayLike,
        foot_radius: float,
        knee_sign: float,
        name: str = "leg",
    ) -> None: ...
    def fk(self, q: ArrayLike) -> NDArray[np.float64]:
        """Foot centre in the base frame, FK_B(q) [m], shape (3,)."""
    def jacobian(self, q: ArrayLike) -> NDArray[np.float64]:
        """∂FK_B/∂q [m/rad], shape (3, 3), column k for joint k."""
    def point_jacobian(
        self, q: ArrayLike, link: int, point: ArrayLike
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Position (3,) [m] and ∂p/∂q (3, 3) of a point fixed on link 0/1/2 (hip/thigh/shank)."""
    def link_frames(self, q: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Origins (3, 3) [m] and rotation matrices (3, 3, 3) of the joint bodies, base frame."""
    def ik(
        self, target: ArrayLike, knee_sign: float | None = None
    ) -> tuple[NDArray[np.float64], bool, bool, float]:
        """IK_B: ``(q, reachable, within_limits, error)`` for a base-frame target [m].

        ``q`` is always within limits; out of reach it is the closest reachable foot
        (Zucker 2011, §3.1). ``within_limits`` is False when a joint limit is what keeps
        the foot off the target; ``error`` is the foot-to-target distance [m].
        """
    @property
    def name(self) -> str: ...
    @property
    def body_pos(self) -> NDArray[np.float64]: ...
    @property
    def body_quat(self) -> NDArray[np.float64]: ...
    @property
    def anchor(self) -> NDArray[np.float64]: ...
    @property
    def axis(self) -> NDArray[np.float64]: ...
    @property
    def lower(self) -> NDArray[np.float64]: ...
    @property
    def upper(self) -> NDArray[np.float64]: ...
    @property
    def velocity_limit(self) -> NDArray[np.float64]: ...
    @property
    def foot(self) -> NDArray[np.float64]: ...
    @property
    def foot_radius(self) -> float: ...
    @property
    def knee_sign(self) -> float: ...

class BodyPoseStep:
    """One body-pose step: the new trunk pose and the applied (Δx, ω), world frame."""

    @property
    def base_pos(self) -> NDArray[np.float64]: ...
    @property
    def base_quat(self) -> NDArray[np.float64]: ...
    @property
    def delta_x(self) -> NDArray[np.float64]: ...
    @property
    def omega(self) -> NDArray[np.float64]: ...
    @property
    def value_before(self) -> float:
        """Σ|e_i| (reachability), signed distance d (obstacle) or CoM margin (support) [m]."""
    @property
    def q(self) -> NDArray[np.float64] | None:
        """Reachability step only: the 12 IK joint angles [rad] at the old pose."""
    @property
    def reachable(self) -> NDArray[np.bool_] | None:
        """Reachability step only: which feet the IK reached at the old pose."""

class Quadruped:
    """Four legs in canonical order LF, RF, LH, RH; q is leg-major (HAA, HFE, KFE) × 4."""

    def __init__(self, legs: list[LegChain]) -> None: ...
    @property
    def legs(self) -> list[LegChain]: ...
    def foot_positions(
        self, q: ArrayLike, base_pos: ArrayLike | None = None, base_quat: ArrayLike | None = None
    ) -> NDArray[np.float64]:
        """World feet (4, 3) [m]: R·FK_B(q_i) + x; identity pose by default."""
    def inverse_kinematics(
        self, feet: ArrayLike, base_pos: ArrayLike | None = None, base_quat: ArrayLike | None = None
    ) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
        """IK_W of world feet (4, 3) [m]: q (12,) [rad] and reached flags (4,)."""
    def fk_batch(self, q: ArrayLike) -> NDArray[np.float64]:
        """Base-frame feet (N, 4, 3) [m] of joint angles (N, 12) [rad]."""
    def ik_batch(self, feet: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
        """IK_B of base-frame feet (N, 4, 3) [m]: q (N, 12) [rad], reached (N, 4)."""
    def reachability_step(
        self,
        feet: ArrayLike,
        base_pos: ArrayLike,
        base_quat: ArrayLike,
        alpha: float,
        beta: float,
    ) -> BodyPoseStep:
        """Zucker 2011 §3.2: Δx = α Σ e_i, ω = β Σ (f'_i − x) × e_i."""
    def point_pose_jacobians(
        self,
        feet: ArrayLike,
        base_pos: ArrayLike,
        base_quat: ArrayLike,
        leg: int | None,
        link: int,
        point: ArrayLike,
    ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
        """Zucker 2011 §3.4: world p (3,) [m], J_p(x), J_p(R) (3, 3) with feet held by IK.

        ``leg=None`` means a trunk point given in the base frame; otherwise ``point``
        is in the frame of ``link`` (0 hip, 1 thigh, 2 shank) of leg ``leg``.
        """
    def obstacle_avoidance_step(
        self,
        feet: ArrayLike,
        base_pos: ArrayLike,
        base_quat: ArrayLike,
        leg: int | None,
        link: int,
        point: ArrayLike,
        distance: float,
        gradient: ArrayLike,
        alpha: float,
        beta: float,
        clearance: float = 0.0,
    ) -> BodyPoseStep:
        """Zucker 2011 §3.4: Δx = α(c − d)·J_p(x)ᵀg, ω = β(c − d)·J_p(R)ᵀg while d < c."""
    @staticmethod
    def com_support_step(
        stance_feet: ArrayLike,
        base_pos: ArrayLike,
        base_quat: ArrayLike,
        com_offset: ArrayLike,
        margin: float,
        max_step: float,
    ) -> BodyPoseStep:
        """Move the CoM x + R·com_offset horizontally (≤ max_step [m]) to ``margin`` [m] inside."""

def support_triangle_incircle(
    a: ArrayLike, b: ArrayLike, c: ArrayLike
) -> tuple[NDArray[np.float64], float]:
    """Incircle centre (2,) [m] and radius [m] of the x–y triangle (a, b, c)."""

def support_polygon_margin(point: ArrayLike, feet: ArrayLike) -> float:
    """Signed x–y distance [m] from ``point`` to the convex hull of ``feet``: positive inside."""

# ---- footstep planner (crates/roughwalk-py/src/footstep.rs) ---------------------------

class FootstepPlanner:
    """The footstep planner of one robot on one terrain (Zucker 2011, §4).

    Built once per terrain (SDF, cost maps, lattice) and planned with many
    times; certificate outcomes are cached across calls.
    """

    def __init__(
        self,
        quadruped: Quadruped,
        nominal_q: ArrayLike,
        base_mass: float,
        base_com: ArrayLike,
        link_mass: ArrayLike,
        link_com: ArrayLike,
        capsule_leg: list[int],
        capsule_link: list[int],
        capsule_a: ArrayLike,
        capsule_b: ArrayLike,
        capsule_radius: list[float],
        heightfield: HeightField,
        sdf_values: NDArray[np.float32],
        sdf_origin: tuple[float, float, float],
        sdf_resolution: float,
        cost_front: ArrayLike,
        cost_hind: ArrayLike,
        config: dict[str, Any],
    ) -> None: ...
    def plan(
        self,
        goal: tuple[float, float],
        start_pose: tuple[float, float, float] | None = None,
        start_feet: ArrayLike | None = None,
        next_leg: int = 2,
        time_limit: float | None = None,
        expansions: int | None = None,
        callback: Callable[[dict[str, Any]], Any] | None = None,
        search: str = "arastar",
        start_trunk: tuple[ArrayLike, ArrayLike] | None = None,
    ) -> dict[str, Any]:
        """Plan from a trunk pose or from feet (4, 2) [m] to the disc around ``goal`` [m].

        ``start_trunk`` (with ``start_feet`` only): the measured trunk position [m]
        and quaternion (w, x, y, z) a start certificate is searched from where the
        pose guessed from the feet has none.
        """
    @property
    def lattice(self) -> tuple[float, float, float, int, int]:
        """(x0, y0, resolution, nx, ny) of the foothold lattice [m, m, m, -, -]."""
    @property
    def heuristic_scales(self) -> tuple[float, float]:
        """Cost per metre of the Euclidean and the Dubins heuristic."""
    @property
    def sdf_error(self) -> float:
        """SDF interpolation error bound added to every certified clearance [m]."""
    @property
    def nominal_height(self) -> float:
        """Trunk height over the feet at the nominal stance [m]."""
    @property
    def foothold_count(self) -> int:
        """Foothold cells of the lattice."""
    @property
    def cache_len(self) -> int:
        """Cached certificate outcomes."""

class BodyPassEvaluator:
    """The trunk block of one footstep's CHOMP (Zucker 2011, §5.3), evaluated in one call."""

    def __init__(
        self,
        quadruped: Quadruped,
        sdf: SdfField,
        point_leg: ArrayLike,
        point_link: ArrayLike,
        point_local: ArrayLike,
        point_radius: ArrayLike,
        point_is_foot: ArrayLike,
        body: ArrayLike,
        feet: ArrayLike,
        support: ArrayLike,
        held_q: ArrayLike,
        active: ArrayLike,
        hips: ArrayLike,
        max_reach: ArrayLike,
        velocity_limit: ArrayLike,
        polygons: list[ArrayLike],
        polygon_index: ArrayLike,
        com_offset: ArrayLike,
        com_offset_acceleration: ArrayLike,
        *,
        dt: float,
        reach_margin: float,
        reach_weight: float,
        damping: float,
        zmp_k: float,
        zmp_margin: float,
        support_weight: float,
        obstacle_epsilon: float,
        obstacle_weight: float,
        gradient: str,
    ) -> None: ...
    def evaluate(self, xi: ArrayLike) -> dict[str, Any]:
        """Terms, gradient (n, 6), clearances, points, q, reached, ZMP margins at ξ (n, 6)."""

class SwingPassEvaluator:
    """The swing-leg block of one footstep's CHOMP (Zucker 2011, §5.3), evaluated in one call."""

    def __init__(
        self,
        quadruped: Quadruped,
        sdf: SdfField,
        point_leg: ArrayLike,
        point_link: ArrayLike,
        point_local: ArrayLike,
        point_radius: ArrayLike,
        point_is_foot: ArrayLike,
        leg: int,
        base_pos: ArrayLike,
        rotation: ArrayLike,
        ends: ArrayLike,
        active: ArrayLike,
        velocity_limit: ArrayLike,
        *,
        dt: float,
        speed_fraction: float,
        speed_weight: float,
        obstacle_epsilon: float,
        obstacle_weight: float,
        gradient: str,
    ) -> None: ...
    def evaluate(self, xi: ArrayLike) -> dict[str, Any]:
        """Terms, gradient (n, 3), the leg's clearances and points at ξ (n, 3) [rad]."""

def center_of_mass_batch(
    quadruped: Quadruped,
    q: ArrayLike,
    link_mass: ArrayLike,
    link_com: ArrayLike,
    base_mass: float,
    base_com: ArrayLike,
) -> NDArray[np.float64]:
    """Whole-robot CoM (N, 3) in the base frame [m] for joint angles (N, 4, 3) [rad]."""

def reach_by_height_and_tilt(
    quadruped: Quadruped,
    hips: ArrayLike,
    feet: ArrayLike,
    base_pos: ArrayLike,
    rotation: ArrayLike,
    iterations: int,
) -> tuple[NDArray[np.float64], NDArray[np.float64]] | None:
    """Trunk position (3,) [m] and orientation (3, 3) lowered and tilted until feet (4, 3) reach.

    ``hips`` (4, 3) are the hip anchors in the base frame [m]; None when every
    foot is reached from the start (Zucker 2011, §3.2 without the horizontal part).
    """

def capsule_clearances(
    quadruped: Quadruped,
    sdf: SdfField,
    leg: ArrayLike,
    link: ArrayLike,
    a: ArrayLike,
    b: ArrayLike,
    radius: ArrayLike,
    q: ArrayLike,
    base_pos: ArrayLike,
    rotation: ArrayLike,
) -> NDArray[np.float64]:
    """Clearances (N, P) [m] of collision capsules at N configurations (q (N, 4, 3) [rad])."""
