"""The tracking bench's ``--trajopt`` and ``--tracking`` settings: fields checked by name."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path
from types import ModuleType

import pytest

BENCH = Path(__file__).resolve().parents[2] / "benchmarks" / "bench_tracking.py"


def _bench() -> ModuleType:
    spec = importlib.util.spec_from_file_location("bench_tracking", BENCH)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # its dataclasses look their module up there
    spec.loader.exec_module(module)
    return module


def test_trajopt_settings_are_parsed_as_config_fields() -> None:
    bench = _bench()
    settings = bench._trajopt_settings("dt_dynamics=0.05, optimize_durations=true")
    assert settings == (("dt_dynamics", 0.05), ("optimize_durations", True))


def test_an_unknown_field_names_the_option_and_the_field() -> None:
    bench = _bench()
    with pytest.raises(SystemExit, match="--trajopt: TrajoptConfig has no field 'dt_dynamic'"):
        bench._trajopt_settings("dt_dynamic=0.05")
    with pytest.raises(SystemExit, match="--tracking: TrackingConfig has no field"):
        bench._tracking_settings("no_such_gain=1")
