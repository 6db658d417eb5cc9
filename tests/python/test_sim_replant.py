"""After a recovery: a foot left on a steep face steps onto the nearest gentle foothold.

``reflex.replant_max_slope`` (:func:`roughwalk.sim.recovery.replant_segments`,
:func:`roughwalk.sim.foothold_snap.replant_targets`).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest

import roughwalk as rw
from roughwalk import _core
from roughwalk.config import override
from roughwalk.planning.foothold_safety import steep_footholds
from roughwalk.sim.config import SimConfig
from roughwalk.sim.executor import Executor
from roughwalk.sim.foothold_snap import replant_targets
from roughwalk.sim.footstep_source import PlannerSource, PlanStart, planner_config
from roughwalk.sim.joint_controller import JointController
from roughwalk.sim.recovery import pose_segment, replant_segments, sliding_leg
from roughwalk.sim.runner import Runner
from roughwalk.sim.world import World
from roughwalk.terrain import Terrain

DX = 0.002


def _standing(robot: rw.Robot, terrain: Terrain) -> tuple[Runner, JointController, object]:
    st = robot.nominal_stance
    base = np.array([0.5, 0.0, st.base_height])
    quat = np.array([1.0, 0.0, 0.0, 0.0])
    q, _ = robot.inverse_kinematics(st.feet + base, base, quat)
    world = World(robot, terrain)
    runner = Runner(world)
    measured = runner.reset(q, base, quat)
    return runner, JointController(world), measured


def _level_pose(robot: rw.Robot, measured: Any, kind: str) -> Any:
    """The level trunk over the measured feet, all four down, as one ``kind`` pose sample."""
    return pose_segment(
        robot,
        np.repeat(measured.base_pos[None], 2, axis=0),
        np.zeros((2, 3)),
        np.repeat(measured.feet[None], 2, axis=0),
        np.ones(4, dtype=bool),
        1e-3,
        kind,
        0.0,
    ).last()


def test_a_replanted_foot_steps_to_its_target_while_the_others_stay() -> None:
    robot = rw.load_robot("littledog")
    runner, controller, measured = _standing(robot, rw.load_terrain("flat"))
    for _ in range(100):  # settle 0.2 s on four feet
        still = _level_pose(robot, measured, "hold")
        measured = runner.step(controller.command(still.q, still, measured))
    start = measured.feet.copy()
    target = start[1] + [0.02, -0.01, 0.0]  # RF 2.2 cm forward and out
    segments = replant_segments(robot, measured, 1, target, 0.25, 0.3, 0.0, 0.015)
    assert segments is not None
    t0 = measured.time
    for k, segment in enumerate(segments):
        begin = measured.time
        while measured.time - begin < segment.duration:
            desired = segment.sample(measured.time - begin)
            measured = runner.step(controller.command(desired.q, desired, measured))
            if k == 1 and measured.time - begin > 0.05:  # the swing, once the foot is off
                carried = float(measured.foot_forces[[0, 2, 3], 2].sum())
                assert carried > 0.8 * robot.mass * 9.81, (measured.time - begin, carried)
            tilt = np.degrees(np.abs(rw.trajectories.euler.matrix_to_rpy(measured.rotation)[:2]))
            assert np.all(tilt < 5.0), (measured.time - t0, tilt)
    assert np.linalg.norm(measured.feet[1] - target) < 0.005
    for leg in (0, 2, 3):
        assert np.linalg.norm(measured.feet[leg, :2] - start[leg, :2]) < 0.003, leg


def test_no_step_where_the_other_three_feet_cannot_hold_the_trunk() -> None:
    robot = rw.load_robot("littledog")
    _, _, measured = _standing(robot, rw.load_terrain("flat"))
    # RF pulled back between the hind feet: RF, LH and RH make a sliver of
    # a triangle that cannot hold the centre of mass 1.5 cm inside it.
    feet = measured.feet.copy()
    feet[1, :2] = 0.5 * (feet[2, :2] + feet[3, :2]) + [0.01, 0.0]
    squeezed = type(measured)(**{**measured.__dict__, "feet": feet})
    target = feet[0] + [0.02, 0.0, 0.0]
    assert replant_segments(robot, squeezed, 0, target, 0.25, 0.3, 0.0, 0.015) is None


def _flank() -> Terrain:
    """A ramp rising 50° from x = 0.60 to 0.62, flat beyond: a foot at x ≈ 0.61 stands on it."""
    x = np.arange(0.0, 0.8, DX)
    y = np.arange(-0.3, 0.3, DX)
    xx, _ = np.meshgrid(x, y, indexing="ij")
    h = np.clip((xx - 0.60) * np.tan(np.radians(50.0)), 0.0, 0.02 * np.tan(np.radians(50.0)))
    return Terrain(h, x0=0.0, y0=-0.3, dx=DX, dy=DX, name="flank")


@pytest.mark.skipif(
    not hasattr(_core, "FootstepPlanner"), reason="the compiled core has no footstep planner"
)
def test_a_foot_on_a_flank_is_replanted_on_the_nearest_gentle_foothold() -> None:
    """RF on a 50° ramp with a 40° limit: it moves; the feet on flat ground stay."""
    robot = rw.load_robot("littledog")
    terrain = _flank()
    source = PlannerSource(robot, terrain, expansions=10, config=planner_config(robot, 0.4, {}))
    r = robot.foot_radius
    steep = steep_footholds(terrain, r, np.radians(40.0))
    feet = np.array([[0.45, 0.1, r], [0.61, -0.1, 0.012 + r], [0.25, 0.1, r], [0.25, -0.1, r]])
    out = replant_targets(source.planner, terrain, feet, r, 0.025, steep)
    assert [leg for leg, _ in out] == [1]
    target = out[0][1]
    assert np.linalg.norm(target[:2] - feet[1, :2]) <= 0.025 + 1e-9
    i, j = round(target[0] / DX), round((target[1] + 0.3) / DX)
    assert not steep[i, j]
    # Not where the nearest gentle foothold is nearer than asked for.
    assert replant_targets(source.planner, terrain, feet, r, 0.025, steep, 0.03) == []
    # Its centre rests on the ground there: on it or, the flank within its disc, above it.
    assert target[2] >= float(terrain.height(target[None, :2])[0]) + r - 1e-9


def test_a_held_foot_sliding_off_its_recovery_foothold_is_caught_while_three_bear() -> None:
    robot = rw.load_robot("littledog")
    _, _, measured = _standing(robot, rw.load_terrain("flat"))
    held = _level_pose(robot, measured, "recovery")
    footholds = measured.feet.copy()
    loads = np.zeros((4, 3))
    loads[:, 2] = 6.0

    def slid(leg: int, by: float, forces: np.ndarray = loads) -> int | None:
        feet = footholds.copy()
        feet[leg, 0] -= by
        now = dataclasses.replace(measured, feet=feet, foot_forces=forces)
        return sliding_leg(now, held, footholds, 0.015, 1.0)

    assert slid(1, 0.01) is None  # within the limit
    assert slid(1, 0.02) == 1
    unloaded = loads.copy()
    unloaded[3, 2] = 0.0
    assert slid(1, 0.02, unloaded) is None  # RH bears nothing: RF cannot be put down again
    # A foot the recovery is still putting down (desired 5 mm off its foothold) is not watched.
    lowering = dataclasses.replace(held, feet=held.feet + [[0.0, 0.0, 0.005]] * 4)
    feet = footholds.copy()
    feet[2, 0] -= 0.03
    now = dataclasses.replace(measured, feet=feet, foot_forces=loads)
    assert sliding_leg(now, lowering, footholds, 0.015, 1.0) is None


def test_a_slide_on_a_diagonal_is_caught_when_fewer_others_must_bear() -> None:
    # Board AE's large-rocks falls: RF slides down a flank while the recovery
    # stands on the RF–LH diagonal, LF and RH bearing nothing.
    robot = rw.load_robot("littledog")
    _, _, measured = _standing(robot, rw.load_terrain("flat"))
    held = _level_pose(robot, measured, "recovery")
    footholds = measured.feet.copy()
    feet = footholds.copy()
    feet[1] += [0.0, -0.012, -0.012]  # 1.7 cm down and out
    forces = np.zeros((4, 3))
    forces[1, 2], forces[2, 2] = 19.0, 2.0
    now = dataclasses.replace(measured, feet=feet, foot_forces=forces)
    watch = [sliding_leg(now, held, footholds, 0.015, 1.0, bearing) for bearing in range(4)]
    assert watch == [1, 1, None, None]  # one other foot (LH) bears load
    # The count is of the other feet: the slid foot's own load is not one of them.
    forces[1, 2] = 0.0
    now = dataclasses.replace(measured, feet=feet, foot_forces=forces)
    assert sliding_leg(now, held, footholds, 0.015, 1.0, 1) == 1
    forces[2, 2] = 0.0
    now = dataclasses.replace(measured, feet=feet, foot_forces=forces)
    assert sliding_leg(now, held, footholds, 0.015, 1.0, 1) is None
    assert sliding_leg(now, held, footholds, 0.015, 1.0, 0) == 1


def _held_on_flat() -> Callable[..., int | None]:
    """``sliding_leg`` of LittleDog held in a recovery on flat ground, four feet
    bearing 8 N, with one foot moved: ``watch(leg, move, others_bearing, drop_m)``."""
    robot = rw.load_robot("littledog")
    _, _, measured = _standing(robot, rw.load_terrain("flat"))
    held = _level_pose(robot, measured, "recovery")
    footholds = measured.feet.copy()
    forces = np.zeros((4, 3))
    forces[:, 2] = 8.0

    def watch(leg: int, move: list[float], others: int = 0, drop: float = 0.0) -> int | None:
        feet = footholds.copy()
        feet[leg] += move
        now = dataclasses.replace(measured, feet=feet, foot_forces=forces)
        return sliding_leg(now, held, footholds, 0.01, 1.0, others, drop_m=drop)

    return watch


def test_a_foot_rising_off_its_foothold_is_no_slide() -> None:
    # The 1 N·s left push at 2.2 s on flat ground: the roll lifts RH 1 cm off
    # its foothold; caught as a slide and re-planted, the robot rolled over.
    watch = _held_on_flat()
    assert watch(3, [0.0, 0.0, 0.012]) is None  # up
    assert watch(3, [0.003, 0.0, 0.012]) is None  # up, 3 mm along
    assert watch(3, [0.0, 0.0, -0.012]) == 3  # down a face
    assert watch(3, [0.008, 0.0, -0.008]) == 3  # along and down
    # Session 17's watch (3 others bearing, no drop gate) is kept as measured: rising counts.
    assert watch(3, [0.0, 0.0, 0.012], others=3) == 3


def test_with_a_drop_only_a_foot_going_down_a_face_is_a_slide() -> None:
    # 1 N·s right push at 2.0 s on flat ground: LH dragged 3 cm along the
    # ground; board AE large rocks seed 4: RF slides down its flank.
    watch = _held_on_flat()
    assert watch(2, [-0.03, 0.0, -0.0003]) == 2  # dragged: a slide without the gate
    assert watch(2, [-0.03, 0.0, -0.0003], drop=0.003) is None  # not down: no slide with it
    assert watch(2, [-0.01, 0.0, -0.004], drop=0.003) == 2  # 4 mm down a face
    assert watch(2, [0.0, 0.0, -0.005], drop=0.003) is None  # down, but within the 1 cm limit


# Board AE, bench large rocks seed 5 (``bench_littledog.py --expansions 40000
# --set reflex.replant_max_slope=0.6981317 --set reflex.recovery_slide_m=0.015``):
# the recovery after the first reflex (1.37 s) settled at 2.18 s with LH on a
# flank. Measured feet [m] (LF, RF, LH, RH) and trunk; the re-plant stepped LH
# 1 cm down the flank, and the re-plan found no certificate there nor within 2 cm.
AE_SEED5_FEET = np.array(
    [
        [0.39626, 0.39468, 0.02422],
        [0.30975, 0.25087, 0.08821],
        [0.19698, 0.35744, 0.05264],
        [0.12974, 0.24191, 0.10239],
    ]
)
AE_SEED5_TRUNK = (
    np.array([0.2543, 0.31481, 0.2143]),
    np.array([0.98058, -0.18393, 0.04581, 0.05029]),
)
AE_SEED5_GOAL = np.array([0.459, 0.3045])
LH = 2


def _recovered_on(
    robot: rw.Robot,
    terrain: Terrain,
    feet: np.ndarray,
    trunk: tuple[np.ndarray, np.ndarray],
    goal: np.ndarray,
    **settings: object,
) -> tuple[Executor, object]:
    """An executor whose recovery has settled with ``feet`` and ``trunk`` measured."""
    source = PlannerSource(robot, terrain, expansions=10, config=planner_config(robot, 0.4, {}))
    config = override(
        SimConfig(),
        {
            "reflex.replant_max_slope": np.radians(40.0),
            "reflex.recovery_slide_m": 0.015,
            **settings,
        },
    )
    executor = Executor(robot, terrain, source, config=config)
    executor._goal = goal
    executor._reflex_next_leg = 0
    base, quat = trunk
    q, _ = robot.inverse_kinematics(feet, base, quat)
    measured = Runner(World(robot, terrain)).reset(q, base, quat)
    return executor, dataclasses.replace(measured, feet=feet.copy())


@pytest.mark.skipif(
    not hasattr(_core, "FootstepPlanner"), reason="the compiled core has no footstep planner"
)
def test_a_foot_stays_where_the_stance_it_would_make_has_no_certificate(littledog_board) -> None:
    robot = rw.load_robot("littledog")
    terrain = littledog_board("AE")
    executor, measured = _recovered_on(robot, terrain, AE_SEED5_FEET, AE_SEED5_TRUNK, AE_SEED5_GOAL)
    # LH stands on a face, and a gentle foothold lies 1 cm down it ...
    found = executor._replant_planner()
    assert found is not None
    targets = replant_targets(
        found[0], terrain, AE_SEED5_FEET, robot.foot_radius, 0.025, found[1], 0.01
    )
    assert [leg for leg, _ in targets] == [LH]
    # ... but no stance with LH there has a certificate: LH stays, nothing is queued.
    assert not executor._replant(measured, 2.18)
    assert not executor.buffer.queued
    refused = executor.log.events_of("replant_refused")
    assert [e["leg"] for e in refused] == ["LH"]
    moved = AE_SEED5_FEET.copy()
    moved[LH] = targets[0][1]
    source = executor.source
    assert not source.certifies(
        PlanStart(feet=moved, next_leg=0, trunk=AE_SEED5_TRUNK), AE_SEED5_GOAL
    )
    # Where LH stands, the stance has one (from the measured trunk, as the re-plan asks).
    kept = PlanStart(feet=AE_SEED5_FEET, next_leg=0, trunk=AE_SEED5_TRUNK)
    assert source.certifies(kept, AE_SEED5_GOAL)
    # A slid LH would be put down where it is, not there.
    np.testing.assert_array_equal(executor._replant_target(measured, LH), AE_SEED5_FEET[LH])
    # With the check off, the step the run took is queued again.
    unchecked, measured = _recovered_on(
        robot,
        terrain,
        AE_SEED5_FEET,
        AE_SEED5_TRUNK,
        AE_SEED5_GOAL,
        **{"reflex.replant_certified": False},
    )
    assert unchecked._replant(measured, 2.18)
    np.testing.assert_allclose(unchecked._replant_target(measured, LH), targets[0][1])


@pytest.mark.skipif(
    not hasattr(_core, "FootstepPlanner"), reason="the compiled core has no footstep planner"
)
def test_a_foot_on_a_flank_steps_where_the_stance_it_makes_is_certified() -> None:
    """RF on a 50° ramp, the other feet on flat ground: the certified step is queued."""
    robot = rw.load_robot("littledog")
    terrain = _flank()
    st = robot.nominal_stance
    base = np.array([0.5, 0.0, st.base_height])
    feet = st.feet + [0.5, 0.0, 0.0]
    feet[1, :2] = (0.612, feet[1, 1])
    feet[:, 2] = np.asarray(terrain.height(feet[:, :2])) + robot.foot_radius
    executor, measured = _recovered_on(
        robot, terrain, feet, (base, np.array([1.0, 0.0, 0.0, 0.0])), np.array([0.75, 0.0])
    )
    assert executor._replant(measured, 0.0)
    assert [e["leg"] for e in executor.log.events_of("replant")] == ["RF"]
    assert not executor.log.events_of("replant_refused")
