"""Footholds a foot slides off are refused: rims and slopes beyond the friction cone (issue 7).

On board AE (``bench_littledog.py --expansions 40000``, large rocks seeds 2
and 3) the bench's start put RF on the rim of a 7.5 cm rock, its centre
3 mm outside the top; as LF (seed 2) or RH (seed 3) swung, RF slid 3.5 cm
down the rock and the robot fell within 1.7 s (``footstep.edge_drop``).
With the rims refused, seed 1's plan put LF on a 52° flank, off which it
slid (``footstep.max_foothold_slope``, opt-in: at 45° no start of that
seed holds). The learned cost took both for footholds like their neighbours.
On the logs board (AD) the rim check alone let feet onto log flanks of
51–59° with less than 3 cm of drop beside them, off which they slid; the
slope limit refuses them and keeps the logs' tops. On the gap course a
walk's plan put RF on the trench floor 3 cm past the near wall, where its
knee met the rim (``footstep.wall_reach``).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

import roughwalk as rw
from roughwalk.planning import FootstepConfig, FootstepPlanner
from roughwalk.planning.foothold_safety import (
    contact_slopes,
    edge_footholds,
    leaning_footholds,
    resting_height,
    steep_footholds,
    wall_footholds,
)
from roughwalk.sim.footstep_source import planner_config
from roughwalk.terrain import Terrain

R = 0.0095  # LittleDog's foot radius [m]
DX = 0.001


def _rock_and_slope() -> Terrain:
    """Flat floor at 0, a 7.5 cm box rock (x ≥ 0.16, y < 0.16), a 30° ramp up from y = 0.16."""
    x = np.arange(0.0, 0.32, DX)
    xx, yy = np.meshgrid(x, x, indexing="ij")
    h = np.where((xx >= 0.16) & (yy < 0.16), 0.075, 0.0)
    h = np.where(yy >= 0.16, (yy - 0.16) * np.tan(np.radians(30.0)), h)
    return Terrain(h, x0=0.0, y0=0.0, dx=DX, dy=DX, name="rim")


def _cell(t: Terrain, x: float, y: float) -> tuple[int, int]:
    return int(round((x - t.x0) / t.dx)), int(round((y - t.y0) / t.dy))


def test_a_foot_near_a_rim_is_on_an_edge_beside_the_wall_and_on_a_slope_it_is_not() -> None:
    t = _rock_and_slope()
    edges = edge_footholds(t, R, drop=0.03)
    rest = resting_height(t, R)
    # Centre 3 mm outside the top: the foot rests on the rim's corner.
    outside = _cell(t, 0.157, 0.08)
    assert rest[outside] > 0.07
    assert edges[outside]
    # Centre 5 mm inside the top: resting flat on it, the floor 7.5 cm down within r.
    assert edges[_cell(t, 0.165, 0.08)]
    # Far inside the top, on the floor beside the wall (resting on the floor),
    # on the open floor and on the 30° ramp: no edge.
    for x, y in ((0.24, 0.08), (0.145, 0.08), (0.08, 0.08), (0.08, 0.24)):
        assert not edges[_cell(t, x, y)], (x, y)
    # The margin reaches farther in from the rim; drop 0 marks nothing.
    inside = _cell(t, 0.172, 0.08)
    assert not edges[inside]
    assert edge_footholds(t, R, drop=0.03, margin=0.005)[inside]
    assert not edge_footholds(t, R, drop=0.0).any()


def test_the_planner_refuses_a_foothold_on_the_rim_and_keeps_the_floor_and_ramp(
    littledog: rw.Robot,
) -> None:
    t = _rock_and_slope()
    on = FootstepPlanner(littledog, t, FootstepConfig.for_robot(littledog, edge_drop=0.03))
    off = FootstepPlanner(littledog, t, FootstepConfig.for_robot(littledog, edge_drop=0.0))
    i, j = _cell(t, 0.157, 0.08)
    assert np.isfinite(off.cost_front[i, j]) and np.isfinite(off.cost_hind[i, j])
    assert np.isinf(on.cost_front[i, j]) and np.isinf(on.cost_hind[i, j])
    # The floor and the ramp keep the learned cost.
    for x, y in ((0.08, 0.08), (0.08, 0.24)):
        k = _cell(t, x, y)
        assert on.cost_front[k] == off.cost_front[k]


def test_a_slope_steeper_than_the_friction_cone_is_steep_and_a_gentler_one_is_not() -> None:
    x = np.arange(0.0, 0.32, DX)
    xx, yy = np.meshgrid(x, x, indexing="ij")
    # Ramps up along x: 30° for y < 0.16, 50° beyond.
    slope = np.where(yy < 0.16, np.radians(30.0), np.radians(50.0))
    t = Terrain(xx * np.tan(slope), x0=0.0, y0=0.0, dx=DX, dy=DX, name="ramps")
    steep = steep_footholds(t, R, np.radians(45.0))
    assert not steep[_cell(t, 0.15, 0.08)]
    assert steep[_cell(t, 0.15, 0.24)]
    assert not steep_footholds(t, R, np.radians(55.0))[_cell(t, 0.15, 0.24)]
    assert not steep_footholds(t, R, 0.5 * np.pi).any()
    robot = rw.load_robot("littledog")
    on = FootstepPlanner(
        robot, t, FootstepConfig.for_robot(robot, max_foothold_slope=np.radians(45.0))
    )
    assert np.isfinite(on.cost_front[_cell(t, 0.15, 0.08)])
    assert np.isinf(on.cost_front[_cell(t, 0.15, 0.24)])


@pytest.fixture(scope="module")
def board_ae(littledog_board: Callable[[str], Terrain]) -> Terrain:
    return littledog_board("AE")


def test_the_bench_start_with_rf_on_a_rock_rim_of_board_ae_is_refused(
    littledog: rw.Robot, board_ae: Terrain
) -> None:
    # Large rocks seed 2's start (bench_littledog.course): RF on the rim.
    start = (0.16046448536997265, 0.30046982286828244, 0.03142257405942804)
    goal = (0.459, 0.3045)
    planner = FootstepPlanner(
        littledog, board_ae, FootstepConfig.for_robot(littledog, edge_drop=0.03)
    )
    refused = planner.plan(start, goal, time_limit=None, expansions=10)
    assert refused.status == "invalid_input"
    assert "foot RF" in (refused.reason or "") and "not on a foothold" in (refused.reason or "")
    assert refused.start_off_foothold == "RF"
    assert refused.to_json()["start_off_foothold"] == "RF"
    off = FootstepPlanner(littledog, board_ae, FootstepConfig.for_robot(littledog, edge_drop=0.0))
    assert off.plan(start, goal, time_limit=None, expansions=10).status != "invalid_input"


def test_the_52_degree_flank_large_rocks_seed_1_planned_lf_onto_is_refused(
    littledog: rw.Robot, board_ae: Terrain
) -> None:
    # LF's planned contact (step 9 of seed 1's plan, start nudged 3 cm right),
    # where LF slid off as RF swung and the robot rolled over.
    i, j = _cell(board_ae, 0.4495, 0.3535)
    on = FootstepPlanner(
        littledog,
        board_ae,
        FootstepConfig.for_robot(littledog, edge_drop=0.03, max_foothold_slope=0.785),
    )
    off = FootstepPlanner(littledog, board_ae, FootstepConfig.for_robot(littledog, edge_drop=0.03))
    assert np.isfinite(off.cost_front[i, j])
    assert np.isinf(on.cost_front[i, j])


@pytest.fixture(scope="module")
def board_ad(littledog_board: Callable[[str], Terrain]) -> Terrain:
    return littledog_board("AD")


def test_log_flanks_feet_slid_off_on_board_ad_pass_the_rim_check_and_the_slope_limit_refuses(
    littledog: rw.Robot, board_ad: Terrain
) -> None:
    # Logs seeds 1 and 3 with the fast options and the rim check alone
    # (bench_littledog.py --expansions 40000): the snapped start stance put
    # RF (seed 1) and RH (seed 3) on a log's flank with less than 3 cm of
    # drop beside them; RF slid 2 cm down it, RH 7 cm, and both runs fell.
    # Each flank is steeper than the friction cone (μ = 1, 45°).
    flanks = {"RF": (0.258, 0.226), "RH": (0.056, 0.272)}
    # Footholds on the logs' tops on which the same runs' feet held.
    tops = ((0.157, 0.408), (0.197, 0.272), (0.384, 0.272))
    r = littledog.foot_radius
    rim = edge_footholds(board_ad, r, drop=0.03)
    steep = steep_footholds(board_ad, r, np.radians(45.0))
    for x, y in flanks.values():
        assert not rim[_cell(board_ad, x, y)], (x, y)
        assert steep[_cell(board_ad, x, y)], (x, y)
    for x, y in tops:
        assert not rim[_cell(board_ad, x, y)] and not steep[_cell(board_ad, x, y)], (x, y)
    rim_only = FootstepPlanner(
        littledog, board_ad, FootstepConfig.for_robot(littledog, edge_drop=0.03)
    )
    both = FootstepPlanner(
        littledog,
        board_ad,
        FootstepConfig.for_robot(littledog, edge_drop=0.03, max_foothold_slope=np.radians(45.0)),
    )
    for leg, (x, y) in flanks.items():
        k = _cell(board_ad, x, y)
        cost = "cost_front" if leg.endswith("F") else "cost_hind"
        assert np.isfinite(getattr(rim_only, cost)[k])
        assert np.isinf(getattr(both, cost)[k])
    for x, y in tops:
        k = _cell(board_ad, x, y)
        assert both.cost_front[k] == rim_only.cost_front[k]
        assert both.cost_hind[k] == rim_only.cost_hind[k]


def _trench() -> Terrain:
    """Flat floor at 0 with a trench 12 cm wide and 10 cm deep from x = 0.10 to 0.22."""
    x = np.arange(0.0, 0.32, DX)
    xx, _ = np.meshgrid(x, x, indexing="ij")
    h = np.where((xx >= 0.10) & (xx < 0.22), -0.10, 0.0)
    return Terrain(h, x0=0.0, y0=0.0, dx=DX, dy=DX, name="trench")


def test_a_trench_floor_is_a_wall_foothold_where_the_knee_meets_the_rim() -> None:
    t = _trench()
    front = wall_footholds(t, R, reach=0.075, height=0.09, heading=0.0, end="front")
    hind = wall_footholds(t, R, reach=0.075, height=0.09, heading=0.0, end="hind")
    # 3 cm past the near wall: a front knee (behind the foot) meets its rim;
    # a hind knee (ahead) has 9 cm of floor before the far wall.
    assert front[_cell(t, 0.13, 0.16)] and not hind[_cell(t, 0.13, 0.16)]
    # 8 cm past the near wall, 4 cm before the far one: the other way round.
    assert not front[_cell(t, 0.18, 0.16)] and hind[_cell(t, 0.18, 0.16)]
    # The pads, a wall lower than the height, and a reach of 0 refuse nothing.
    for x in (0.05, 0.27):
        assert not front[_cell(t, x, 0.16)] and not hind[_cell(t, x, 0.16)]
    assert not wall_footholds(t, R, 0.075, 0.11, 0.0, "front").any()
    assert not wall_footholds(t, R, 0.0, 0.09, 0.0, "front").any()
    # Heading π: walking the other way, the far wall is behind the front feet.
    back = wall_footholds(t, R, reach=0.075, height=0.09, heading=np.pi, end="front")
    assert back[_cell(t, 0.18, 0.16)] and not back[_cell(t, 0.13, 0.16)]


def test_the_wall_check_refuses_rf_the_gap_floor_beside_the_near_wall_and_keeps_a_way_across(
    littledog: rw.Robot,
) -> None:
    # Gap seed 0 (bench_littledog.py --expansions 40000, session-15 defaults):
    # step 20 put RF on the trench floor at x = 0.970, 3 cm past the near wall
    # (x = 0.94); RF's shank came to rest on the rim, the foot hung 7 cm above
    # the floor, LF and RH lost their load and the foot-force reflex fired.
    gap = rw.load_terrain("gap")
    walk = FootstepPlanner(littledog, gap, planner_config(littledog, 0.4, {"wall_reach": 0.075}))
    unchecked = FootstepPlanner(littledog, gap, planner_config(littledog, 0.4, {}))
    rf = _cell(gap, 0.970, -0.037)
    assert np.isfinite(unchecked.cost_front[rf])
    assert np.isinf(walk.cost_front[rf])
    # The trench floor keeps footholds for both ends: front feet near its far
    # wall, hind feet near its near one, where the plans' other feet stood.
    assert np.isfinite(walk.cost_front[_cell(gap, 1.03, -0.04)])
    assert np.isfinite(walk.cost_hind[_cell(gap, 0.975, -0.068)])


@pytest.mark.parametrize("degrees", [10.0, 30.0, 50.0])
def test_a_foot_on_a_plane_leans_as_the_plane(degrees: float) -> None:
    """On a plane the resting sphere's contact leans by the plane's slope (grid-quantised)."""
    dx = 0.0005
    x = np.arange(0.0, 0.1, dx)
    h = np.tan(np.radians(degrees)) * x[:, None] * np.ones((1, len(x)))
    terrain = Terrain(h, x0=0.0, y0=0.0, dx=dx, dy=dx, name="plane")
    lean = np.degrees(contact_slopes(terrain, 0.0103))[50:-50, 50:-50]
    assert np.all(np.abs(lean - degrees) < 2.5)


def test_a_foot_lowered_beside_a_ridge_rests_on_its_corner() -> None:
    """A 5 mm ridge 3 mm wide on flat ground; a foot lowered with its centre 4.5 mm
    beside the ridge rests on the ridge's corner, leaning asin(4.5 / 10.3) = 26°."""
    dx = 0.0005
    x = np.arange(0.0, 0.1, dx)
    h = np.where(np.abs(x - 0.05) <= 0.0015 + 1e-9, 0.005, 0.0)[:, None] * np.ones((1, 40))
    terrain = Terrain(h, x0=0.0, y0=0.0, dx=dx, dy=dx, name="ridge")
    r = 0.0103
    i = int(round(0.044 / dx))  # foot centre 6 mm from the ridge's middle, 4.5 mm from its side
    lean = np.degrees(contact_slopes(terrain, r))[i, 20]
    assert lean == pytest.approx(np.degrees(np.arcsin(0.0045 / r)), abs=2.0)
    assert leaning_footholds(terrain, r, np.radians(20.0))[i, 20]
    assert not leaning_footholds(terrain, r, 0.5 * np.pi).any()

    # The planner refuses such a foothold with footstep.max_contact_slope, not without
    # (a board-sized copy on a 1 mm grid, for the learned cost's features).
    big = np.arange(0.0, 0.4, 0.001)
    ridge = np.where(np.abs(big - 0.2) <= 0.0015 + 1e-9, 0.005, 0.0)[:, None] * np.ones((1, 300))
    board = Terrain(ridge, x0=0.0, y0=0.0, dx=0.001, dy=0.001, name="ridge")
    robot = rw.load_robot("littledog")
    on = FootstepPlanner(
        robot, board, FootstepConfig.for_robot(robot, max_contact_slope=np.radians(20.0))
    )
    off = FootstepPlanner(robot, board, FootstepConfig.for_robot(robot))
    k = _cell(board, 0.194, 0.15)  # 5 mm beside the ridge: a 29° contact
    assert np.isinf(on.cost_front[k]) and np.isinf(on.cost_hind[k])
    assert np.isfinite(off.cost_front[k])
    assert np.isfinite(on.cost_front[_cell(board, 0.1, 0.15)])  # flat ground stays
