"""Footholds a round foot slides off (rims, slopes past the friction cone) or a knee hits a wall at.

The learned terrain cost (Zucker 2011, §4.2) hardly tells such footholds
from their neighbours: its quadratic fits over discs of 1–6 cm smooth a
7 cm cliff into a slope, and on the LittleDog large-rocks board (AE) the
footholds with a drop of over 3 cm beside them cost a median 2.33 against
1.58 for the others. The bench's large
rocks runs fell from both kinds:

- **on a rim** (seeds 2 and 3): the start put RF on the rim of a 7.5 cm
  rock, its centre 3 mm outside the top; as LF (seed 2) or RH (seed 3)
  swung, RF slid 3.5 cm down the rock and the trunk tipped over;
- **on a slope** (seed 1 with the rims refused): the plan put LF on a 52°
  flank; it slid off as RF swung, and the robot rolled over. A foot
  pressed down vertically slides where the slope is steeper than the
  friction cone, atan μ (45° at μ = 1). On the logs board (AD) the rim
  check alone let the start put RF and RH on logs' flanks of 51–59° with
  less than 3 cm of drop beside them; both slid (2 and 7 cm) and the runs
  fell. A log's flank is a slope, not a rim: the slope limit refuses it.

:func:`edge_footholds` marks the terrain cells where a foot of radius r
would rest with terrain more than ``drop`` below its sole within r +
``margin`` of its centre. The resting height is that of the sphere lowered
onto the height field, max over the disc of h(p) + √(r² − |p − c|²) − r; a
foot on the floor beside a wall rests on the floor and is not on an edge,
one on top of the wall within r of its rim is. :func:`steep_footholds`
marks the cells whose mean slope over the foot's disc exceeds a limit.

:func:`wall_footholds` marks the cells with a wall beside them where the
leg stands: LittleDog's knees point backwards on the front legs and forwards
on the hind legs, 2–7 cm from the foot and 10–11 cm above its sole, so a
front foot put down just past a wall (the near side of a trench) brings its
shank onto the wall's rim. On the bench's gap (a 12 cm trench, 10 cm deep,
``bench_littledog.py --expansions 40000``, seed 0) the plan put RF on the
trench floor 3 cm past the near wall: its step's touchdown sample had the
shank 1.6 cm inside the rim (the step was marked invalid and walked as it
was), the shank came to rest on the rim, the foot hung 7 cm above the floor,
LF and RH lost their load, and the foot-force reflex cost 1.1 s. The pose
certificate had passed that stance: it checks the certified trunk pose,
not the trunk of the swing's touchdown, which lags behind it and slants the
leg further back.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray
from scipy import ndimage

from roughwalk.terrain.terrain import Terrain

__all__ = [
    "contact_slopes",
    "edge_footholds",
    "leaning_footholds",
    "resting_centres",
    "resting_height",
    "steep_footholds",
    "unsafe_footholds",
    "wall_footholds",
]


def _disc(radius: float, dx: float, dy: float) -> tuple[NDArray[np.bool_], NDArray[np.float64]]:
    """The grid offsets within ``radius`` [m]: a footprint mask and their squared distances [m²]."""
    ni = max(int(np.ceil(radius / dx)), 0)
    nj = max(int(np.ceil(radius / dy)), 0)
    i, j = np.mgrid[-ni : ni + 1, -nj : nj + 1]
    d2 = (i * dx) ** 2 + (j * dy) ** 2
    return d2 <= radius * radius + 1e-15, d2


def resting_height(terrain: Terrain, foot_radius: float) -> NDArray[np.float64]:
    """Height [m] of the sole of a sphere of ``foot_radius`` [m] lowered onto each grid cell.

    (nx, ny), x-major like ``terrain.heights`` (unknown cells as that fills
    them): max over the cells p within the radius of h(p) + √(r² − |p − c|²) − r.
    """
    h = np.asarray(terrain.heights, dtype=float)
    inside, d2 = _disc(foot_radius, terrain.dx, terrain.dy)
    bump = np.where(inside, np.sqrt(np.maximum(foot_radius**2 - d2, 0.0)) - foot_radius, 0.0)
    return np.asarray(
        ndimage.grey_dilation(h, footprint=inside, structure=bump, mode="nearest"), dtype=float
    )


def resting_centres(
    terrain: Terrain, xy: NDArray[np.float64], foot_radius: float
) -> NDArray[np.float64]:
    """Centres (n, 3) [m] of spheres of ``foot_radius`` [m] lowered vertically onto ``xy`` (n, 2).

    The pointwise :func:`resting_height` plus the radius, with the terrain
    read bilinearly at the grid's own spacing over the foot's disc: where
    the foot rests when put down straight over a foothold, whatever the
    surface's normal at the one point under its centre.
    """
    pts = np.atleast_2d(np.asarray(xy, dtype=float))[:, :2]
    step = min(terrain.dx, terrain.dy)
    n = max(int(np.ceil(foot_radius / step)), 1)
    i, j = np.mgrid[-n : n + 1, -n : n + 1]
    off = np.column_stack([i.ravel(), j.ravel()]) * (foot_radius / n)
    d2 = np.sum(off**2, axis=1)
    keep = d2 <= foot_radius**2 + 1e-15
    off, d2 = off[keep], d2[keep]
    bump = np.sqrt(np.maximum(foot_radius**2 - d2, 0.0))
    h = np.asarray(terrain.height((pts[:, None, :] + off[None]).reshape(-1, 2)), dtype=float)
    top = np.max(h.reshape(len(pts), len(off)) + bump[None], axis=1)
    return np.column_stack([pts, top])


def contact_slopes(terrain: Terrain, foot_radius: float) -> NDArray[np.float64]:
    """Slope [rad] of the contact a sphere of ``foot_radius`` [m] lowered onto each cell makes.

    (nx, ny), x-major. The sphere lowered straight down rests on the cell p
    within its disc that maximises h(p) + √(r² − |p − c|²); its contact
    normal then leans asin(|p − c| / r) from vertical. That, not the disc's
    mean slope (:func:`steep_footholds`), is the face a foot pressed down
    there stands on: where it leans beyond the friction cone, the foot slides.
    """
    h = np.asarray(terrain.heights, dtype=float)
    inside, d2 = _disc(foot_radius, terrain.dx, terrain.dy)
    ni, nj = (inside.shape[0] - 1) // 2, (inside.shape[1] - 1) // 2
    padded = np.pad(h, ((ni, ni), (nj, nj)), mode="edge")
    best = np.full(h.shape, -np.inf)
    lean = np.zeros(h.shape)
    for a, b in zip(*np.nonzero(inside), strict=True):
        top = padded[a : a + h.shape[0], b : b + h.shape[1]] + np.sqrt(
            max(foot_radius**2 - d2[a, b], 0.0)
        )
        higher = top > best
        best = np.where(higher, top, best)
        lean = np.where(higher, np.sqrt(d2[a, b]), lean)
    return np.asarray(np.arcsin(np.clip(lean / foot_radius, 0.0, 1.0)), dtype=float)


def leaning_footholds(terrain: Terrain, foot_radius: float, max_slope: float) -> NDArray[np.bool_]:
    """Cells (nx, ny) whose contact leans beyond ``max_slope`` [rad] (:func:`contact_slopes`).

    ``max_slope`` ≥ π/2 marks none.
    """
    if max_slope >= 0.5 * np.pi:
        return np.zeros(np.asarray(terrain.heights).shape, dtype=bool)
    return np.asarray(contact_slopes(terrain, foot_radius) > max_slope, dtype=bool)


def edge_footholds(
    terrain: Terrain, foot_radius: float, drop: float, margin: float = 0.0
) -> NDArray[np.bool_]:
    """Cells (nx, ny) where a foot would rest with a drop of more than ``drop`` [m] beside it.

    A cell is on an edge when, within ``foot_radius`` + ``margin`` [m] of it,
    the terrain lies more than ``drop`` below the sole of the foot resting
    there (:func:`resting_height`). ``drop`` ≤ 0 marks none.
    """
    shape = np.asarray(terrain.heights).shape
    if drop <= 0:
        return np.zeros(shape, dtype=bool)
    rest = resting_height(terrain, foot_radius)
    h = np.asarray(terrain.heights, dtype=float)
    footprint, _ = _disc(foot_radius + margin, terrain.dx, terrain.dy)
    low = ndimage.minimum_filter(h, footprint=footprint, mode="nearest")
    return np.asarray(rest - low > drop, dtype=bool)


def steep_footholds(terrain: Terrain, foot_radius: float, max_slope: float) -> NDArray[np.bool_]:
    """Cells (nx, ny) steeper than ``max_slope`` [rad]: the mean gradient over the foot's disc.

    ``max_slope`` ≥ π/2 marks none.
    """
    shape = np.asarray(terrain.heights).shape
    if max_slope >= 0.5 * np.pi:
        return np.zeros(shape, dtype=bool)
    h = np.asarray(terrain.heights, dtype=float)
    gx, gy = np.gradient(h, terrain.dx, terrain.dy)
    inside, _ = _disc(foot_radius, terrain.dx, terrain.dy)
    mean = inside / inside.sum()
    mx = ndimage.convolve(gx, mean, mode="nearest")
    my = ndimage.convolve(gy, mean, mode="nearest")
    return np.asarray(np.hypot(mx, my) > np.tan(max_slope), dtype=bool)


def wall_footholds(
    terrain: Terrain,
    foot_radius: float,
    reach: float,
    height: float,
    heading: float,
    end: str,
) -> NDArray[np.bool_]:
    """Cells (nx, ny) with a wall beside them, on the side where the leg's knee stands.

    A cell is at a wall when, in the strip of the foot's width (2
    ``foot_radius``) that runs ``reach`` [m] from its centre towards the knee
    (backwards along ``heading`` [rad] for the ``end`` "front" legs, forwards
    for "hind"), the terrain rises more than ``height`` [m] above the sole of
    the foot resting there (:func:`resting_height`). ``reach`` ≤ 0 marks none.
    """
    shape = np.asarray(terrain.heights).shape
    if reach <= 0:
        return np.zeros(shape, dtype=bool)
    if end not in ("front", "hind"):
        raise ValueError(f"end must be 'front' or 'hind', got {end!r}")
    sign = -1.0 if end == "front" else 1.0
    ux, uy = sign * np.cos(heading), sign * np.sin(heading)
    ni = max(int(np.ceil(reach / terrain.dx)), 0)
    nj = max(int(np.ceil(reach / terrain.dy)), 0)
    i, j = np.mgrid[-ni : ni + 1, -nj : nj + 1]
    px, py = i * terrain.dx, j * terrain.dy
    along = px * ux + py * uy
    across = np.abs(-px * uy + py * ux)
    strip = (along >= -1e-12) & (along <= reach + 1e-12) & (across <= foot_radius + 1e-12)
    h = np.asarray(terrain.heights, dtype=float)
    high = ndimage.maximum_filter(h, footprint=strip, mode="nearest")
    return np.asarray(high - resting_height(terrain, foot_radius) > height, dtype=bool)


def unsafe_footholds(
    terrain: Terrain, foot_radius: float, drop: float, margin: float, max_slope: float
) -> NDArray[np.bool_]:
    """Cells (nx, ny) on an edge (:func:`edge_footholds`) or too steep (:func:`steep_footholds`)."""
    return edge_footholds(terrain, foot_radius, drop, margin) | steep_footholds(
        terrain, foot_radius, max_slope
    )
