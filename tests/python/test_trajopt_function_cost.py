"""What IPOPT's function evaluations cost: the row functions' Hessians, the objective alone.

The dynamics and leg-reach rows are calls of small SX functions whose own
Hessians are mapped over the samples (see ``formulation._call_hessians``);
on the learned single-pallet walk they were most of the Hessian's
operations. Their functions are written so that CasADi's Hessian of them is
small; these tests hold the values to the textbook forms and the sizes
below the old forms'.
"""

from __future__ import annotations

import casadi as ca
import numpy as np
import pytest

from roughwalk.robots import load_robot
from roughwalk.terrain import load_terrain
from roughwalk.trajopt import Formulation, TerrainModel, make_gait, melon_config
from roughwalk.trajopt.parameters import MELON_REACH_CONSTRAINTS
from roughwalk.trajopt.robot_model import GRAVITY, rigid_body_from_robot
from roughwalk.trajopt.variables import angular_acceleration, angular_velocity, euler_to_rotation


@pytest.fixture(scope="module")
def reach_walk() -> Formulation:
    """A 4-step Melon walk onto the single pallet with the leg-reach rows."""
    config = melon_config(duration=2.0, steps=4, constraints=MELON_REACH_CONSTRAINTS)
    terrain = TerrainModel(
        load_terrain("single_pallet"), config.terrain, config.costs.step_edge_sigma
    )
    body = rigid_body_from_robot(load_robot("anymal_c"))
    return Formulation(config, body, make_gait("walk", 4, 2.0), terrain)


def _function(nlp: Formulation, name: str) -> ca.Function:
    rows = next(r for r in nlp.rows if r.name == name)
    assert rows.calls
    return rows.calls[0].function


def _hessian_operations(fn: ca.Function) -> int:
    """Operations of ∇²ᵤ(λᵀF(u)) over all of F's inputs, as the formulation builds it."""
    symbols = [ca.SX.sym(f"u{i}", fn.sparsity_in(i)) for i in range(fn.n_in())]
    flat = ca.vertcat(*[ca.vec(s) for s in symbols])
    lam = ca.SX.sym("lam", fn.numel_out(0))
    hess, _ = ca.hessian(ca.dot(lam, ca.vec(fn(*symbols))), flat)
    return int(ca.Function("local", [flat, lam], [ca.triu(hess)]).n_instructions())


def test_dynamics_rows_are_newton_euler_in_the_world_frame(reach_walk: Formulation) -> None:
    """m c̈ − Σf − m g and I_w ω̇ + ω × I_w ω − Σ (p − c) × f, I_w = R I Rᵀ, at random states."""
    body = reach_walk.body
    residual = _function(reach_walk, "dynamics")
    rng = np.random.default_rng(3)
    for _ in range(20):
        c, cdd, eta, etad, etadd = (rng.normal(size=3) for _ in range(5))
        feet, forces = rng.normal(size=12), 200 * rng.normal(size=12)
        got = np.asarray(residual(c, cdd, eta, etad, etadd, feet, forces)).ravel()
        rot = euler_to_rotation(eta)
        i_world = rot @ np.asarray(body.inertia_matrix) @ rot.T
        omega = angular_velocity(eta, etad)
        omega_dot = angular_acceleration(eta, etad, etadd)
        foot_forces = forces.reshape(4, 3)
        torque = np.cross(feet.reshape(4, 3) - c, foot_forces).sum(axis=0)
        angular = i_world @ omega_dot + np.cross(omega, i_world @ omega) - torque
        linear = body.mass * (cdd + np.array([0.0, 0.0, GRAVITY])) - foot_forces.sum(axis=0)
        np.testing.assert_allclose(got, np.concatenate([angular, linear]), rtol=1e-12, atol=1e-9)


def test_leg_reach_rows_are_the_squared_distance_in_the_base_frame(
    reach_walk: Formulation,
) -> None:
    squared = _function(reach_walk, "leg_reach")
    rng = np.random.default_rng(4)
    for _ in range(20):
        c, eta, foot, o = (rng.normal(size=3) for _ in range(4))
        d = euler_to_rotation(eta).T @ (foot - c) - o
        assert float(squared(c, eta, foot, o)) == pytest.approx(d @ d, rel=1e-12, abs=1e-12)


def test_row_functions_have_small_hessians(reach_walk: Formulation) -> None:
    # As first written (I_w = R I Rᵀ, ω and ω̇ in the world frame; ‖Rᵀ(p − c) − o‖²)
    # they took 3144 and 1186 operations; on the 16-step single-pallet walk
    # their mapped Hessians were 0.64 M of the Hessian's 0.81 M operations.
    assert _hessian_operations(_function(reach_walk, "dynamics")) < 2000
    assert _hessian_operations(_function(reach_walk, "leg_reach")) < 700


def test_leg_reach_leaves_the_positions_curvature_diagonal(reach_walk: Formulation) -> None:
    """∇²_p of ‖Rᵀ(p − c) − o‖² is 2I: no off-diagonal entries between a foot's coordinates."""
    squared = _function(reach_walk, "leg_reach")
    c, eta, foot, o = (ca.SX.sym(n, 3) for n in ("c", "eta", "p", "o"))
    block = ca.hessian(squared(c, eta, foot, o), foot)[0]
    assert block.nnz() == 3
    np.testing.assert_allclose(np.asarray(ca.DM(ca.evalf(block))), 2 * np.eye(3))


def _sx_operations(fn: ca.Function) -> int:
    """Operations of the SX functions an MX function calls (its own MX glue not counted)."""
    total = 0
    for i in range(fn.n_instructions()):
        if fn.instruction_id(i) == ca.OP_CALL:
            called = fn.instruction_MX(i).which_function()
            if called.is_a("SXFunction"):
                total += int(called.n_instructions())
    return total


def test_objective_does_not_compute_the_constraints(reach_walk: Formulation) -> None:
    # IPOPT evaluates f and g apart (every trial point): an f that came out of
    # one SX function with g computed all the rows as well.
    nlp = reach_walk.nlp
    assert isinstance(nlp, dict)
    f = ca.Function("f", [nlp["x"], nlp["p"]], [nlp["f"]])
    g = ca.Function("g", [nlp["x"], nlp["p"]], [nlp["g"]])
    assert _sx_operations(f) < _sx_operations(g)
