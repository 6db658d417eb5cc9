"""The collision model contains the robot's MJCF collision geoms (conservative, Zucker §3.3)."""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import roughwalk
from roughwalk.errors import RobotModelError
from roughwalk.robots.collision_model import CollisionModel, capsules_for_box


def _capsule_distance(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Distance (N,) from points p (N, 3) to segment a–b."""
    d = b - a
    dd = float(d @ d)
    t = np.zeros(len(p)) if dd < 1e-18 else np.clip((p - a) @ d / dd, 0.0, 1.0)
    return np.linalg.norm(p - (a + t[:, None] * d), axis=1)


def _inside_any(points: np.ndarray, wa: np.ndarray, wb: np.ndarray, r: np.ndarray) -> np.ndarray:
    inside = np.zeros(len(points), dtype=bool)
    for k in range(len(r)):
        inside |= _capsule_distance(points, wa[k], wb[k]) <= r[k] + 1e-12
    return inside


def _sample_geom(m: mujoco.MjModel, d: mujoco.MjData, g: int, rng, n: int) -> np.ndarray:
    """World points uniformly spread over the surface-and-interior of geom g (box, capsule, ...)."""
    size = m.geom_size[g]
    kind = m.geom_type[g]
    u = rng.uniform(-1, 1, size=(n, 3))
    if kind == mujoco.mjtGeom.mjGEOM_BOX:
        local = u * size
        local[: n // 2] = np.sign(local[: n // 2]) * size  # corners, the hardest points
    elif kind == mujoco.mjtGeom.mjGEOM_SPHERE:
        v = u / np.linalg.norm(u, axis=1, keepdims=True)
        local = v * size[0]
    elif kind == mujoco.mjtGeom.mjGEOM_CAPSULE:
        v = u / np.linalg.norm(u, axis=1, keepdims=True)
        local = v * size[0] + np.outer(rng.uniform(-1, 1, n), [0, 0, size[1]])
    elif kind == mujoco.mjtGeom.mjGEOM_CYLINDER:
        ang = rng.uniform(0, 2 * np.pi, n)
        local = np.column_stack(
            [size[0] * np.cos(ang), size[0] * np.sin(ang), size[1] * rng.choice([-1, 1], n)]
        )
    else:
        pytest.skip(f"geom type {kind} not sampled")
    return d.geom_xpos[g] + local @ d.geom_xmat[g].reshape(3, 3).T


@pytest.mark.parametrize("name", ["littledog", "anymal_c"])
def test_primitives_contain_every_collision_geom(name: str) -> None:
    robot = roughwalk.load_robot(name)
    cm = CollisionModel.from_robot(robot)
    m = robot.mj_model()
    d = mujoco.MjData(m)
    rng = np.random.default_rng(0)
    for _ in range(3):
        q = rng.uniform(np.maximum(robot.joint_lower, -3), np.minimum(robot.joint_upper, 3))
        pos = rng.normal(size=3)
        quat = rng.normal(size=4)
        quat /= np.linalg.norm(quat)
        d.qpos[:] = robot.qpos(q, pos, quat)
        mujoco.mj_kinematics(m, d)
        wa, wb = cm.world_segments(robot, q, pos, quat)
        for g in (geom.geom_id for geom in robot.collision_geoms):
            pts = _sample_geom(m, d, g, rng, 400)
            assert _inside_any(pts, wa, wb, cm.radius).all(), f"{name}: geom {g} not covered"


def test_feet_are_flagged_and_sit_at_the_foot_centres() -> None:
    robot = roughwalk.load_robot("anymal_c")
    cm = CollisionModel.from_robot(robot)
    assert cm.is_foot.sum() == 4
    wa, _ = cm.world_segments(robot, robot.nominal_q)
    feet = robot.foot_positions(robot.nominal_q)
    np.testing.assert_allclose(wa[cm.is_foot], feet, atol=1e-12)
    np.testing.assert_allclose(cm.radius[cm.is_foot], robot.foot_radius)


@settings(max_examples=60, deadline=None)
@given(
    st.lists(st.floats(0.001, 0.5), min_size=3, max_size=3),
    st.integers(0, 2**31 - 1),
)
def test_box_capsules_cover_the_box(half: list[float], seed: int) -> None:
    h = np.asarray(half)
    caps = capsules_for_box(h)
    rng = np.random.default_rng(seed)
    corners = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]) * h
    pts = np.vstack([corners, rng.uniform(-1, 1, (200, 3)) * h])
    wa = np.array([c[0] for c in caps])
    wb = np.array([c[1] for c in caps])
    r = np.array([c[2] for c in caps])
    assert _inside_any(pts, wa, wb, r).all()
    # ...and is not absurdly loose: radius at most the box's cross-section half-diagonal.
    s = np.sort(h)
    assert r.max() <= np.hypot(s[0], s[1]) + 1e-12


def test_padding_inflates_and_bad_padding_is_refused() -> None:
    robot = roughwalk.load_robot("littledog")
    base = CollisionModel.from_robot(robot)
    padded = CollisionModel.from_robot(robot, padding=0.005)
    np.testing.assert_allclose(padded.radius - base.radius, 0.005)
    with pytest.raises(RobotModelError, match="padding"):
        CollisionModel.from_robot(robot, padding=float("nan"))


def test_robot_show_and_info_cli(tmp_path: Path) -> None:
    import json

    from roughwalk.cli.main import main

    out = tmp_path / "r.json"
    assert main(["robot", "info", "littledog", "--json", str(out)]) == 0
    data = json.loads(out.read_text())
    assert data["schema"] == "robot_info" and data["robot"] == "littledog"
    assert abs(data["info"]["mass"] - 2.75) < 0.03
    assert set(data["info"]["nominal_stance"]["feet_base_frame"]) == {"LF", "RF", "LH", "RH"}
    png = tmp_path / "r.png"
    assert main(["robot", "show", "anymal_c", "-o", str(png)]) == 0
    assert png.stat().st_size > 20_000
    assert main(["robot", "info", "anymel"]) == 1


def _brute_capsule_distance(terrain, wa, wb, radius) -> float:
    """Capsule-to-terrain distance by dense sampling of both (no SDF code)."""
    from scipy.spatial import cKDTree

    lo = np.minimum(wa, wb) - radius - 0.03
    hi = np.maximum(wa, wb) + radius + 0.03
    xs = np.arange(lo[0], hi[0], 0.001)
    ys = np.arange(lo[1], hi[1], 0.001)
    gx, gy = np.meshgrid(xs, ys, indexing="ij")
    xy = np.column_stack([gx.ravel(), gy.ravel()])
    surface = np.column_stack([xy, terrain.height(xy)])
    t = np.linspace(0, 1, 200)[:, None]
    axis = wa + t * (wb - wa)
    dist, _ = cKDTree(surface).query(axis)
    return float(dist.min() - radius)


def test_whole_body_distance_matches_brute_force_and_names_the_link() -> None:
    robot = roughwalk.load_robot("littledog")
    terrain = roughwalk.load_terrain("barrier:resolution=0.004")
    sdf = terrain.sdf(resolution=0.004)
    cm = CollisionModel.from_robot(robot)
    q = robot.nominal_q
    # Trunk over the barrier, low enough that a leg link is the closest part.
    x_barrier = float(terrain.x[np.argmax(terrain.heights.max(axis=1))])
    base = np.array([x_barrier - 0.09, 0.0, robot.nominal_stance.base_height + 0.02])
    res = cm.distance(robot, sdf, q, base)
    wa, wb = cm.world_segments(robot, q, base)
    assert np.isinf(res.per_primitive[cm.is_foot]).all()
    k = res.primitive
    assert not cm.is_foot[k] and res.leg == cm.leg[k] and res.link == cm.link[k]
    exact = _brute_capsule_distance(terrain, wa[k], wb[k], cm.radius[k])
    voxel_half_diag = 0.5 * np.sqrt(3) * 0.004
    assert abs(res.distance - exact) <= voxel_half_diag + 1e-3
    # The minimum really is the minimum over the non-foot primitives.
    assert res.distance == pytest.approx(np.min(res.per_primitive))
    # Moving the closest point along the gradient increases the distance (first order).
    d_here, _ = sdf.query(res.point[None, :])
    d_moved, _ = sdf.query((res.point + 1e-3 * res.gradient)[None, :])
    assert d_moved[0] > d_here[0]
    # Feet included: the feet touch the ground in a nominal stance on the pad.
    flat = np.array([0.15, 0.0, robot.nominal_stance.base_height])
    with_feet = cm.distance(robot, sdf, q, flat, exclude_feet=False)
    assert cm.is_foot[with_feet.primitive] and abs(with_feet.distance) < 3e-3
