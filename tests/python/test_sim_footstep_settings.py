"""``footstep.`` settings of a run reach the footstep planner's config (run, bench, ``--set``)."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import pytest

from roughwalk.cli.common import simulation_settings
from roughwalk.cli.main import main
from roughwalk.errors import ConfigError
from roughwalk.planning.footstep_config import FootstepConfig
from roughwalk.robots import load_robot
from roughwalk.sim import run
from roughwalk.sim.footstep_source import (
    EXECUTION_FOOTHOLD_SAFETY,
    planner_config,
    split_footstep_settings,
)


def test_footstep_keys_are_split_from_the_simulation_settings() -> None:
    sim, footstep = split_footstep_settings(
        {
            "reflex.enabled": "false",
            "footstep.edge_drop": "0.03",
            "footstep.certificate.clearance": 0.01,
        }
    )
    assert sim == {"reflex.enabled": "false"}
    assert footstep == {"edge_drop": "0.03", "certificate.clearance": 0.01}


def test_planner_config_applies_the_changes_after_the_longer_actions() -> None:
    robot = load_robot("littledog")
    default = FootstepConfig.for_robot(robot)
    # A walk refuses rims and flanks beyond the friction cone unless told otherwise.
    walk = planner_config(robot, 0.0, {})
    assert walk == replace(default, **EXECUTION_FOOTHOLD_SAFETY)
    assert walk.edge_drop > 0 and walk.max_foothold_slope < default.max_foothold_slope
    assert planner_config(robot, 0.0, {"edge_drop": "0"}).edge_drop == 0.0
    config = planner_config(
        robot, 0.4, {"edge_drop": "0.04", "certificate.start_clearance": "0.002"}
    )
    assert config.edge_drop == pytest.approx(0.04)
    assert config.certificate.start_clearance == pytest.approx(0.002)
    # The longer actions are still there: the changes did not start from the defaults.
    assert max(a[0] for a in config.actions) > max(a[0] for a in default.actions) + 1e-6


def test_set_checks_footstep_keys_before_any_run() -> None:
    sim, _ = simulation_settings(["footstep.edge_drop=0.03", "reflex.enabled=false"])
    assert sim["footstep.edge_drop"] == "0.03"
    with pytest.raises(ConfigError, match="edge_dorp"):
        simulation_settings(["footstep.edge_dorp=0.03"])
    with pytest.raises(ConfigError, match="edge_drop"):
        simulation_settings(["footstep.edge_drop=wide"])


def test_run_gives_footstep_keys_to_the_planner_config() -> None:
    # Routed to the simulation's own config, the key would be refused as an
    # unknown SimConfig field; it is refused by the planner's config instead.
    with pytest.raises(ConfigError, match="FootstepConfig"):
        run(
            "littledog",
            "flat",
            (0.0, 0.0, 0.0),
            (0.3, 0.0),
            planner="planner",
            **{"footstep.edge_dorp": 0.03},
        )


def test_roughwalk_run_refuses_an_unknown_footstep_setting_naming_it(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code = main(
        [
            "run",
            "--robot",
            "littledog",
            "--terrain",
            "flat",
            "--start",
            "0,0,0",
            "--goal",
            "0.3,0",
            "--out-dir",
            str(tmp_path),
            "--set",
            "footstep.edge_dorp=0.03",
        ]
    )
    assert code == 1
    err = capsys.readouterr().err
    assert "edge_dorp" in err and "FootstepConfig" in err
    assert not (tmp_path / "index.html").exists()


def test_roughwalk_run_takes_trajectory_settings_and_checks_them(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    argv = ["run", "--robot", "littledog", "--terrain", "flat", "--start", "0.3,0,0"]
    argv += ["--goal", "0.6,0", "--out-dir", str(tmp_path), "--no-video"]
    assert main([*argv, "--set", "trajectory.swing.time_lwa=joint"]) == 1
    assert "time_lwa" in capsys.readouterr().err
    out = tmp_path / "run.json"
    assert main([*argv, "--set", "trajectory.swing.time_law=joint", "--json", str(out)]) == 0
