"""Signed distance field (Zucker 2011, §3.3) against brute force, finite differences and files.

The brute force here shares no code with the SDF: exact point–triangle
distances in numpy over the terrain's own triangulation (two triangles per
cell, as ``Terrain.to_mesh``), with the grid's edge heights continued beyond
it (the clamping every height query uses), and a cell only skipped when a
lower bound from its height range proves it farther than the best so far.
"""

from __future__ import annotations

import dataclasses
import json
import math
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
import trimesh
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.typing import NDArray

from roughwalk.errors import ConfigError, InvalidArgumentError, TerrainError
from roughwalk.terrain import SdfConfig, SignedDistanceField, Terrain
from roughwalk.terrain.sdf import EDT_BACKENDS

RES = 0.005
HALF_DIAGONAL = 0.5 * math.sqrt(3.0) * RES


# ------------------------------------------------------------------ brute force
def _point_triangle_distance(
    p: NDArray[np.float64], a: NDArray[np.float64], b: NDArray[np.float64], c: NDArray[np.float64]
) -> NDArray[np.float64]:
    """Distance from point p (3,) to each triangle (a[i], b[i], c[i]) (M, 3)."""
    n = np.cross(b - a, c - a)
    nn = np.einsum("ij,ij->i", n, n)

    def side(u: NDArray[np.float64], v: NDArray[np.float64]) -> NDArray[np.float64]:
        return np.einsum("ij,ij->i", np.cross(v - u, p - u), n)

    inside = (nn > 0) & (side(a, b) >= 0) & (side(b, c) >= 0) & (side(c, a) >= 0)
    plane = np.abs(np.einsum("ij,ij->i", p - a, n)) / np.sqrt(np.where(nn > 0, nn, 1.0))

    def segment(u: NDArray[np.float64], v: NDArray[np.float64]) -> NDArray[np.float64]:
        d = v - u
        l2 = np.einsum("ij,ij->i", d, d)
        t = np.clip(np.einsum("ij,ij->i", p - u, d) / np.where(l2 > 0, l2, 1.0), 0.0, 1.0)
        return np.linalg.norm(p - (u + t[:, None] * d), axis=1)

    edges = np.minimum(np.minimum(segment(a, b), segment(b, c)), segment(c, a))
    return np.where(inside, plane, edges)


def _triangulated_height(t: Terrain, x: float, y: float) -> float:
    """Height of the terrain's triangulated surface at (x, y), clamped beyond the grid."""
    nx, ny = t.shape
    gx = min(max((x - t.x0) / t.dx, 0.0), nx - 1.0)
    gy = min(max((y - t.y0) / t.dy, 0.0), ny - 1.0)
    i, j = min(int(gx), nx - 2), min(int(gy), ny - 2)
    tx, ty = gx - i, gy - j
    z = t.heights
    if tx >= ty:
        return float(z[i, j] + (z[i + 1, j] - z[i, j]) * tx + (z[i + 1, j + 1] - z[i + 1, j]) * ty)
    return float(z[i, j] + (z[i + 1, j + 1] - z[i, j + 1]) * tx + (z[i, j + 1] - z[i, j]) * ty)


class BruteForce:
    """Exact signed distance to a terrain's triangulated, edge-extended surface.

    The grid is padded with its edge heights far enough that every query
    point's closest point lies within the padding.
    """

    def __init__(self, terrain: Terrain, points: NDArray[np.float64]) -> None:
        t = self.t = terrain
        x_min, x_max, y_min, y_max = t.extent
        reach = max(
            abs(p[2] - _triangulated_height(t, p[0], p[1]))
            + max(x_min - p[0], p[0] - x_max, y_min - p[1], p[1] - y_max, 0.0)
            for p in points
        )
        pad = self.pad = int(math.ceil(reach / min(t.dx, t.dy))) + 2
        h = self.h = np.pad(t.heights, pad, mode="edge")
        corners = np.stack([h[:-1, :-1], h[1:, :-1], h[:-1, 1:], h[1:, 1:]])
        self.lo, self.hi = corners.min(axis=0), corners.max(axis=0)
        self.xa = t.x0 + (np.arange(h.shape[0] - 1) - pad) * t.dx
        self.ya = t.y0 + (np.arange(h.shape[1] - 1) - pad) * t.dy

    def distance(self, p: NDArray[np.float64]) -> float:
        """Unsigned distance [m] from p to the surface."""
        t = self.t
        best = abs(p[2] - _triangulated_height(t, p[0], p[1]))  # the point straight above/below
        # Cells that could hold a closer point: within `best` horizontally…
        i0 = max(int(math.floor((p[0] - best - t.x0) / t.dx)) + self.pad - 1, 0)
        i1 = min(int(math.ceil((p[0] + best - t.x0) / t.dx)) + self.pad + 1, len(self.xa))
        j0 = max(int(math.floor((p[1] - best - t.y0) / t.dy)) + self.pad - 1, 0)
        j1 = min(int(math.ceil((p[1] + best - t.y0) / t.dy)) + self.pad + 1, len(self.ya))
        xa, ya = self.xa[i0:i1], self.ya[j0:j1]
        gx = np.maximum(0, np.maximum(xa - p[0], p[0] - (xa + t.dx)))
        gy = np.maximum(0, np.maximum(ya - p[1], p[1] - (ya + t.dy)))
        lo, hi = self.lo[i0:i1, j0:j1], self.hi[i0:i1, j0:j1]
        gz = np.maximum(0, np.maximum(lo - p[2], p[2] - hi))
        # …and whose height range does not rule them out.
        i, j = np.nonzero(gx[:, None] ** 2 + gy[None, :] ** 2 + gz**2 < best**2 * (1 + 1e-9))
        if len(i) == 0:
            return best
        h, dx, dy = self.h, t.dx, t.dy
        x, y, i, j = xa[i], ya[j], i + i0, j + j0
        a = np.column_stack([x, y, h[i, j]])
        b = np.column_stack([x + dx, y, h[i + 1, j]])
        c = np.column_stack([x + dx, y + dy, h[i + 1, j + 1]])
        d = np.column_stack([x, y + dy, h[i, j + 1]])
        return min(
            best,
            float(_point_triangle_distance(p, a, b, c).min()),
            float(_point_triangle_distance(p, a, c, d).min()),
        )

    def signed(self, points: NDArray[np.float64]) -> NDArray[np.float64]:
        """Signed distances [m], negative below the surface."""
        out = np.array([self.distance(p) for p in points])
        below = np.array([p[2] < _triangulated_height(self.t, p[0], p[1]) for p in points])
        return np.where(below, -out, out)


# ------------------------------------------------------------------- terrains
def _grid_terrain(f: Callable[..., NDArray[np.float64]], name: str, d: float = 0.0025) -> Terrain:
    x = np.arange(0.0, 0.3 + 1e-9, d)
    y = np.arange(-0.1, 0.1 + 1e-9, d)
    gx, gy = np.meshgrid(x, y, indexing="ij")
    return Terrain(f(gx, gy), x[0], y[0], d, d, name=name)


def _rocks(gx: NDArray[np.float64], gy: NDArray[np.float64]) -> NDArray[np.float64]:
    rng = np.random.default_rng(4)
    z = 0.004 * rng.random(gx.shape)
    for cx, cy, r, h in zip(
        rng.uniform(0, 0.3, 6),
        rng.uniform(-0.1, 0.1, 6),
        rng.uniform(0.02, 0.05, 6),
        rng.uniform(0.02, 0.06, 6),
        strict=False,
    ):
        z = np.maximum(z, h * np.sqrt(np.clip(1 - ((gx - cx) ** 2 + (gy - cy) ** 2) / r**2, 0, 1)))
    return z


SYNTHETIC: dict[str, Callable[..., NDArray[np.float64]]] = {
    "step": lambda gx, gy: np.where(gx > 0.15, 0.06, 0.0),
    "barrier": lambda gx, gy: np.where(np.abs(gx - 0.15) < 0.02, 0.08, 0.0),
    "sinusoid": lambda gx, gy: 0.02 * np.sin(gx * 25) * np.cos(gy * 20),
    "tilted_plane": lambda gx, gy: 0.3 * gx - 0.2 * gy + 0.01,
    "rocks": _rocks,
}


def _sample_points(
    sdf: SignedDistanceField, rng: np.random.Generator, n_near: int, n_far: int
) -> NDArray[np.float64]:
    """Points near the surface (±3 voxels of it, vertically) and anywhere in the lattice."""
    lo, hi = np.array(sdf.origin), np.array(sdf.upper)
    far = lo + (hi - lo) * rng.random((n_far, 3))
    near = lo + (hi - lo) * rng.random((n_near, 3))
    near[:, 2] = sdf.terrain.height(near[:, :2]) + rng.uniform(-3 * RES, 3 * RES, n_near)
    return np.vstack([near, far])


def _check_against_brute_force(
    sdf: SignedDistanceField, points: NDArray[np.float64], tolerance: float
) -> None:
    exact = BruteForce(sdf.terrain, points).signed(points)
    d, g = sdf.query(points)
    err = np.abs(d - exact)
    worst = int(np.argmax(err))
    assert err.max() <= tolerance, (
        f"|d − exact| = {err.max() * 1000:.2f} mm > {tolerance * 1000:.2f} mm at {points[worst]} "
        f"(d = {d[worst]:.5f}, exact = {exact[worst]:.5f})"
    )
    far = np.abs(exact) > sdf.resolution
    assert np.all(np.sign(d[far]) == np.sign(exact[far])), "wrong sign more than a voxel away"
    assert np.all(np.isfinite(g))


@pytest.fixture(scope="module")
def sinusoid_sdf() -> SignedDistanceField:
    return _grid_terrain(SYNTHETIC["sinusoid"], "sinusoid").sdf(RES, z_margin=0.06)


# ---------------------------------------------------------------------- tests
@pytest.mark.parametrize("board", ["terrainAE", "terrainA"])
def test_littledog_board_matches_brute_force(
    littledog_board: Callable[[str], Terrain], board: str
) -> None:
    full = littledog_board(board)
    # A 0.2 m × 0.2 m window of the board keeps the test fast.
    i0, j0, n = 170, 170, 169
    t = Terrain(
        full.heights[i0 : i0 + n, j0 : j0 + n],
        full.x0 + i0 * full.dx,
        full.y0 + j0 * full.dy,
        full.dx,
        full.dy,
        name=board,
    )
    sdf = t.sdf(RES, z_margin=0.05)
    points = _sample_points(sdf, np.random.default_rng(0), 150, 150)
    _check_against_brute_force(sdf, points, HALF_DIAGONAL)


@pytest.mark.parametrize("name", sorted(SYNTHETIC))
def test_synthetic_terrain_matches_brute_force(name: str) -> None:
    sdf = _grid_terrain(SYNTHETIC[name], name).sdf(RES, z_margin=0.05)
    points = _sample_points(sdf, np.random.default_rng(1), 100, 100)
    _check_against_brute_force(sdf, points, HALF_DIAGONAL)


def _registered_generators() -> list[str]:
    try:
        from roughwalk.terrain.generators import GENERATORS
    except ImportError:  # pragma: no cover - the generators are another module
        return []
    return sorted(GENERATORS)


@pytest.mark.parametrize("name", _registered_generators())
def test_every_registered_generator_matches_brute_force(name: str) -> None:
    from roughwalk.terrain.generators import generate

    t = generate(name, resolution=0.04)
    x_min, x_max, y_min, y_max = t.extent
    lo, hi = t.height_range
    volume = (x_max - x_min) * (y_max - y_min) * (hi - lo + 0.1)
    res = max(0.01, (volume / 150_000) ** (1 / 3))  # a coarse lattice, ≈ 150 000 voxels
    sdf = t.sdf(res, z_margin=0.05)
    rng = np.random.default_rng(2)
    lo3, hi3 = np.array(sdf.origin), np.array(sdf.upper)
    points = lo3 + (hi3 - lo3) * rng.random((60, 3))
    near = lo3 + (hi3 - lo3) * rng.random((60, 3))
    near[:, 2] = t.height(near[:, :2]) + rng.uniform(-2 * res, 2 * res, 60)
    _check_against_brute_force(sdf, np.vstack([points, near]), 0.5 * math.sqrt(3) * res)


@settings(max_examples=60, deadline=None)
@given(
    st.floats(0.0, 1.0),
    st.floats(0.0, 1.0),
    st.floats(-0.04, 0.08),
)
def test_property_sign_and_distance(
    sinusoid_sdf: SignedDistanceField, u: float, v: float, z: float
) -> None:
    lo, hi = np.array(sinusoid_sdf.origin), np.array(sinusoid_sdf.upper)
    p = np.array([[lo[0] + u * (hi[0] - lo[0]), lo[1] + v * (hi[1] - lo[1]), z]])
    _check_against_brute_force(sinusoid_sdf, p, HALF_DIAGONAL)


@pytest.mark.parametrize("name", ["sinusoid", "tilted_plane"])
def test_gradient_matches_finite_differences_and_is_a_unit_vector(name: str) -> None:
    t = _grid_terrain(SYNTHETIC[name], name)
    sdf = t.sdf(RES, z_margin=0.06)
    rng = np.random.default_rng(3)
    lo = np.array(sdf.origin)
    # Points 2–5 cm above gently varying ground, kept off cell faces so that
    # ±h stays within one cell of the trilinear interpolant.
    cells = rng.integers(4, np.array(sdf.shape) - 5, size=(200, 3))
    p = lo + (cells + rng.uniform(0.1, 0.9, (200, 3))) * RES
    p[:, 2] = t.height(p[:, :2]) + rng.uniform(0.02, 0.05, 200)
    frac = (p - lo) / RES % 1.0
    p = p[np.all((frac > 0.01) & (frac < 0.99), axis=1)]
    _, g = sdf.query(p)
    h = 1e-6
    for axis in range(3):
        e = np.zeros(3)
        e[axis] = h
        fd = (sdf.query(p + e)[0] - sdf.query(p - e)[0]) / (2 * h)
        np.testing.assert_allclose(g[:, axis], fd, atol=1e-6)
    np.testing.assert_allclose(np.linalg.norm(g, axis=1), 1.0, atol=0.05)


def test_outside_the_lattice_falls_back_to_the_exact_height_field_distance(
    sinusoid_sdf: SignedDistanceField,
) -> None:
    t = sinusoid_sdf.terrain
    x_min, x_max, y_min, y_max = t.extent
    rng = np.random.default_rng(5)
    n = 40
    beyond_x = np.column_stack(
        [
            rng.uniform(x_max + 0.01, x_max + 0.1, n),
            rng.uniform(y_min, y_max, n),
            rng.uniform(0.0, 0.1, n),
        ]
    )
    beyond_y = np.column_stack(
        [
            rng.uniform(x_min, x_max, n),
            rng.uniform(y_min - 0.1, y_min - 0.01, n),
            rng.uniform(-0.1, 0.1, n),
        ]
    )
    above = np.column_stack(
        [rng.uniform(x_min, x_max, n), rng.uniform(y_min, y_max, n), rng.uniform(0.1, 0.3, n)]
    )
    corner_below = np.column_stack(
        [
            rng.uniform(x_max + 0.01, x_max + 0.1, n),
            rng.uniform(y_max + 0.01, y_max + 0.1, n),
            rng.uniform(-0.2, -0.05, n),
        ]
    )
    points = np.vstack([beyond_x, beyond_y, above, corner_below])
    assert not any(np.all((p >= sinusoid_sdf.origin) & (p <= sinusoid_sdf.upper)) for p in points)
    exact = BruteForce(t, points).signed(points)
    d, g = sinusoid_sdf.query(points)
    np.testing.assert_allclose(d, exact, atol=1e-9)
    assert np.all(d[-n:] < 0), "below the extended ground is inside"
    np.testing.assert_allclose(np.linalg.norm(g, axis=1), 1.0, atol=1e-9)


def test_spheres_are_points_minus_radius(sinusoid_sdf: SignedDistanceField) -> None:
    rng = np.random.default_rng(6)
    c = _sample_points(sinusoid_sdf, rng, 50, 50)
    r = rng.uniform(0.0, 0.03, len(c))
    d, g = sinusoid_sdf.query_spheres(c, r)
    dp, gp = sinusoid_sdf.query(c)
    np.testing.assert_array_equal(d, dp - r)
    np.testing.assert_array_equal(g, gp)
    np.testing.assert_array_equal(sinusoid_sdf.query_spheres(c, 0.01)[0], dp - 0.01)


def test_capsules_are_the_minimum_over_their_samples_minus_radius(
    sinusoid_sdf: SignedDistanceField,
) -> None:
    rng = np.random.default_rng(7)
    a = _sample_points(sinusoid_sdf, rng, 20, 20)
    b = a + rng.uniform(-0.08, 0.08, a.shape)
    r = rng.uniform(0.0, 0.02, len(a))
    for samples in (2, 9, 40):
        d, g, t = sinusoid_sdf.query_capsules(a, b, r, samples=samples, return_fraction=True)
        s = np.linspace(0.0, 1.0, samples)
        pts = a[:, None, :] + s[None, :, None] * (b - a)[:, None, :]
        ds, gs = sinusoid_sdf.query(pts.reshape(-1, 3))
        ds = ds.reshape(len(a), samples)
        k = np.argmin(ds, axis=1)
        np.testing.assert_array_equal(d, ds[np.arange(len(a)), k] - r)
        np.testing.assert_array_equal(t, s[k])
        np.testing.assert_array_equal(g, gs.reshape(len(a), samples, 3)[np.arange(len(a)), k])
    # The default sampling (≤ one voxel apart) is within half a voxel of a dense minimum.
    d, _ = sinusoid_sdf.query_capsules(a, b, r)
    s = np.linspace(0.0, 1.0, 2001)
    dense = sinusoid_sdf.query(
        (a[:, None, :] + s[None, :, None] * (b - a)[:, None, :]).reshape(-1, 3)
    )[0]
    dense = dense.reshape(len(a), -1).min(axis=1) - r
    assert np.all(d >= dense - 1e-12) and np.all(d - dense <= 0.5 * RES + 1e-9)


def test_save_and_load_give_identical_queries(
    sinusoid_sdf: SignedDistanceField, tmp_path: Path
) -> None:
    path = tmp_path / "field.npz"
    sinusoid_sdf.save(path)
    loaded = SignedDistanceField.load(path)
    rng = np.random.default_rng(8)
    inside = _sample_points(sinusoid_sdf, rng, 100, 100)
    outside = inside + np.array([0.5, 0.0, 0.0])
    for p in (inside, outside):
        for a, b in zip(sinusoid_sdf.query(p), loaded.query(p), strict=False):
            np.testing.assert_array_equal(a, b)
    assert loaded.info() == sinusoid_sdf.info()
    assert loaded.config == sinusoid_sdf.config
    json.dumps(loaded.info())
    np.testing.assert_array_equal(loaded.terrain.heights, sinusoid_sdf.terrain.heights)


def test_loading_what_is_not_an_sdf_file_names_the_file(
    sinusoid_sdf: SignedDistanceField, tmp_path: Path
) -> None:
    text = tmp_path / "notes.npz"
    text.write_text("hello")
    other = tmp_path / "other.npz"
    np.savez(other, values=np.zeros((2, 2, 2), dtype=np.float32))
    missing = tmp_path / "missing.npz"
    damaged = tmp_path / "damaged.npz"
    sinusoid_sdf.save(damaged)
    with np.load(damaged) as z:
        data = {k: z[k] for k in z.files}
    data["values"] = data["values"][:, :, :1]  # lattice values of the wrong shape
    data["origin"] = np.array([np.nan, 0.0, 0.0])
    np.savez(damaged, **data)
    for bad in (text, other, missing, damaged):
        with pytest.raises(TerrainError, match=bad.name):
            SignedDistanceField.load(bad)


def test_voxel_budget_names_the_finest_resolution_that_fits() -> None:
    t = _grid_terrain(SYNTHETIC["rocks"], "rocks")
    budget = 50_000
    with pytest.raises(TerrainError, match=r"resolution=") as info:
        t.sdf(0.002, max_voxels=budget)
    message = str(info.value)
    assert "0.002" in message and "max_voxels=50,000" in message
    fit = float(message.split("finest resolution that fits is resolution=")[1].split(" ")[0])
    sdf = t.sdf(fit, max_voxels=budget)
    assert math.prod(sdf.shape) <= budget
    # …and it is the finest: 2 % finer no longer fits.
    with pytest.raises(TerrainError):
        t.sdf(fit * 0.98, max_voxels=budget)


@pytest.mark.parametrize(
    ("call", "bad"),
    [
        ("query", np.array([[0.1, np.nan, 0.0]])),
        ("query", np.array([[0.1, 0.0, np.inf]])),
        ("query", np.zeros((4, 2))),
        ("query", np.zeros((2, 3, 3))),
        ("query", [["a", "b", "c"]]),
        ("spheres_radius", np.array([-0.01])),
        ("spheres_radius", np.array([np.nan])),
        ("spheres_radius", np.array([0.1, 0.2])),
        ("capsule_samples", 1),
        ("capsule_samples", 2.5),
        ("capsule_shapes", None),
    ],
)
def test_bad_input_is_an_invalid_argument_error(
    sinusoid_sdf: SignedDistanceField, call: str, bad: object
) -> None:
    p = np.array([[0.1, 0.0, 0.02]])
    with pytest.raises(InvalidArgumentError):
        if call == "query":
            sinusoid_sdf.query(bad)  # type: ignore[arg-type]
        elif call == "spheres_radius":
            sinusoid_sdf.query_spheres(p, bad)  # type: ignore[arg-type]
        elif call == "capsule_samples":
            sinusoid_sdf.query_capsules(p, p + 0.01, 0.01, samples=bad)  # type: ignore[arg-type]
        else:
            sinusoid_sdf.query_capsules(p, np.zeros((2, 3)), 0.01)


def test_config_is_checked_and_overridable() -> None:
    with pytest.raises(ConfigError, match="resolution"):
        SdfConfig(resolution=-0.01)
    with pytest.raises(ConfigError, match="edt_backend"):
        SdfConfig(edt_backend="fmm")
    with pytest.raises(ConfigError, match="band_cells"):
        SdfConfig(band_cells=0.5)
    t = _grid_terrain(SYNTHETIC["step"], "step")
    with pytest.raises(ConfigError, match="unknown config field 'resolutoin'"):
        t.sdf(resolutoin=0.01)
    sdf = t.sdf(0.01, config=SdfConfig(z_margin=0.02, band_cells=3))
    assert sdf.config == dataclasses.replace(
        SdfConfig(), resolution=0.01, z_margin=0.02, band_cells=3
    )
    assert sdf.origin[2] == pytest.approx(-0.02)
    info = sdf.info()
    assert info["shape"] == list(sdf.shape) and info["memory_bytes"] == 4 * math.prod(sdf.shape)
    assert info["backend"] == "rust" and info["build_time_s"] > 0
    json.dumps(info)


@pytest.mark.parametrize("backend", [b for b in EDT_BACKENDS if b != "rust"])
def test_other_edt_backends(backend: str) -> None:
    t = _grid_terrain(SYNTHETIC["rocks"], "rocks")
    ours = t.sdf(RES, z_margin=0.05)
    theirs = t.sdf(RES, z_margin=0.05, edt_backend=backend)
    assert theirs.backend == backend and theirs.shape == ours.shape
    band = np.abs(ours.values) <= 2 * RES
    # Same exact band; outside it, scipy's feature transform only breaks ties
    # differently, while `edt` (distances only) is coarser.
    np.testing.assert_array_equal(theirs.values[band], ours.values[band])
    tolerance = HALF_DIAGONAL if backend == "scipy" else 2 * HALF_DIAGONAL
    points = _sample_points(ours, np.random.default_rng(9), 60, 60)
    _check_against_brute_force(theirs, points, tolerance)


def _tunnel_block() -> tuple[trimesh.Trimesh, NDArray[np.float64]]:
    """A 6 cm block on the ground with a 2 cm square tunnel through it along x."""
    vertices: list[list[float]] = []
    faces: list[list[int]] = []

    def quad(*corners: tuple[float, float, float]) -> None:
        n = len(vertices)
        vertices.extend([list(c) for c in corners])
        faces.extend([[n, n + 1, n + 2], [n, n + 2, n + 3]])

    x0, x1, y0, y1, z0, z1 = 0.02, 0.08, 0.02, 0.08, 0.0, 0.06
    ty0, ty1, tz0, tz1 = 0.04, 0.06, 0.0, 0.02  # an arch: the tunnel floor is the ground
    quad((x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1))
    quad((x0, y0, z0), (x0, ty0, z0), (x1, ty0, z0), (x1, y0, z0))
    quad((x0, ty1, z0), (x0, y1, z0), (x1, y1, z0), (x1, ty1, z0))
    quad((x0, y0, z0), (x1, y0, z0), (x1, y0, z1), (x0, y0, z1))
    quad((x0, y1, z0), (x0, y1, z1), (x1, y1, z1), (x1, y1, z0))
    for x in (x0, x1):
        quad((x, y0, z0), (x, ty0, z0), (x, ty0, z1), (x, y0, z1))
        quad((x, ty1, z0), (x, y1, z0), (x, y1, z1), (x, ty1, z1))
        quad((x, ty0, tz1), (x, ty1, tz1), (x, ty1, z1), (x, ty0, z1))
    quad((x0, ty0, tz1), (x0, ty1, tz1), (x1, ty1, tz1), (x1, ty0, tz1))
    quad((x0, ty0, tz0), (x0, ty0, tz1), (x1, ty0, tz1), (x1, ty0, tz0))
    quad((x0, ty1, tz0), (x1, ty1, tz0), (x1, ty1, tz1), (x0, ty1, tz1))
    mesh = trimesh.Trimesh(np.array(vertices), np.array(faces), process=False)

    def solid(p: NDArray[np.float64]) -> NDArray[np.bool_]:
        block = np.all((p > [x0, y0, z0]) & (p < [x1, y1, z1]), axis=1)
        tunnel = (p[:, 1] > ty0) & (p[:, 1] < ty1) & (p[:, 2] < tz1)
        return block & ~tunnel

    return mesh, solid  # type: ignore[return-value]


def test_mesh_terrain_with_an_arch_matches_brute_force() -> None:
    mesh, solid = _tunnel_block()
    d = 0.005
    x = np.arange(0.0, 0.1 + 1e-9, d)
    gx, gy = np.meshgrid(x, x, indexing="ij")
    top = np.where((gx >= 0.02) & (gx <= 0.08) & (gy >= 0.02) & (gy <= 0.08), 0.06, 0.0)
    t = Terrain(top, 0.0, 0.0, d, d, name="arch", mesh=mesh)
    sdf = t.sdf(0.004, z_margin=0.03)
    rng = np.random.default_rng(10)
    lo, hi = np.array(sdf.origin), np.array(sdf.upper)
    p = lo + (hi - lo) * rng.random((400, 3))
    # And some right inside the arch, where a height field would see solid block.
    arch = np.column_stack(
        [rng.uniform(0.03, 0.07, 60), rng.uniform(0.042, 0.058, 60), rng.uniform(0.002, 0.018, 60)]
    )
    p = np.vstack([p, arch])
    tri = mesh.triangles
    exact = np.array(
        [_point_triangle_distance(q, tri[:, 0], tri[:, 1], tri[:, 2]).min() for q in p]
    )
    exact = np.where(solid(p), -exact, exact)
    got, _ = sdf.query(p)
    assert np.all(got[-60:] > 0), "the arch is open space"
    far = np.abs(exact) > sdf.resolution
    assert np.all(np.sign(got[far]) == np.sign(exact[far]))
    err = np.abs(got - exact)
    assert err.max() <= 0.5 * math.sqrt(3) * sdf.resolution, f"{err.max()} at {p[np.argmax(err)]}"


def test_rust_feature_transform_finds_a_nearest_seed_like_scipy() -> None:
    from scipy import ndimage

    from roughwalk import _core

    rng = np.random.default_rng(11)
    for shape, density in (
        ((7, 5, 9), 0.05),
        ((30, 20, 25), 0.002),
        ((4, 4, 4), 0.5),
        ((9, 1, 6), 0.2),
    ):
        seeds = rng.random(shape) < density
        seeds.flat[rng.integers(seeds.size)] = True
        nearest = _core.feature_transform(seeds)
        assert seeds.flat[nearest.ravel()].all(), "every answer is a seed"
        ours = np.linalg.norm(
            np.stack(np.unravel_index(nearest, shape)) - np.indices(shape), axis=0
        )
        np.testing.assert_allclose(ours, ndimage.distance_transform_edt(~seeds), atol=1e-12)
    assert (_core.feature_transform(np.zeros((3, 4, 5), dtype=bool)) == -1).all()
