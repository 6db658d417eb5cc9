"""Into the LittleDog gap's trench on the ``gap`` generator: the plan's poses and the walk.

The 12 cm trench is wider than a foot's move (``max_foot_travel`` 0.6 L),
so the planner steps a front foot onto its floor, 10 cm down. The
certificate's first trunk pose is tilted like the feet; at up to 0.5 rad
that rolled the trunk 19-23° towards the low foot, a hind thigh sank into
the trunk shell, and in simulation that leg's swing stalled against the
trunk (bench gap seed 0: 1.4 mm of contact, both hip torques at their
2.5 N·m limit, a foot-position reflex, then no start to re-plan from).
"""

from __future__ import annotations

import mujoco
import pytest

import roughwalk as rw
from roughwalk.planning import FootstepPlan, FootstepPlanner
from roughwalk.sim import run

START = (0.75, 0.0, 0.0)
GOAL = (1.05, 0.0)
# Contact depth [m] a leg may have against the trunk shell: MuJoCo's
# contact margin, below the 1.4 mm that stalled the swing.
MAX_SELF_CONTACT_DEPTH = 1e-3


@pytest.fixture(scope="module")
def plan(littledog: rw.Robot) -> FootstepPlan:
    planner = FootstepPlanner(littledog, rw.load_terrain("gap"))
    result = planner.plan(START, GOAL, time_limit=None, expansions=3000)
    assert result.status == "solved", result.reason
    return result


def test_the_plan_steps_onto_the_trench_floor(plan: FootstepPlan) -> None:
    # The stances below matter only if the plan goes down into the trench.
    assert min(f.z for f in plan.footsteps) < -0.09


def test_no_leg_sinks_into_the_trunk_in_any_certificate(
    littledog: rw.Robot, plan: FootstepPlan
) -> None:
    model = littledog.mj_model()
    data = mujoco.MjData(model)
    base = model.body(littledog.base_body).id
    trunk = {g for g in range(model.ngeom) if model.geom_bodyid[g] == base}
    certificates = [plan.initial_pose, *plan.certificates]
    worst = []
    for k, cert in enumerate(certificates):
        data.qpos[:] = littledog.qpos(cert.q, cert.base_pos, cert.base_quat)
        mujoco.mj_forward(model, data)
        for c in data.contact[: data.ncon]:
            if (c.geom1 in trunk) != (c.geom2 in trunk):
                leg = c.geom2 if c.geom1 in trunk else c.geom1
                worst.append((-float(c.dist), k, model.body(model.geom_bodyid[leg]).name))
    assert all(depth <= MAX_SELF_CONTACT_DEPTH for depth, _, _ in worst), sorted(worst)[-3:]


def test_littledog_walks_into_the_trench_to_the_goal_without_a_reflex() -> None:
    # Before the guess's tilt was capped at 0.15 rad: a foot-position reflex
    # 5 s in, and no certificate for the stance it left to re-plan from.
    result = run(
        "littledog",
        "gap",
        START,
        GOAL,
        **{
            "executor.plan_expansions": 3000,
            "executor.compute_time_scale": 0,
            "executor.initial_plan_s": 300,
        },
    )
    assert min(f.z for p in result.plans for f in p.footsteps) < -0.09
    assert result.success, result.outcome.reason
    assert result.outcome.reflexes == 0
