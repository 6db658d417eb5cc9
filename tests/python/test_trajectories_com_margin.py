"""``zmp.com_margin``: the planned CoM kept inside each swing's support triangle."""

from __future__ import annotations

import numpy as np
import pytest

import roughwalk as rw
from roughwalk import _core
from roughwalk.errors import ConfigError
from roughwalk.trajectories.footstep_trajectory import swing_com_margins
from roughwalk.trajectories.generator import FootstepTrajectoryGenerator, next_start

HAVE_PLANNER = hasattr(_core, "FootstepPlanner")


def cross(u: np.ndarray, v: np.ndarray) -> float:
    return float(u[0] * v[1] - u[1] * v[0])


def brute_margins(points: np.ndarray, triangle: np.ndarray) -> np.ndarray:
    """Signed distance of each point to the triangle's boundary, inside positive, by brute force."""
    tri = triangle[:, :2]
    out = []
    for p in points:
        dists = []
        for i in range(3):
            a, b = tri[i], tri[(i + 1) % 3]
            t = np.clip((p - a) @ (b - a) / ((b - a) @ (b - a)), 0.0, 1.0)
            dists.append(np.linalg.norm(p - (a + t * (b - a))))
        # Inside: every corner sees p on the same side as the opposite corner.
        signs = [
            np.sign(cross(tri[(i + 1) % 3] - tri[i], p - tri[i]))
            * np.sign(cross(tri[(i + 1) % 3] - tri[i], tri[(i + 2) % 3] - tri[i]))
            for i in range(3)
        ]
        inside = all(s >= 0 for s in signs)
        out.append(min(dists) if inside else -min(dists))
    return np.array(out)


@pytest.fixture(scope="module")
def crawl():
    if not HAVE_PLANNER:
        pytest.skip("the footstep planner's core is not built")
    from roughwalk.planning.footstep_planner import plan_footsteps

    robot = rw.load_robot("littledog")
    terrain = rw.load_terrain("large_rocks:seed=3")
    plan = plan_footsteps(robot, terrain, (0.2, 0.0, 0.0), (0.6, 0.0), time_limit=5.0)
    assert plan.solved, plan.reason
    return robot, terrain, plan


def initial_states(robot, terrain, plan, com_margin: float) -> list:
    """Each step's initial trajectory (after re-timing) from where the last one ended."""
    cfg = rw.trajectories.trajectory_config(**{"zmp.com_margin": com_margin})
    gen = FootstepTrajectoryGenerator(robot, terrain, config=cfg)
    prepared = gen.prepare(plan)
    start = prepared.start
    out = []
    for k in range(len(prepared.sequence)):
        use = prepared.shortcuts[k] is not None
        state, _ = gen._retimed(prepared, k, start, use, 1.0, 1.0)
        out.append((gen, prepared, k, start, use, state))
        start = next_start(state)
    return out


def test_swing_com_margins_match_brute_force(crawl) -> None:
    robot, terrain, plan = crawl
    for _, _, _, _, _, state in initial_states(robot, terrain, plan, 0.0)[:6]:
        com = state.preview.com[state.lift_off : state.touchdown + 1]
        expected = brute_margins(com, np.asarray(state.step.support_triangle))
        np.testing.assert_allclose(swing_com_margins(state), expected, atol=1e-12)


def test_the_com_margin_raises_every_short_swing_and_leaves_the_others(crawl) -> None:
    robot, terrain, plan = crawl
    need = 0.01
    off = initial_states(robot, terrain, plan, 0.0)
    short = 0
    for gen0, _prepared, k, start, use, state in off:
        cfg = rw.trajectories.trajectory_config(**{"zmp.com_margin": need})
        gen = FootstepTrajectoryGenerator(robot, terrain, config=cfg, sdf=gen0.sdf)
        kept, _ = gen._retimed(gen.prepare(plan), k, start, use, 1.0, 1.0)
        before, after = swing_com_margins(state).min(), swing_com_margins(kept).min()
        if before >= need:
            # Already inside: the same trajectory, untouched.
            assert kept.timing == state.timing
            np.testing.assert_array_equal(kept.preview.com, state.preview.com)
        else:
            short += 1
            assert after > before + 1e-3, (k, before, after)
            assert kept.timing.duration_s <= gen.config.timing.max_step_s + 1e-9
    # The default crawl comes within the margin on most swings of this course.
    assert short >= len(off) // 2


def test_config_rejects_a_negative_com_margin() -> None:
    with pytest.raises(ConfigError, match="com_margin"):
        rw.trajectories.trajectory_config(**{"zmp.com_margin": -0.01})
