"""Every step of returned plans, checked without the planner's code.

MuJoCo's kinematics on the robot's MJCF with each certificate's 18 DOF gives
the foot centres, joint angles and the whole-body centre of mass; a
brute-force nearest-point search over a dense sampling of the terrain's
triangulated surface gives the body's clearance; the action geometry is
re-derived here from the footsteps alone.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import mujoco
import numpy as np
import pytest
from scipy.spatial import cKDTree

import roughwalk as rw
from roughwalk.planning import FootstepPlanner

LEGS = ("LF", "RF", "LH", "RH")
TERRAINS = (
    "round_rocks:seed=7,length=0.9,width=0.6,pad_start=0.3,pad_end=0.15,max_height=0.05",
    "sloped_rocks:seed=3,length=0.9,width=0.6,pad_start=0.3,pad_end=0.15,max_height=0.05",
)
# (terrain, footstep.normal_radius): the foot centres sit along the point
# normal, and once along the mean slope over the foot's disc.
CASES = (*((t, 0.0) for t in TERRAINS), (TERRAINS[1], 0.0103))
START = (0.25, 0.0, 0.0)
GOAL = (0.6, 0.05)


def surface_samples(terrain: rw.Terrain, centre: np.ndarray, half: float, n: int = 4) -> np.ndarray:
    """Points on the terrain's triangulated surface (two triangles a-b-c, a-c-d per cell,
    as the SDF meshes it) every dx/n, within ``half`` [m] of ``centre`` (x, y)."""
    i0 = max(int((centre[0] - half - terrain.x0) / terrain.dx), 0)
    i1 = min(int((centre[0] + half - terrain.x0) / terrain.dx) + 1, terrain.shape[0] - 1)
    j0 = max(int((centre[1] - half - terrain.y0) / terrain.dy), 0)
    j1 = min(int((centre[1] + half - terrain.y0) / terrain.dy) + 1, terrain.shape[1] - 1)
    z = terrain.heights
    s, t = np.meshgrid(np.arange(n) / n, np.arange(n) / n, indexing="ij")
    s, t = s.ravel(), t.ravel()
    ii, jj = np.meshgrid(np.arange(i0, i1), np.arange(j0, j1), indexing="ij")
    ii, jj = ii.ravel()[:, None], jj.ravel()[:, None]
    z00, z10, z11, z01 = z[ii, jj], z[ii + 1, jj], z[ii + 1, jj + 1], z[ii, jj + 1]
    lower = s >= t  # triangle a(00)-b(10)-c(11), else a(00)-c(11)-d(01)
    height = np.where(
        lower,
        z00 + s * (z10 - z00) + t * (z11 - z10),
        z00 + t * (z01 - z00) + s * (z11 - z01),
    )
    x = terrain.x0 + (ii + s) * terrain.dx
    y = terrain.y0 + (jj + t) * terrain.dy
    return np.column_stack([x.ravel(), y.ravel(), height.ravel()])


def surface_height(terrain: rw.Terrain, p: np.ndarray) -> np.ndarray:
    """Height of the triangulated surface under points p (N, 3)."""
    gi = (p[:, 0] - terrain.x0) / terrain.dx
    gj = (p[:, 1] - terrain.y0) / terrain.dy
    i = np.clip(np.floor(gi).astype(int), 0, terrain.shape[0] - 2)
    j = np.clip(np.floor(gj).astype(int), 0, terrain.shape[1] - 2)
    s, t = np.clip(gi - i, 0, 1), np.clip(gj - j, 0, 1)
    z = terrain.heights
    z00, z10, z11, z01 = z[i, j], z[i + 1, j], z[i + 1, j + 1], z[i, j + 1]
    return np.where(
        s >= t,
        z00 + s * (z10 - z00) + t * (z11 - z10),
        z00 + t * (z01 - z00) + s * (z11 - z01),
    )


def body_samples(
    model: mujoco.MjModel, data: mujoco.MjData, feet: set[int]
) -> list[tuple[np.ndarray, float]]:
    """Per colliding non-foot geom: points on its core (axis or surface), the radius to subtract."""
    out = []
    for g in range(model.ngeom):
        if g in feet or (model.geom_contype[g] == 0 and model.geom_conaffinity[g] == 0):
            continue
        pos, rot, size = data.geom_xpos[g], data.geom_xmat[g].reshape(3, 3), model.geom_size[g]
        kind = model.geom_type[g]
        if kind == mujoco.mjtGeom.mjGEOM_CAPSULE:
            t = np.linspace(-size[1], size[1], max(int(2 * size[1] / 5e-4), 2))
            out.append((pos + np.outer(t, rot[:, 2]), float(size[0])))
        elif kind == mujoco.mjtGeom.mjGEOM_SPHERE:
            out.append((pos[None, :], float(size[0])))
        elif kind == mujoco.mjtGeom.mjGEOM_BOX:
            axes = [np.linspace(-h, h, max(int(2 * h / 2e-3), 2)) for h in size]
            pts = []
            for a in range(3):
                b, c = [k for k in range(3) if k != a]
                u, v = np.meshgrid(axes[b], axes[c], indexing="ij")
                for sign in (-1, 1):
                    local = np.zeros((u.size, 3))
                    local[:, a], local[:, b], local[:, c] = sign * size[a], u.ravel(), v.ravel()
                    pts.append(local)
            out.append((pos + np.vstack(pts) @ rot.T, 0.0))
        else:
            raise AssertionError(f"no brute-force sampler for geom type {kind}")
    return out


def brute_disc_normals(terrain: rw.Terrain, xy: np.ndarray, radius: float) -> np.ndarray:
    """Normals of the mean bilinear gradient over the points within ``radius`` of each
    row of ``xy``, on a grid of spacing radius / ceil(radius / min(dx, dy))."""
    n = math.ceil(radius / min(terrain.dx, terrain.dy))
    i, j = np.mgrid[-n : n + 1, -n : n + 1]
    off = np.column_stack([i.ravel(), j.ravel()]) * (radius / n)
    off = off[np.sum(off**2, axis=1) <= radius**2 + 1e-15]
    out = []
    for p in xy:
        _, g = terrain.height_and_gradient(p + off)
        gx, gy = g.mean(axis=0)
        out.append(np.array([-gx, -gy, 1.0]) / math.sqrt(gx * gx + gy * gy + 1.0))
    return np.array(out)


def cross2(u: np.ndarray, v: np.ndarray) -> float:
    return float(u[0] * v[1] - u[1] * v[0])


def triangle_margin(p: np.ndarray, tri: np.ndarray) -> float:
    """Signed distance of p inside the triangle (x, y), positive inside."""
    orient = math.copysign(1.0, cross2(tri[1] - tri[0], tri[2] - tri[0]))
    out = math.inf
    for k in range(3):
        a, b = tri[k], tri[(k + 1) % 3]
        out = min(out, orient * cross2(b - a, p - a) / float(np.linalg.norm(b - a)))
    return out


@pytest.fixture(scope="module", params=CASES, ids=lambda c: f"{c[0].split(':')[0]}-r{c[1]}")
def planned(request: pytest.FixtureRequest, littledog: rw.Robot) -> tuple[FootstepPlanner, Any]:
    spec, normal_radius = request.param
    config = dataclasses.replace(
        rw.planning.FootstepConfig.for_robot(littledog), normal_radius=normal_radius
    )
    planner = FootstepPlanner(littledog, rw.load_terrain(spec), config)
    plan = planner.plan(START, GOAL, time_limit=None, expansions=400)
    assert plan.status == "solved", plan.reason
    return planner, plan


def test_every_certificate_holds_its_stance_in_mujoco(
    littledog: rw.Robot, planned: tuple[FootstepPlanner, Any]
) -> None:
    planner, plan = planned
    config, terrain = planner.config, planner.terrain
    model = littledog.mj_model()
    data = mujoco.MjData(model)
    foot_geoms = {LEGS.index(leg): model.geom(f"{leg}_foot").id for leg in LEGS}
    radius = {i: float(model.geom_size[g][0]) for i, g in foot_geoms.items()}
    joints = [model.joint(name).id for name in littledog.joint_names]
    base = model.body(littledog.base_body).id
    stances = plan.stances()
    order = config.walking_order
    moved = ["-"] + [f.leg for f in plan.footsteps[4:]]
    certificates = [plan.initial_pose, *plan.certificates]
    assert len(certificates) == len(stances)
    worst_clearance = math.inf
    centre = stances[:, :, :2].reshape(-1, 2)
    middle = 0.5 * (centre.min(axis=0) + centre.max(axis=0))
    half = 0.5 * float(np.max(centre.max(axis=0) - centre.min(axis=0))) + 0.2
    tree = cKDTree(surface_samples(terrain, middle, half))
    for k, (cert, stance) in enumerate(zip(certificates, stances, strict=True)):
        data.qpos[:] = littledog.qpos(cert.q, cert.base_pos, cert.base_quat)
        mujoco.mj_kinematics(model, data)
        mujoco.mj_comPos(model, data)
        # Foot centres on their footholds: the contact point plus the radius
        # along the normal (the mean slope's over the disc with normal_radius).
        normals = terrain.normal(stance[:, :2])
        if config.normal_radius > 0:
            normals = brute_disc_normals(terrain, stance[:, :2], config.normal_radius)
        for i, g in foot_geoms.items():
            target = stance[i] + radius[i] * normals[i]
            assert np.linalg.norm(data.geom_xpos[g] - target) < 1e-3, (k, LEGS[i])
        # Joint angles within the MJCF's limits.
        for j, value in zip(joints, cert.q, strict=True):
            lo, hi = model.jnt_range[j]
            assert lo - 1e-9 <= value <= hi + 1e-9, (k, model.joint(j).name, value)
        # CoM over the triangle of the feet that stay down for the next step.
        next_leg = order[0] if k == 0 else order[(order.index(moved[k]) + 1) % 4]
        support = [i for i in range(4) if LEGS[i] != next_leg]
        com = data.subtree_com[base]
        np.testing.assert_allclose(com, cert.com, atol=1e-9)
        assert triangle_margin(com[:2], stance[support, :2]) > 0.0, k
        # Whole-body clearance, feet excluded, by brute force over the surface.
        for points, r in body_samples(model, data, set(foot_geoms.values())):
            assert np.all(points[:, 2] > surface_height(terrain, points)), (k, "inside the terrain")
            d, _ = tree.query(points, distance_upper_bound=r + 0.02)
            worst_clearance = min(worst_clearance, float(d.min()) - r)
    # The brute force overestimates distances by at most the sampling's half
    # diagonal on the slope (~1 mm at 1.25 mm spacing).
    assert worst_clearance - 1e-3 >= config.certificate.clearance, worst_clearance


def test_every_step_is_one_of_the_actions(
    littledog: rw.Robot, planned: tuple[FootstepPlanner, Any]
) -> None:
    planner, plan = planned
    config = planner.config
    nominal = littledog.nominal_stance.feet[:, :2]
    nominal = nominal - nominal.mean(axis=0)
    actions = np.asarray(config.actions)
    h = planner.lattice[2]
    slack = config.local_search_radius + h * math.sqrt(0.5) + 1e-9
    stances = plan.stances()
    for k, step in enumerate(plan.footsteps[4:]):
        before = stances[k][:, :2]
        leg = LEGS.index(step.leg)
        c = before.mean(axis=0)
        front, hind = before[:2].mean(axis=0), before[2:].mean(axis=0)
        theta = math.atan2(*(front - hind)[::-1])

        def rot(a: float) -> np.ndarray:
            return np.array([[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]])

        targets = np.array(
            [c + rot(theta + a[2]) @ nominal[leg] + rot(theta) @ a[:2] for a in actions]
        )
        to = np.array([step.x, step.y])
        assert np.min(np.linalg.norm(targets - to, axis=1)) <= slack, k
        assert np.linalg.norm(to - before[leg]) <= config.max_foot_travel + 1e-9, k
