"""`roughwalk sdf`: JSON with build time, shape and resolution; npz that loads back; a picture."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from roughwalk.cli.main import main
from roughwalk.terrain import load_terrain
from roughwalk.terrain.sdf import SignedDistanceField


def test_sdf_command_writes_json_npz_and_picture(tmp_path: Path) -> None:
    out, npz, png = tmp_path / "s.json", tmp_path / "s.npz", tmp_path / "s.png"
    spec = "steps:resolution=0.01"
    code = main(
        ["sdf", spec, "--resolution", "0.01", "--json", str(out), "--npz", str(npz), "-o", str(png)]
    )
    assert code == 0
    data = json.loads(out.read_text())
    assert data["schema"] == "sdf" and data["terrain"] == load_terrain(spec).spec
    assert data["resolution"] == 0.01 and data["build_time_s"] > 0
    sdf = SignedDistanceField.load(npz)
    assert list(sdf.shape) == data["shape"]
    terrain = load_terrain(data["terrain"])
    xy = np.array([[0.2, 0.0], [1.0, 0.1]])
    d, _ = sdf.query(np.column_stack([xy, terrain.height(xy) + 0.05]))
    np.testing.assert_allclose(d, 0.05, atol=0.01)
    assert png.stat().st_size > 10_000


def test_sdf_command_set_override_and_bad_value(tmp_path: Path, capsys) -> None:
    out = tmp_path / "s.json"
    assert (
        main(
            [
                "sdf",
                "flat",
                "--set",
                "z_margin=0.05",
                "--set",
                "resolution=0.02",
                "--json",
                str(out),
            ]
        )
        == 0
    )
    assert json.loads(out.read_text())["config"]["z_margin"] == 0.05
    assert main(["sdf", "flat", "--set", "resolutoin=0.02"]) == 1
    assert "resolution" in capsys.readouterr().err
