"""The friction cone: μ every way with the elliptic cone, μ/√2 between the pyramid's axes."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

import roughwalk
from roughwalk.errors import ConfigError
from roughwalk.sim.config import ContactConfig, WorldConfig
from roughwalk.sim.world import World


def slide_mm(contact: ContactConfig, slope_deg: float, azimuth_deg: float) -> float:
    """How far [mm] a 1 cm foot, held from turning, slides in 1 s on a plane tilted ``slope_deg``.

    The plane falls along ``azimuth_deg`` from the contact frame's first
    tangent axis; the foot and plane carry ``contact``'s friction, ``solref``
    and ``solimp``, with its cone and ``impratio``, at the world's 2 kHz.
    """
    a, s = np.radians(azimuth_deg), np.radians(slope_deg)
    axis = np.array([-np.sin(a), np.cos(a), 0.0])
    quat = np.concatenate([[np.cos(s / 2)], np.sin(s / 2) * axis])
    geom = (
        f'friction="{contact.friction} {contact.torsional_friction} {contact.rolling_friction}" '
        f'condim="{contact.condim}" solref="{contact.timeconst} {contact.dampratio}" '
        f'solimp="{" ".join(str(v) for v in contact.solimp)}"'
    )
    xml = f"""<mujoco>
      <option timestep="0.0005" cone="{contact.cone}" impratio="{contact.impratio}"
              integrator="implicitfast"/>
      <worldbody>
        <geom type="plane" size="1 1 0.1" quat="{" ".join(map(str, quat))}" {geom}/>
        <body><joint type="slide" axis="1 0 0"/><joint type="slide" axis="0 1 0"/>
          <joint type="slide" axis="0 0 1"/>
          <geom type="sphere" size="0.01" mass="0.5" {geom}/></body>
      </worldbody></mujoco>"""
    m = mujoco.MjModel.from_xml_string(xml)
    d = mujoco.MjData(m)
    rot = np.zeros(9)
    mujoco.mju_quat2Mat(rot, quat)
    d.qpos[:] = rot.reshape(3, 3)[:, 2] * 0.0099
    for _ in range(200):
        mujoco.mj_step(m, d)
    start = d.qpos.copy()
    for _ in range(2000):
        mujoco.mj_step(m, d)
    return float(np.linalg.norm(d.qpos - start) * 1000)


def test_the_elliptic_cone_holds_a_foot_on_a_40_degree_slope_in_every_direction() -> None:
    contact = ContactConfig(cone="elliptic", impratio=10.0)
    for azimuth in (0.0, 22.5, 45.0, 67.5):
        assert slide_mm(contact, 40.0, azimuth) < 1.0, azimuth
    # Beyond atan μ = 45° it slides whichever way the slope falls.
    for azimuth in (0.0, 45.0):
        assert slide_mm(contact, 50.0, azimuth) > 100.0, azimuth


def test_the_pyramid_lets_a_foot_slide_where_a_slope_falls_between_its_axes() -> None:
    contact = ContactConfig(cone="pyramidal", impratio=1.0)
    assert slide_mm(contact, 40.0, 0.0) < 10.0
    # μ/√2 ≈ 0.71 between the axes: atan 0.71 ≈ 35°.
    assert slide_mm(contact, 40.0, 45.0) > 100.0


def test_the_world_takes_the_cone_and_impratio(littledog) -> None:
    cfg = WorldConfig(contact=ContactConfig(cone="elliptic", impratio=10.0))
    world = World(littledog, roughwalk.load_terrain("flat"), cfg)
    assert world.model.opt.cone == mujoco.mjtCone.mjCONE_ELLIPTIC
    assert world.model.opt.impratio == pytest.approx(10.0)


def test_by_default_the_world_keeps_each_robot_files_cone(littledog) -> None:
    flat = roughwalk.load_terrain("flat")
    anymal = World(roughwalk.load_robot("anymal_c"), flat)
    assert anymal.model.opt.cone == mujoco.mjtCone.mjCONE_ELLIPTIC
    assert anymal.model.opt.impratio == pytest.approx(100.0)
    dog = World(littledog, flat)
    assert dog.model.opt.cone == mujoco.mjtCone.mjCONE_PYRAMIDAL
    assert dog.model.opt.impratio == pytest.approx(1.0)


def test_contact_config_rejects_an_unknown_cone_and_a_nonpositive_impratio() -> None:
    with pytest.raises(ConfigError, match="cone"):
        ContactConfig(cone="round")
    with pytest.raises(ConfigError, match="impratio"):
        ContactConfig(impratio=0.0)
