"""The terrain commands: JSON envelopes, pictures, and errors that name the problem."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from roughwalk.cli.main import main
from roughwalk.terrain import list_generators, load_terrain


def test_terrain_list_names_every_generator_with_parameters(tmp_path: Path, capsys) -> None:
    out = tmp_path / "gens.json"
    assert main(["terrain", "list", "--json", str(out)]) == 0
    printed = capsys.readouterr().out
    data = json.loads(out.read_text())
    assert data["schema"] == "terrain_generators" and data["version"] >= 1
    names = {g["name"] for g in data["generators"]}
    assert names == {g.name for g in list_generators()}
    for required in ("flat", "large_rocks", "single_pallet", "double_pallet", "towr_gap"):
        assert required in names
        assert required in printed
    rocks = next(g for g in data["generators"] if g["name"] == "large_rocks")
    assert {"seed", "max_height"} <= {p["name"] for p in rocks["params"]}


def test_terrain_info_json_rebuilds_the_terrain(tmp_path: Path) -> None:
    out = tmp_path / "info.json"
    spec = "stepping_stones:seed=2"
    assert main(["terrain", "info", spec, "--json", str(out)]) == 0
    data = json.loads(out.read_text())
    assert data["schema"] == "terrain_info"
    rebuilt = load_terrain(data["terrain"])
    original = load_terrain(spec)
    np.testing.assert_array_equal(rebuilt.heights, original.heights)
    assert data["info"]["shape"] == list(original.shape)


def test_terrain_show_writes_a_png(tmp_path: Path) -> None:
    png = tmp_path / "t.png"
    assert main(["terrain", "show", "barrier", "-o", str(png)]) == 0
    with Image.open(png) as im:
        assert im.format == "PNG" and im.size[0] > 400
        # Not a blank canvas: the relief has many distinct colours.
        assert len(np.unique(np.asarray(im.convert("RGB")).reshape(-1, 3), axis=0)) > 100


def test_terrain_show_a_course_of_real_boards(tmp_path: Path, shared_dir: Path) -> None:
    boards = shared_dir / "terrains" / "littledog"
    spec = f"{boards / 'terrainA.mat'}+{boards / 'terrainC.mat'}@90"
    out = tmp_path / "info.json"
    assert main(["terrain", "info", spec, "--json", str(out)]) == 0
    x_span = json.loads(out.read_text())["info"]["extent"]["x"]
    assert x_span[1] - x_span[0] > 1.2


@pytest.mark.parametrize(
    ("spec", "fragment"),
    [
        ("nonexistent_board.mat", "nonexistent_board.mat"),
        ("large_rockz", "large_rocks"),
        ("large_rocks:seeed=3", "seed"),
        ("large_rocks:max_height=-1", "max_height"),
        ("flat@45", "90"),
    ],
)
def test_bad_terrain_specs_fail_with_a_message(spec: str, fragment: str, capsys) -> None:
    assert main(["terrain", "info", spec]) == 1
    err = capsys.readouterr().err
    assert "error" in err and fragment in err
