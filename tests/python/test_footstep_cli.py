"""``roughwalk plan``: the issue's flags, the JSON fields, the picture, the exit codes."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from roughwalk.cli.main import main
from roughwalk.planning.footstep_cost import hand_set_terrain_cost

TERRAIN = "round_rocks:seed=7,length=0.9,width=0.6,pad_start=0.3,pad_end=0.15,max_height=0.05"


def test_plan_writes_the_json_and_the_picture(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out, png = tmp_path / "plan.json", tmp_path / "plan.png"
    argv = ["plan", "--robot", "littledog", "--terrain", TERRAIN, "--start", "0.25,0,0"]
    argv += ["--goal", "0.6,0.05", "--time-limit", "5", "--expansions", "200"]
    assert main([*argv, "--json", str(out), "-o", str(png)]) == 0
    assert "solved" in capsys.readouterr().out
    data = json.loads(out.read_text())
    assert data["schema"] == "footstep_plan" and data["robot"] == "littledog"
    assert data["terrain"] == TERRAIN and data["status"] == "solved"
    n = len(data["footsteps"]) - 4
    assert n == len(data["certificates"]) > 0
    assert [c["step"] for c in data["certificates"]] == list(range(1, n + 1))
    assert all(len(c["q"]) == 12 for c in data["certificates"])
    assert data["solutions"][0]["time_s"] == data["first_solution_s"]
    assert data["states_expanded"] <= 200 and data["actions_per_s"] > 0
    assert data["heuristic"] == "dubins" and data["epsilon0"] == 3.0
    with Image.open(png) as im:
        assert im.format == "PNG" and im.size[0] > 600
        assert len(np.unique(np.asarray(im.convert("RGB")).reshape(-1, 3), axis=0)) > 100
    # --set reaches the config.
    again = tmp_path / "again.json"
    assert main([*argv, "--json", str(again), "--set", "heuristic=euclidean"]) in (0, 1)
    assert json.loads(again.read_text())["heuristic"] == "euclidean"


def test_plan_with_a_cost_file_and_bad_input(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    cost = tmp_path / "cost.json"
    hand_set_terrain_cost().save(cost)
    out = tmp_path / "plan.json"
    argv = ["plan", "--terrain", TERRAIN, "--start", "0.25,0,0", "--expansions", "20"]
    assert main([*argv, "--goal", "3,0", "--cost", str(cost), "--json", str(out)]) == 1
    data = json.loads(out.read_text())
    assert data["status"] == "invalid_input" and "off the terrain" in data["reason"]
    assert data["cost_model"] == str(cost)
    assert main([*argv, "--goal", "0.6"]) == 1
    assert "--goal expects 2" in capsys.readouterr().err
