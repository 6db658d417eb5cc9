"""Batched whole-body kinematics of the trajectories wing: references and finite differences."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import roughwalk as rw
from roughwalk import _core
from roughwalk.robots import reference_fk
from roughwalk.trajectories.euler import (
    matrix_to_rpy,
    quat_to_rpy,
    rpy_rate_matrix,
    rpy_to_matrix,
    rpy_to_quat,
)
from roughwalk.trajectories.support_polygon import convex_polygon, polygon_margin
from roughwalk.trajectories.whole_body import WholeBody


@pytest.fixture(scope="module")
def wb(littledog: rw.Robot) -> WholeBody:
    return WholeBody(littledog)


def _random_q(littledog: rw.Robot, n: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    q0 = littledog.to_canonical(littledog.nominal_q).reshape(4, 3)
    return q0[None] + rng.normal(0.0, 0.25, (n, 4, 3))


def test_link_frames_match_the_reference_chain(littledog: rw.Robot, wb: WholeBody) -> None:
    q = _random_q(littledog, 6, 0)
    positions, rotations, _, _ = wb.link_frames(q)
    for n in range(q.shape[0]):
        for i, leg in enumerate(littledog.leg_descriptions):
            p, r = reference_fk.leg_link_frames(leg, q[n, i])
            np.testing.assert_allclose(positions[n, i], p, atol=1e-12)
            np.testing.assert_allclose(rotations[n, i], r, atol=1e-12)


def test_feet_com_and_ik_agree_with_the_robot(littledog: rw.Robot, wb: WholeBody) -> None:
    q = _random_q(littledog, 4, 1)
    feet = wb.foot_positions(q)
    com = wb.center_of_mass(q)
    for n in range(q.shape[0]):
        q12 = littledog.from_canonical(q[n].reshape(12))
        np.testing.assert_allclose(feet[n], littledog.foot_positions(q12), atol=1e-12)
        np.testing.assert_allclose(com[n], littledog.center_of_mass(q12), atol=1e-12)
    nominal = littledog.to_canonical(littledog.nominal_q).reshape(1, 4, 3)
    q_ik, reached = wb.inverse_kinematics(wb.foot_positions(nominal))
    assert reached.all()
    np.testing.assert_allclose(wb.foot_positions(q_ik), wb.foot_positions(nominal), atol=1e-9)


def test_body_points_lie_on_the_collision_capsules(littledog: rw.Robot, wb: WholeBody) -> None:
    q = _random_q(littledog, 3, 2)
    p_base, _ = wb.points_base(q)
    pts = wb.points
    for n in range(q.shape[0]):
        a, b = wb.collision.world_segments(littledog, littledog.from_canonical(q[n].reshape(12)))
        for u in range(len(pts)):
            k = pts.primitive[u]
            ab = b[k] - a[k]
            t = np.clip((p_base[n, u] - a[k]) @ ab / max(ab @ ab, 1e-18), 0, 1)
            assert np.linalg.norm(a[k] + t * ab - p_base[n, u]) < 1e-12


def _pose_points(wb: WholeBody, feet_w, x, rpy, held_q, support):
    rot = rpy_to_matrix(rpy)
    q, _ = wb.inverse_kinematics(((feet_w - x) @ rot)[None])
    q = np.where(support[:, None], q[0], held_q)[None]
    p_base, _ = wb.points_base(q)
    return x + p_base[0] @ rot.T


def test_body_pass_jacobians_match_finite_differences(littledog: rw.Robot, wb: WholeBody) -> None:
    """Zucker 2011 §3.4: supporting legs follow by IK, the lifted leg rides rigidly."""
    stance = littledog.nominal_stance
    feet_w = stance.feet + [0.0, 0.0, stance.base_height]
    support = np.array([True, False, True, True])
    held_q = littledog.to_canonical(littledog.nominal_q).reshape(4, 3) + [0.1, 0.3, -0.2]
    x0 = np.array([0.01, -0.005, stance.base_height + 0.01])
    rpy0 = np.array([0.05, -0.03, 0.1])
    rot = rpy_to_matrix(rpy0)
    q, _ = wb.inverse_kinematics(((feet_w - x0) @ rot)[None])
    q = np.where(support[:, None], q[0], held_q)[None]
    world, jac = wb.body_pass_jacobians(
        q, x0[None], rot[None], rpy0[None], support[None], damping=0.0
    )
    np.testing.assert_allclose(
        world[0], _pose_points(wb, feet_w, x0, rpy0, held_q, support), atol=1e-12
    )
    h = 1e-6
    for k in range(6):
        d = np.zeros(6)
        d[k] = h
        plus = _pose_points(wb, feet_w, x0 + d[:3], rpy0 + d[3:], held_q, support)
        minus = _pose_points(wb, feet_w, x0 - d[:3], rpy0 - d[3:], held_q, support)
        np.testing.assert_allclose(jac[0, :, :, k], (plus - minus) / (2 * h), atol=1e-6)


def test_swing_pass_jacobians_match_finite_differences(littledog: rw.Robot, wb: WholeBody) -> None:
    q = _random_q(littledog, 1, 3)
    x = np.array([0.2, 0.1, 0.15])
    rot = rpy_to_matrix([0.1, -0.2, 0.3])
    leg = 2
    frames = wb.link_frames(q)
    p_base, _ = wb.points_base(q, frames)
    u = np.flatnonzero(wb.points.leg == leg)
    t = np.zeros_like(u)
    jac = wb.swing_pass_jacobians_at(frames, p_base[0, u], rot[None], t, u)
    h = 1e-6
    for j in range(3):
        dq = np.zeros((1, 4, 3))
        dq[0, leg, j] = h
        plus = x + wb.points_base(q + dq)[0][0, u] @ rot.T
        minus = x + wb.points_base(q - dq)[0][0, u] @ rot.T
        np.testing.assert_allclose(jac[:, :, j], (plus - minus) / (2 * h), atol=1e-7)


@settings(max_examples=40, deadline=None)
@given(st.floats(-1.2, 1.2), st.floats(-1.4, 1.4), st.floats(-3.1, 3.1))
def test_euler_angles_round_trip_and_rate_map(roll: float, pitch: float, yaw: float) -> None:
    rpy = np.array([roll, pitch, yaw])
    rot = rpy_to_matrix(rpy)
    np.testing.assert_allclose(rot @ rot.T, np.eye(3), atol=1e-12)
    np.testing.assert_allclose(matrix_to_rpy(rot), rpy, atol=1e-9)
    np.testing.assert_allclose(quat_to_rpy(rpy_to_quat(rpy)), rpy, atol=1e-9)
    # ω = E·ṙpy: [ω]× = Ṙ·Rᵀ.
    h = 1e-6
    e = rpy_rate_matrix(rpy)
    for k in range(3):
        d = np.zeros(3)
        d[k] = h
        rdot = (rpy_to_matrix(rpy + d) - rpy_to_matrix(rpy - d)) / (2 * h)
        w = rdot @ rot.T
        np.testing.assert_allclose([w[2, 1], w[0, 2], w[1, 0]], e[:, k], atol=1e-7)


def test_polygon_margin_matches_the_core_and_its_gradient() -> None:
    rng = np.random.default_rng(4)
    for _ in range(60):
        feet = rng.normal(0.0, 0.1, (int(rng.integers(3, 5)), 3))
        poly = convex_polygon(feet)
        pts = rng.normal(0.0, 0.15, (6, 2))
        margin, grad = polygon_margin(pts, poly)
        expected = [_core.support_polygon_margin(p, feet) for p in pts]
        np.testing.assert_allclose(margin, expected, atol=1e-12)
        h = 1e-7
        for a in range(2):
            d = np.zeros(2)
            d[a] = h
            fd = (polygon_margin(pts + d, poly)[0] - polygon_margin(pts - d, poly)[0]) / (2 * h)
            np.testing.assert_allclose(grad[:, a], fd, atol=1e-5)
