"""``roughwalk cache``: warm stores one NLP structure, list shows it, clear removes it."""

from __future__ import annotations

import json
import time
from pathlib import Path

import pytest

from roughwalk.cli.main import main
from roughwalk.trajopt import clear_cache, nlp_cache

_WARM = ["cache", "warm", "--preset", "towr", "--gait", "trot", "--steps", "4", "--duration", "1"]


def test_warm_list_and_clear(
    nlp_cache_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["cache", "list"]) == 0
    assert "0 entries" in capsys.readouterr().out

    assert main(_WARM) == 0
    assert capsys.readouterr().out.startswith("serialized:")
    clear_cache()  # a new process would not have it in memory
    assert main(_WARM) == 0
    assert capsys.readouterr().out.startswith("deserialized:")

    listing = tmp_path / "list.json"
    assert main(["cache", "list", "--json", str(listing)]) == 0
    assert "1 entries" in capsys.readouterr().out
    (entry,) = json.loads(listing.read_text())["entries"]
    assert entry["kind"] == "serialized"
    assert entry["n_variables"] > 0
    files = (nlp_cache_dir / entry["key"]).iterdir()
    assert entry["size_bytes"] == sum(p.stat().st_size for p in files)

    # A crashed writer's leftover (no metadata) is listed as such.
    (nlp_cache_dir / "0123abcd").mkdir()
    assert {e.kind for e in nlp_cache.entries()} == {"serialized", "unreadable"}

    assert main(["cache", "clear", "--kind", "compiled"]) == 0
    assert "removed 0 entries" in capsys.readouterr().out
    assert main(["cache", "clear"]) == 0
    assert "removed 2 entries" in capsys.readouterr().out
    assert list(nlp_cache_dir.iterdir()) == []


def test_warm_reports_a_bad_structure(
    nlp_cache_dir: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # Four swings cannot fit in 0.1 s: nothing is built or stored.
    args = ["cache", "warm", "--preset", "towr", "--gait", "trot", "--steps", "4"]
    assert main([*args, "--duration", "0.1"]) == 1
    assert capsys.readouterr().out.startswith("not stored:")
    assert nlp_cache.entries() == []


def test_warm_entry_serves_a_solve_with_the_default_iterations(nlp_cache_dir: Path) -> None:
    # warm takes no iteration; the solves it prepares for take the config's.
    from roughwalk.terrain import load_terrain
    from roughwalk.trajopt import Task, optimize_motion, towr_config

    assert main(_WARM) == 0
    clear_cache()  # a new process would not have it in memory
    result = optimize_motion(
        None,
        load_terrain("flat"),
        Task((0.0, 0.0, 0.0), (0.5, 0.0, 0.0)),
        config=towr_config(),
        gait="trot",
        steps=4,
        duration=1.0,
        compiled="auto",
        max_iter=1,
    )
    assert result.build == "deserialized"
    assert len(nlp_cache.entries()) == 1


def test_a_killed_writer_s_leftover_is_listed_and_cleared_once_stale(
    nlp_cache_dir: Path,
) -> None:
    nlp_cache_dir.mkdir(parents=True)
    leftover = nlp_cache_dir / "0123abcd.tmp-xyz"
    leftover.mkdir()
    (leftover / "nlp.casadi").write_bytes(b"\0" * 1000)
    # Young: a writer may be at work in it, so it is neither listed nor removed.
    assert nlp_cache.entries() == []
    assert nlp_cache.clear() == []
    assert leftover.is_dir()
    # Older than STALE_WRITE_S: its writer was killed.
    later = time.time() + nlp_cache.STALE_WRITE_S + 1
    (entry,) = nlp_cache.entries(now=later)
    assert (entry.key, entry.kind, entry.size_bytes) == ("0123abcd", "unfinished", 1000)
    assert [e.kind for e in nlp_cache.clear(kind="unfinished", now=later)] == ["unfinished"]
    assert list(nlp_cache_dir.iterdir()) == []


def test_warm_refuses_a_robot_the_named_body_ignores(
    nlp_cache_dir: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # The towr preset's body is TOWR's published ANYmal: a --robot would be ignored.
    assert main([*_WARM, "--robot", "littledog"]) != 0
    err = capsys.readouterr().err
    assert "--robot littledog has no effect" in err and "towr_anymal" in err
    assert nlp_cache.entries() == []
