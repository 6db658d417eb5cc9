"""ZMP preview control (Kajita 2003) and the ZMP reference of Zucker 2011, §5.2."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from roughwalk.errors import InvalidArgumentError
from roughwalk.trajectories.timing import StepTiming
from roughwalk.trajectories.zmp_preview import ZmpPreviewController, riccati_doubling
from roughwalk.trajectories.zmp_reference import (
    ZmpReference,
    inside_triangle,
    shortcut_anchor,
    shrink_triangle,
)

DT = 0.02


def _crawl_reference() -> tuple[ZmpReference, list[StepTiming]]:
    anchors = np.array(
        [
            [0.0, 0.0],
            [0.01, 0.02],
            [0.03, -0.015],
            [0.045, 0.02],
            [0.06, -0.02],
            [0.07, 0.0],
            [0.07, 0.0],
        ]
    )
    timings = [StepTiming(0.3, 0.4)] * 4 + [StepTiming(0.3, 0.4, settle_s=1.6)]
    # The cart stands still for 0.6 s first: preview control needs warning of a move.
    return ZmpReference.through_anchors(anchors, timings, start_time=0.6), timings


@settings(max_examples=40, deadline=None)
@given(
    com_height=st.floats(0.05, 1.0),
    dt=st.sampled_from([0.002, 0.005, 0.01, 0.02, 0.04]),
    jerk_weight=st.floats(1e-9, 1e-3),
)
def test_riccati_doubling_equals_scipy(com_height: float, dt: float, jerk_weight: float) -> None:
    """The doubling algorithm finds scipy's stabilising P of the cart-table DARE."""
    from scipy.linalg import solve_discrete_are

    t = dt
    a = np.array([[1.0, t, t * t / 2], [0.0, 1.0, t], [0.0, 0.0, 1.0]])
    b = np.array([[t**3 / 6], [t * t / 2], [t]])
    c = np.array([[1.0, 0.0, -com_height / 9.81]])
    q, r = c.T @ c, np.array([[jerk_weight]])
    p = riccati_doubling(a, b, q, r)
    reference = solve_discrete_are(a, b, q, r)
    scale = np.max(np.abs(reference))
    assert np.max(np.abs(p - reference)) <= 1e-9 * scale
    # And it solves the equation itself, not just agrees with scipy.
    k = np.linalg.solve(r + b.T @ p @ b, b.T @ p @ a)
    residual = a.T @ p @ a - p - a.T @ p @ b @ k + q
    assert np.max(np.abs(residual)) <= 1e-10 * scale
    # Stabilising: the closed loop's eigenvalues lie inside the unit circle.
    assert np.max(np.abs(np.linalg.eigvals(a - b @ k))) < 1.0


def test_riccati_doubling_reports_failure() -> None:
    """An unstabilisable pair (an unstable mode B cannot reach) raises instead of looping."""
    a = np.diag([2.0, 0.5])
    b = np.array([[0.0], [1.0]])
    with pytest.raises(InvalidArgumentError, match="did not converge"):
        riccati_doubling(a, b, np.eye(2), np.eye(1))


def test_riccati_solution_and_gains() -> None:
    c = ZmpPreviewController(0.17, DT)
    a, b = c.A, c.B
    q = c.C.T @ c.C
    p = c.P
    g = np.linalg.inv(1e-6 + b.T @ p @ b)
    residual = a.T @ p @ a - a.T @ p @ b @ g @ b.T @ p @ a + q - p
    assert np.abs(residual).max() < 1e-6 * np.abs(p).max()
    assert np.all(np.abs(np.linalg.eigvals(a - b @ c.K[None])) < 1)  # stable closed loop
    # A ZMP held at rest must keep the cart at rest: Σ f_j = K·(1, 0, 0).
    assert c.preview_gains(400).sum() == pytest.approx(c.K[0], rel=1e-9)


def test_preview_tracks_the_reference_and_starts_and_ends_at_rest() -> None:
    ref, _ = _crawl_reference()
    t = np.arange(0.0, ref.end_time + 1e-9, DT)
    samples = ref.sample(t)
    c = ZmpPreviewController(0.17, DT)
    run = c.run(samples, len(t) - 1, preview=75)
    # Starts at rest on the reference; the preview begins moving it by jerk only.
    np.testing.assert_allclose(run.com[0], samples[0])
    np.testing.assert_allclose(run.com_velocity[0], 0.0)
    np.testing.assert_allclose(run.com_acceleration[0], 0.0)
    err = np.linalg.norm(run.zmp - samples, axis=1)
    assert err.max() < 0.004
    assert np.sqrt(np.mean(err**2)) < 0.001
    # Ends at rest over the last anchor after the settling phase.
    assert np.linalg.norm(run.com[-1] - samples[-1]) < 1e-3
    assert np.linalg.norm(run.com_velocity[-1]) < 5e-3
    assert np.linalg.norm(run.com_acceleration[-1]) < 5e-2
    # Its ZMP is the cart-table's: c − (z_c/g)·c̈.
    np.testing.assert_allclose(run.zmp, run.com - 0.17 / 9.81 * run.com_acceleration, atol=1e-12)


def test_preview_improves_with_a_longer_window() -> None:
    ref, _ = _crawl_reference()
    t = np.arange(0.0, ref.end_time + 1e-9, DT)
    samples = ref.sample(t)
    c = ZmpPreviewController(0.17, DT)
    errors = [
        np.abs(c.run(samples, len(t) - 1, preview=n).zmp - samples).max() for n in (2, 10, 75)
    ]
    assert errors[0] > errors[1] > errors[2]


def test_a_run_continues_where_the_last_one_stopped() -> None:
    ref, _ = _crawl_reference()
    t = np.arange(0.0, ref.end_time + 1e-9, DT)
    samples = ref.sample(t)
    c = ZmpPreviewController(0.17, DT)
    whole = c.run(samples, 60, preview=50)
    first = c.run(samples, 25, preview=50)
    second = c.run(samples[25:], 35, first.final_state, preview=50)
    np.testing.assert_allclose(second.com, whole.com[25:], atol=1e-12)


def test_reference_through_anchors_shifts_then_holds() -> None:
    ref, timings = _crawl_reference()
    # During the swing of step 2 the reference holds anchor 2; mid-shift it is halfway.
    t_swing = 0.6 + timings[0].duration_s + timings[1].shift_s + 0.2
    np.testing.assert_allclose(ref.sample([t_swing])[0], [0.03, -0.015])
    t_mid = 0.6 + timings[0].duration_s + timings[1].shift_s / 2
    np.testing.assert_allclose(ref.sample([t_mid])[0], [0.02, 0.0025])
    with pytest.raises(InvalidArgumentError, match="anchors"):
        ZmpReference.through_anchors(np.zeros((3, 2)), timings)


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 10_000))
def test_shortcut_is_inside_the_shrunk_triangle_and_never_longer(seed: int) -> None:
    rng = np.random.default_rng(seed)
    tri = rng.uniform(-0.1, 0.1, (3, 2))
    inner = shrink_triangle(tri, 0.01)
    centre = inner.mean(axis=0)
    prev, nxt = rng.uniform(-0.15, 0.15, (2, 2))
    p = shortcut_anchor(prev, centre, nxt, tri, 0.01)
    assert inside_triangle(p[None], inner, tol=1e-9)[0]

    def length(x: np.ndarray) -> float:
        return float(np.linalg.norm(x - prev) + np.linalg.norm(x - nxt))

    assert length(p) <= length(centre) + 1e-12
    # Brute force over a dense grid of the shrunk triangle: nothing much shorter.
    w = rng.dirichlet(np.ones(3), 4000)
    grid = w @ inner
    best = min(length(g) for g in grid)
    assert length(p) <= best + 2e-3


def test_shrunk_triangle_keeps_the_margin() -> None:
    tri = np.array([[0.0, 0.0], [0.2, 0.0], [0.0, 0.1]])
    inner = shrink_triangle(tri, 0.01)
    from roughwalk.trajectories.support_polygon import convex_polygon, polygon_margin

    margins, _ = polygon_margin(inner, convex_polygon(tri))
    np.testing.assert_allclose(margins, 0.01, atol=1e-12)


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 10_000))
def test_shrunk_triangle_by_margin_alone_is_the_incentre_scaling(seed: int) -> None:
    rng = np.random.default_rng(seed)
    tri = rng.uniform(-0.1, 0.1, (3, 2))
    a, b, c = (np.linalg.norm(tri[(i + 1) % 3] - tri[(i + 2) % 3]) for i in range(3))
    centre = (a * tri[0] + b * tri[1] + c * tri[2]) / (a + b + c)
    area = _area(tri)
    r = 2.0 * area / (a + b + c)
    margin = rng.uniform(0.0, 1.5 * r)
    expected = centre + max(r - margin, 0.0) / r * (tri - centre)
    np.testing.assert_allclose(shrink_triangle(tri, margin), expected, atol=1e-12)


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 10_000), st.floats(0.0, 0.3))
def test_shrunk_triangle_plans_the_least_load_on_every_foot(seed: int, share: float) -> None:
    rng = np.random.default_rng(seed)
    tri = rng.uniform(-0.1, 0.1, (3, 2))
    edges = np.linalg.norm(tri[[1, 2, 0]] - tri[[2, 0, 1]], axis=1)
    area = _area(tri)
    # No support triangle is flatter than a foot: on one a few µm high
    # (seed 3371: 8 µm) the static force solve's regularisation, not the
    # geometry, sets the loads (shares 0.497 against 0.500).
    assume(2 * area / edges.max() >= 0.002)
    inner = shrink_triangle(tri, 0.01, min_share=share)
    from roughwalk.trajectories.contact_forces import static_contact_forces
    from roughwalk.trajectories.support_polygon import convex_polygon, polygon_margin

    # Any point of the inner triangle: at least the share of the weight on
    # every foot, and the margin from every edge (while the triangle is not
    # shrunk to a point).
    w = rng.dirichlet(np.ones(3), 50)
    zmp = w @ inner
    feet = np.zeros((50, 4, 3))
    feet[:, :3, :2] = tri
    feet[:, 3, :2] = 1.0
    support = np.tile([True, True, True, False], (50, 1))
    mass, g = 2.0, 9.81
    loads = static_contact_forces(feet, support, zmp, np.zeros((50, 3)), mass, g)[:, :3, 2]
    least = np.maximum(0.01 * edges / (2 * area), share)
    if least.sum() < 1.0:
        # (static_contact_forces regularises its solve: loads to ~1e-5 N)
        assert np.all(loads >= share * mass * g - 1e-4)
        margins, _ = polygon_margin(zmp, convex_polygon(tri))
        assert np.all(margins >= 0.01 - 1e-9)
    else:
        # One point, whose shares are in the ratio of what the edges ask for.
        np.testing.assert_allclose(inner, np.repeat(inner[:1], 3, axis=0), atol=1e-12)
        np.testing.assert_allclose(
            loads / (mass * g), np.tile(least / least.sum(), (50, 1)), atol=1e-4
        )


def test_the_least_load_keeps_the_zmp_off_the_diagonal() -> None:
    # A crawl's support triangle: front left, hind right, and the third foot
    # (front right) 12 cm off the diagonal; 18 % of the weight on it keeps
    # the ZMP 2.16 cm off the diagonal, where a margin of 1.5 cm put 12.5 %.
    tri = np.array([[0.1, 0.075], [-0.1, -0.075], [0.1, -0.075]])
    diagonal = np.array([0.6, -0.8])  # unit normal of the diagonal, toward the third foot
    by_margin = (shrink_triangle(tri, 0.015) - tri[0]) @ diagonal
    assert float(np.min(by_margin)) == pytest.approx(0.015, abs=1e-9)
    by_load = (shrink_triangle(tri, 0.015, min_share=0.18) - tri[0]) @ diagonal
    assert float(np.min(by_load)) == pytest.approx(0.18 * 0.12, abs=1e-9)


def _area(tri: np.ndarray) -> float:
    u, v = tri[1] - tri[0], tri[2] - tri[0]
    return 0.5 * abs(float(u[0] * v[1] - u[1] * v[0]))
