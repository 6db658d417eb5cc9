"""Courses: boards laid end to end along x, rotated, padded and resampled."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from roughwalk.errors import TerrainError
from roughwalk.terrain import Terrain, load_terrain
from roughwalk.terrain.course import make_course, rotate_board

Board = Callable[[str], Terrain]


def grid_points(t: Terrain) -> np.ndarray:
    gx, gy = np.meshgrid(t.x, t.y, indexing="ij")
    return np.column_stack([gx.ravel(), gy.ravel()])


def offsets(boards: list[Terrain]) -> list[float]:
    """The original rule: board k moves by the sum of the last x values of boards 0..k−1."""
    return [sum(b.extent[1] for b in boards[:k]) for k in range(len(boards))]


def test_three_boards_in_a_row(littledog_board: Board) -> None:
    boards = [littledog_board(n) for n in ("A", "C", "Y")]
    course = make_course(boards, rotations=[0, 0, 0], spec="A+C+Y")
    assert course.name == "terrainA+terrainC+terrainY" and course.spec == "A+C+Y"
    # One increasing, uniform x axis from the first board's start to the last one's end.
    shifts = offsets(boards)
    assert course.extent[0] == pytest.approx(boards[0].x0)
    assert course.extent[1] == pytest.approx(shifts[2] + boards[2].extent[1])
    assert np.all(np.diff(course.x) > 0)
    assert course.dx == pytest.approx(min(min(b.dx, b.dy) for b in boards), rel=1e-3)
    assert course.dx <= min(min(b.dx, b.dy) for b in boards)
    # The boards abut: no gap along x. A is 1 mm wider in y than C and Y, and
    # that strip is unknown beside C and Y.
    narrow = min(b.extent[3] for b in boards)
    assert course.known[:, course.y <= narrow].all()
    beside = course.x > shifts[1] + 1e-9
    assert not course.known[np.ix_(beside, course.y > narrow + 1e-9)].any()

    pts = grid_points(course)
    h = course.raw_heights.ravel()
    for k, (b, shift) in enumerate(zip(boards, shifts, strict=True)):
        x_min, x_max, y_min, y_max = b.extent
        start = x_min + shift if k == 0 else shifts[k]  # earlier boards' ends lie under this one
        end = x_max + shift if k == 2 else shifts[k + 1]
        inside = (
            (pts[:, 0] > start + 1e-9)
            & (pts[:, 0] < end - 1e-9)
            & (pts[:, 1] >= y_min)
            & (pts[:, 1] <= y_max)
        )
        assert inside.sum() > 100_000
        # At course grid points: the board's own bilinear height at the un-shifted point.
        local = pts[inside] - [shift, 0.0]
        np.testing.assert_allclose(h[inside], b.height(local), rtol=0, atol=1e-12)

        # Between grid points both are averages of nearby board samples: they lie
        # within the range of the board's heights around the point.
        rng = np.random.default_rng(k)
        xy = np.column_stack([rng.uniform(start, end, 300), rng.uniform(y_min, y_max, 300)])
        ours, theirs = course.height(xy), b.height(xy - [shift, 0.0])
        for p, a, c in zip(xy - [shift, 0.0], ours, theirs, strict=True):
            i = int((p[0] - b.x0) / b.dx)
            j = int((p[1] - b.y0) / b.dy)
            window = b.heights[max(i - 2, 0) : i + 4, max(j - 2, 0) : j + 4]
            assert window.min() - 1e-12 <= a <= window.max() + 1e-12
            assert abs(a - c) <= np.ptp(window) + 1e-12


def test_boards_on_one_grid_keep_their_file_heights_exactly(littledog_board: Board) -> None:
    # C, Y and AE share x = 0 … 0.609 m on the same 0.609/512 m grid, so the
    # course grid passes through every board grid point.
    boards = [littledog_board(n) for n in ("C", "Y", "AE")]
    course = load_terrain("+".join(b.spec for b in boards))
    assert course.shape == (3 * 512 + 1, 513)
    for k, b in enumerate(boards):
        block = course.raw_heights[512 * k : 512 * k + 512]
        np.testing.assert_allclose(block, b.raw_heights[:512], rtol=0, atol=1e-12)
    # Where two boards meet, the later one wins.
    np.testing.assert_allclose(course.raw_heights[512], boards[1].raw_heights[0], atol=1e-12)


def test_later_board_wins_where_boards_overlap() -> None:
    first = Terrain(np.full((11, 5), 1.0), 0.0, 0.0, 0.1, 0.1, name="one")
    second = Terrain(np.full((11, 5), 2.0), -0.2, 0.0, 0.1, 0.1, name="two")  # x ∈ [−0.2, 0.8]
    course = make_course([first, second])
    assert course.extent[:2] == pytest.approx((0.0, 1.8))
    x = course.x
    row = course.heights[:, 2]
    np.testing.assert_array_equal(row[x < 0.8 - 1e-9], 1.0)
    np.testing.assert_array_equal(row[x >= 0.8 - 1e-9], 2.0)


def test_rotation_by_180_turns_the_board_about_its_centre(littledog_board: Board) -> None:
    a = littledog_board("A")
    course = load_terrain(f"{a.spec}@180")
    assert course.name == "terrainA@180"
    assert course.extent == pytest.approx(a.extent)
    x_min, x_max, y_min, y_max = a.extent
    pts = grid_points(course)
    mirrored = np.array([x_min + x_max, y_min + y_max]) - pts
    np.testing.assert_allclose(course.raw_heights.ravel(), a.height(mirrored), atol=1e-12)
    # The barrier (x ≈ 0.19 … 0.42 m) now stands at x ≈ 0.19 … 0.42 m mirrored.
    assert course.height([0.609 - 0.3, 0.3])[0] > 0.03


def test_rotation_by_90_turns_counter_clockwise() -> None:
    # A ramp rising along +x; after +90° (counter-clockwise from above) it rises along +y.
    gx, _ = np.meshgrid(np.arange(7), np.arange(4), indexing="ij")
    ramp = Terrain(0.01 * gx, 1.0, 2.0, 0.1, 0.2, name="ramp")
    turned = rotate_board(ramp, 90)
    assert turned.shape == (4, 7) and (turned.dx, turned.dy) == (0.2, 0.1)
    c = np.array([1.3, 2.3])  # the centre stays put
    assert np.mean(turned.extent[:2]) == pytest.approx(c[0])
    assert np.mean(turned.extent[2:]) == pytest.approx(c[1])
    rng = np.random.default_rng(0)
    p = c + rng.uniform(-0.28, 0.28, size=(20, 2))
    back = c + (p - c) @ np.array([[0.0, -1.0], [1.0, 0.0]])  # R(−90°) applied to p − c
    np.testing.assert_allclose(turned.height(p), ramp.height(back), atol=1e-12)
    assert np.all(np.diff(turned.heights, axis=1) > 0) and np.all(
        turned.heights[1:] == turned.heights[:-1]
    )
    np.testing.assert_array_equal(rotate_board(ramp, -270).heights, turned.heights)
    np.testing.assert_array_equal(rotate_board(turned, 270).heights, ramp.heights)


def test_pads_are_flat_floor_and_widths_that_differ_are_unknown() -> None:
    wide = Terrain(np.full((6, 11), 0.05), 0.0, 0.0, 0.1, 0.1, name="wide")  # y ∈ [0, 1]
    narrow = Terrain(np.full((6, 5), 0.08), 0.0, 0.2, 0.1, 0.1, name="narrow")  # y ∈ [0.2, 0.6]
    course = make_course([wide, narrow], pad_before=0.3, pad_after=0.2)
    assert course.extent == pytest.approx((-0.3, 1.2, 0.0, 1.0))
    x, y = course.x, course.y
    pads = (x < -1e-9) | (x > 1.0 + 1e-9)
    assert np.all(course.raw_heights[pads] == 0.0) and course.known[pads].all()
    board2 = (x > 0.5 + 1e-9) & (x < 1.0 + 1e-9)
    outside = (y < 0.2 - 1e-9) | (y > 0.6 + 1e-9)
    assert not course.known[np.ix_(board2, outside)].any()
    assert np.all(course.raw_heights[np.ix_(board2, ~outside)] == 0.08)
    assert not course.is_known([0.8, 0.9])[0] and course.is_known([0.8, 0.4])[0]


def test_course_options_through_load_terrain(littledog_board: Board, shared_dir: Path) -> None:
    a, c = littledog_board("A"), littledog_board("C")
    course = load_terrain(f"{a.spec}+{c.spec}@90", pad_before=0.1, course_resolution=0.005)
    assert course.name == "terrainA+terrainC@90"
    assert course.dx <= 0.005 and course.dx == pytest.approx(0.005, rel=0.01)
    assert course.extent[0] == pytest.approx(-0.1)


@pytest.mark.parametrize(
    ("kwargs", "fragment"),
    [
        ({"rotations": [45]}, "multiple of 90"),
        ({"rotations": [0, 0]}, "one per board"),
        ({"pad_before": -0.1}, "pad_before"),
        ({"pad_after": float("nan")}, "pad_after"),
        ({"resolution": 0.0}, "resolution"),
        ({"resolution": 1e-7}, "too large"),
    ],
)
def test_bad_course_options(kwargs: dict, fragment: str) -> None:
    board = Terrain(np.zeros((5, 5)), 0.0, 0.0, 0.1, 0.1)
    with pytest.raises(TerrainError, match=fragment):
        make_course([board], **kwargs)


def test_a_course_needs_boards() -> None:
    with pytest.raises(TerrainError, match="at least one board"):
        make_course([])
