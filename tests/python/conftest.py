"""Fixtures shared by the Python tests: the ../shared data beside the checkout."""

from __future__ import annotations

import os
from collections.abc import Callable, Iterator
from functools import cache
from pathlib import Path

import pytest

import roughwalk
from roughwalk.terrain import Terrain

# ../shared beside the checkout, or $ROUGHWALK_SHARED (a worktree elsewhere).
SHARED_DIR = Path(
    os.environ.get("ROUGHWALK_SHARED") or Path(__file__).resolve().parents[2].parent / "shared"
)
LITTLEDOG_BOARDS = ("terrainA", "terrainAC", "terrainAD", "terrainAE", "terrainC", "terrainY")


@pytest.fixture(scope="session")
def shared_dir() -> Path:
    """The shared data directory (read only; never copy from it into the project)."""
    if not SHARED_DIR.is_dir():
        pytest.skip(f"shared data not found at {SHARED_DIR}")
    return SHARED_DIR


@cache
def _load_board(path: Path) -> Terrain:
    from roughwalk.terrain.loaders import load_file

    return load_file(path)


@pytest.fixture(scope="session")
def littledog_board(shared_dir: Path) -> Callable[[str], Terrain]:
    """Load a LittleDog board by name ("terrainA", "A", ...), cached for the session."""

    def load(name: str) -> Terrain:
        stem = name if name.startswith("terrain") else f"terrain{name}"
        return _load_board(shared_dir / "terrains" / "littledog" / f"{stem}.mat")

    return load


@pytest.fixture(scope="module")
def littledog() -> roughwalk.Robot:
    """Our LittleDog model, loaded once per test module."""
    return roughwalk.load_robot("littledog")


@pytest.fixture
def nlp_cache_dir(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[Path]:
    """An empty NLP cache of the test's own ($ROUGHWALK_CACHE), in-process cache cleared."""
    from roughwalk.trajopt import clear_cache

    monkeypatch.setenv("ROUGHWALK_CACHE", str(tmp_path))
    clear_cache()
    yield tmp_path / "nlp"
    clear_cache()
