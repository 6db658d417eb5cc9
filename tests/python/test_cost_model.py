"""TerrainCost for the planner: cost maps against point queries, orientation, shipped default."""

from __future__ import annotations

import json
import sqlite3
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from roughwalk.cli.main import main
from roughwalk.errors import InvalidArgumentError
from roughwalk.planning import (
    CostLearningConfig,
    PairSelector,
    Preference,
    PreferenceDataset,
    PreferenceStore,
    ScriptedExpert,
    TerrainCost,
    agreement,
    default_cost_path,
    learn_cost,
)
from roughwalk.planning.default_cost import (
    DefaultCostRecipe,
    build_default_preferences,
    data_dir,
)
from roughwalk.terrain import Terrain, compute_features, load_terrain

RADII = (0.01, 0.02, 0.04)


def random_cost(oriented: bool, seed: int = 0) -> TerrainCost:
    rng = np.random.default_rng(seed)
    n = 9 * len(RADII)
    # Small weights over curvatures [1/m] and larger over slopes: costs of order 1–10.
    w = rng.normal(size=n) * np.tile([0.01, 0.01, 0.01, 1, 1, 0.01, 0.01, 1, 10], len(RADII))
    return TerrainCost({"front": w, "hind": -w}, RADII, oriented=oriented)


@pytest.fixture(scope="module")
def rocks() -> Terrain:
    return load_terrain("large_rocks:seed=4,length=0.8,pad_start=0.1,pad_end=0.1")


def test_cost_map_matches_point_queries_at_cell_centres(rocks: Terrain) -> None:
    cost = random_cost(oriented=False)
    grid = cost.cost_map(rocks, leg="hind")
    assert grid.shape == rocks.shape and grid.dtype == np.float64
    feats = cost.features_for(rocks)
    gx, gy = np.meshgrid(rocks.x, rocks.y, indexing="ij")
    xy = np.column_stack([gx.ravel(), gy.ravel()])
    points = cost.cost_at(feats, xy, leg="hind").reshape(grid.shape)
    # A point is usable where the cells around it are (at a cell centre, round-off
    # may pick the cells on either side), so compare where all 8 neighbours are valid.
    from scipy.ndimage import binary_erosion

    inner = binary_erosion(feats.valid, structure=np.ones((3, 3), dtype=bool))
    assert inner.sum() > 0.5 * feats.valid.sum()
    np.testing.assert_allclose(points[inner], grid[inner], rtol=1e-9)
    assert np.all(np.isinf(points[~feats.valid]))
    assert np.all(np.isinf(grid[~feats.valid]))
    assert np.all(np.isfinite(grid[feats.valid]))
    # Hand-computed: exp(−w·f) at one cell.
    i, j = np.argwhere(feats.valid)[len(np.argwhere(feats.valid)) // 2]
    assert grid[i, j] == pytest.approx(np.exp(-feats.values[i, j] @ cost.weights["hind"]))
    # One point, as a (2,) array.
    assert cost.cost_at(feats, xy[i * rocks.shape[1] + j])[0] == pytest.approx(
        cost.cost_at(feats, xy[[i * rocks.shape[1] + j]])[0]
    )


def test_flat_ground_costs_one_and_unknown_ground_infinity() -> None:
    cost = TerrainCost.load()
    heights = np.zeros((120, 80))
    heights[50:60, 30:40] = np.nan
    t = Terrain(heights, 0.0, 0.0, 0.005, 0.005)
    grid = cost.cost_map(t)
    feats = cost.features_for(t)
    assert np.all(grid[feats.valid] == 1.0)
    assert np.all(np.isinf(grid[50:60, 30:40]))
    # Within the largest radius of the unknown patch, the disc touches it.
    reach = int(np.ceil(max(cost.radii) / 0.005))
    assert np.isinf(grid[50 - reach + 1, 35]) and np.isfinite(grid[50 - reach - 1, 35])
    assert np.all(np.isinf(cost.cost_at(feats, [[0.27, 0.17], [-1.0, 0.2]])))


def _rotated(t: Terrain) -> Terrain:
    """The terrain turned by +90° about z: heights'[a, b] = heights[b, n − 1 − a]."""
    n = t.shape[0]
    half = (n - 1) / 2 * t.dx
    return Terrain(t.heights[:, ::-1].T, -half, -half, t.dx, t.dy)


@pytest.mark.parametrize("heading", [0.0, 0.4, -2.0])
def test_oriented_cost_turns_with_the_ground(heading: float) -> None:
    # Ground turned by 90° and a robot turned by 90° see the same foothold.
    rng = np.random.default_rng(1)
    n = 61
    half = (n - 1) / 2 * 0.005
    x = np.linspace(-half, half, n)
    gx, gy = np.meshgrid(x, x, indexing="ij")
    heights = (
        0.02 * np.sin(9 * gx + 3) * np.cos(5 * gy) + 0.1 * gx + 0.01 * rng.normal(size=gx.shape)
    )
    ground = Terrain(heights, -half, -half, 0.005, 0.005)
    turned = _rotated(ground)
    cost = random_cost(oriented=True, seed=2)
    p = np.array([[0.02, -0.01], [-0.03, 0.025], [0.0, 0.0]])
    rp = np.column_stack([-p[:, 1], p[:, 0]])
    np.testing.assert_allclose(turned.height(rp), ground.height(p), atol=1e-12)
    a = cost.cost_at(cost.features_for(ground), p, heading=heading)
    b = cost.cost_at(cost.features_for(turned), rp, heading=heading + np.pi / 2)
    np.testing.assert_allclose(a, b, rtol=1e-9)
    # The oriented map for a heading equals point queries with that heading.
    grid = cost.cost_map(ground, heading=heading)
    i = np.array([30, 20, 41])
    j = np.array([30, 35, 25])
    xy = np.column_stack([ground.x[i], ground.y[j]])
    np.testing.assert_allclose(
        cost.cost_at(cost.features_for(ground), xy, heading=heading), grid[i, j], rtol=1e-9
    )
    # ... and differs from the map of another heading: orientation is used.
    assert not np.allclose(grid[i, j], cost.cost_map(ground, heading=heading + 1.0)[i, j])


def test_bad_queries_name_the_problem(rocks: Terrain) -> None:
    oriented = random_cost(oriented=True)
    with pytest.raises(InvalidArgumentError, match="give the robot's heading"):
        oriented.cost_map(rocks)
    plain = random_cost(oriented=False)
    with pytest.raises(InvalidArgumentError, match="unknown leg 'left'"):
        plain.cost_map(rocks, leg="left")
    with pytest.raises(InvalidArgumentError, match="radii"):
        plain.cost_at(compute_features(rocks, radii=(0.01, 0.02)), [[0.4, 0.0]])
    with pytest.raises(InvalidArgumentError, match="27 entries"):
        plain.utility(np.zeros(5))


def test_cost_show_writes_picture_and_arrays(tmp_path: Path, capsys) -> None:
    spec = "logs:seed=2,length=0.8,pad_start=0.1,pad_end=0.1"
    png, npz, js = tmp_path / "map.png", tmp_path / "map.npz", tmp_path / "map.json"
    args = ["cost", "show", "--terrain", spec, "-o", str(png), "--npz", str(npz)]
    assert main([*args, "--json", str(js), "--leg", "hind"]) == 0
    assert "shipped default" in capsys.readouterr().out
    with np.load(npz) as archive:  # closed here: a leaked handle warns in a later test
        arrays = {k: archive[k] for k in archive.files}
    terrain = load_terrain(spec)
    np.testing.assert_array_equal(arrays["x"], terrain.x)
    np.testing.assert_array_equal(arrays["y"], terrain.y)
    expected = TerrainCost.load().cost_map(terrain, leg="hind")
    np.testing.assert_array_equal(arrays["cost"], expected)
    assert np.isinf(arrays["cost"]).any() and (arrays["cost"][np.isfinite(expected)] >= 0).all()
    with Image.open(png) as im:
        assert im.format == "PNG" and im.size[0] > 800
        rgb = np.asarray(im.convert("RGB")).reshape(-1, 3)
        # The jet map's blue (flat pads) and red (log flanks) are both there.
        assert np.any((rgb[:, 2] > 150) & (rgb[:, 0] < 60))
        assert np.any((rgb[:, 0] > 150) & (rgb[:, 2] < 60))
    summary = json.loads(js.read_text())
    assert summary["schema"] == "cost_show" and summary["terrain"] == spec


def test_shipped_default_is_what_its_rebuild_command_makes(tmp_path: Path) -> None:
    shipped = data_dir() / "default_preferences.sqlite"
    assert default_cost_path() == data_dir() / "default_cost.json"
    rebuilt = tmp_path / "prefs.sqlite"
    n = build_default_preferences(rebuilt)
    assert n == DefaultCostRecipe().n_total

    def rows(path: Path) -> list[tuple]:
        conn = sqlite3.connect(f"file:{path}?mode=ro", uri=True)
        out = conn.execute(
            "SELECT ta.spec, a_x, a_y, a_heading, tb.spec, b_x, b_y, b_heading, leg, label, "
            "created_at, source FROM preferences p JOIN terrains ta ON ta.id = p.a_terrain "
            "JOIN terrains tb ON tb.id = p.b_terrain ORDER BY p.id"
        ).fetchall()
        conn.close()
        return out

    assert rows(rebuilt) == rows(shipped)
    # The shipped weights are what learning from the shipped judgements gives.
    with PreferenceStore.open(shipped, readonly=True) as store:
        data = PreferenceDataset.from_store(store, TerrainCost.load().radii)
    relearned, _ = learn_cost(data, CostLearningConfig(folds=0))
    default = TerrainCost.load()
    np.testing.assert_allclose(relearned.weights["front"], default.weights["front"], rtol=1e-9)
    assert default.metadata["n_preferences"] == n
    assert default.metadata["cv_agreement"] > 0.65


def test_shipped_default_agrees_with_the_expert_on_unseen_terrains() -> None:
    specs = ["large_rocks:seed=31", "round_rocks:seed=32", "sloped_rocks:seed=33", "logs:seed=34"]
    terrains = {s: load_terrain(s) for s in specs}
    cost = TerrainCost.load()
    feats = {s: cost.features_for(t) for s, t in terrains.items()}
    selector = PairSelector(list(terrains.values()), features=list(feats.values()), seed=3)
    pairs = [selector.propose(None) for _ in range(600)]
    labels = ScriptedExpert().judge([(p.a, p.b) for p in pairs], terrains, noisy=False)
    data = PreferenceDataset.from_preferences(
        [Preference(p.a, p.b, p.leg, lab) for p, lab in zip(pairs, labels, strict=True)], feats
    )
    assert agreement(cost, data) >= 0.88


def test_features_in_any_frame_give_the_same_costs(rocks: Terrain) -> None:
    # Precomputed features may come in a heading frame; each cost turns them
    # into the frame its weights expect.
    for oriented in (False, True):
        cost = random_cost(oriented=oriented, seed=5)
        heading = 0.7 if oriented else None
        reference = cost.cost_map(rocks, heading=heading)
        for frame in (None, -1.2, 0.7):
            feats = compute_features(rocks, radii=RADII, oriented_heading=frame)
            grid = cost.cost_map(rocks, heading=heading, features=feats)
            np.testing.assert_allclose(grid, reference, rtol=1e-9)
            xy = np.array([[0.3, 0.05], [0.52, -0.1]])
            np.testing.assert_allclose(
                cost.cost_at(feats, xy, heading=heading),
                cost.cost_at(cost.features_for(rocks), xy, heading=heading),
                rtol=1e-9,
            )
