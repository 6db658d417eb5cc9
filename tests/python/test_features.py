"""Terrain features (Zucker 2011, §4.2): known surfaces, brute-force fits, orientation."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from roughwalk.errors import InvalidArgumentError, TerrainError
from roughwalk.terrain import Terrain, compute_features, generate, orient_features
from roughwalk.terrain.features import DEFAULT_RADII, FEATURE_NAMES

# An anisotropic grid with (0, 0) on a grid point, so that the x and y spacings
# are both exercised and the cell at the origin is easy to find.
DX, DY = 0.004, 0.005
NX, NY = 81, 61
X0, Y0 = -40 * DX, -30 * DY
I0, J0 = 40, 30
RADII = (0.012, 0.02, 0.03)


def grid_terrain(fn, x0=X0, y0=Y0, nx=NX, ny=NY, dx=DX, dy=DY) -> Terrain:
    x = x0 + dx * np.arange(nx)
    y = y0 + dy * np.arange(ny)
    gx, gy = np.meshgrid(x, y, indexing="ij")
    return Terrain(fn(gx, gy), x0, y0, dx, dy)


def block(features, n):
    """(nx, ny, 9) features of radius number n."""
    return features.values[:, :, n * 9 : (n + 1) * 9]


def rotation(psi):
    c, s = np.cos(psi), np.sin(psi)
    return np.array([[c, -s], [s, c]])


def brute_force_fit(terrain, i, j, radius, heading=0.0):
    """Least squares over the disc at cell (i, j), in the frame turned by ``heading``."""
    dx, dy = terrain.dx, terrain.dy
    p_max, q_max = int(radius / dx + 1e-9), int(radius / dy + 1e-9)
    r_t = rotation(heading).T
    rows, rhs = [], []
    for p in range(-p_max, p_max + 1):
        for q in range(-q_max, q_max + 1):
            u = np.array([p * dx, q * dy])
            if u @ u <= radius**2 * (1 + 1e-9):
                ux, uy = r_t @ u
                rows.append([ux * ux, 2 * ux * uy, uy * uy, ux, uy, 1.0])
                rhs.append(terrain.heights[i + p, j + q] - terrain.heights[i, j])
    a, b = np.array(rows), np.array(rhs)
    beta = np.linalg.lstsq(a, b, rcond=None)[0]
    rms = np.sqrt(np.mean((a @ beta - b) ** 2))
    return beta, rms


def test_names_and_layout():
    f = compute_features(grid_terrain(lambda x, y: 0 * x), radii=RADII)
    assert f.values.shape == (NX, NY, 9 * len(RADII))
    assert f.names[:9] == tuple(f"r0.012/{n}" for n in FEATURE_NAMES)
    assert f.names[9] == "r0.02/k_xx"
    assert f.index("r0.03/residual") == 26
    assert FEATURE_NAMES == (
        "k_xx",
        "k_xy",
        "k_yy",
        "k_x",
        "k_y",
        "lambda_min",
        "lambda_max",
        "grad_norm",
        "residual",
    )
    with pytest.raises(InvalidArgumentError, match="r0.012/k_xx"):
        f.index("r0.5/k_xx")


@pytest.mark.parametrize("height", [0.0, 0.37, -2.5])
def test_flat_gives_exactly_zero_for_every_radius(height):
    t = Terrain(np.full((70, 60), height), 0.0, 0.0, 0.005, 0.005)
    f = t.features(radii=DEFAULT_RADII)
    assert np.all(f.values == 0.0)


def test_flat_parts_of_a_mixed_terrain_are_exactly_zero():
    # FFT round-off from the wall spreads over the whole board; the flat ground
    # away from the wall must still give the zero vector.
    t = generate("barrier", resolution=0.005)
    f = compute_features(t, radii=(0.02, 0.06))
    x = t.x
    for n, r in enumerate(f.radii):
        far = np.abs(x - 1.0) > 0.025 + r + 2 * t.dx
        assert np.all(block(f, n)[far] == 0.0)
        # Cells whose disc crosses a face of the wall do see it.
        crossing = np.abs(np.abs(x - 1.0) - 0.025) < r - 2 * t.dx
        assert np.all(np.abs(block(f, n)[crossing]).max(axis=2) > 0)


def test_paraboloid_coefficients():
    a, b, c, d, e, f0 = 3.0, -1.2, 0.7, 0.4, -0.25, 0.05
    t = grid_terrain(lambda x, y: a * x * x + 2 * b * x * y + c * y * y + d * x + e * y + f0)
    f = compute_features(t, radii=RADII)
    gx, gy = np.meshgrid(t.x, t.y, indexing="ij")
    lam = np.linalg.eigvalsh(np.array([[a, b], [b, c]]))
    for n in range(len(RADII)):
        v = block(f, n)[f.valid_by_radius[n]]
        xc, yc = gx[f.valid_by_radius[n]], gy[f.valid_by_radius[n]]
        kx = 2 * a * xc + 2 * b * yc + d
        ky = 2 * b * xc + 2 * c * yc + e
        np.testing.assert_allclose(v[:, 0], a, atol=1e-6)
        np.testing.assert_allclose(v[:, 1], b, atol=1e-6)
        np.testing.assert_allclose(v[:, 2], c, atol=1e-6)
        np.testing.assert_allclose(v[:, 3], kx, atol=1e-6)
        np.testing.assert_allclose(v[:, 4], ky, atol=1e-6)
        np.testing.assert_allclose(v[:, 5], lam[0], atol=1e-6)
        np.testing.assert_allclose(v[:, 6], lam[1], atol=1e-6)
        np.testing.assert_allclose(v[:, 7], np.hypot(kx, ky), atol=1e-6)
        assert np.all(v[:, 8] < 1e-6)


coefficient = st.floats(-5.0, 5.0, allow_nan=False)


@settings(max_examples=30, deadline=None)
@given(
    st.tuples(*[coefficient] * 5),
    st.floats(-np.pi, np.pi),
    st.sampled_from([(0, 0), (5, -3), (-7, 6)]),
)
def test_any_quadratic_is_recovered_in_any_heading(coeffs, psi, cell):
    # Zucker's oriented features of z = uᵀKu + kᵀu at a cell c: K' = RᵀKR and
    # k' = Rᵀ(2Kc + k), with zero residual.
    a, b, c, d, e = coeffs
    t = grid_terrain(lambda x, y: a * x * x + 2 * b * x * y + c * y * y + d * x + e * y)
    f = compute_features(t, radii=(0.012, 0.02), oriented_heading=psi)
    i, j = I0 + cell[0], J0 + cell[1]
    centre = np.array([t.x[i], t.y[j]])
    big_k = np.array([[a, b], [b, c]])
    r = rotation(psi)
    kp = r.T @ big_k @ r
    gp = r.T @ (2 * big_k @ centre + np.array([d, e]))
    expected = [kp[0, 0], kp[0, 1], kp[1, 1], gp[0], gp[1]]
    for n in range(2):
        assert f.valid_by_radius[n, i, j]
        got = block(f, n)[i, j]
        np.testing.assert_allclose(got[:5], expected, atol=1e-6)
        np.testing.assert_allclose(got[5:7], np.linalg.eigvalsh(big_k), atol=1e-6)
        assert got[8] < 1e-6


def test_tilted_plane_has_only_slope_features():
    gx_, gy_ = 0.3, -0.55
    t = grid_terrain(lambda x, y: gx_ * x + gy_ * y + 1.25)
    f = compute_features(t, radii=DEFAULT_RADII[:3] + (0.012,))
    for n in range(len(f.radii)):
        v = block(f, n)[f.valid_by_radius[n]]
        assert np.all(v[:, [0, 1, 2, 5, 6, 8]] == 0.0)
        np.testing.assert_allclose(v[:, 3], gx_, atol=1e-9)
        np.testing.assert_allclose(v[:, 4], gy_, atol=1e-9)
        np.testing.assert_allclose(v[:, 7], np.hypot(gx_, gy_), atol=1e-9)


def test_against_brute_force_least_squares_on_noise():
    rng = np.random.default_rng(7)
    t = Terrain(rng.normal(0.0, 0.01, (50, 44)), 0.3, -0.1, DX, DY)
    f = compute_features(t, radii=RADII)
    for n, r in enumerate(RADII):
        for i, j in [(12, 10), (25, 22), (37, 33), (20, 30)]:
            assert f.valid_by_radius[n, i, j]
            beta, rms = brute_force_fit(t, i, j, r)
            got = block(f, n)[i, j]
            np.testing.assert_allclose(got[:5], beta[:5], rtol=1e-9, atol=1e-9)
            assert got[8] == pytest.approx(rms, rel=1e-9)
            assert got[8] > 1e-3  # noise is not a quadratic


def test_eigenvalues_and_gradient_norm_match_numpy():
    rng = np.random.default_rng(3)
    t = Terrain(rng.normal(0.0, 0.01, (40, 40)), 0.0, 0.0, 0.005, 0.005)
    f = compute_features(t, radii=(0.02,))
    v = f.values.reshape(-1, 9)
    k = np.stack([v[:, [0, 1]], v[:, [1, 2]]], axis=1)
    lam = np.linalg.eigvalsh(k)
    np.testing.assert_allclose(v[:, 5], lam[:, 0], atol=1e-9)
    np.testing.assert_allclose(v[:, 6], lam[:, 1], atol=1e-9)
    np.testing.assert_allclose(v[:, 7], np.hypot(v[:, 3], v[:, 4]), atol=1e-12)


@pytest.mark.parametrize("psi", [0.6, -2.1, np.pi / 2])
def test_oriented_features_fit_a_rotated_surface(psi):
    # A quadratic written in the heading frame: z = u'ᵀ K' u' + k'ᵀ u' with u' = Rᵀ u.
    kp = np.array([[2.0, 0.8], [0.8, -1.5]])
    gp = np.array([0.3, -0.7])
    r_t = rotation(psi).T

    def surface(x, y):
        ux = r_t[0, 0] * x + r_t[0, 1] * y
        uy = r_t[1, 0] * x + r_t[1, 1] * y
        return (
            kp[0, 0] * ux**2 + 2 * kp[0, 1] * ux * uy + kp[1, 1] * uy**2 + gp[0] * ux + gp[1] * uy
        )

    t = grid_terrain(surface)
    f = compute_features(t, radii=RADII, oriented_heading=psi)
    assert f.heading == psi
    for n in range(len(RADII)):
        at_origin = block(f, n)[I0, J0]
        np.testing.assert_allclose(at_origin[:5], [2.0, 0.8, -1.5, 0.3, -0.7], atol=1e-6)
        valid = block(f, n)[f.valid_by_radius[n]]
        np.testing.assert_allclose(
            valid[:, :3], np.broadcast_to([2.0, 0.8, -1.5], (len(valid), 3)), atol=1e-6
        )
    # Asking the world-frame features for the same heading gives the same numbers.
    world = compute_features(t, radii=RADII)
    xy = np.array([[t.x[I0], t.y[J0]], [t.x[30], t.y[25]]])
    np.testing.assert_allclose(world.at(xy, heading=psi), f.at(xy), atol=1e-9)


def test_oriented_features_against_brute_force_in_the_turned_frame():
    rng = np.random.default_rng(11)
    t = Terrain(rng.normal(0.0, 0.01, (50, 44)), 0.0, 0.0, DX, DY)
    psi = 0.9
    f = compute_features(t, radii=(0.02,), oriented_heading=psi)
    for i, j in [(15, 12), (30, 25)]:
        beta, rms = brute_force_fit(t, i, j, 0.02, heading=psi)
        np.testing.assert_allclose(f.values[i, j, :5], beta[:5], rtol=1e-9, atol=1e-9)
        assert f.values[i, j, 8] == pytest.approx(rms, rel=1e-9)


def test_orient_composes_and_keeps_invariants():
    rng = np.random.default_rng(5)
    t = Terrain(rng.normal(0.0, 0.01, (30, 30)), 0.0, 0.0, 0.005, 0.005)
    v = compute_features(t, radii=(0.01, 0.02)).values
    a, b = 0.4, -1.3
    np.testing.assert_allclose(
        orient_features(orient_features(v, a), b), orient_features(v, a + b), atol=1e-9
    )
    turned = orient_features(v, a).reshape(30, 30, 2, 9)
    np.testing.assert_array_equal(turned[..., 5:], v.reshape(30, 30, 2, 9)[..., 5:])
    # A quarter turn: the robot's x axis is the world's y axis.
    q = orient_features(v, np.pi / 2).reshape(-1, 2, 9)
    w = v.reshape(-1, 2, 9)
    np.testing.assert_allclose(q[..., 0], w[..., 2], atol=1e-9)
    np.testing.assert_allclose(q[..., 1], -w[..., 1], atol=1e-9)
    np.testing.assert_allclose(q[..., 3], w[..., 4], atol=1e-9)
    np.testing.assert_allclose(q[..., 4], -w[..., 3], atol=1e-9)
    with pytest.raises(InvalidArgumentError):
        orient_features(v[..., :10], 0.1)


def test_validity_at_borders_and_unknown_cells():
    z = np.zeros((40, 30))
    z[20, 12] = np.nan
    t = Terrain(z, 0.0, 0.0, 0.005, 0.005)
    f = compute_features(t, radii=(0.01, 0.02))
    i, j = np.meshgrid(np.arange(40), np.arange(30), indexing="ij")
    for n, cells in enumerate((2, 4)):
        inside = (i >= cells) & (i < 40 - cells) & (j >= cells) & (j < 30 - cells)
        touches = (i - 20) ** 2 + (j - 12) ** 2 <= cells**2
        np.testing.assert_array_equal(f.valid_by_radius[n], inside & ~touches)
    np.testing.assert_array_equal(f.valid, f.valid_by_radius.all(axis=0))


def test_at_nearest_bilinear_and_footholds():
    rng = np.random.default_rng(2)
    t = Terrain(rng.normal(0.0, 0.01, (30, 20)), 0.1, 0.2, 0.005, 0.005)
    f = compute_features(t, radii=(0.01,))
    pts = np.array([[t.x[7], t.y[4]], [t.x[12], t.y[15]]])
    np.testing.assert_allclose(f.at(pts), f.values[[7, 12], [4, 15]], atol=1e-12)
    np.testing.assert_array_equal(
        f.at(pts + 0.001, interpolation="nearest"), f.values[[7, 12], [4, 15]]
    )
    mid = np.array([[(t.x[7] + t.x[8]) / 2, t.y[4]]])
    np.testing.assert_allclose(f.at(mid)[0], (f.values[7, 4] + f.values[8, 4]) / 2, atol=1e-12)
    stances = np.stack([pts, pts[::-1]])  # (2 stances, 2 feet, 2)
    got = f.at_footholds(stances, heading=np.array([[0.3], [-0.2]]))
    assert got.shape == (2, 2, 9)
    np.testing.assert_allclose(got[1, 0], f.at(pts[1:], heading=-0.2)[0], atol=1e-12)
    assert f.valid_at(np.array([[t.x[10], t.y[10]], [t.x[0], t.y[0]], [-5.0, 0.0]])).tolist() == [
        True,
        False,
        False,
    ]
    with pytest.raises(InvalidArgumentError):
        f.at(pts, interpolation="cubic")


def test_float32_storage():
    t = grid_terrain(lambda x, y: 2.0 * x * x)
    f = compute_features(t, radii=(0.02,), dtype=np.float32)
    assert f.values.dtype == np.float32
    np.testing.assert_allclose(f.values[f.valid][:, 0], 2.0, rtol=1e-5)


@pytest.mark.parametrize(
    ("radii", "match"),
    [
        ((0.005,), "smaller than 1.5 grid cells"),
        ((0.02, 0.02), "distinct"),
        ((), "empty"),
        ((-0.01,), "positive"),
    ],
)
def test_bad_radii(radii, match):
    t = Terrain(np.zeros((20, 20)), 0.0, 0.0, 0.005, 0.005)
    with pytest.raises(TerrainError, match=match):
        compute_features(t, radii=radii)


def test_real_board_against_brute_force(littledog_board):
    # A LittleDog board at 1.2 mm: the 6 cm disc is a 101 × 101 kernel.
    t = littledog_board("AE")
    f = compute_features(t, radii=(0.01, 0.06))
    rng = np.random.default_rng(0)
    cells = np.argwhere(f.valid)[rng.choice(int(f.valid.sum()), 4, replace=False)]
    for n, r in enumerate(f.radii):
        for i, j in cells:
            beta, rms = brute_force_fit(t, i, j, r)
            got = block(f, n)[i, j]
            scale = np.abs(beta[:5]).max()
            np.testing.assert_allclose(got[:5], beta[:5], atol=1e-8 * scale)
            assert got[8] == pytest.approx(rms, rel=1e-6)
