"""``roughwalk optimize``: the issue's flags, the JSON result the tracker reads, the picture."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
from PIL import Image

from roughwalk.cli.main import main

FLAGS = [
    "optimize", "--robot", "anymal_c", "--terrain", "flat", "--gait", "walk", "--steps", "4",
    "--duration", "2.0", "--start", "0,0,0", "--goal", "0.3,0.05,0.1", "--init", "heuristic",
    "--max-iter", "300", "--fixed-durations",
]  # fmt: skip


def test_optimize_writes_json_npz_and_picture(tmp_path: Path, capsys) -> None:
    out, png, npz = tmp_path / "out.json", tmp_path / "plot.png", tmp_path / "motion.npz"
    code = main([*FLAGS, "--json", str(out), "-o", str(png), "--npz", str(npz)])
    printed = capsys.readouterr().out
    data = json.loads(out.read_text())
    assert code == 0 and data["solved"] is True and "exact" in printed
    assert data["schema"] == "trajopt_result" and data["robot"] == "anymal_c"
    for key in (
        "status",
        "iterations",
        "solve_time_s",
        "objective",
        "max_violation",
        "max_force_n",
        "n_variables",
    ):
        assert key in data
    # 20 base polynomials: 21 nodes of 12 variables, plus the feet's 20·4 + 108.
    assert data["n_variables"] == 12 * 21 + 20 * 4 + 108
    with np.load(data["trajectory_npz"]) as samples:
        np.testing.assert_allclose(samples["com_position"][-1, :2], [0.3, 0.05], atol=1e-4)
        assert samples["contact"].shape == (len(samples["t"]), 4)
    with Image.open(png) as image:
        assert image.size[0] > 800 and image.size[1] > 500


def test_optimize_bad_task_reports_a_status(tmp_path: Path, capsys) -> None:
    out = tmp_path / "bad.json"
    flags = [f if f != "2.0" else "0.2" for f in FLAGS]  # 4 steps in 0.2 s
    assert main([*flags, "--json", str(out)]) == 1
    data = json.loads(out.read_text())
    assert data["status"] == "invalid_input" and data["solved"] is False
    assert "too short" in data["message"] and "invalid_input" in capsys.readouterr().out
    assert main([*FLAGS[:-1], "--start", "0,0"]) == 1
    assert "--start must be X,Y,YAW" in capsys.readouterr().err


def test_a_named_body_model_still_names_the_robot_that_executes_it(tmp_path: Path) -> None:
    # `roughwalk track` loads the JSON's robot: TOWR's body parameters are not a robot.
    out = tmp_path / "towr.json"
    assert main([*FLAGS, "--set", "body_model=towr_anymal", "--json", str(out)]) == 0
    data = json.loads(out.read_text())
    assert data["robot"] == "anymal_c" and data["body_model"] == "towr_anymal"


def test_leg_reach_is_on_by_default_and_no_leg_reach_drops_its_rows(tmp_path: Path) -> None:
    """The ball-per-leg constraint is in the default problem; ``--no-leg-reach`` removes it."""
    counts = []
    for k, extra in enumerate(([], ["--leg-reach"], ["--no-leg-reach"])):
        out = tmp_path / f"reach{k}.json"
        main([*FLAGS, "--max-iter", "0", *extra, "--json", str(out)])
        counts.append(json.loads(out.read_text())["n_constraints"])
    assert counts[0] == counts[1] > counts[2]
