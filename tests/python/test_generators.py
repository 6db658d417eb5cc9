"""Terrain generators: the contract over every generator, and the published dimensions."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from roughwalk.errors import TerrainError
from roughwalk.terrain import generate, list_generators, load_terrain
from roughwalk.terrain.generators import GENERATORS, generator_info
from roughwalk.terrain.generators.littledog_rocks import LargeRocksParams, large_rocks

CANONICAL = [
    "flat",
    "large_rocks",
    "round_rocks",
    "sloped_rocks",
    "logs",
    "gap",
    "barrier",
    "steps",
    "stairs",
    "stepping_stones",
    "single_pallet",
    "double_pallet",
    "towr_block",
    "towr_stairs",
    "towr_gap",
    "towr_slope",
]
LITTLEDOG = CANONICAL[:10]
RANDOM = [g.name for g in list_generators() if g.randomized]


def coarse(name: str) -> dict[str, float]:
    """A resolution parameter that keeps the test fast."""
    return {"resolution": 0.01 if name in LITTLEDOG else 0.025}


def test_every_canonical_name_is_registered_and_listed():
    assert [g.name for g in list_generators()] == CANONICAL
    assert set(RANDOM) == {"large_rocks", "round_rocks", "sloped_rocks", "logs", "stepping_stones"}
    for g in list_generators():
        assert g.description
        assert g.parameters
        for p in g.parameters:
            assert p.type in (int, float, bool)
            assert isinstance(p.default, p.type)
            assert isinstance(p.unit, str) and p.doc
        json.dumps(g.to_dict())
    units = {p.name: p.unit for p in generator_info("large_rocks").parameters}
    assert units["max_height"] == "m" and units["resolution"] == "m"
    assert generator_info("large_rocks").default_config().max_height == 0.108


@pytest.mark.parametrize("name", CANONICAL)
def test_contract(name):
    t = generate(name, **coarse(name))
    assert t.name == name
    assert np.all(np.isfinite(t.raw_heights))
    if name in LITTLEDOG:
        assert t.extent == pytest.approx((0.0, 2.0, -0.3, 0.3), abs=1e-12)
    else:
        assert t.extent == pytest.approx((-1.0, 5.0, -1.5, 1.5), abs=1e-12)
    assert t.dx == pytest.approx(coarse(name)["resolution"], rel=0.05)
    lo, hi = t.height_range
    assert (hi - lo > 0.02) == (name != "flat")
    # The spec it carries rebuilds it exactly.
    again = load_terrain(t.spec)
    np.testing.assert_array_equal(again.heights, t.heights)
    assert again.spec == t.spec


@pytest.mark.parametrize("name", RANDOM)
def test_seeded(name):
    a = generate(name, seed=4, resolution=0.01)
    b = generate(name, seed=4, resolution=0.01)
    c = generate(name, seed=5, resolution=0.01)
    np.testing.assert_array_equal(a.heights, b.heights)
    assert not np.array_equal(a.heights, c.heights)


@pytest.mark.parametrize("name", LITTLEDOG)
def test_littledog_height_limit_and_flat_pads(name):
    t = generate(name, resolution=0.01)
    cfg = generator_info(name).default_config()
    lo, hi = t.height_range
    assert hi <= 0.108 + 1e-12
    assert lo >= -0.1 - 1e-12
    x = t.x
    start = t.heights[x < cfg.pad_start - 1e-9]
    end = t.heights[x > cfg.length - cfg.pad_end + 1e-9]
    assert np.all(start == 0.0)
    assert np.all(end == end[0, 0])
    if name != "flat":
        between = t.heights[(x > cfg.pad_start) & (x < cfg.length - cfg.pad_end)]
        assert np.ptp(between) > 0.03


@pytest.mark.parametrize("name", RANDOM)
def test_max_height_parameter_is_respected(name):
    t = generate(name, seed=2, max_height=0.05, resolution=0.01)
    assert t.height_range[1] <= 0.05 + 1e-12
    assert t.height_range[1] > 0.02


def test_canonical_spec_and_string_parameters():
    t = generate("large_rocks", seed="3", max_height="0.08")
    assert t.spec == "large_rocks:seed=3,max_height=0.08"
    assert generate("large_rocks").spec == "large_rocks"
    # A direct call with the config gives the same terrain and spec.
    d = large_rocks(LargeRocksParams(seed=3, max_height=0.08))
    np.testing.assert_array_equal(d.heights, t.heights)
    assert d.spec == t.spec and d.name == "large_rocks"
    assert generate("large_rocks", seed=3.0).spec == "large_rocks:seed=3"


def probe(t, points):
    return t.height(np.array(points, dtype=float))


def test_single_pallet_dimensions():
    t = generate("single_pallet")
    inside = [(1.0, 0.0), (1.6, 0.0), (2.2, 0.0), (1.6, -0.5), (1.6, 0.5), (1.05, 0.45)]
    outside = [(0.99, 0.0), (2.21, 0.0), (1.6, 0.51), (1.6, -0.51), (0.0, 0.0), (3.0, 1.0)]
    np.testing.assert_allclose(probe(t, inside), 0.165, atol=1e-12)
    np.testing.assert_allclose(probe(t, outside), 0.0, atol=1e-12)
    on_top = t.heights > 0.1
    xs, ys = t.x[on_top.any(axis=1)], t.y[on_top.any(axis=0)]
    assert (xs.min(), xs.max()) == pytest.approx((1.0, 2.2), abs=1e-9)
    assert (ys.min(), ys.max()) == pytest.approx((-0.5, 0.5), abs=1e-9)


def test_double_pallet_dimensions():
    t = generate("double_pallet")
    np.testing.assert_allclose(probe(t, [(1.2, 0.0), (1.0, 0.3), (1.39, -0.4)]), 0.145, atol=1e-12)
    np.testing.assert_allclose(probe(t, [(1.8, 0.0), (1.4, 0.0), (2.2, 0.5)]), 0.31, atol=1e-12)
    np.testing.assert_allclose(probe(t, [(0.99, 0.0), (2.21, 0.0), (1.8, 0.51)]), 0.0, atol=1e-12)
    top = t.heights > 0.2
    assert t.x[top.any(axis=1)].min() == pytest.approx(1.4, abs=1e-9)
    assert t.x[top.any(axis=1)].max() == pytest.approx(2.2, abs=1e-9)


def test_towr_block():
    t = generate("towr_block")
    np.testing.assert_allclose(
        probe(t, [(0.5, 0), (0.7, 0), (0.715, 0), (0.73, 0), (1.0, 0), (4.2, 0), (4.21, 0)]),
        [0.0, 0.0, 0.25, 0.5, 0.5, 0.5, 0.0],
        atol=1e-9,
    )


def test_towr_stairs():
    t = generate("towr_stairs")
    np.testing.assert_allclose(
        probe(
            t, [(0.9, 0), (1.0, 0), (1.2, 0), (1.4, 0), (1.9, 1.0), (2.39, 0), (2.4, 0), (2.6, 0)]
        ),
        [0.0, 0.2, 0.2, 0.4, 0.4, 0.4, 0.0, 0.0],
        atol=1e-9,
    )


def test_towr_gap():
    t = generate("towr_gap")
    # z = a (x − 1.0)(x − 1.5) with a = 4·1.5 / 0.5² = 24.
    np.testing.assert_allclose(
        probe(t, [(0.9, 0), (1.0, 0), (1.1, 0), (1.25, 0), (1.4, -1.0), (1.5, 0), (1.6, 0)]),
        [0.0, 0.0, 24 * 0.1 * -0.4, -1.5, 24 * 0.4 * -0.1, 0.0, 0.0],
        atol=1e-9,
    )
    assert t.height_range[0] == pytest.approx(-1.5)


def test_towr_slope():
    t = generate("towr_slope")
    np.testing.assert_allclose(
        probe(t, [(0.9, 0), (1.0, 0), (1.5, 0), (2.0, 0), (2.5, 0.7), (3.0, 0), (3.1, 0)]),
        [0.0, 0.0, 0.35, 0.7, 0.35, 0.0, 0.0],
        atol=1e-9,
    )


def test_littledog_block_dimensions():
    gap = generate("gap")
    np.testing.assert_allclose(
        probe(gap, [(0.93, 0), (1.0, 0.2), (1.06, 0), (1.07, 0)]), [0, -0.1, -0.1, 0], atol=1e-9
    )
    barrier = generate("barrier")
    np.testing.assert_allclose(
        probe(barrier, [(0.97, 0), (1.0, 0), (1.025, 0.1)]), [0, 0.08, 0.08], atol=1e-9
    )
    stairs = generate("stairs")
    np.testing.assert_allclose(
        probe(stairs, [(0.45, 0), (0.6, 0), (0.85, 0), (1.1, 0), (1.4, 0), (1.9, 0)]),
        [0, 0.027, 0.054, 0.081, 0.108, 0.108],
        atol=1e-9,
    )
    steps = generate("steps")
    np.testing.assert_allclose(
        probe(steps, [(0.5, 0), (0.6, 0), (0.75, 0), (1.0, 0), (1.35, 0), (1.4, 0), (1.5, 0)]),
        [0, 0.054, 0.108, 0.108, 0.054, 0.054, 0.0],
        atol=1e-9,
    )
    stones = generate("stepping_stones", resolution=0.005)
    pit = stones.heights[(stones.x > 0.36) & (stones.x < 1.64)]
    assert pit.min() == pytest.approx(-0.1)
    assert 0.3 < np.mean(pit > -0.1) < 0.7  # stones and gaps, both plentiful


def test_unknown_generator_lists_the_known_ones():
    with pytest.raises(TerrainError, match="unknown terrain generator 'lage_rocks'") as e:
        generate("lage_rocks")
    for name in CANONICAL:
        assert name in str(e.value)
    with pytest.raises(TerrainError, match="towr_slope"):
        load_terrain("nothing_like_this:seed=1")


def test_unknown_parameter_lists_the_valid_ones():
    with pytest.raises(TerrainError, match="unknown parameter 'hieght'") as e:
        generate("barrier", hieght=0.1)
    for p in ("center", "thickness", "height", "resolution", "pad_start"):
        assert p in str(e.value)


@pytest.mark.parametrize(
    ("name", "params", "bad"),
    [
        ("large_rocks", {"seed": "3.5"}, "seed"),
        ("large_rocks", {"seed": 3.5}, "seed"),
        ("large_rocks", {"seed": -1}, "seed"),
        ("flat", {"resolution": 1e-5}, "resolution"),
        ("towr_block", {"resolution": 1e-4}, "resolution"),
        ("large_rocks", {"max_height": "nan"}, "max_height"),
        ("large_rocks", {"max_height": math.nan}, "max_height"),
        ("large_rocks", {"max_height": "tall"}, "max_height"),
        ("flat", {"length": -2.0}, "length"),
        ("logs", {"resolution": 0}, "resolution"),
        ("single_pallet", {"height": -0.1}, "height"),
        ("towr_gap", {"width": "inf"}, "width"),
        ("large_rocks", {"pad_start": 1.0, "pad_end": 1.0}, "pad_start"),
        ("gap", {"center": 0.2}, "center"),
        ("double_pallet", {"top_offset": 2.0}, "top_offset"),
        ("stepping_stones", {"stone_size": 0.2}, "stone_size"),
        ("round_rocks", {"min_radius": 0.06}, "min_radius"),
        ("towr_slope", {"x_max": -1.0}, "x_max"),
    ],
)
def test_bad_values_name_the_parameter(name, params, bad):
    with pytest.raises(TerrainError, match=bad):
        generate(name, **params)


def test_registry_is_a_dict_of_infos():
    assert GENERATORS["towr_gap"].family == "towr"
    assert GENERATORS["single_pallet"].family == "pallets"
