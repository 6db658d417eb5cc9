"""Courses: terrain boards laid end to end along x, as in the LittleDog program.

The rule is the original software's: board k keeps its own coordinates, its
x values shifted by the sum of the last x values (x_max) of boards 0..k−1;
y is kept, and heights are kept as measured, since the boards stood on one
floor. Where two placed boards overlap the later one wins. The course is
resampled on one grid by bilinear interpolation of each board's measured
heights (unknown wherever an interpolation corner is unknown), and may get
flat pads at height 0 (the floor) before the first and after the last board,
for the start and the goal. Cells of the course rectangle that no board and
no pad covers (boards of different widths) are unknown.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from roughwalk.errors import TerrainError
from roughwalk.terrain.terrain import Terrain

__all__ = ["make_course", "rotate_board"]

#: Largest course grid [points] (a 10 m × 2 m course at 1.2 mm is ~14 million).
_MAX_POINTS = 50_000_000
#: Fraction of a cell under which a coordinate counts as on a grid line.
_SNAP = 1e-6


def rotate_board(board: Terrain, degrees: int) -> Terrain:
    """``board`` rotated about its own centre by a multiple of 90° [deg].

    Positive angles turn counter-clockwise seen from above (about +z): at
    +90° the board's +x edge becomes its +y edge. The grid stays x-major,
    its spacings swap for odd quarter turns, and the centre of the board's
    rectangle stays where it was. A kept mesh is rotated with it.
    """
    if int(degrees) != degrees or int(degrees) % 90 != 0:
        raise TerrainError(f"board '{board.name}': rotation {degrees}° is not a multiple of 90°")
    k = (int(degrees) // 90) % 4
    if k == 0:
        return board
    raw = np.rot90(board.raw_heights, k)
    dx, dy = (board.dy, board.dx) if k % 2 else (board.dx, board.dy)
    x_min, x_max, y_min, y_max = board.extent
    cx, cy = 0.5 * (x_min + x_max), 0.5 * (y_min + y_max)
    nx, ny = raw.shape
    mesh = None
    if board.mesh is not None:
        import trimesh

        mesh = board.mesh.copy()
        turn = trimesh.transformations.rotation_matrix(k * np.pi / 2, [0, 0, 1], [cx, cy, 0])
        mesh.apply_transform(turn)
    return Terrain(
        raw,
        cx - 0.5 * (nx - 1) * dx,
        cy - 0.5 * (ny - 1) * dy,
        dx,
        dy,
        name=f"{board.name}@{k * 90}",
        spec=f"{board.spec}@{k * 90}",
        mesh=mesh,
    )


def make_course(
    boards: Sequence[Terrain],
    rotations: Sequence[int] | None = None,
    resolution: float | None = None,
    pad_before: float = 0.0,
    pad_after: float = 0.0,
    spec: str | None = None,
) -> Terrain:
    """Lay ``boards`` end to end along x and resample them on one grid.

    Parameters
    ----------
    boards:
        The boards, first to last.
    rotations:
        Per board, a multiple of 90° [deg] to turn it about its own centre
        before placing it (see :func:`rotate_board`); default none.
    resolution:
        Course grid spacing [m] (the same along x and y); default the finest
        spacing of any board. It is lowered slightly so that the grid spans
        the course exactly.
    pad_before, pad_after:
        Length [m] of flat floor (height 0) added before the first board and
        after the last one, over the course's whole width.
    spec:
        The spec string that rebuilds this course (default: its name).

    Returns
    -------
    Terrain
        Named after its boards (``"terrainA+terrainC@180"``). Board meshes
        are not carried over: a course is a height field.

    """
    boards = list(boards)
    if not boards:
        raise TerrainError("a course needs at least one board")
    rotations = [0] * len(boards) if rotations is None else list(rotations)
    if len(rotations) != len(boards):
        raise TerrainError(
            f"got {len(rotations)} rotations for {len(boards)} boards; give one per board"
        )
    for label, pad in (("pad_before", pad_before), ("pad_after", pad_after)):
        if not np.isfinite(pad) or pad < 0:
            raise TerrainError(f"{label} must be a finite length ≥ 0 [m], got {pad}")

    placed: list[tuple[Terrain, float]] = []
    offset = 0.0
    for board, rotation in zip(boards, rotations, strict=True):
        b = rotate_board(board, rotation)
        placed.append((b, offset))
        offset += b.extent[1]

    if resolution is None:
        res = min(min(b.dx, b.dy) for b, _ in placed)
    else:
        res = float(resolution)
        if not np.isfinite(res) or res <= 0:
            raise TerrainError(f"course resolution must be finite and positive [m], got {res}")
    boards_x_min = min(b.x0 + off for b, off in placed)
    boards_x_max = max(b.extent[1] + off for b, off in placed)
    x_min, x_max = boards_x_min - pad_before, boards_x_max + pad_after
    y_min = min(b.y0 for b, _ in placed)
    y_max = max(b.extent[3] for b, _ in placed)
    nx = int(np.ceil((x_max - x_min) / res - _SNAP)) + 1
    ny = int(np.ceil((y_max - y_min) / res - _SNAP)) + 1
    if nx * ny > _MAX_POINTS:
        raise TerrainError(
            f"a course grid of {nx}×{ny} points at {res:g} m is too large "
            f"(at most {_MAX_POINTS:,}); pass a coarser resolution"
        )
    dx = (x_max - x_min) / (nx - 1)
    dy = (y_max - y_min) / (ny - 1)
    xs: NDArray[np.float64] = x_min + dx * np.arange(nx, dtype=np.float64)
    ys: NDArray[np.float64] = y_min + dy * np.arange(ny, dtype=np.float64)

    heights = np.full((nx, ny), np.nan)
    heights[xs < boards_x_min - _SNAP * dx, :] = 0.0
    heights[xs > boards_x_max + _SNAP * dx, :] = 0.0
    for b, off in placed:
        bx_min, bx_max, by_min, by_max = b.extent
        ix = np.flatnonzero(
            (xs >= bx_min + off - _SNAP * b.dx) & (xs <= bx_max + off + _SNAP * b.dx)
        )
        iy = np.flatnonzero((ys >= by_min - _SNAP * b.dy) & (ys <= by_max + _SNAP * b.dy))
        if ix.size and iy.size:
            heights[np.ix_(ix, iy)] = sample_bilinear(b, xs[ix] - off, ys[iy])

    name = "+".join(
        b.name if (rot // 90) % 4 == 0 else f"{b.name}@{(rot // 90) % 4 * 90}"
        for b, rot in zip(boards, rotations, strict=True)
    )
    try:
        return Terrain(heights, x_min, y_min, dx, dy, name=name, spec=spec or name)
    except TerrainError as e:
        raise TerrainError(f"course {name}: {e}") from None


def sample_bilinear(
    board: Terrain, xs: NDArray[np.float64], ys: NDArray[np.float64]
) -> NDArray[np.float64]:
    """Bilinear heights [m] of ``board`` on the grid ``xs`` × ``ys`` [m], from its raw heights.

    A sample is unknown (NaN) when any grid corner with a non-zero weight is
    unknown; coordinates within a millionth of a cell of a grid line take
    that line's values exactly.
    """
    raw = board.raw_heights
    ix, tx = _cell(xs, board.x0, board.dx, raw.shape[0])
    iy, ty = _cell(ys, board.y0, board.dy, raw.shape[1])
    out = np.zeros((len(xs), len(ys)))
    unknown = np.zeros((len(xs), len(ys)), dtype=bool)
    for ax, wx in ((ix, 1.0 - tx), (ix + 1, tx)):
        for ay, wy in ((iy, 1.0 - ty), (iy + 1, ty)):
            w = wx[:, None] * wy[None, :]
            z = raw[np.ix_(ax, ay)]
            used = w > 0
            out += np.where(used, w * np.where(np.isnan(z), 0.0, z), 0.0)
            unknown |= used & np.isnan(z)
    out[unknown] = np.nan
    return out


def _cell(
    v: NDArray[np.float64], v0: float, step: float, n: int
) -> tuple[NDArray[np.intp], NDArray[np.float64]]:
    """Cell index (0..n−2) and fraction (0..1) of each coordinate, snapped to grid lines."""
    g = np.clip((v - v0) / step, 0.0, n - 1.0)
    near = np.abs(g - np.round(g)) < _SNAP
    g[near] = np.round(g[near])
    i = np.minimum(np.floor(g).astype(np.intp), n - 2)
    return i, g - i
