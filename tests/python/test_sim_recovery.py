"""The reflex's recovery motion: where the lifted feet go down."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import roughwalk
from roughwalk.config import override
from roughwalk.sim import CrawlSource
from roughwalk.sim.config import ReflexConfig, SimConfig
from roughwalk.sim.executor import Executor, nudged_stances
from roughwalk.sim.recovery import (
    centred_fit,
    nearer_catch,
    off_edge,
    recently_loaded,
    recovery_segment,
    settled,
    standing_feet,
)
from roughwalk.sim.runner import Runner
from roughwalk.sim.world import World
from roughwalk.trajectories.body_keyframes import nominal_fit
from roughwalk.trajectories.euler import rpy_to_quat
from roughwalk.trajectories.whole_body import WholeBody


@pytest.fixture(scope="module")
def standing() -> tuple[roughwalk.Robot, roughwalk.Terrain, object]:
    robot = roughwalk.load_robot("littledog")
    terrain = roughwalk.load_terrain("flat")
    st = robot.nominal_stance
    base = np.array([0.5, 0.0, st.base_height])
    q, _ = robot.inverse_kinematics(st.feet + base, base, np.array([1.0, 0.0, 0.0, 0.0]))
    measured = Runner(World(robot, terrain)).reset(q, base, np.array([1.0, 0.0, 0.0, 0.0]))
    return robot, terrain, measured


def footholds(standing, velocity, capture_max_m: float = 0.04) -> np.ndarray:
    """Where recovery puts the feet of the robot moving at ``velocity`` [m/s], LH lifted."""
    robot, terrain, measured = standing
    moving = dataclasses.replace(measured, base_vel=np.asarray(velocity, dtype=float))
    lifted = np.array([True, True, False, True])  # LH in the air
    _, feet = recovery_segment(
        robot, terrain, moving, measured.feet, lifted, 0.5, 0.3, 0.0, capture_max_m=capture_max_m
    )
    return feet


def test_a_lifted_foot_goes_down_straight_when_the_trunk_is_still(standing) -> None:
    _, _, measured = standing
    feet = footholds(standing, [0.0, 0.0, 0.0])
    np.testing.assert_allclose(feet[:, :2], measured.feet[:, :2], atol=1e-12)


def test_a_trunk_heading_for_the_lifted_foot_moves_it_to_the_capture_point(standing) -> None:
    robot, _, measured = standing
    # Pushed to the left (+y), LH lifted: LH goes down v·√(h/g) further left.
    h = measured.base_pos[2] - measured.feet[:, 2].mean()
    feet = footholds(standing, [0.0, 0.2, 0.0])
    np.testing.assert_allclose(feet[2, :2] - measured.feet[2, :2], [0.0, 0.2 * np.sqrt(h / 9.81)])
    assert feet[2, 2] == pytest.approx(robot.foot_radius, abs=1e-3)  # on the ground
    np.testing.assert_allclose(feet[[0, 1, 3]], measured.feet[[0, 1, 3]])  # the others stay
    # A harder push: the step is bounded.
    far = footholds(standing, [0.0, 2.0, 0.0])
    assert np.linalg.norm(far[2, :2] - measured.feet[2, :2]) == pytest.approx(0.04)
    # Moving away from the lifted foot's side: no step inwards.
    away = footholds(standing, [0.0, -0.2, 0.0])
    np.testing.assert_allclose(away[2, :2], measured.feet[2, :2], atol=1e-12)
    # Capture off: straight down.
    off = footholds(standing, [0.0, 0.2, 0.0], capture_max_m=0.0)
    np.testing.assert_allclose(off[2, :2], measured.feet[2, :2], atol=1e-12)


def test_a_supporting_foot_on_the_ground_stands_though_it_bears_no_load_this_instant(
    standing,
) -> None:
    """Board AE, bench large rocks seed 0: at the reflex only RF bore load.

    RH chattered on a rock face and LF had let go for the instant; taken
    for lifted, their weight went to RF alone and the robot rolled over.
    """
    robot, terrain, measured = standing
    forces = np.zeros((4, 3))
    forces[1, 2] = 12.0  # only RF loaded
    feet = measured.feet.copy()
    feet[2, 2] += 0.03  # LH 3 cm up: swinging
    feet[3, 2] += 0.004  # RH a few mm up: chattering on its foothold
    at_reflex = dataclasses.replace(measured, foot_forces=forces, feet=feet)
    support = np.array([True, True, False, True])  # LH swings
    down = standing_feet(robot, terrain, at_reflex, support, 1.0)
    np.testing.assert_array_equal(down, [True, True, False, True])
    # Where the plan had a foot in the air, only its load says it stands.
    swinging = np.array([False, True, False, True])
    down = standing_feet(robot, terrain, at_reflex, swinging, 1.0)
    np.testing.assert_array_equal(down, [False, True, False, True])
    # A supporting foot lifted 3 cm (a slip off an edge) does not stand.
    feet[3, 2] += 0.03
    lifted = dataclasses.replace(at_reflex, feet=feet)
    down = standing_feet(robot, terrain, lifted, support, 1.0)
    np.testing.assert_array_equal(down, [True, True, False, False])


def test_a_foot_loaded_a_few_ticks_before_the_reflex_counts_as_loaded() -> None:
    """Board AE, bench large rocks seed 6: RH bore 6.4 N at 0.912 s, none to the reflex at 0.946."""
    last = np.array([-np.inf, 0.946, 0.946, 0.912])  # LF swinging, RF and LH loaded now
    np.testing.assert_array_equal(recently_loaded(last, 0.946, 0.0), [False, True, True, False])
    np.testing.assert_array_equal(recently_loaded(last, 0.946, 0.05), [False, True, True, True])
    np.testing.assert_array_equal(recently_loaded(last, 0.946, 0.03), [False, True, True, False])


def recovery_of_a_chattering_foot(
    standing, window_s: float, rh_up_m: float = 0.005
) -> tuple[dict, np.ndarray]:
    """The recovery's event and footholds where RH, ``rh_up_m`` up, bore load 34 ms before."""
    robot, terrain, measured = standing
    config = override(SimConfig(), {"reflex.loaded_window_s": window_s})
    executor = Executor(robot, terrain, CrawlSource(robot, terrain), config=config)
    forces = np.zeros((4, 3))
    forces[[1, 2], 2] = 12.0  # RF and LH loaded at the reflex, LF swinging
    feet = measured.feet.copy()
    feet[0, 2] += 0.03  # LF in the air
    feet[3, 2] += rh_up_m  # RH bounced off its foothold (a rock face)
    at_reflex = dataclasses.replace(measured, foot_forces=forces, feet=feet)
    now = float(measured.time)
    executor._last_loaded[:] = [-np.inf, now, now, now - 0.034]
    executor._start_recovery(at_reflex, executor._standing(at_reflex), now)
    event = executor.log.events_of("recovery")[-1]
    return event, np.asarray(event["footholds"])


def test_a_foot_that_bore_load_within_the_window_is_not_put_down_like_a_lifted_one(
    standing,
) -> None:
    _, _, measured = standing
    event, footholds = recovery_of_a_chattering_foot(standing, 0.05)
    assert event["feet_down"] == [False, True, True, True]
    assert footholds[3, 2] == pytest.approx(measured.feet[3, 2] + 0.005)  # RH stays
    assert footholds[0, 2] < measured.feet[0, 2] + 0.01  # LF goes down
    # Without the window RH is taken for lifted and lowered (as on main).
    event, footholds = recovery_of_a_chattering_foot(standing, 0.0)
    assert event["feet_down"] == [False, True, True, False]
    assert footholds[3, 2] < measured.feet[3, 2] + 0.001
    # A foot lifting off 2 cm up (bench logs seed 1's RF at 1.50 s) is put down, window or not.
    event, footholds = recovery_of_a_chattering_foot(standing, 0.05, rh_up_m=0.02)
    assert event["feet_down"] == [False, True, True, False]
    assert footholds[3, 2] < measured.feet[3, 2] + 0.001


def test_a_foot_caught_over_a_steps_edge_goes_down_on_the_step_not_on_its_corner(standing) -> None:
    """The steps course, seed 1 of ``bench littledog --classes steps --expansions 40000``.

    The foot-force reflex fired at 8.36 s while RF swung up to the 10.8 cm
    step, RF 2.5 mm past the step's edge (x ≈ 0.695): straight down, it
    stood on the corner, slipped, and the robot rolled over.
    """
    robot, _, measured = standing
    steps = roughwalk.load_terrain("steps")
    at_reflex = dataclasses.replace(
        measured,
        base_pos=np.array([0.5877, 0.01332, 0.18383]),
        base_quat=np.array([0.98816, -0.10751, -0.1049, 0.0313]),
        base_vel=np.array([0.0073, 0.0175, 0.0117]),
        feet=np.array(
            [
                [0.68546, 0.06994, 0.06427],
                [0.69777, -0.05661, 0.14315],
                [0.49034, 0.07059, 0.01086],
                [0.51873, -0.04215, 0.0102],
            ]
        ),
    )
    planned = at_reflex.feet.copy()
    planned[1] = [0.7474, -0.05255, 0.108 + robot.foot_radius]
    planned[2] = [0.4949, 0.05855, robot.foot_radius]
    down = np.array([True, False, False, True])
    _, feet = recovery_segment(
        robot, steps, at_reflex, planned, down, 0.5, 0.3, 0.0, capture_max_m=0.04
    )
    r = robot.foot_radius
    under = feet[1, :2] + 0.5 * r * np.array([[0, 0], [1, 0], [-1, 0], [0, 1], [0, -1]])
    ground = steps.height(under)
    np.testing.assert_allclose(ground, 0.108, atol=1e-9)  # all of it on the step
    assert 0.0 < feet[1, 0] - at_reflex.feet[1, 0] <= 0.02  # towards its foothold, a little
    # LH, slid 1.3 cm off its foothold on flat ground, goes back onto it.
    np.testing.assert_allclose(feet[2, :2], planned[2, :2], atol=1e-12)
    # With no flat ground within reach, the catch stays.
    corner = off_edge(steps, at_reflex.feet[1], planned[1], r, 0.0)
    np.testing.assert_allclose(corner, at_reflex.feet[1])


def test_a_foot_caught_climbing_out_of_a_trench_goes_down_on_its_lip_with_catch_nearer(
    standing,
) -> None:
    """``reflex.catch_nearer``: the flat ground nearest the foot on its way out of a trench.

    The gap course's trench spans x 0.94–1.06 m, 10 cm deep. RH, caught 3
    cm over the lip's height and still over the floor, 2 cm short of the far
    wall, goes back down to the floor by default; with the option it lands
    on the lip, short of its planned foothold 6 cm further on, its foot 1 cm
    clear of the edge.
    """
    robot, _, measured = standing
    gap = roughwalk.load_terrain("gap")
    r = robot.foot_radius
    base = np.array([1.12, 0.0, measured.base_pos[2]])
    feet = robot.nominal_stance.feet + base * np.array([1.0, 1.0, 0.0])
    feet[:, 2] = r
    feet[3] = [1.04, feet[3, 1], 0.03]  # RH over the trench, short of its far wall
    at_reflex = dataclasses.replace(measured, base_pos=base, base_vel=np.zeros(3), feet=feet)
    planned = feet.copy()
    planned[3] = [1.14, feet[3, 1], r]
    down = np.array([True, True, True, False])
    _, held = recovery_segment(robot, gap, at_reflex, planned, down, 0.5, 0.3, 0.0)
    assert gap.height(held[3:, :2])[0] == pytest.approx(-0.1)
    _, held = recovery_segment(
        robot, gap, at_reflex, planned, down, 0.5, 0.3, 0.0, catch_nearer=True
    )
    assert gap.height(held[3:, :2])[0] == pytest.approx(0.0)
    assert 1.06 + r + 0.01 <= held[3, 0] < 1.06 + r + 0.01 + 0.005  # the nearest such ground
    np.testing.assert_allclose(held[3, 1], feet[3, 1])  # on the way to the planned foothold
    np.testing.assert_allclose(held[:3], feet[:3])  # the standing feet stay


def test_nearer_catch_needs_nearer_flat_ground_and_a_way_over_it() -> None:
    r = 0.0103
    gap = roughwalk.load_terrain("gap")
    flat = roughwalk.load_terrain("flat")
    lip = np.array([1.14, 0.0, r])
    # Over the floor near the far wall, 3 cm up: the lip is nearer than the floor.
    high = np.array([1.04, 0.0, 0.03])
    land = nearer_catch(gap, high, high, lip, r)
    assert land is not None and np.linalg.norm(land - high) < 0.1
    # Planned on the edge itself: no landing has the flat margin around it.
    assert nearer_catch(gap, high, high, np.array([1.07, 0.0, r]), r) is None
    # Below the lip's height, 1 cm from the wall: the lip is nearer than the
    # floor, but the straight arched way there runs the sole into the wall.
    low = np.array([1.05, 0.0, -0.01])
    assert np.linalg.norm(np.array([1.085, 0.0, r]) - low) < 0.09
    assert nearer_catch(gap, low, low, lip, r) is None
    # On level ground the catch stays, even moved out by a capture offset
    # away from a planned foothold nearer the foot.
    rng = np.random.default_rng(3)
    for _ in range(50):
        foot = np.array([0.5, 0.0, r]) + rng.uniform([-0.03, -0.03, 0.0], [0.03, 0.03, 0.06])
        catch = foot + np.array([*rng.uniform(-0.04, 0.04, 2), 0.0])
        planned = np.array([*(foot[:2] + rng.uniform(-0.06, 0.06, 2)), r])
        assert nearer_catch(flat, foot, catch, planned, r) is None


def test_the_trunk_settles_with_its_centre_of_mass_over_the_feet_on_a_tilted_stance() -> None:
    robot = roughwalk.load_robot("littledog")
    st = robot.nominal_stance
    feet = st.feet + np.array([0.5, 0.0, 0.0])
    feet[feet[:, 1] < 0, 2] += 0.03  # the right feet 3 cm up a step: a 14° roll
    pos, rpy = centred_fit(robot, feet)
    assert abs(rpy[0]) > 0.2
    quat = rpy_to_quat(rpy)
    q, reachable = robot.inverse_kinematics(feet, pos, quat)
    assert reachable.all()
    com = robot.center_of_mass(q, pos, quat)
    np.testing.assert_allclose(com[:2], feet[:, :2].mean(axis=0), atol=1e-3)
    # The plain fit leaves it centimetres towards the low (left) feet.
    fit_pos, _ = nominal_fit(WholeBody(robot), feet)
    q, _ = robot.inverse_kinematics(feet, fit_pos, quat)
    assert robot.center_of_mass(q, fit_pos, quat)[1] - feet[:, 1].mean() > 0.02


def test_a_replan_without_a_start_certificate_tries_stances_one_foot_moved_nearest_first(
    standing,
) -> None:
    """``reflex.replan_nudge_m``: the candidates, the leg that lifts first first."""
    _, _, measured = standing
    feet = measured.feet
    stances = list(nudged_stances(feet, 0.02, first_leg=2))
    assert len(stances) == 2 * 4 * 8
    moved = np.array([np.linalg.norm(s[:, :2] - feet[:, :2], axis=1) for s in stances])
    # One foot at a time, never its height, 1 cm before 2 cm.
    assert np.all(np.count_nonzero(moved > 1e-12, axis=1) == 1)
    np.testing.assert_allclose(moved.max(axis=1), [0.01] * 32 + [0.02] * 32)
    np.testing.assert_array_equal(
        np.array([s[:, 2] for s in stances]), np.tile(feet[:, 2], (64, 1))
    )
    # LH (the next to lift) first at each distance, then LF, RF, RH.
    legs = moved.argmax(axis=1)
    np.testing.assert_array_equal(legs[:32], np.repeat([2, 0, 1, 3], 8))
    assert list(nudged_stances(feet, 0.0)) == []


def test_a_still_robot_on_three_loaded_feet_is_settled_only_when_three_are_asked_for(
    standing,
) -> None:
    """The recovery's hold ends on a still trunk and ``reflex.settled_loaded_feet`` loaded feet.

    Four feet share the load indeterminately: on the logs board one rested
    unloaded after a recovery and the hold ran its whole extension.
    """
    _, _, measured = standing

    def state(fz: list[float], rate: float) -> object:
        forces = np.zeros((4, 3))
        forces[:, 2] = fz
        return dataclasses.replace(
            measured, foot_forces=forces, base_angvel=np.array([rate, 0.0, 0.0])
        )

    still = state([9.0, 0.0, 8.0, 9.5], 0.05)  # RF a millimetre high: no load
    assert not settled(still, 0.2, 4, 1.0)
    assert settled(still, 0.2, 3, 1.0)
    # Rocking onto the left feet: two loaded, not settled either way.
    assert not settled(state([13.0, 0.0, 13.5, 0.0], 0.05), 0.2, 3, 1.0)
    # Turning faster than the rate: not settled, however many feet bear load.
    assert not settled(state([6.7] * 4, 0.3), 0.2, 3, 1.0)
    assert settled(state([6.7] * 4, 0.05), 0.2, 4, 1.0)
    assert ReflexConfig().settled_loaded_feet == 3
    with pytest.raises(roughwalk.ConfigError, match="settled_loaded_feet must be 3 or 4"):
        ReflexConfig(settled_loaded_feet=2)


def _recovering(standing, **settings: object) -> tuple[Executor, object, object, float]:
    """An executor in a recovery on four feet on flat ground: (executor, measured, desired, now)."""
    robot, terrain, measured = standing
    config = override(SimConfig(), {"reflex.recovery_slide_m": 0.01, **settings})
    executor = Executor(robot, terrain, CrawlSource(robot, terrain), config=config)
    forces = np.zeros((4, 3))
    forces[:, 2] = 8.0
    loaded = dataclasses.replace(measured, foot_forces=forces)
    now = float(measured.time)
    executor._last_loaded[:] = now
    desired = executor._start_recovery(loaded, executor._standing(loaded), now)
    return executor, loaded, desired, now


def _slide_rf(executor: Executor, measured, desired, now: float, by: float, bearing: list[int]):
    """Tick the watch 0.05 s with RF ``by`` [m] off its foothold and only ``bearing`` loaded."""
    feet = measured.feet.copy()
    feet[1] += [0.0, -by, 0.0]
    forces = np.zeros((4, 3))
    forces[bearing, 2] = 10.0
    # The feet that bear nothing have not borne load lately either (the 50 ms window).
    executor._last_loaded[[i for i in range(4) if i not in bearing]] = -np.inf
    slid = None
    for k in range(6):
        t = now + 0.01 * k
        executor._last_loaded[bearing] = t
        state = dataclasses.replace(measured, feet=feet, foot_forces=forces, time=t)
        slid = executor._recovery_slide(state, desired, t)
        if slid is not None:
            return slid, state, t
    return slid, None, now


def test_a_scripted_slide_on_a_diagonal_during_a_recovery_is_caught_and_replanted(
    standing,
) -> None:
    # RF slides 1.5 cm while only LF and RH bear load (board AE, large rocks seed 4).
    executor, measured, desired, now = _recovering(
        standing,
        **{"reflex.recovery_slide_bearing": 2, "reflex.recovery_slide_response": "replant"},
    )
    # LF alone bearing is not a diagonal: not watched.
    assert _slide_rf(executor, measured, desired, now, 0.015, [0])[0] is None
    slid, state, t = _slide_rf(executor, measured, desired, now, 0.015, [0, 3])
    assert slid == 1
    assert t - now >= executor.config.reflex.persist_s - 1e-9  # it must last persist_s
    # On flat ground there is nowhere better to step: the recovery starts over, RF bearing.
    restarts = len(executor.log.events_of("recovery"))
    executor._catch_slide(state, desired, t, slid)
    assert len(executor.log.events_of("recovery")) == restarts + 1
    assert executor.log.events_of("recovery")[-1]["feet_down"][1]
    assert not executor.log.events_of("replant")
    # With a foothold 1.5 cm on (a face's foot), RF steps there.
    target = state.feet[1] + [0.0, -0.015, 0.0]
    executor._slide_target = lambda measured, leg: target  # type: ignore[method-assign]
    executor._catch_slide(state, desired, t, slid)
    replant = executor.log.events_of("replant")[-1]
    assert replant["leg"] == "RF"
    np.testing.assert_allclose(replant["target"], target)
    # The queued motion lifts RF with the other three down, then all four down again.
    support = [s.support[0] for s in executor.buffer.queued]
    assert any(np.array_equal(s, [True, False, True, True]) for s in support)
    assert np.all(support[-1])


def test_a_slide_within_the_limit_or_with_too_few_feet_bearing_is_not_caught(standing) -> None:
    executor, measured, desired, now = _recovering(standing)
    assert _slide_rf(executor, measured, desired, now, 0.008, [0, 2, 3])[0] is None
    # On main's setting (3 others bearing) the diagonal slide is not watched.
    assert _slide_rf(executor, measured, desired, now, 0.015, [0, 3])[0] is None
    assert _slide_rf(executor, measured, desired, now, 0.015, [0, 2, 3])[0] == 1


def test_the_slide_watch_settings_are_checked() -> None:
    from roughwalk.errors import ConfigError

    for bad in (
        {"reflex.recovery_slide_bearing": 4},
        {"reflex.recovery_slide_response": "jump"},
        {"reflex.recovery_slide_drop_m": -0.001},
    ):
        with pytest.raises(ConfigError):
            override(SimConfig(), bad)
    assert ReflexConfig().recovery_slide_bearing == 3  # main's watch by default
