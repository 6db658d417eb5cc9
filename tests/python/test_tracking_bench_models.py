"""The tracking bench's ``--models DIR``: a candidate model is run and solved with its own set."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from _benchmarks import load_benchmark

pytest.importorskip("roughwalk.learning")

from roughwalk.learning.initializer import MODELS_DIR  # noqa: E402
from roughwalk.trajopt.parameters import MELON_REACH_CONSTRAINTS  # noqa: E402

DOUBLE = MODELS_DIR / "anymal_c_double_pallet_walk16.npz"


@pytest.fixture
def candidate(tmp_path: Path) -> Path:
    """A folder holding one double-pallet model under another name."""
    shutil.copy(DOUBLE, tmp_path / "candidate.npz")
    return tmp_path


def test_without_a_folder_the_shipped_model_is_used() -> None:
    bench = load_benchmark("bench_tracking")
    assert bench.learned_init("double_pallet", False, None) == "learned"


def test_the_folder_s_model_that_fits_the_problem_is_used(candidate: Path) -> None:
    bench = load_benchmark("bench_tracking")
    init = bench.learned_init("double_pallet", False, candidate)
    assert init == f"learned:{candidate / 'candidate.npz'}"
    assert bench.learned_model_for("double_pallet", False, init) == ""
    chosen = bench.constraints_for("double_pallet", False, init)
    assert chosen == (*MELON_REACH_CONSTRAINTS, "unilateral_between_nodes")


def test_a_folder_without_a_fitting_model_is_reported_not_replaced(candidate: Path) -> None:
    bench = load_benchmark("bench_tracking")
    init = bench.learned_init("single_pallet", False, candidate)
    assert init == f"learned:{candidate}"
    assert bench.learned_model_for("single_pallet", False, init) != ""
