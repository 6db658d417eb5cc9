"""Where a planned contact point puts the foot: a sphere resting on the terrain, not in it."""

from __future__ import annotations

import numpy as np
import pytest

import roughwalk as rw
from roughwalk.errors import ConfigError, InvalidArgumentError
from roughwalk.planning.foothold_safety import resting_centres
from roughwalk.terrain.terrain import Terrain
from roughwalk.trajectories.config import TrajectoryConfig
from roughwalk.trajectories.step_sequence import StepSequence
from roughwalk.trajectories.whole_body import WholeBody

DX = 0.001


def _ridge_terrain() -> Terrain:
    """Flat ground with a 3 mm wide, 5 mm high ridge along y at x = 0.20 m (1 mm grid)."""
    x = np.arange(0.0, 0.4 + DX / 2, DX)
    y = np.arange(-0.2, 0.2 + DX / 2, DX)
    h = np.zeros((len(x), len(y)))
    h[np.abs(x - 0.20) <= 0.0015 + 1e-9, :] = 0.005
    return Terrain(h, float(x[0]), float(y[0]), DX, DX, name="ridge")


def _plan(littledog: rw.Robot, step_xy: tuple[float, float], z: float) -> dict:
    feet = littledog.nominal_stance.feet.copy() + [0.08, 0.0, 0.0]
    feet[:, 2] = 0.0
    return {
        "robot": "littledog",
        "terrain": "ridge",
        "footsteps": [
            {"leg": leg, "x": f[0], "y": f[1], "z": f[2]}
            for leg, f in zip(("LF", "RF", "LH", "RH"), feet, strict=True)
        ]
        + [{"leg": "LF", "x": step_xy[0], "y": step_xy[1], "z": z}],
    }


def _sinks(terrain: Terrain, centre: np.ndarray, radius: float) -> float:
    """How deep [m] the terrain's grid points reach inside a sphere at ``centre``."""
    x, y = np.meshgrid(terrain.x, terrain.y, indexing="ij")
    pts = np.column_stack([x.ravel(), y.ravel(), np.asarray(terrain.heights).ravel()])
    near = np.linalg.norm(pts[:, :2] - centre[:2], axis=1) < 2 * radius
    return float(max(0.0, radius - np.min(np.linalg.norm(pts[near] - centre, axis=1))))


def test_a_contact_on_a_ridge_flank_rests_the_foot_on_the_ridge(littledog: rw.Robot) -> None:
    """The swing's target over a contact on a steep flank is a sphere on the ridge, not in it.

    The contact (x = 0.199 m, on the ridge's 1 mm flank) has a bilinear
    normal of 68°, while the foot's disc is nearly flat. Along that normal
    the centre lies 7 mm below the ridge's top, 6 mm inside the rock.
    """
    terrain = _ridge_terrain()
    r = littledog.foot_radius
    contact = (0.1985, 0.0)
    assert np.degrees(terrain.slope(np.array([contact]))[0]) > 60.0
    wb = WholeBody(littledog)
    z = float(terrain.height(np.array([contact]))[0])
    normal = StepSequence.from_plan(_plan(littledog, contact, z), wb, terrain=terrain)
    assert _sinks(terrain, normal.steps[0].target, r) > 0.004  # the centre along the normal
    seq = StepSequence.from_plan(
        _plan(littledog, contact, z), wb, terrain=terrain, foot_centre="resting"
    )
    target = seq.steps[0].target
    assert _sinks(terrain, target, r) < 2e-4
    np.testing.assert_allclose(target[:2], contact, atol=1e-12)
    # It rests: lower by a millimetre and it sinks in.
    assert _sinks(terrain, target - [0.0, 0.0, 0.001], r) > 5e-4
    # The stance's feet on flat ground are where they were.
    np.testing.assert_allclose(seq.initial_stance[:, 2], r, atol=1e-9)


def test_disc_centre_sits_along_the_mean_slope_of_the_foots_disc(littledog: rw.Robot) -> None:
    """On the ridge's flank the disc's mean slope leans 2° against the point normal's 79°:
    the centre along it sinks 2.5 mm, half the flank's height it stands below the top
    (6 mm along the point normal); only "resting" clears the ridge."""
    terrain = _ridge_terrain()
    r = littledog.foot_radius
    contact = (0.1985, 0.0)
    wb = WholeBody(littledog)
    z = float(terrain.height(np.array([contact]))[0])
    seq = StepSequence.from_plan(
        _plan(littledog, contact, z), wb, terrain=terrain, foot_centre="disc"
    )
    n = terrain.disc_normal(np.array([contact]), r)[0]
    assert n[2] > np.cos(np.radians(30.0)) > terrain.normal(np.array([contact]))[0][2]
    np.testing.assert_allclose(seq.steps[0].target, [*contact, z] + r * n, atol=1e-12)
    normal = StepSequence.from_plan(_plan(littledog, contact, z), wb, terrain=terrain)
    sinks = _sinks(terrain, seq.steps[0].target, r)
    assert sinks < 0.003 < 0.005 < _sinks(terrain, normal.steps[0].target, r)
    np.testing.assert_allclose(seq.initial_stance[:, 2], r, atol=1e-9)


def test_resting_centres_on_flat_and_a_step() -> None:
    terrain = _ridge_terrain()
    r = 0.0103
    out = resting_centres(terrain, np.array([[0.1, 0.0], [0.2, 0.05]]), r)
    np.testing.assert_allclose(out[0], [0.1, 0.0, r], atol=1e-9)
    np.testing.assert_allclose(out[1], [0.2, 0.05, 0.005 + r], atol=1e-9)


def test_foot_centre_is_checked() -> None:
    with pytest.raises(ConfigError, match="foot_centre"):
        TrajectoryConfig(foot_centre="lowest")


def test_from_plan_refuses_an_unknown_foot_centre(littledog: rw.Robot) -> None:
    with pytest.raises(InvalidArgumentError, match="foot_centre"):
        StepSequence.from_plan(
            _plan(littledog, (0.1, 0.0), 0.0),
            WholeBody(littledog),
            terrain=_ridge_terrain(),
            foot_centre="lowest",
        )
