"""The terrain as the NLP sees it: a smooth height, its gradient and a step-edge cost field.

TOWR's terrains are analytic functions with hand-written derivatives; ours
are height grids (:class:`~roughwalk.terrain.Terrain`) with sharp steps. The
NLP needs heights and normals that CasADi can differentiate twice (the
force constraint's normal holds the gradient, so the exact Hessian needs
third derivatives). We therefore blur the grid slightly, resample it and use
the samples as the control points of a tensor-product **quartic** B-spline:
control points that are the heights themselves make the spline variation
diminishing (no overshoot at steps, unlike an interpolating spline), and a
quartic keeps its third derivatives continuous (CasADi cannot take
derivatives of a B-spline down to degree 0).

Edges for Melon et al.'s step-edge cost (§III-A.2) are the cells whose slope
exceeds ``edge_slope``; the cost field exp(−x_s²/2σ²), x_s the distance to the
nearest edge cell, is a second spline on the same grid.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import casadi as ca
import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import ndimage

from roughwalk.errors import InvalidArgumentError
from roughwalk.trajopt.parameters import TerrainModelConfig

if TYPE_CHECKING:
    from roughwalk.terrain import Terrain

__all__ = ["TerrainModel"]

_DEGREE = 4
_PAD = _DEGREE + 1  # control points added around the grid so that queries stay inside


def _knots(start: float, step: float, n: int) -> list[float]:
    """Uniform knots that centre the basis function of control point i on start + i·step."""
    return list(start + (np.arange(n + _DEGREE + 1) - (_DEGREE + 1) / 2) * step)


class TerrainModel:
    """A smooth, twice-differentiable height field over a :class:`Terrain`.

    :attr:`function` maps a point xy (2, 1) to (h, ∂h/∂x, ∂h/∂y, edge cost)
    (4, 1); it is a CasADi MX function (B-splines cannot be SX). A terrain
    whose heights are all equal is :attr:`flat`: then the NLP uses constants.
    """

    def __init__(
        self,
        terrain: Terrain,
        config: TerrainModelConfig | None = None,
        edge_sigma: float = 0.05,
    ) -> None:
        self.config = config or TerrainModelConfig()
        self.edge_sigma = float(edge_sigma)
        self.terrain = terrain
        self.name = terrain.spec
        heights = np.asarray(terrain.heights, dtype=float)
        lo, hi = float(heights.min()), float(heights.max())
        self.flat = hi - lo < 1e-9
        self.flat_height = 0.5 * (lo + hi)
        self.extent = terrain.extent
        self.function: ca.Function | None = None
        self._maps: dict[int, ca.Function] = {}
        if not self.flat:
            self._build(heights)

    def _build(self, heights: NDArray[np.float64]) -> None:
        t = self.terrain
        cfg = self.config
        sigma_cells = (cfg.smoothing / t.dx, cfg.smoothing / t.dy)
        smooth = (
            ndimage.gaussian_filter(heights, sigma_cells, mode="nearest")
            if cfg.smoothing
            else heights
        )
        # Edges are found on the unblurred heights, so a step stays an edge
        # even when the blur spreads it over a few cells.
        gx, gy = np.gradient(heights, t.dx, t.dy)
        edges = np.hypot(gx, gy) > cfg.edge_slope
        if edges.any():
            distance = ndimage.distance_transform_edt(~edges, sampling=(t.dx, t.dy))
            edge_cost = np.exp(-(distance**2) / (2 * self.edge_sigma**2))
        else:
            edge_cost = np.zeros_like(heights)
        x_min, x_max, y_min, y_max = self.extent
        step = cfg.resolution
        nx = max(2, round((x_max - x_min) / step) + 1)
        ny = max(2, round((y_max - y_min) / step) + 1)
        sx = (x_max - x_min) / (nx - 1)
        sy = (y_max - y_min) / (ny - 1)
        xs = x_min + (np.arange(-_PAD, nx + _PAD)) * sx
        ys = y_min + (np.arange(-_PAD, ny + _PAD)) * sy
        gi, gj = np.meshgrid(
            np.clip((xs - t.x0) / t.dx, 0, heights.shape[0] - 1),
            np.clip((ys - t.y0) / t.dy, 0, heights.shape[1] - 1),
            indexing="ij",
        )
        coords = np.array([gi, gj])
        control = ndimage.map_coordinates(smooth, coords, order=1, mode="nearest")
        edge_control = ndimage.map_coordinates(edge_cost, coords, order=1, mode="nearest")
        knots = [_knots(xs[0], sx, len(xs)), _knots(ys[0], sy, len(ys))]
        degree = [_DEGREE, _DEGREE]
        spline_h = ca.Function.bspline(
            "terrain_height", knots, control.ravel(order="F").tolist(), degree, 1, {}
        )
        spline_e = ca.Function.bspline(
            "terrain_edge", knots, edge_control.ravel(order="F").tolist(), degree, 1, {}
        )
        xy = ca.MX.sym("xy", 2)
        # Queries beyond the grid see its border (as Terrain does): clamp into the spline's domain.
        lo = ca.DM([xs[_PAD], ys[_PAD]])
        hi = ca.DM([xs[-_PAD - 1], ys[-_PAD - 1]])
        q = ca.fmin(ca.fmax(xy, lo), hi)
        h = spline_h(q)
        grad = ca.jacobian(h, xy)
        self.function = ca.Function(
            "terrain", [xy], [ca.vertcat(h, grad.T, spline_e(q))], ["xy"], ["h_grad_edge"]
        )
        self._has_edges = bool(edges.any())

    @property
    def has_edges(self) -> bool:
        """Whether any cell is steep enough to count as an edge."""
        return not self.flat and self._has_edges

    def mapped(self, n: int) -> ca.Function:
        """:attr:`function` over n points: xy (2, n) → (4, n)."""
        if self.function is None:
            raise InvalidArgumentError("a flat terrain has no terrain function")
        if n not in self._maps:
            self._maps[n] = self.function.map(n)
        return self._maps[n]

    def evaluate(self, xy: ArrayLike) -> NDArray[np.float64]:
        """(N, 4) rows (h [m], ∂h/∂x, ∂h/∂y, edge cost) at the (N, 2) points ``xy`` [m]."""
        points = np.atleast_2d(np.asarray(xy, dtype=float))
        if points.shape[1] != 2:
            raise InvalidArgumentError(f"expected xy of shape (N, 2), got {points.shape}")
        if self.flat:
            out = np.zeros((len(points), 4))
            out[:, 0] = self.flat_height
            return out
        return np.asarray(self.mapped(len(points))(points.T)).T

    def height(self, xy: ArrayLike) -> NDArray[np.float64]:
        """Smoothed heights [m] (N,) at ``xy`` [m]."""
        return self.evaluate(xy)[:, 0]

    def normal(self, xy: ArrayLike) -> NDArray[np.float64]:
        """Unit upward normals (N, 3) of the smoothed surface at ``xy`` [m]."""
        values = self.evaluate(xy)
        n = np.column_stack([-values[:, 1], -values[:, 2], np.ones(len(values))])
        return n / np.linalg.norm(n, axis=1, keepdims=True)

    def edge_cost(self, xy: ArrayLike) -> NDArray[np.float64]:
        """Step-edge cost exp(−x_s²/2σ²) (N,) at ``xy`` [m]."""
        return self.evaluate(xy)[:, 3]
