"""The Terrain type: queries, unknown cells, mesh and MuJoCo height-field exports."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import ndimage

from roughwalk.errors import InvalidArgumentError, TerrainError
from roughwalk.terrain import Terrain


def random_terrain(seed: int = 0, nx: int = 13, ny: int = 9) -> Terrain:
    rng = np.random.default_rng(seed)
    return Terrain(rng.normal(scale=0.02, size=(nx, ny)), -0.31, 0.17, 0.05, 0.04)


def grid_points(t: Terrain) -> np.ndarray:
    gx, gy = np.meshgrid(t.x, t.y, indexing="ij")
    return np.column_stack([gx.ravel(), gy.ravel()])


def tilted_plane(a: float, b: float, c: float) -> Terrain:
    x = -0.5 + 0.1 * np.arange(11)
    y = 0.2 + 0.05 * np.arange(8)
    gx, gy = np.meshgrid(x, y, indexing="ij")
    return Terrain(a * gx + b * gy + c, -0.5, 0.2, 0.1, 0.05)


# ------------------------------------------------------------------ queries
@pytest.mark.parametrize("interpolation", ["bilinear", "bicubic"])
def test_interpolation_is_exact_at_grid_points(interpolation: str) -> None:
    t = random_terrain()
    h = t.height(grid_points(t), interpolation)
    np.testing.assert_allclose(h, t.heights.ravel(), rtol=0, atol=1e-12)


def test_heights_are_x_major() -> None:
    # heights[i, j] is at (x0 + i·dx, y0 + j·dy): a ramp along x only.
    h = np.outer(np.arange(5), np.ones(3)) * 0.1
    t = Terrain(h, 1.0, 2.0, 0.5, 0.25)
    assert t.height([1.0 + 2 * 0.5, 2.25])[0] == pytest.approx(0.2)
    assert t.height([1.0, 2.5])[0] == pytest.approx(0.0)


def test_bilinear_is_linear_along_a_cell_edge() -> None:
    t = random_terrain(1)
    i, j = 4, 3
    for s in (0.0, 0.25, 0.7, 1.0):
        p = [t.x[i] + s * t.dx, t.y[j]]
        expected = (1 - s) * t.heights[i, j] + s * t.heights[i + 1, j]
        assert t.height(p)[0] == pytest.approx(expected, abs=1e-12)


@pytest.mark.parametrize("interpolation", ["bilinear", "bicubic"])
def test_gradient_matches_finite_differences(interpolation: str) -> None:
    t = random_terrain(2)
    rng = np.random.default_rng(3)
    lo, hi = np.array(t.extent[::2]), np.array(t.extent[1::2])
    xy = lo + 0.05 + rng.random((50, 2)) * (hi - lo - 0.1)
    _, g = t.height_and_gradient(xy, interpolation)
    e = 1e-6
    for k in range(2):
        d = np.zeros(2)
        d[k] = e
        fd = (t.height(xy + d, interpolation) - t.height(xy - d, interpolation)) / (2 * e)
        np.testing.assert_allclose(g[:, k], fd, atol=1e-6)


def test_bicubic_is_smooth_across_cell_edges_where_bilinear_is_not() -> None:
    t = random_terrain(4)
    e = 1e-9
    xs = t.x[2:-2]
    y = t.y[3] + 0.3 * t.dy
    left = np.column_stack([xs - e, np.full_like(xs, y)])
    right = np.column_stack([xs + e, np.full_like(xs, y)])
    _, g_left = t.height_and_gradient(left, "bicubic")
    _, g_right = t.height_and_gradient(right, "bicubic")
    np.testing.assert_allclose(g_left, g_right, atol=1e-5)
    # The same test fails for bilinear interpolation: its slope jumps at cell edges.
    _, b_left = t.height_and_gradient(left, "bilinear")
    _, b_right = t.height_and_gradient(right, "bilinear")
    assert np.max(np.abs(b_left[:, 0] - b_right[:, 0])) > 1e-2


@pytest.mark.parametrize("interpolation", ["bilinear", "bicubic"])
def test_normals_and_slope_on_a_tilted_plane(interpolation: str) -> None:
    a, b = 0.3, -0.45
    t = tilted_plane(a, b, 0.1)
    rng = np.random.default_rng(5)
    xy = np.column_stack([rng.uniform(-0.4, 0.4, 40), rng.uniform(0.25, 0.5, 40)])
    np.testing.assert_allclose(t.height(xy, interpolation), a * xy[:, 0] + b * xy[:, 1] + 0.1)
    n = t.normal(xy, interpolation)
    np.testing.assert_allclose(np.linalg.norm(n, axis=1), 1.0, atol=1e-12)
    expected = np.array([-a, -b, 1.0]) / np.sqrt(a * a + b * b + 1)
    np.testing.assert_allclose(n, np.tile(expected, (40, 1)), atol=1e-12)
    np.testing.assert_allclose(t.slope(xy, interpolation), np.arctan(np.hypot(a, b)), atol=1e-12)


def test_bicubic_reproduces_a_plane_in_the_edge_cells() -> None:
    t = tilted_plane(0.3, -0.45, 0.1)
    xy = np.array([[-0.47, 0.3], [0.46, 0.4], [0.0, 0.21], [0.1, 0.54]])
    np.testing.assert_allclose(
        t.height(xy, "bicubic"), 0.3 * xy[:, 0] - 0.45 * xy[:, 1] + 0.1, atol=1e-9
    )


def test_queries_outside_the_grid_clamp_to_the_edge() -> None:
    t = random_terrain(6)
    x_min, x_max, y_min, y_max = t.extent
    inside = np.array([[x_min, t.y[4]], [x_max, t.y[2]], [t.x[3], y_max]])
    outside = inside + np.array([[-1.0, 0.0], [0.5, 0.0], [0.0, 2.0]])
    np.testing.assert_allclose(t.height(outside), t.height(inside), atol=1e-12)


# ------------------------------------------------------------ unknown cells
def terrain_with_holes() -> tuple[Terrain, np.ndarray]:
    rng = np.random.default_rng(7)
    raw = rng.uniform(0.0, 0.05, size=(20, 16))
    raw[3:6, 4:8] = np.nan  # an interior hole
    raw[0:2, 10:16] = np.nan  # a hole on the grid's edge
    # Two holes sharing a single high border cell (12, 8): each must see it.
    raw[10:12, 7:10] = np.nan
    raw[13:15, 7:10] = np.nan
    raw[12, 8] = 0.2
    raw[15, 0] = np.inf  # infinite counts as unknown too
    return Terrain(raw, 0.0, 0.0, 0.01, 0.01), raw


def test_unknown_cells_are_masked_and_raw_keeps_nan() -> None:
    t, raw = terrain_with_holes()
    unknown = ~np.isfinite(raw)
    np.testing.assert_array_equal(t.known, ~unknown)
    assert np.isnan(t.raw_heights[unknown]).all()
    np.testing.assert_array_equal(t.raw_heights[~unknown], raw[~unknown])
    assert np.isfinite(t.heights).all()
    np.testing.assert_array_equal(t.heights[~unknown], raw[~unknown])
    # is_known: false in every cell with an unknown corner, true in fully known cells.
    centres = grid_points(t)[::1] + 0.5 * np.array([t.dx, t.dy])
    nx, ny = t.shape
    cell_ok = ~(unknown[:-1, :-1] | unknown[1:, :-1] | unknown[:-1, 1:] | unknown[1:, 1:])
    centres = centres.reshape(nx, ny, 2)[:-1, :-1].reshape(-1, 2)
    np.testing.assert_array_equal(t.is_known(centres), cell_ok.ravel())


def test_unknown_regions_are_filled_with_their_highest_border_height() -> None:
    t, raw = terrain_with_holes()
    unknown = ~np.isfinite(raw)
    labels, n = ndimage.label(unknown)
    assert n == 5
    for k in range(1, n + 1):
        region = labels == k
        ring = ndimage.binary_dilation(region, structure=np.ones((3, 3))) & ~unknown
        border_max = raw[ring].max()
        filled = t.heights[region]
        assert np.all(filled >= border_max)  # conservative: never a hole
        assert np.all(filled == border_max)  # and no higher than needed
    # Both holes around the shared high cell were raised to it.
    assert t.heights[11, 8] == pytest.approx(0.2) and t.heights[13, 8] == pytest.approx(0.2)


@pytest.mark.parametrize(
    ("heights", "fragment"),
    [
        (np.full((4, 4), np.nan), "unknown"),
        (np.zeros((1, 5)), "at least 2×2"),
        (np.zeros(5), "at least 2×2"),
    ],
)
def test_bad_height_arrays_are_refused(heights: np.ndarray, fragment: str) -> None:
    with pytest.raises(TerrainError, match=fragment):
        Terrain(heights, 0.0, 0.0, 0.1, 0.1)


@pytest.mark.parametrize(("x0", "dx"), [(np.nan, 0.1), (0.0, np.inf), (0.0, 0.0), (0.0, -0.1)])
def test_bad_grid_numbers_are_refused(x0: float, dx: float) -> None:
    with pytest.raises(TerrainError):
        Terrain(np.zeros((3, 3)), x0, 0.0, dx, 0.1)


# ------------------------------------------------------------------ exports
def test_mesh_export_has_a_vertex_at_every_grid_point_facing_up() -> None:
    t, _ = terrain_with_holes()
    m = t.to_mesh()
    nx, ny = t.shape
    assert len(m.vertices) == nx * ny and len(m.faces) == 2 * (nx - 1) * (ny - 1)
    np.testing.assert_array_equal(m.vertices[:, :2], grid_points(t))
    np.testing.assert_array_equal(m.vertices[:, 2], t.heights.ravel())
    assert np.all(m.face_normals[:, 2] > 0)
    # Each triangle's corners are grid neighbours: its x–y area is half a cell.
    np.testing.assert_allclose(m.area_faces.min() >= 0.5 * t.dx * t.dy - 1e-15, True)


def mujoco_surface_heights(t: Terrain, xy: np.ndarray) -> np.ndarray:
    """Heights [m] of MuJoCo's own surface for ``t.to_mujoco_hfield()``, by vertical rays."""
    mujoco = pytest.importorskip("mujoco")
    hf = t.to_mujoco_hfield()
    nrow, ncol = hf.elevation.shape
    size = " ".join(f"{v!r}" for v in hf.size)
    pos = " ".join(f"{v!r}" for v in hf.center)
    xml = f"""
    <mujoco>
      <asset><hfield name="terrain" nrow="{nrow}" ncol="{ncol}" size="{size}"/></asset>
      <worldbody><geom type="hfield" hfield="terrain" pos="{pos}"/></worldbody>
    </mujoco>"""
    model = mujoco.MjModel.from_xml_string(xml)
    model.hfield_data[:] = hf.elevation.ravel()
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    top = t.height_range[1] + 1.0
    geom = np.zeros(1, dtype=np.int32)
    out = np.empty(len(xy))
    for k, (x, y) in enumerate(xy):
        dist = mujoco.mj_ray(
            model, data, np.array([x, y, top]), np.array([0.0, 0.0, -1.0]), None, 1, -1, geom
        )
        assert dist >= 0, f"ray at ({x}, {y}) missed the height field"
        out[k] = top - dist
    return out


def test_mujoco_hfield_matches_the_terrain_at_grid_points() -> None:
    rng = np.random.default_rng(8)
    t = Terrain(rng.uniform(-0.03, 0.08, size=(12, 7)), -0.4, 1.3, 0.05, 0.07)
    hf = t.to_mujoco_hfield()
    assert hf.elevation.shape == (7, 12)  # rows along y, columns along x
    lo, hi = t.height_range
    tol = 1e-6 * (hi - lo) + 1e-9  # MuJoCo stores elevations as float32
    # Rays exactly on the outer boundary may miss by rounding: nudge them 1 nm inside.
    pts = grid_points(t)
    centre = np.array([np.mean(t.extent[:2]), np.mean(t.extent[2:])])
    pts -= 1e-9 * np.sign(pts - centre)
    np.testing.assert_allclose(mujoco_surface_heights(t, pts), t.height(pts), rtol=0, atol=tol)


def test_mujoco_hfield_matches_between_grid_points() -> None:
    # On a plane MuJoCo's two triangles per cell and our bilinear cells agree exactly.
    t = tilted_plane(0.2, -0.35, 0.05)
    rng = np.random.default_rng(9)
    xy = np.column_stack([rng.uniform(-0.5, 0.5, 100), rng.uniform(0.2, 0.55, 100)])
    lo, hi = t.height_range
    np.testing.assert_allclose(
        mujoco_surface_heights(t, xy), t.height(xy), rtol=0, atol=1e-6 * (hi - lo) + 1e-9
    )
    # On rough ground they differ inside a cell, but both stay within its corners.
    r = random_terrain(10)
    xy = np.column_stack(
        [rng.uniform(r.extent[0], r.extent[1], 100), rng.uniform(r.extent[2], r.extent[3], 100)]
    )
    mj = mujoco_surface_heights(r, xy)
    i = np.minimum(((xy[:, 0] - r.x0) // r.dx).astype(int), r.shape[0] - 2)
    j = np.minimum(((xy[:, 1] - r.y0) // r.dy).astype(int), r.shape[1] - 2)
    corners = np.stack([r.heights[i + a, j + b] for a in (0, 1) for b in (0, 1)])
    tol = 1e-6 * np.ptp(r.heights)
    assert np.all(mj >= corners.min(axis=0) - tol) and np.all(mj <= corners.max(axis=0) + tol)


def test_disc_normal_is_the_plane_normal_and_the_point_normal_at_radius_zero() -> None:
    t = tilted_plane(0.3, -0.45, 0.1)
    xy = np.array([[0.0, 0.3], [0.2, 0.4]])
    for radius in (0.0, 0.01, 0.05):
        np.testing.assert_allclose(t.disc_normal(xy, radius), t.normal(xy), atol=1e-12)
    rough = random_terrain(3)
    np.testing.assert_allclose(rough.disc_normal(xy, 0.0), rough.normal(xy), atol=1e-12)


def test_disc_normal_is_the_mean_slope_by_the_divergence_theorem() -> None:
    """The mean gradient over a disc is (1/πr²)∮ h n ds: an independent check of the
    grid-point average (1 mm grid, 1 cm disc, 3 cm ripples), which the point normal
    misses by 6–23°. The grid's points cover the disc to within a point's spacing,
    so the two means differ by up to 2°."""
    d = 0.001
    x = np.arange(0.0, 0.2 + d / 2, d)
    gx, gy = np.meshgrid(x, x, indexing="ij")
    h = 0.004 * np.sin(200 * gx) * np.cos(120 * gy) + 0.3 * gx
    t = Terrain(h, 0.0, 0.0, d, d)
    r = 0.01
    theta = np.linspace(0.0, 2 * np.pi, 4000, endpoint=False)
    ring = r * np.column_stack([np.cos(theta), np.sin(theta)])

    def angle(a: np.ndarray, b: np.ndarray) -> float:
        return float(np.degrees(np.arccos(min(1.0, float(a @ b)))))

    for c in ([0.07, 0.09], [0.12, 0.05], [0.1, 0.13], [0.031, 0.077]):
        hb = t.height(np.asarray(c) + ring)
        mean = (hb[:, None] * ring).mean(axis=0) * 2 / r**2  # (1/πr²)·∮ h n r dθ
        want = np.array([-mean[0], -mean[1], 1.0]) / np.sqrt(mean @ mean + 1.0)
        got = t.disc_normal(np.array([c]), r)[0]
        point = t.normal(np.array([c]))[0]
        assert angle(got, want) < 2.5
        assert angle(point, want) > angle(got, want) + 3.0


def test_disc_normal_refuses_a_negative_radius() -> None:
    with pytest.raises(InvalidArgumentError, match="radius"):
        tilted_plane(0.1, 0.0, 0.0).disc_normal(np.array([[0.0, 0.3]]), -0.01)
