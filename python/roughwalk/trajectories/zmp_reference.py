"""The ZMP reference: a linear spline through the support anchors (Zucker 2011, §5.2).

"The first step in building footstep trajectories is to construct a linear
spline path for the ZMP to follow. The default choice for the ZMP in each
footstep is the body position given by the corresponding pose certificate ...
The linear spline path is transformed into a time-referenced trajectory by
considering the estimated duration for each footstep." Here the anchor of a
step is the certificate's centre of mass (what the certificate guarantees to
lie in the support triangle): during the step's shift phase the ZMP moves in
a straight line from the previous anchor to it; during the swing it moves
on, inside the swing's support triangle, to the point of that triangle
nearest the next anchor (:func:`closest_point_in_triangle`), so that the
trunk comes within reach of the next certificate by touchdown.

Footnote 2: "to achieve faster walking speeds and minimize the displacement
of the trunk, we also test a 'shortcut' ZMP position that reduces the overall
length of the spline." :func:`shortcut_anchor` is the point of the support
triangle, shrunk by a margin, that makes the path previous → anchor → next
shortest.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from roughwalk.errors import InvalidArgumentError
from roughwalk.trajectories.timing import StepTiming

__all__ = [
    "ZmpReference",
    "shortcut_anchor",
    "shrink_triangle",
    "inside_triangle",
    "closest_point_in_triangle",
]


class ZmpReference:
    """A piecewise-linear ZMP path: knots at times (K,) [s] through points (K, 2) [m]."""

    def __init__(self, times: ArrayLike, points: ArrayLike) -> None:
        t = np.asarray(times, dtype=float)
        p = np.asarray(points, dtype=float)
        if t.ndim != 1 or p.shape != (t.shape[0], 2) or t.shape[0] < 1:
            raise InvalidArgumentError(
                f"ZMP reference needs K times and (K, 2) points, got {t.shape} and {p.shape}"
            )
        if np.any(np.diff(t) < 0):
            raise InvalidArgumentError(f"ZMP reference times must not decrease, got {t}")
        self.times = t
        self.points = p

    @classmethod
    def through_anchors(
        cls,
        anchors: ArrayLike,
        timings: Sequence[StepTiming],
        start_time: float = 0.0,
        exits: ArrayLike | None = None,
    ) -> ZmpReference:
        """The reference of consecutive footsteps.

        ``anchors`` (S + 1, 2) [m]: the ZMP at rest before the first step,
        then one per step (inside that step's support triangle); with a
        settling phase on the last step, one more: where the ZMP comes to rest.
        Step k shifts from anchor k − 1 to anchor k, then moves in the first
        three quarters of its swing to ``exits[k]`` (S, 2) (default: holds
        anchor k) and holds it; the next shift starts from there. A settling
        phase moves to the final anchor in its first half and holds it.
        """
        a = np.asarray(anchors, dtype=float)
        settle = any(t.settle_s > 0 for t in timings)
        expected = len(timings) + 1 + (1 if settle else 0)
        if a.shape != (expected, 2):
            raise InvalidArgumentError(
                f"{len(timings)} steps{' with settling' if settle else ''} need "
                f"{expected} ZMP anchors (2-D), got shape {a.shape}"
            )
        out = a[1 : len(timings) + 1] if exits is None else np.asarray(exits, dtype=float)
        if out.shape != (len(timings), 2):
            raise InvalidArgumentError(
                f"exits must have shape ({len(timings)}, 2), one per step; got {out.shape}"
            )
        times = [start_time]
        points = [a[0]]
        t = start_time
        for k, timing in enumerate(timings, start=1):
            t += timing.shift_s
            times.append(t)
            points.append(a[k])
            # Reach the exit three quarters into the swing and hold it, so the
            # ZMP has settled when the foot lands.
            times.append(t + 0.75 * timing.swing_s)
            points.append(out[k - 1])
            t += timing.swing_s
            times.append(t)
            points.append(out[k - 1])
            if timing.settle_s > 0:
                times.append(t + timing.settle_s / 2)
                points.append(a[k + 1])
                t += timing.settle_s
                times.append(t)
                points.append(a[k + 1])
        return cls(np.array(times), np.array(points))

    def sample(self, t: ArrayLike) -> NDArray[np.float64]:
        """Reference ZMP (n, 2) [m] at times t [s], held beyond the first and last knots."""
        tt = np.asarray(t, dtype=float)
        return np.stack([np.interp(tt, self.times, self.points[:, a]) for a in range(2)], axis=-1)

    @property
    def end_time(self) -> float:
        """Time [s] of the last knot."""
        return float(self.times[-1])


def _incircle(tri: NDArray[np.float64]) -> tuple[NDArray[np.float64], float]:
    a = np.linalg.norm(tri[1] - tri[2])
    b = np.linalg.norm(tri[2] - tri[0])
    c = np.linalg.norm(tri[0] - tri[1])
    perimeter = a + b + c
    if perimeter < 1e-12:
        return tri[0].copy(), 0.0
    centre = (a * tri[0] + b * tri[1] + c * tri[2]) / perimeter
    area = 0.5 * abs(
        (tri[1, 0] - tri[0, 0]) * (tri[2, 1] - tri[0, 1])
        - (tri[2, 0] - tri[0, 0]) * (tri[1, 1] - tri[0, 1])
    )
    return centre, 2.0 * area / perimeter


def shrink_triangle(
    triangle: ArrayLike, margin: float, min_share: float = 0.0
) -> NDArray[np.float64]:
    """The triangle (3, 2) [m] of points at least ``margin`` [m] inside ``triangle``.

    Every edge moves in by ``margin``; with ``min_share`` also by that share
    of the height of the opposite corner (where it is more): a ZMP there
    puts at least that share of the weight on every foot of the triangle
    (the static loads are the ZMP's barycentric coordinates). Too much of
    either leaves one point: the incentre for ``margin`` alone, in general
    the point whose coordinates are in the ratio of the edges' demands.
    """
    tri = np.asarray(triangle, dtype=float)[:, :2]
    centre, r = _incircle(tri)
    if r <= 0:
        return np.repeat(centre[None], 3, axis=0)
    area = 0.5 * abs(
        (tri[1, 0] - tri[0, 0]) * (tri[2, 1] - tri[0, 1])
        - (tri[2, 0] - tri[0, 0]) * (tri[1, 1] - tri[0, 1])
    )
    # Height of corner i over the opposite edge, and the least barycentric
    # coordinate of corner i the margin and the share ask for.
    edges = np.linalg.norm(tri[[1, 2, 0]] - tri[[2, 0, 1]], axis=1)
    least = np.maximum(margin * edges / (2.0 * area), min_share)
    total = float(least.sum())
    if total >= 1.0:
        point = (least / total) @ tri
        return np.repeat(point[None], 3, axis=0)
    weights = np.tile(least, (3, 1))
    weights[np.arange(3), np.arange(3)] = 1.0 - (total - least)
    return weights @ tri


def inside_triangle(
    points: ArrayLike, triangle: ArrayLike, tol: float = 1e-12
) -> NDArray[np.bool_]:
    """Whether points (n, 2) lie in the triangle (3, 2) (either orientation)."""
    p = np.asarray(points, dtype=float).reshape(-1, 2)
    t = np.asarray(triangle, dtype=float)[:, :2]
    signs = []
    for i in range(3):
        a, b = t[i], t[(i + 1) % 3]
        signs.append((b[0] - a[0]) * (p[:, 1] - a[1]) - (b[1] - a[1]) * (p[:, 0] - a[0]))
    s = np.stack(signs, axis=1)
    return np.all(s >= -tol, axis=1) | np.all(s <= tol, axis=1)


def closest_point_in_triangle(
    point: ArrayLike, triangle: ArrayLike, margin: float, min_share: float = 0.0
) -> NDArray[np.float64]:
    """The point (2,) of ``triangle`` shrunk (:func:`shrink_triangle`) nearest to ``point`` [m]."""
    p = np.asarray(point, dtype=float)[:2]
    inner = shrink_triangle(triangle, margin, min_share)
    if inside_triangle(p[None], inner)[0]:
        return p.copy()
    best, best_d = inner[0], np.inf
    for i in range(3):
        a, b = inner[i], inner[(i + 1) % 3]
        ab = b - a
        t = float(np.clip((p - a) @ ab / max(float(ab @ ab), 1e-24), 0.0, 1.0))
        c = a + t * ab
        d = float(np.linalg.norm(p - c))
        if d < best_d:
            best, best_d = c, d
    return np.asarray(best, dtype=float)


def shortcut_anchor(
    previous: ArrayLike,
    anchor: ArrayLike,
    following: ArrayLike,
    triangle: ArrayLike,
    margin: float,
    samples: int = 64,
    min_share: float = 0.0,
) -> NDArray[np.float64]:
    """The footnote-2 shortcut ZMP (2,) [m] for one step.

    Minimises |previous − p| + |p − following| over p in ``triangle``
    shrunk by ``margin`` and ``min_share`` (:func:`shrink_triangle`), ties
    broken toward ``anchor`` (the certificate's);
    found among dense samples of the segment previous–following inside the
    shrunk triangle and of its boundary.
    """
    a = np.asarray(previous, dtype=float)[:2]
    b = np.asarray(following, dtype=float)[:2]
    home = np.asarray(anchor, dtype=float)[:2]
    inner = shrink_triangle(triangle, margin, min_share)
    s = np.linspace(0.0, 1.0, samples + 1)[:, None]
    on_segment = a + s * (b - a)
    on_segment = on_segment[inside_triangle(on_segment, inner, tol=1e-12)]
    edges = [inner[i] + s * (inner[(i + 1) % 3] - inner[i]) for i in range(3)]
    candidates = np.concatenate([on_segment, *edges])
    length = np.linalg.norm(candidates - a, axis=1) + np.linalg.norm(candidates - b, axis=1)
    # Ties (a whole stretch of the segment inside) go to the point nearest the certificate.
    score = length + 1e-3 * np.linalg.norm(candidates - home, axis=1)
    best = candidates[int(np.argmin(score))]
    here = float(np.linalg.norm(home - a) + np.linalg.norm(home - b))
    if inside_triangle(home[None], inner)[0] and here <= float(np.min(length)) + 1e-12:
        return home.copy()
    return best
