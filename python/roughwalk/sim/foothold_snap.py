"""Moving measured feet onto the planner's footholds before a re-plan.

A re-plan starts from the feet where they stand (Zucker 2011, §6), but a
foot that slid during a reflex can stand on a lattice cell the planner
never allows as a foothold (a rock's flank or edge, whose terrain cost is
infinite): the planner then refuses the whole start stance ("foot … is not
on a foothold"), and the run ends although the foot is a few millimetres
from ground the planner accepts (LittleDog large-rocks board AE).
:func:`snap_to_footholds` moves only such feet to the nearest foothold
cell within a small radius; the rest keep where they are. The planner's
lattice and cost maps are read as its core reads them (nearest lattice
cell, nearest terrain cell, unknown ground is no foothold).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from roughwalk.planning.foothold_safety import resting_centres

if TYPE_CHECKING:
    from roughwalk.planning.footstep_planner import FootstepPlanner
    from roughwalk.terrain.terrain import Terrain

__all__ = ["footholds_toward", "replant_targets", "snap_to_footholds"]


def _foothold(
    planner: FootstepPlanner, terrain: Terrain, xy: NDArray[np.float64], front: bool
) -> NDArray[np.bool_]:
    """Whether each lattice point ``xy`` (n, 2) [m] is a foothold for a front or hind foot."""
    grid = planner.cost_front if front else planner.cost_hind
    nx, ny = terrain.shape
    gi = np.clip(np.round((xy[:, 0] - terrain.x0) / terrain.dx), 0, nx - 1).astype(int)
    gj = np.clip(np.round((xy[:, 1] - terrain.y0) / terrain.dy), 0, ny - 1).astype(int)
    cost = np.asarray(grid).reshape(nx, ny)[gi, gj]
    return np.isfinite(cost) & np.asarray(terrain.is_known(xy), dtype=bool)


def _on(cells: NDArray[np.bool_], terrain: Terrain, xy: NDArray[np.float64]) -> NDArray[np.bool_]:
    """Whether the terrain cells nearest the points ``xy`` (n, 2) [m] are marked in ``cells``."""
    nx, ny = terrain.shape
    gi = np.clip(np.round((xy[:, 0] - terrain.x0) / terrain.dx), 0, nx - 1).astype(int)
    gj = np.clip(np.round((xy[:, 1] - terrain.y0) / terrain.dy), 0, ny - 1).astype(int)
    return np.asarray(cells[gi, gj], dtype=bool)


def snap_to_footholds(
    planner: FootstepPlanner,
    terrain: Terrain,
    feet: NDArray[np.float64],
    radius: float,
    refused: NDArray[np.bool_] | None = None,
) -> tuple[NDArray[np.float64], list[int]]:
    """Feet (4, 3) [m, canonical legs] with those off a foothold moved onto the nearest one.

    Only x and y change. A foot with no foothold within ``radius`` [m] stays
    (the planner will say why). Returns the feet and the legs moved.

    ``refused``: terrain cells (nx, ny) no foot may stand on though the
    planner allows them; a foot whose own centre is on one moves too, and
    no foot moves onto one.
    """
    x0, y0, h, nx, ny = planner.lattice
    out = np.array(feet, dtype=float)
    moved: list[int] = []
    reach = int(np.ceil(radius / h))
    offsets = np.array(
        [(i, j) for i in range(-reach, reach + 1) for j in range(-reach, reach + 1)], dtype=float
    )
    offsets = offsets[np.hypot(offsets[:, 0], offsets[:, 1]) * h <= radius + 1e-12]
    offsets = offsets[np.argsort(np.hypot(offsets[:, 0], offsets[:, 1]), kind="stable")]
    for leg in range(4):
        cell = np.round((out[leg, :2] - (x0, y0)) / h)
        cells = cell + offsets
        inside = (cells[:, 0] >= 0) & (cells[:, 1] >= 0) & (cells[:, 0] < nx) & (cells[:, 1] < ny)
        cells = cells[inside]
        if len(cells) == 0:
            continue
        xy = np.array([x0, y0]) + h * cells
        ok = _foothold(planner, terrain, xy, front=leg < 2)
        here = True
        if refused is not None:
            ok &= ~_on(refused, terrain, xy)
            here = not bool(_on(refused, terrain, out[leg : leg + 1, :2])[0])
        if ok[0] and np.all(cells[0] == cell) and here:
            continue
        if not np.any(ok):
            continue
        out[leg, :2] = xy[int(np.argmax(ok))]
        moved.append(leg)
    return out, moved


def replant_targets(
    planner: FootstepPlanner,
    terrain: Terrain,
    feet: NDArray[np.float64],
    foot_radius: float,
    radius: float,
    refused: NDArray[np.bool_],
    at_least: float = 0.0,
) -> list[tuple[int, NDArray[np.float64]]]:
    """The feet (4, 3) [m] a recovered robot should re-plant, and where: [(leg, centre (3,))].

    A foot on a ``refused`` cell (a face too steep) goes to the nearest
    foothold within ``radius`` [m] that is not refused
    (:func:`snap_to_footholds`), if that is at least ``at_least`` [m]
    away, its centre where a sphere of ``foot_radius`` [m] rests there.
    A foot merely a few millimetres off the footholds stays: the re-plan
    snaps it. Legs in canonical order.
    """
    snapped, moved = snap_to_footholds(planner, terrain, feet, radius, refused=refused)
    steep = _on(refused, terrain, np.asarray(feet, dtype=float)[:, :2])
    return [
        (leg, resting_centres(terrain, snapped[leg : leg + 1, :2], foot_radius)[0])
        for leg in sorted(moved)
        if steep[leg] and np.linalg.norm(snapped[leg, :2] - feet[leg, :2]) >= at_least
    ]


def footholds_toward(
    planner: FootstepPlanner,
    terrain: Terrain,
    foot: NDArray[np.float64],
    toward: NDArray[np.float64],
    radius: float,
    foot_radius: float,
    front: bool,
    least_gain: float = 0.01,
) -> NDArray[np.float64]:
    """Foot centres (n, 3) [m] a foot at ``foot`` can step to, nearer ``toward`` (x–y) first.

    The planner's lattice points within ``radius`` [m] of ``foot`` that are
    footholds for a front or hind foot (``front``) and at least
    ``least_gain`` [m] nearer ``toward`` than ``foot`` is, each at the
    height where a sphere of ``foot_radius`` [m] rests there. (The planner's
    footholds: with ``footstep.max_foothold_slope`` a walk's refuse faces.)
    """
    x0, y0, h, nx, ny = planner.lattice
    reach = int(np.ceil(radius / h))
    cell = np.round((np.asarray(foot, dtype=float)[:2] - (x0, y0)) / h)
    i, j = np.meshgrid(np.arange(-reach, reach + 1), np.arange(-reach, reach + 1), indexing="ij")
    cells = cell + np.stack([i.ravel(), j.ravel()], axis=1)
    cells = cells[(cells[:, 0] >= 0) & (cells[:, 1] >= 0) & (cells[:, 0] < nx) & (cells[:, 1] < ny)]
    xy = np.array([x0, y0]) + h * cells
    xy = xy[np.linalg.norm(xy - np.asarray(foot, dtype=float)[:2], axis=1) <= radius + 1e-12]
    if len(xy) == 0:
        return np.zeros((0, 3))
    xy = xy[_foothold(planner, terrain, xy, front)]
    goal = np.asarray(toward, dtype=float)[:2]
    from_foot = float(np.linalg.norm(np.asarray(foot, dtype=float)[:2] - goal))
    d = np.linalg.norm(xy - goal, axis=1)
    keep = d <= from_foot - least_gain
    xy, d = xy[keep], d[keep]
    if len(xy) == 0:
        return np.zeros((0, 3))
    return resting_centres(terrain, xy[np.argsort(d, kind="stable")], foot_radius)
