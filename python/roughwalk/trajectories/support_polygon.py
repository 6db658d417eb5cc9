"""Signed distance to a support polygon, batched, with its gradient.

The margin of a point to the convex hull of the supporting feet (x–y) is
positive inside (distance to the nearest edge) and negative outside (minus
the distance to the polygon). It is the ZMP criterion of Zucker 2011, §5.2,
and its gradient drives the stability term of CHOMP (§5.3).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from roughwalk.errors import InvalidArgumentError

__all__ = ["convex_polygon", "polygon_margin"]


def convex_polygon(points: ArrayLike) -> NDArray[np.float64]:
    """Counter-clockwise convex hull (k, 2) of x–y points (n, 2 or 3) (monotone chain)."""
    p = np.asarray(points, dtype=float)[:, :2]
    if p.shape[0] < 1:
        raise InvalidArgumentError("a support polygon needs at least one foot")
    pts = sorted({(float(x), float(y)) for x, y in p})
    if len(pts) <= 2:
        return np.array(pts)

    def cross(o: tuple[float, float], a: tuple[float, float], b: tuple[float, float]) -> float:
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    lower: list[tuple[float, float]] = []
    for q in pts:
        while len(lower) >= 2 and cross(lower[-2], lower[-1], q) <= 0:
            lower.pop()
        lower.append(q)
    upper: list[tuple[float, float]] = []
    for q in reversed(pts):
        while len(upper) >= 2 and cross(upper[-2], upper[-1], q) <= 0:
            upper.pop()
        upper.append(q)
    return np.array(lower[:-1] + upper[:-1])


def polygon_margin(
    points: ArrayLike, polygon: ArrayLike
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Signed margins (n,) [m] of points (n, 2) to a CCW convex polygon (k, 2), and their gradients.

    The gradients ∂margin/∂point are (n, 2).

    Inside: the distance to the nearest edge line, gradient its inward
    normal. Outside: minus the distance to the nearest boundary point,
    gradient the unit vector from the point toward it.
    """
    p = np.asarray(points, dtype=float).reshape(-1, 2)
    poly = np.asarray(polygon, dtype=float)
    a = poly
    b = np.roll(poly, -1, axis=0)
    edge = b - a
    length = np.linalg.norm(edge, axis=1)
    if poly.shape[0] < 3 or np.any(length < 1e-12):
        # Degenerate support (a point or a segment): the distance to it, negative.
        seg_a, seg_b = (poly[0], poly[-1])
        d = seg_b - seg_a
        t = np.clip(((p - seg_a) @ d) / max(float(d @ d), 1e-24), 0.0, 1.0)
        closest = seg_a + t[:, None] * d
        diff = closest - p
        dist = np.linalg.norm(diff, axis=1)
        grad = diff / np.maximum(dist, 1e-12)[:, None]
        return -dist, grad
    normal = np.stack([-edge[:, 1], edge[:, 0]], axis=1) / length[:, None]  # inward for CCW
    signed = np.einsum("nkd,kd->nk", p[:, None, :] - a[None], normal)
    inside = np.all(signed >= 0, axis=1)
    nearest_edge = np.argmin(signed, axis=1)
    margin = np.empty(p.shape[0])
    grad = np.empty((p.shape[0], 2))
    margin[inside] = signed[inside, nearest_edge[inside]]
    grad[inside] = normal[nearest_edge[inside]]
    out = ~inside
    if np.any(out):
        q = p[out]
        t = np.clip(np.einsum("nkd,kd->nk", q[:, None, :] - a[None], edge) / length**2, 0.0, 1.0)
        closest = a[None] + t[:, :, None] * edge[None]
        dist = np.linalg.norm(closest - q[:, None, :], axis=2)
        k = np.argmin(dist, axis=1)
        rows = np.arange(q.shape[0])
        best = dist[rows, k]
        margin[out] = -best
        grad[out] = (closest[rows, k] - q) / np.maximum(best, 1e-12)[:, None]
    return margin, grad
