"""The touchdown adapter: early-landed feet stop where they stand, unloaded supports search down."""

from __future__ import annotations

from dataclasses import replace
from types import SimpleNamespace

import numpy as np
import pytest
from _sim_states import standing_step

import roughwalk
from roughwalk.errors import ConfigError
from roughwalk.robots._rotations import quat_multiply, quat_to_matrix
from roughwalk.sim.config import TouchdownConfig
from roughwalk.sim.reflexes import orientation_error
from roughwalk.sim.touchdown_adapter import TouchdownAdapter

DT = 0.002


@pytest.fixture(scope="module")
def stance() -> object:
    """The desired state of a footstep standing in LittleDog's nominal stance, trunk pitched."""
    return standing_step(roughwalk.load_robot("littledog"), (0.0, 0.1, 0.0))


def measured_like(desired: object, fz: list[float], quat: np.ndarray | None = None) -> object:
    forces = np.zeros((4, 3))
    forces[:, 2] = fz
    return SimpleNamespace(
        feet=np.array(desired.feet, dtype=float),
        foot_forces=forces,
        base_quat=desired.base_quat if quat is None else quat,
    )


def test_an_unloaded_support_foot_searches_down_to_its_bound_and_holds_when_loaded(stance) -> None:
    cfg = TouchdownConfig(search_rate_m_s=0.05, search_max_m=0.01)
    adapter = TouchdownAdapter(cfg, DT)
    measured = measured_like(stance, [8.0, 0.0, 8.0, 8.0])
    offsets = adapter.update(stance, measured)
    np.testing.assert_allclose(adapter.height, [0.0, -0.05 * DT, 0.0, 0.0], atol=1e-15)
    # The body-frame offset is the world one, (0, 0, h), seen from the pitched trunk.
    rot = quat_to_matrix(stance.base_quat)
    np.testing.assert_allclose(rot @ offsets[1], [0.0, 0.0, -0.05 * DT], atol=1e-15)
    assert not np.any(offsets[[0, 2, 3]])
    for _ in range(200):
        adapter.update(stance, measured)
    assert adapter.height[1] == pytest.approx(-0.01)
    adapter.height[1] = -0.004
    loaded = measured_like(stance, [8.0, 3.0, 8.0, 8.0])
    adapter.update(stance, loaded)
    assert adapter.height[1] == pytest.approx(-0.004)


def test_a_tilted_trunk_does_not_lengthen_a_lifted_support_foot(stance) -> None:
    adapter = TouchdownAdapter(TouchdownConfig(max_tilt_rad=0.05), DT)
    rolled = np.array([np.cos(0.05), np.sin(0.05), 0.0, 0.0])  # 0.1 rad about x
    quat = quat_multiply(rolled, stance.base_quat)
    assert orientation_error(quat, stance.base_quat) == pytest.approx(0.1)
    for _ in range(10):
        adapter.update(stance, measured_like(stance, [8.0, 0.0, 8.0, 8.0], quat))
    assert not np.any(adapter.height)


def test_an_early_landing_stops_the_foot_where_it_stands_and_fades_in_flight(stance) -> None:
    cfg = TouchdownConfig(early_force_n=2.0, early_window_s=0.1, release_s=0.05)
    adapter = TouchdownAdapter(cfg, DT)
    support = np.array([True, False, True, True])
    landing = np.array([np.inf, 0.05, np.inf, np.inf])
    swing = replace(stance, support=support, touchdown_in=landing)
    measured = measured_like(swing, [8.0, 5.0, 8.0, 8.0])
    measured.feet[1, 2] += 0.006  # it met the ground 6 mm above its planned path
    adapter.update(swing, measured)
    assert adapter.height[1] == pytest.approx(0.006)
    # Still lowering its target, the plan goes deeper; the foot's target does not.
    deeper = replace(swing, feet=swing.feet - np.array([0.0, 0.0, 0.002]))
    adapter.update(deeper, measured)
    assert adapter.height[1] == pytest.approx(0.008)
    # A contact long before the planned touchdown (lift-off, a scrape) is no landing.
    leaving = replace(swing, touchdown_in=np.array([np.inf, 0.3, np.inf, np.inf]))
    adapter.update(leaving, measured)
    assert adapter.height[1] == pytest.approx(0.008 * np.exp(-DT / 0.05))
    adapter.reset()
    assert not np.any(adapter.height)
    off = TouchdownAdapter(TouchdownConfig(enabled=False), DT)
    assert not np.any(off.update(swing, measured))


def test_config_rejects_nonsense() -> None:
    with pytest.raises(ConfigError):
        TouchdownConfig(search_max_m=-0.01)
    with pytest.raises(ConfigError):
        TouchdownConfig(release_s=0.0)
