"""The anytime footstep planner (Zucker 2011, §4): ARA* over four-foot states.

:class:`FootstepPlanner` does the per-terrain precomputation of §4.5 once —
the terrain's signed distance field and its front and hind terrain-cost
maps — and then plans and re-plans as often as needed; the Rust core keeps
a cache of pose-certificate outcomes between calls, so a re-plan after an
execution error starts warm. :func:`plan_footsteps` is the one-call form.

A plan starts from a trunk pose (x, y, yaw): the robot's nominal stance
placed there, its feet dropped onto the terrain and snapped to the foothold
lattice. A re-plan starts from the feet where they stand.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from roughwalk import _core
from roughwalk.errors import InvalidArgumentError, PlanningError, TerrainError
from roughwalk.planning.foothold_safety import (
    leaning_footholds,
    unsafe_footholds,
    wall_footholds,
)
from roughwalk.planning.footstep_config import LEG_INDEX, FootstepConfig
from roughwalk.planning.footstep_cost import FootholdCost, default_terrain_cost
from roughwalk.planning.footstep_plan import (
    Footstep,
    FootstepPlan,
    PoseCertificate,
    SolutionReport,
)
from roughwalk.robots.collision_model import CollisionModel
from roughwalk.robots.robot import Robot
from roughwalk.terrain.sdf import SignedDistanceField
from roughwalk.terrain.terrain import Terrain

__all__ = ["FootstepPlanner", "plan_footsteps"]

LEGS = ("LF", "RF", "LH", "RH")
_FAILURES = ("unreachable", "center_of_mass", "collision")

SolutionCallback = Callable[[SolutionReport], Any]


class FootstepPlanner:
    """Footstep planning for one robot on one terrain.

    Parameters
    ----------
    robot:
        The quadruped.
    terrain:
        The terrain; unknown cells are never footholds.
    config:
        Planner settings; :meth:`FootstepConfig.for_robot` by default.
    cost:
        The terrain cost (anything with ``cost_map(terrain, heading, leg)``);
        the learned default (:func:`default_terrain_cost`) if None.
    sdf:
        A prebuilt signed distance field of ``terrain`` to reuse; built at
        ``config.sdf_resolution`` if None.
    refused:
        (front, hind) boolean masks of the terrain's cells (nx, ny) that are
        no footholds for the front or the hind legs, on top of the
        config's checks: footholds an execution found unwalkable
        (:meth:`with_refused`).

    """

    def __init__(
        self,
        robot: Robot,
        terrain: Terrain,
        config: FootstepConfig | None = None,
        cost: FootholdCost | None = None,
        sdf: SignedDistanceField | None = None,
        refused: tuple[np.ndarray, np.ndarray] | None = None,
    ) -> None:
        self.robot = robot
        self.terrain = terrain
        self.config = config if config is not None else FootstepConfig.for_robot(robot)
        self.cost = cost if cost is not None else default_terrain_cost()
        quadruped = robot._quadruped()
        if quadruped is None:
            raise PlanningError(
                f"robot '{robot.name}' has no analytic leg IK, which pose certificates need: "
                f"{robot._core_error}"
            )
        t0 = time.perf_counter()
        if sdf is None:
            sdf = terrain.sdf(self.config.sdf_resolution, z_margin=self.config.sdf_z_margin)
        self.sdf = sdf
        t1 = time.perf_counter()
        heading = self.config.cost_heading
        try:
            self.cost_front = np.asarray(self.cost.cost_map(terrain, heading, "front"), float)
            hind = getattr(self.cost, "separate_legs", True)
            self.cost_hind = (
                np.asarray(self.cost.cost_map(terrain, heading, "hind"), float)
                if hind
                else self.cost_front
            )
        except TerrainError as e:
            raise PlanningError(
                f"the terrain cost cannot be evaluated on {terrain}: {e}. Pass a cost that "
                "suits this grid (cost=..., or --cost FILE with features learned at larger radii)"
            ) from None
        c = self.config
        if c.edge_drop > 0 or c.max_foothold_slope < 0.5 * np.pi:
            # Rims and slopes a round foot slides off are no footholds.
            unsafe = unsafe_footholds(
                terrain, robot.foot_radius, c.edge_drop, c.edge_margin, c.max_foothold_slope
            )
            self.cost_front = np.where(unsafe, np.inf, self.cost_front)
            self.cost_hind = np.where(unsafe, np.inf, self.cost_hind)
        if c.max_contact_slope < 0.5 * np.pi:
            # A foot whose contact leans beyond the cone slides, whatever the disc's mean slope.
            leaning = leaning_footholds(terrain, robot.foot_radius, c.max_contact_slope)
            self.cost_front = np.where(leaning, np.inf, self.cost_front)
            self.cost_hind = np.where(leaning, np.inf, self.cost_hind)
        if c.wall_reach > 0:
            # Where a knee would meet a wall's rim, for each end's knees.
            for end in ("front", "hind"):
                at_wall = wall_footholds(
                    terrain, robot.foot_radius, c.wall_reach, c.wall_height, heading, end
                )
                if end == "front":
                    self.cost_front = np.where(at_wall, np.inf, self.cost_front)
                else:
                    self.cost_hind = np.where(at_wall, np.inf, self.cost_hind)
        if refused is not None:
            front, hind = (np.asarray(m, dtype=bool) for m in refused)
            if front.shape != self.cost_front.shape or hind.shape != self.cost_hind.shape:
                raise InvalidArgumentError(
                    f"refused masks must have the terrain's shape {self.cost_front.shape}, "
                    f"got {front.shape} and {hind.shape}"
                )
            self.cost_front = np.where(front, np.inf, self.cost_front)
            self.cost_hind = np.where(hind, np.inf, self.cost_hind)
        t2 = time.perf_counter()
        collision = CollisionModel.from_robot(robot)
        body = ~collision.is_foot
        d = robot.description
        self._core = _core.FootstepPlanner(
            quadruped,
            robot.to_canonical(robot.nominal_q),
            float(d.base_mass),
            np.asarray(d.base_com, dtype=float),
            np.asarray(d.link_mass, dtype=float),
            np.asarray(d.link_com, dtype=float),
            [int(v) for v in collision.leg[body]],
            [int(v) for v in collision.link[body]],
            collision.a[body],
            collision.b[body],
            [float(v) for v in collision.radius[body]],
            terrain.core,
            np.ascontiguousarray(sdf.values, dtype=np.float32),
            (float(sdf.origin[0]), float(sdf.origin[1]), float(sdf.origin[2])),
            float(sdf.resolution),
            self.cost_front,
            self.cost_hind,
            self.config.to_core(),
        )
        t3 = time.perf_counter()
        self.precompute_s = {"sdf": t1 - t0, "cost_map": t2 - t1, "model": t3 - t2}
        self._goal: tuple[float, float] | None = None

    def refused_masks(self, leg: int, x: float, y: float, radius: float) -> tuple[Any, Any]:
        """(front, hind) masks of the terrain's cells within ``radius`` [m] of (x, y) [m].

        Only the end of ``leg`` (canonical index, 0–3: LF, RF, LH, RH) gets the
        disc; the other mask is empty. For ``refused``.
        """
        t = self.terrain
        xs, ys = np.meshgrid(
            np.asarray(t.x, dtype=float), np.asarray(t.y, dtype=float), indexing="ij"
        )
        disc = (xs - x) ** 2 + (ys - y) ** 2 <= radius**2
        empty = np.zeros_like(disc)
        return (disc, empty) if LEGS[int(leg)].endswith("F") else (empty, disc)

    def with_refused(self, refused: tuple[Any, Any]) -> FootstepPlanner:
        """A planner like this one, with the (front, hind) masks ``refused`` as no footholds.

        The signed distance field is shared; the certificate cache starts anew.
        """
        return FootstepPlanner(
            self.robot, self.terrain, self.config, self.cost, self.sdf, refused=refused
        )

    @property
    def lattice(self) -> tuple[float, float, float, int, int]:
        """The foothold lattice (x0, y0, resolution, nx, ny) [m, m, m, -, -]."""
        x0, y0, h, nx, ny = self._core.lattice
        return float(x0), float(y0), float(h), int(nx), int(ny)

    @property
    def heuristic_scales(self) -> tuple[float, float]:
        """Cost per metre of the Euclidean (admissible) and Dubins heuristics [1/m]."""
        e, d = self._core.heuristic_scales
        return float(e), float(d)

    @property
    def sdf_error(self) -> float:
        """The SDF interpolation error bound added to the certified clearance [m]."""
        return float(self._core.sdf_error)

    @property
    def cache_size(self) -> int:
        """Certificate outcomes cached so far."""
        return int(self._core.cache_len)

    def plan(
        self,
        start: ArrayLike,
        goal: ArrayLike,
        time_limit: float | None = 5.0,
        expansions: int | None = None,
        callback: SolutionCallback | None = None,
        search: str = "arastar",
    ) -> FootstepPlan:
        """Plan from a trunk pose to a goal point.

        Parameters
        ----------
        start:
            Trunk (x, y, yaw) [m, m, rad]: the nominal stance is placed there.
        goal:
            Goal point (x, y) [m]; reached when the feet's centroid is within
            ``config.goal_radius`` of it.
        time_limit:
            Wall-clock budget [s]; None for none.
        expansions:
            Budget of expanded states: the deterministic mode (same inputs,
            same budget, same plan). With both budgets None the search runs
            until its plan is proven optimal or the space is exhausted.
        callback:
            Called with each improved :class:`SolutionReport` as it is found;
            returning True stops the search.
        search:
            ``"arastar"``, or ``"exhaustive"`` (Dijkstra; small instances only).

        Returns
        -------
        FootstepPlan
            Bad input (NaN, a start or goal off the terrain, a start stance
            without a pose certificate) gives status ``invalid_input`` with a
            reason rather than an exception.

        """
        s = self._vector(start, 3, "start")
        g = self._vector(goal, 2, "goal")
        self._goal = (float(g[0]), float(g[1]))
        raw = self._run(
            g,
            time_limit,
            expansions,
            callback,
            search,
            start_pose=tuple(float(v) for v in s),
        )
        return self._result(raw, tuple(float(v) for v in s), self._goal)

    def replan(
        self,
        feet: ArrayLike,
        next_leg: str = "LH",
        goal: ArrayLike | None = None,
        time_limit: float | None = 2.0,
        expansions: int | None = None,
        callback: SolutionCallback | None = None,
        trunk: tuple[ArrayLike, ArrayLike] | None = None,
    ) -> FootstepPlan:
        """Plan again from the feet where they stand (after an execution error).

        ``feet`` (4, 2) or (4, 3) [m] in canonical order (LF, RF, LH, RH; z is
        ignored); ``next_leg`` moves first; ``goal`` defaults to the last
        plan's. Its own budget: ``time_limit`` [s] (the paper's recovery
        target is 2 s) and/or ``expansions``. Certificates computed by
        earlier plans on this terrain are reused. ``trunk``, the measured
        trunk position (3,) [m] and quaternion (4,) (w, x, y, z): where the
        pose guessed from the feet gives the start stance no certificate, one
        is searched from there, keeping the body only
        ``certificate.start_clearance`` off the terrain (the robot stands
        there already); the stances the plan reaches are certified as ever.
        """
        if goal is None:
            if self._goal is None:
                raise InvalidArgumentError("replan needs a goal: no earlier plan to take it from")
            g = np.asarray(self._goal, dtype=float)
        else:
            g = self._vector(goal, 2, "goal")
        if next_leg not in LEG_INDEX:
            raise InvalidArgumentError(
                f"next_leg {next_leg!r} is not a leg; known: {', '.join(LEG_INDEX)}"
            )
        try:
            f = np.asarray(feet, dtype=float)
        except (TypeError, ValueError):
            raise InvalidArgumentError(
                f"feet must be numbers of shape (4, 2), got {feet!r}"
            ) from None
        if f.ndim != 2 or f.shape[0] != 4 or f.shape[1] not in (2, 3):
            raise InvalidArgumentError(f"feet must have shape (4, 2) or (4, 3), got {f.shape}")
        start_trunk = None
        if trunk is not None:
            pos = self._vector(trunk[0], 3, "trunk position")
            quat = self._vector(trunk[1], 4, "trunk quaternion")
            start_trunk = (tuple(float(v) for v in pos), tuple(float(v) for v in quat))
        self._goal = (float(g[0]), float(g[1]))
        raw = self._run(
            g,
            time_limit,
            expansions,
            callback,
            "arastar",
            start_feet=np.ascontiguousarray(f[:, :2]),
            next_leg=LEG_INDEX[next_leg],
            start_trunk=start_trunk,
        )
        return self._result(raw, tuple(float(v) for v in f[:, :2].ravel()), self._goal)

    # ---- internals ----------------------------------------------------------------

    @staticmethod
    def _vector(value: ArrayLike, n: int, what: str) -> np.ndarray:
        try:
            a = np.asarray(value, dtype=float).reshape(-1)
        except (TypeError, ValueError):
            raise InvalidArgumentError(f"{what} must be {n} numbers, got {value!r}") from None
        if a.shape != (n,):
            raise InvalidArgumentError(f"{what} must be {n} numbers, got {a.size}")
        return a

    def _run(
        self,
        goal: np.ndarray,
        time_limit: float | None,
        expansions: int | None,
        callback: SolutionCallback | None,
        search: str,
        **start: Any,
    ) -> dict[str, Any]:
        if time_limit is not None and not (math.isfinite(time_limit) and time_limit >= 0):
            raise InvalidArgumentError(
                f"time_limit must be a finite number of seconds >= 0, got {time_limit}"
            )
        if expansions is not None and expansions < 0:
            raise InvalidArgumentError(f"expansions must be >= 0, got {expansions}")
        wrapped = None
        if callback is not None:

            def wrapped(report: dict[str, Any]) -> bool:
                return bool(callback(_report(report)))

        return dict(
            self._core.plan(
                (float(goal[0]), float(goal[1])),
                time_limit=time_limit,
                expansions=expansions,
                callback=wrapped,
                search=search,
                **start,
            )
        )

    def _certificate(self, raw: dict[str, Any], step: int) -> PoseCertificate:
        return PoseCertificate(
            step=step,
            base_pos=np.asarray(raw["base_pos"], dtype=float),
            base_quat=np.asarray(raw["base_quat"], dtype=float),
            q=self.robot.from_canonical(np.asarray(raw["q"], dtype=float)),
            com=np.asarray(raw["com"], dtype=float),
            com_margin=float(raw["com_margin"]),
            clearance=float(raw["clearance"]),
            singularity=float(raw["singularity"]),
            penalty=float(raw["penalty"]),
            iterations=int(raw["iterations"]),
        )

    def _result(
        self, raw: dict[str, Any], start: tuple[float, ...], goal: tuple[float, float]
    ) -> FootstepPlan:
        start_cert = raw["start_certificate"]
        failures = raw["certificate_failures"]
        return FootstepPlan(
            status=str(raw["status"]),
            reason=raw["message"],
            footsteps=tuple(
                Footstep(LEGS[leg], float(x), float(y), float(z))
                for leg, x, y, z in raw["footsteps"]
            ),
            certificates=tuple(
                self._certificate(c, k + 1) for k, c in enumerate(raw["certificates"])
            ),
            initial_pose=None if start_cert is None else self._certificate(start_cert, 0),
            heuristic=str(raw["heuristic"]),
            bound_guaranteed=bool(raw["bound_guaranteed"]),
            epsilon0=float(raw["epsilon0"]),
            epsilon_decrement=float(raw["epsilon_decrement"]),
            final_epsilon=float(raw["final_epsilon"]),
            epsilon_bound=float(raw["epsilon_bound"]),
            cost=None if raw["cost"] is None else float(raw["cost"]),
            solutions=tuple(_report(s) for s in raw["solutions"]),
            states_expanded=int(raw["states_expanded"]),
            states_generated=int(raw["states_generated"]),
            actions_evaluated=int(raw["actions_evaluated"]),
            search_s=float(raw["search_s"]),
            elapsed_s=float(raw["elapsed_s"]),
            certificate_cache_hits=int(raw["certificate_cache_hits"]),
            certificate_rounds=int(raw["certificate_rounds"]),
            certificate_failures=dict(zip(_FAILURES, (int(v) for v in failures), strict=True)),
            tree=np.asarray(raw["tree"], dtype=float).reshape(-1, 5),
            robot=self.robot.name,
            terrain=self.terrain.spec,
            start=start,
            goal=goal,
            start_off_foothold=(
                None if raw["start_off_foothold"] is None else LEGS[raw["start_off_foothold"]]
            ),
        )


def _report(raw: dict[str, Any]) -> SolutionReport:
    return SolutionReport(
        time_s=float(raw["time_s"]),
        cost=float(raw["cost"]),
        epsilon=float(raw["epsilon"]),
        epsilon_bound=float(raw["epsilon_bound"]),
        expansions=int(raw["expansions"]),
    )


def plan_footsteps(
    robot: Robot,
    terrain: Terrain,
    start: ArrayLike,
    goal: ArrayLike,
    time_limit: float | None = 5.0,
    *,
    expansions: int | None = None,
    cost: FootholdCost | None = None,
    callback: SolutionCallback | None = None,
    **config: Any,
) -> FootstepPlan:
    """Plan footsteps for ``robot`` on ``terrain`` from trunk pose ``start`` to ``goal``.

    ``start`` is (x, y, yaw) [m, m, rad], ``goal`` (x, y) [m].

    ``config`` overrides :meth:`FootstepConfig.for_robot` fields
    (``heuristic="euclidean"``, ``epsilon0=2``, ``certificate_clearance=0.006``).
    See :meth:`FootstepPlanner.plan` for the budgets and the result.
    """
    planner = FootstepPlanner(robot, terrain, FootstepConfig.for_robot(robot, **config), cost)
    return planner.plan(start, goal, time_limit, expansions, callback)
