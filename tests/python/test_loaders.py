"""Terrain file loaders: the real shared files, each format's convention, bad input."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
import scipy.io
import trimesh
from PIL import Image

from roughwalk.errors import TerrainError
from roughwalk.terrain import Terrain, load_terrain
from roughwalk.terrain.loaders import SUPPORTED_SUFFIXES, load_file, save_npz

LITTLEDOG_BOARDS = ("terrainA", "terrainAC", "terrainAD", "terrainAE", "terrainC", "terrainY")
OCS2_MAPS = ("demo_terrain", "gaps", "hurdles", "side_gap", "step", "stepping_stones")


def grid_points(t: Terrain) -> np.ndarray:
    gx, gy = np.meshgrid(t.x, t.y, indexing="ij")
    return np.column_stack([gx.ravel(), gy.ravel()])


# -------------------------------------------------------- LittleDog boards
@pytest.mark.parametrize("name", LITTLEDOG_BOARDS)
def test_board_heights_are_exact_at_the_files_grid_points(
    name: str, shared_dir: Path, littledog_board: Callable[[str], Terrain]
) -> None:
    data = scipy.io.loadmat(shared_dir / "terrains" / "littledog" / f"{name}.mat")
    x, y, z = data["x"].ravel(), data["y"].ravel(), data["Z"]
    t = littledog_board(name)
    assert t.shape == (x.size, y.size)
    assert t.name == name
    gx, gy = np.meshgrid(x, y)  # MATLAB's convention: Z[i, j] at (x[j], y[i])
    pts = np.column_stack([gx.ravel(), gy.ravel()])
    known = np.isfinite(z.ravel())
    np.testing.assert_allclose(t.height(pts)[known], z.ravel()[known], rtol=0, atol=1e-12)
    assert t.extent == pytest.approx((x.min(), x.max(), y.min(), y.max()), abs=1e-15)


def test_board_a_barrier_runs_across_x(littledog_board: Callable[[str], Terrain]) -> None:
    # terrainA.jpg: a ~4 cm barrier spanning the board's whole y range, between
    # x ≈ 0.19 m and x ≈ 0.42 m; flat floor before and after it.
    t = littledog_board("A")
    ys = np.linspace(0.01, 0.60, 60)
    for x, low, high in ((0.1, -0.005, 0.005), (0.3, 0.03, 0.045), (0.5, -0.005, 0.005)):
        h = t.height(np.column_stack([np.full_like(ys, x), ys]))
        assert np.all((h > low) & (h < high)), (x, h.min(), h.max())
    # Along x the profile rises and falls by the barrier's height; along y it barely varies.
    xs = np.linspace(0.01, 0.60, 300)
    for y in (0.1, 0.3, 0.5):
        along_x = t.height(np.column_stack([xs, np.full_like(xs, y)]))
        assert np.ptp(along_x) > 0.035
    along_y = t.height(np.column_stack([np.full(300, 0.3), np.linspace(0.01, 0.60, 300)]))
    assert np.ptp(along_y) < 0.005


def test_mat_y_as_a_row_and_decreasing_axes(tmp_path: Path) -> None:
    x = np.linspace(0.5, 0.0, 6)  # decreasing: flipped on load
    y = np.array([[0.1, 0.2, 0.3, 0.4]])  # a 1×M row vector
    gx, gy = np.meshgrid(x, y.ravel())
    z = 2.0 * gx + 0.5 * gy
    z[1, 2] = np.nan  # unknown cell
    scipy.io.savemat(tmp_path / "board.mat", {"x": x[None, :], "y": y, "Z": z})
    t = load_file(tmp_path / "board.mat")
    assert (t.x0, t.y0) == pytest.approx((0.0, 0.1)) and t.dx == pytest.approx(0.1)
    pts = np.column_stack([gx.ravel(), gy.ravel()])
    known = np.isfinite(z.ravel())
    np.testing.assert_allclose(t.height(pts)[known], z.ravel()[known], atol=1e-12)
    assert not t.is_known([x[2], 0.2])[0]
    assert t.raw_heights[3, 1] != t.raw_heights[3, 1]  # x = 0.3 is index 3 after the flip


# ------------------------------------------------------- OCS2 elevation maps
@pytest.mark.parametrize("name", OCS2_MAPS)
def test_ocs2_maps_load_with_the_right_extent(name: str, shared_dir: Path) -> None:
    path = shared_dir / "terrains" / "ocs2_anymal" / f"{name}.png"
    img = np.asarray(Image.open(path))
    rows, cols = img.shape[:2]
    t = load_terrain(path)
    assert t.shape == (rows, cols)
    assert (t.dx, t.dy) == (0.04, 0.04)
    # The map covers rows × cols cells of 4 cm centred on the origin; the grid
    # points are the cell centres.
    x_min, x_max, y_min, y_max = t.extent
    assert (x_max - x_min + 0.04, y_max - y_min + 0.04) == pytest.approx((rows * 0.04, cols * 0.04))
    assert (x_min + x_max, y_min + y_max) == pytest.approx((0.0, 0.0), abs=1e-12)
    np.testing.assert_allclose(t.heights, img[::-1, ::-1, 0] / 255 * 0.35, atol=1e-15)
    assert t.height_range[1] <= 0.35


def pattern(rows: int = 5, cols: int = 4) -> np.ndarray:
    """Distinct gray levels in an image with no symmetry."""
    return (np.arange(rows * cols).reshape(rows, cols) * 11 + 7).astype(np.uint8)


def test_png_follows_grid_maps_convention(tmp_path: Path) -> None:
    img = pattern()
    Image.fromarray(img, mode="L").save(tmp_path / "map.png")
    t = load_file(tmp_path / "map.png", resolution=0.1, scale=0.5, origin=(1.0, -2.0))
    rows, cols = img.shape
    for r in range(rows):
        for c in range(cols):
            # Row 0 is the largest x, column 0 the largest y; centred on the origin.
            x = 1.0 + ((rows - 1) / 2 - r) * 0.1
            y = -2.0 + ((cols - 1) / 2 - c) * 0.1
            assert t.height([x, y])[0] == pytest.approx(img[r, c] / 255 * 0.5, abs=1e-12)
    # The brightest pixel (last row, last column) is at the smallest x and y.
    assert np.unravel_index(np.argmax(t.heights), t.shape) == (0, 0)


def test_png_colour_modes_and_alpha(tmp_path: Path) -> None:
    gray = pattern()
    Image.fromarray(np.repeat(gray[..., None], 3, axis=2), mode="RGB").save(tmp_path / "g.png")
    reference = load_file(tmp_path / "g.png", resolution=0.1)
    Image.fromarray(gray, mode="L").save(tmp_path / "l.png")
    np.testing.assert_array_equal(
        load_file(tmp_path / "l.png", resolution=0.1).heights, reference.heights
    )

    rng = np.random.default_rng(0)
    colour = rng.integers(0, 256, size=(5, 4, 3), dtype=np.uint8)
    Image.fromarray(colour, mode="RGB").save(tmp_path / "c.png")
    luma = colour.astype(float) @ np.array([0.299, 0.587, 0.114])
    np.testing.assert_allclose(
        load_file(tmp_path / "c.png", resolution=0.1).heights, luma[::-1, ::-1] / 255 * 0.35
    )

    alpha = np.full_like(gray, 255)
    alpha[1, 2] = 0  # transparent: unknown, as grid_map leaves it empty
    rgba = np.dstack([gray, gray, gray, alpha])
    Image.fromarray(rgba, mode="RGBA").save(tmp_path / "a.png")
    t = load_file(tmp_path / "a.png", resolution=0.1)
    expected_known = (alpha >= 128)[::-1, ::-1]
    np.testing.assert_array_equal(t.known, expected_known)

    deep = (np.arange(20).reshape(5, 4) * 3000 + 5).astype(np.uint16)
    Image.fromarray(deep).save(tmp_path / "d16.png")
    t16 = load_file(tmp_path / "d16.png", resolution=0.1, scale=1.0)
    np.testing.assert_allclose(t16.heights, deep[::-1, ::-1] / 65535, atol=1e-15)


# ------------------------------------------------------------- npy and npz
def holey_terrain() -> Terrain:
    rng = np.random.default_rng(1)
    raw = rng.normal(scale=0.03, size=(9, 6))
    raw[2:4, 1] = np.nan
    return Terrain(raw, -0.4, 0.25, 0.02, 0.03, name="holey")


def test_npz_round_trip_keeps_the_grid_and_the_unknown_cells(tmp_path: Path) -> None:
    t = holey_terrain()
    u = load_file(save_npz(t, tmp_path / "t.npz"))
    np.testing.assert_array_equal(u.raw_heights, t.raw_heights)  # NaN == NaN here
    np.testing.assert_array_equal(u.known, t.known)
    assert (u.x0, u.y0, u.dx, u.dy, u.name) == (t.x0, t.y0, t.dx, t.dy, "holey")


def test_npz_with_coordinate_vectors_or_resolution(tmp_path: Path) -> None:
    t = holey_terrain()
    np.savez(tmp_path / "xy.npz", heights=t.raw_heights, x=t.x, y=t.y)
    u = load_file(tmp_path / "xy.npz")
    assert (u.x0, u.y0) == (t.x0, t.y0) and (u.dx, u.dy) == pytest.approx((t.dx, t.dy))
    np.savez(tmp_path / "res.npz", heights=t.raw_heights, resolution=[0.02, 0.03], origin=[1, 2])
    v = load_file(tmp_path / "res.npz")
    assert (v.x0, v.y0, v.dx, v.dy) == (1.0, 2.0, 0.02, 0.03)
    np.savez(tmp_path / "bare.npz", heights=t.raw_heights)
    w = load_file(tmp_path / "bare.npz", resolution=0.05, origin=(3.0, 4.0))
    assert (w.x0, w.y0, w.dx, w.dy) == (3.0, 4.0, 0.05, 0.05)


def test_npy_round_trip(tmp_path: Path) -> None:
    t = holey_terrain()
    np.save(tmp_path / "h.npy", t.raw_heights)
    u = load_file(tmp_path / "h.npy", resolution=(t.dx, t.dy), origin=(t.x0, t.y0))
    np.testing.assert_array_equal(u.raw_heights, t.raw_heights)
    pts = grid_points(t)
    np.testing.assert_array_equal(u.height(pts), t.height(pts))


# ------------------------------------------------------------------ meshes
@pytest.mark.parametrize("suffix", [".stl", ".obj", ".ply"])
def test_mesh_round_trip(tmp_path: Path, suffix: str) -> None:
    rng = np.random.default_rng(2)
    gx, gy = np.meshgrid(np.arange(30), np.arange(20), indexing="ij")
    h = 0.02 * np.sin(0.4 * gx) * np.cos(0.3 * gy) + rng.normal(scale=0.002, size=gx.shape)
    t = Terrain(h, -0.3, 0.1, 0.01, 0.012)
    t.to_mesh().export(tmp_path / f"t{suffix}")
    u = load_file(tmp_path / f"t{suffix}", resolution=(0.01, 0.012))
    assert u.mesh is None  # a height field's mesh is 2.5-D
    assert u.shape == t.shape and u.known.all()
    assert (u.x0, u.y0, u.dx, u.dy) == pytest.approx((t.x0, t.y0, t.dx, t.dy), rel=1e-6)
    # STL stores float32: heights agree to float precision (slope × 1e-7 m).
    np.testing.assert_allclose(u.heights, t.heights, atol=1e-6)


def test_mesh_with_vertical_walls_is_2_5d(tmp_path: Path) -> None:
    # A 5 cm step with an exactly vertical riser at x = 0.5, on grid points.
    v = np.array(
        [[0, 0, 0], [0.5, 0, 0], [0.5, 1, 0], [0, 1, 0],
         [0.5, 0, 0.05], [1, 0, 0.05], [1, 1, 0.05], [0.5, 1, 0.05]], dtype=float,
    )  # fmt: skip
    f = np.array([[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7], [1, 4, 7], [1, 7, 2]])
    trimesh.Trimesh(v, f, process=False).export(tmp_path / "step.stl")
    t = load_file(tmp_path / "step.stl", resolution=0.1)
    assert t.mesh is None and t.shape == (11, 11)
    assert t.height([0.2, 0.5])[0] == pytest.approx(0.0, abs=1e-7)
    assert t.height([0.5, 0.5])[0] == pytest.approx(0.05, abs=1e-7)  # upper envelope
    assert t.height([0.8, 0.5])[0] == pytest.approx(0.05, abs=1e-7)


def test_closed_solid_block_is_2_5d_and_its_top_is_the_terrain(tmp_path: Path) -> None:
    box = trimesh.creation.box(extents=[1.0, 0.6, 0.1])
    box.apply_translation([0.5, 0.3, 0.0])
    box.export(tmp_path / "box.stl")
    t = load_file(tmp_path / "box.stl", resolution=0.05)
    assert t.mesh is None
    np.testing.assert_allclose(t.heights, 0.05, atol=1e-7)


def test_mesh_with_an_overhang_is_kept_as_a_mesh(tmp_path: Path) -> None:
    floor = trimesh.creation.box(extents=[1.0, 1.0, 0.02])
    ball = trimesh.creation.icosphere(subdivisions=2, radius=0.1)
    ball.apply_translation([0.1, -0.05, 0.3])
    trimesh.util.concatenate([floor, ball]).export(tmp_path / "overhang.ply")
    t = load_file(tmp_path / "overhang.ply", resolution=0.02)
    assert t.mesh is not None and len(t.mesh.faces) == len(floor.faces) + len(ball.faces)
    # Heights are the upper envelope: the ball's top above its centre, the floor elsewhere.
    assert t.height([0.1, -0.05])[0] == pytest.approx(0.4, abs=0.005)
    assert t.height([-0.3, 0.3])[0] == pytest.approx(0.01, abs=1e-6)


def test_open_sheet_folded_over_itself_is_not_2_5d(tmp_path: Path) -> None:
    # Two overlapping open squares at different heights (not a closed solid).
    square = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], dtype=float)
    upper = square * [0.5, 0.5, 1] + [0.3, 0.2, 0.2]
    faces = np.array([[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]])
    trimesh.Trimesh(np.vstack([square, upper]), faces).export(tmp_path / "two.obj")
    t = load_file(tmp_path / "two.obj", resolution=0.05)
    assert t.mesh is not None


# ------------------------------------------------------------- bad input
def write_mat(tmp_path: Path, name: str = "bad.mat", **variables: object) -> Path:
    p = tmp_path / name
    scipy.io.savemat(p, variables)
    return p


def bad_inputs(tmp_path: Path) -> list[tuple[Path, dict, str]]:
    x = np.linspace(0, 1, 5)[None, :]
    y = np.linspace(0, 1, 4)[:, None]
    z = np.zeros((4, 5))
    cases: list[tuple[Path, dict, str]] = [
        (tmp_path / "missing.mat", {}, "does not exist"),
        (write_mat(tmp_path, "shape.mat", x=x, y=y, Z=z.T), {}, "expected Z of shape"),
        (write_mat(tmp_path, "noz.mat", x=x, y=y), {}, "missing variable"),
        (write_mat(tmp_path, "nan.mat", x=x, y=y, Z=np.full((4, 5), np.nan)), {}, "unknown"),
        (
            write_mat(tmp_path, "inf.mat", x=x * np.array([1, 1, np.inf, 1, 1]), y=y, Z=z),
            {},
            "not finite",
        ),
        (
            write_mat(tmp_path, "uneven.mat", x=np.array([[0, 0.1, 0.35, 0.4, 0.5]]), y=y, Z=z),
            {},
            "not uniformly spaced",
        ),
        (
            write_mat(tmp_path, "zigzag.mat", x=np.array([[0, 0.2, 0.1, 0.3, 0.4]]), y=y, Z=z),
            {},
            "strictly increasing",
        ),
        (write_mat(tmp_path, "matrix.mat", x=np.zeros((2, 5)), y=y, Z=z), {}, "vector"),
    ]
    cases += [
        (write_mat(tmp_path, "complex.mat", x=x, y=y, Z=z + 1j), {}, "real numeric"),
        (write_mat(tmp_path, "text.mat", x="abcde", y=y, Z=z), {}, "real numeric"),
    ]
    (tmp_path / "garbage.mat").write_bytes(b"not a mat file at all")
    cases.append((tmp_path / "garbage.mat", {}, "cannot read"))
    Image.fromarray(np.zeros((4, 4), np.uint8)).save(tmp_path / "m.png")
    cases += [
        (tmp_path / "m.png", {"scale": float("nan")}, "scale"),
        (tmp_path / "m.png", {"resolution": 0.0}, "resolution"),
        (tmp_path / "m.png", {"resolution": float("inf")}, "resolution"),
        (tmp_path / "m.png", {"origin": (0.0, float("nan"))}, "origin"),
        (tmp_path / "m.png", {"colour": "red"}, "unknown loader option"),
    ]
    Image.fromarray(np.zeros((3, 4, 4), np.uint8), mode="RGBA").save(tmp_path / "clear.png")
    cases.append((tmp_path / "clear.png", {}, "every cell is unknown"))
    Image.fromarray(np.zeros((1, 4), np.uint8)).save(tmp_path / "thin.png")
    cases.append((tmp_path / "thin.png", {}, "2×2"))
    (tmp_path / "empty.stl").write_bytes(b"")
    (tmp_path / "junk.ply").write_bytes(b"ply\nthis is not a mesh\n")
    cases += [
        (tmp_path / "empty.stl", {}, "empty.stl"),
        (tmp_path / "junk.ply", {}, "junk.ply"),
    ]
    (tmp_path / "flat.obj").write_text("v 0 0 0\nv 1 0 0\nv 1 0 1\nf 1 2 3\n")
    cases.append((tmp_path / "flat.obj", {}, "horizontal extent"))
    np.save(tmp_path / "h.npy", np.zeros((3, 3)))
    np.save(tmp_path / "v.npy", np.zeros(3))
    np.savez(tmp_path / "noh.npz", height=np.zeros((3, 3)), resolution=0.1)
    np.savez(tmp_path / "nores.npz", heights=np.zeros((3, 3)))
    np.savez(tmp_path / "xy.npz", heights=np.zeros((3, 3)), x=np.arange(4.0), y=np.arange(3.0))
    cases += [
        (tmp_path / "h.npy", {}, "resolution"),
        (tmp_path / "v.npy", {"resolution": 0.1}, "2-D"),
        (tmp_path / "noh.npz", {}, "unknown key"),
        (tmp_path / "nores.npz", {}, "no grid spacing"),
        (tmp_path / "xy.npz", {}, "'x' has 4"),
        (tmp_path / "terrain.tif", {}, "unsupported terrain file type"),
    ]
    return cases


def test_bad_input_raises_terrain_errors_naming_the_file(tmp_path: Path) -> None:
    for path, options, fragment in bad_inputs(tmp_path):
        with pytest.raises(TerrainError) as info:
            load_file(path, **options)
        message = str(info.value)
        assert path.name in message, message
        assert fragment in message, (fragment, message)


def test_unsupported_suffix_lists_the_supported_ones(tmp_path: Path) -> None:
    with pytest.raises(TerrainError) as info:
        load_file(tmp_path / "board.xyz")
    for suffix in SUPPORTED_SUFFIXES:
        assert suffix in str(info.value)
