"""The lift gate: a foot lifts only once the feet that stay down bear their share."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

import roughwalk
from roughwalk.errors import ConfigError
from roughwalk.sim import run
from roughwalk.sim.config import LiftGateConfig, SimConfig
from roughwalk.sim.lift_gate import LiftGate
from roughwalk.sim.trajectory_buffer import Segment, TrajectoryBuffer

DT = 0.002
LIFT = 50
"""LF is down for samples 0 … LIFT − 1 and up from sample LIFT on."""


def lifting_segment(kind: str = "step") -> Segment:
    """0.2 s at the control rate: four feet down (6 N planned each), then LF up (9, 7, 5 N)."""
    n = 101
    t = np.arange(n) * DT
    support = np.ones((n, 4), dtype=bool)
    support[LIFT:, 0] = False
    forces = np.zeros((n, 4, 3))
    forces[:LIFT, :, 2] = 6.0
    forces[LIFT:, 1:, 2] = [9.0, 7.0, 5.0]
    quat = np.zeros((n, 4))
    quat[:, 0] = 1.0
    q = np.linspace(0.0, 0.1, n)[:, None] * np.ones((1, 12))
    return Segment(
        t=t,
        q=q,
        qd=np.full((n, 12), 0.5),
        base_pos=np.zeros((n, 3)),
        base_quat=quat,
        feet=np.zeros((n, 4, 3)),
        support=support,
        forces=forces,
        phase=(~support[:, 0]).astype(np.int64),
        kind=kind,
        step=1,
    )


def loads(fz: list[float]) -> SimpleNamespace:
    forces = np.zeros((4, 3))
    forces[:, 2] = fz
    return SimpleNamespace(foot_forces=forces)


def tau_before_lift() -> float:
    return (LIFT - 1) * DT


def test_a_staying_foot_that_bears_nothing_holds_the_lift_off_up_to_the_longest_hold() -> None:
    seg = lifting_segment()
    gate = LiftGate(LiftGateConfig(enabled=True, least_n=2.0, fraction=0.5, max_hold_s=0.01), DT)
    tau = tau_before_lift()
    desired = seg.sample(tau)
    # LH (index 2) bears nothing while LF is about to lift: hold, five ticks (0.01 s).
    held = [gate.hold(seg, tau, desired, loads([6, 6, 0.0, 6])) for _ in range(8)]
    assert held == [True] * 5 + [False] * 3
    assert gate.short == [2]
    # The tick that ends the hold reports its length; the next ones nothing.
    gate2 = LiftGate(LiftGateConfig(enabled=True, max_hold_s=0.01), DT)
    for _ in range(5):
        assert gate2.hold(seg, tau, desired, loads([6, 6, 0.0, 6]))
    assert not gate2.hold(seg, tau, desired, loads([6, 6, 0.0, 6]))
    assert gate2.released_s == pytest.approx(0.01)
    assert not gate2.hold(seg, tau, desired, loads([6, 6, 0.0, 6]))
    assert gate2.released_s == 0.0


def test_the_gate_lets_a_lift_off_go_when_the_staying_feet_bear() -> None:
    seg = lifting_segment()
    gate = LiftGate(LiftGateConfig(enabled=True, least_n=2.0, fraction=0.5), DT)
    tau = tau_before_lift()
    desired = seg.sample(tau)
    assert gate.hold(seg, tau, desired, loads([6, 6, 1.9, 6]))
    # 2 N is enough (least_n); the lifting foot's own load does not matter.
    assert not gate.hold(seg, tau, desired, loads([0, 6, 2.0, 6]))
    assert gate.released_s == pytest.approx(DT)
    # A foot planned light (5 N on RH) needs only half of it, if that is less than least_n.
    light = LiftGate(LiftGateConfig(enabled=True, least_n=4.0, fraction=0.5), DT)
    assert not light.hold(seg, tau, desired, loads([6, 6, 6, 2.5]))
    assert light.hold(seg, tau, desired, loads([6, 6, 6, 2.4]))


def test_the_gate_only_acts_at_a_lift_off_of_a_footstep_and_when_enabled() -> None:
    seg = lifting_segment()
    unloaded = loads([0.0, 0.0, 0.0, 0.0])
    gate = LiftGate(LiftGateConfig(enabled=True), DT)
    # Mid-shift (no foot lifts at the next tick) and mid-swing: no hold.
    for k in (0, 20, LIFT, LIFT + 20):
        assert not gate.hold(seg, k * DT, seg.sample(k * DT), unloaded)
    recovery = lifting_segment(kind="recovery")
    assert not gate.hold(recovery, tau_before_lift(), recovery.sample(tau_before_lift()), unloaded)
    off = LiftGate(LiftGateConfig(), DT)
    assert not off.hold(seg, tau_before_lift(), seg.sample(tau_before_lift()), unloaded)


def test_a_delayed_buffer_replays_the_same_instant() -> None:
    seg = lifting_segment()
    buffer = TrajectoryBuffer()
    buffer.append(seg)
    now = tau_before_lift()
    first, _, _ = buffer.advance(now)
    buffer.delay(DT)
    again, _, _ = buffer.advance(now + DT)
    np.testing.assert_array_equal(again.q, first.q)
    np.testing.assert_array_equal(again.support, first.support)
    later, _, _ = buffer.advance(now + 2 * DT)
    assert not later.support[0]


def test_config_rejects_nonsense() -> None:
    for bad in ({"least_n": -1.0}, {"fraction": float("nan")}, {"max_hold_s": -0.1}):
        with pytest.raises(ConfigError, match="lift_gate"):
            LiftGateConfig(**bad)


def test_a_strict_gate_holds_the_walk_and_the_holds_are_its_gate_share(littledog) -> None:
    """Flat ground, every staying foot asked to bear its whole planned load: lift-offs wait."""
    terrain = roughwalk.load_terrain("flat")
    strict = LiftGateConfig(enabled=True, least_n=1e3, fraction=1.0, max_hold_s=0.05)
    gated = run(littledog, terrain, (0.3, 0.0, 0.0), (0.6, 0.0), config=SimConfig(lift_gate=strict))
    plain = run(littledog, terrain, (0.3, 0.0, 0.0), (0.6, 0.0), config=SimConfig())
    assert gated.outcome.success and plain.outcome.success, gated.outcome.reason
    holds = gated.log.events_of("lift_gate")
    assert len(holds) >= 4
    assert all(0 < e["held_s"] <= strict.max_hold_s + 1e-9 and e["legs"] for e in holds)
    held = sum(e["held_s"] for e in holds)
    split = gated.outcome.extra["time_breakdown"]
    assert split["gate_s"] == pytest.approx(held, abs=3 * DT)
    assert plain.outcome.extra["time_breakdown"]["gate_s"] == 0.0
    # The plan's clock stood still for the holds: the walk took that much longer.
    assert gated.outcome.time_s > plain.outcome.time_s + 0.5 * held
