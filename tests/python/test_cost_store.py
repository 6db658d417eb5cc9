"""The preference store and bad input: clear errors, and nothing lost or overwritten."""

from __future__ import annotations

import hashlib
import json
import signal
import sqlite3
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

from roughwalk.cli.main import main
from roughwalk.errors import InvalidArgumentError, TerrainError
from roughwalk.planning import (
    CostModelError,
    Foothold,
    Preference,
    PreferenceDataset,
    PreferenceStore,
    PreferenceStoreError,
    TerrainCost,
    TerrainResolver,
)
from roughwalk.terrain import Terrain, load_terrain
from roughwalk.terrain.loaders import save_npz

SPEC = "round_rocks:seed=1,length=0.6,pad_start=0.05,pad_end=0.05"


def digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


@pytest.fixture(scope="module")
def terrain() -> Terrain:
    return load_terrain(SPEC)


def judgements(spec: str, n: int, seed: int = 0) -> list[Preference]:
    rng = np.random.default_rng(seed)
    out = []
    for i in range(n):
        a = Foothold(spec, *rng.uniform([0.1, -0.15], [0.5, 0.15]), rng.uniform(-0.3, 0.3))
        b = Foothold(spec, *rng.uniform([0.1, -0.15], [0.5, 0.15]), 0.0)
        out.append(Preference(a, b, ("front", "hind")[i % 2], ("a", "b", "equal")[i % 3]))
    return out


def make_store(path: Path, terrain: Terrain, n: int = 30, bulk: bool = False) -> list[Preference]:
    prefs = judgements(terrain.spec, n)
    with PreferenceStore.open(path, create=True) as store:
        store.add_terrain(terrain)
        if bulk:
            store.add_many(prefs)
        else:
            for p in prefs:
                store.add(p)
    return prefs


def test_store_round_trip_one_row_per_judgement(tmp_path: Path, terrain: Terrain) -> None:
    path = tmp_path / "prefs.sqlite"
    prefs = make_store(path, terrain, n=12)
    with PreferenceStore.open(path, readonly=True) as store:
        back = store.preferences()
        assert store.count() == 12
        assert [t.spec for t in store.terrains()] == [terrain.spec]
    for p, q in zip(prefs, back, strict=True):
        assert (q.a, q.b, q.leg, q.label, q.source) == (p.a, p.b, p.leg, p.label, "human")
        assert q.created_at > 1.6e9
    # Raw rows, as another tool would see them.
    conn = sqlite3.connect(path)
    rows = conn.execute("SELECT a_x, a_heading, leg, label FROM preferences ORDER BY id").fetchall()
    conn.close()
    assert len(rows) == 12
    assert rows[0] == (prefs[0].a.x, prefs[0].a.heading, prefs[0].leg, prefs[0].label)


def test_reopening_adds_to_the_same_store(tmp_path: Path, terrain: Terrain) -> None:
    path = tmp_path / "prefs.sqlite"
    make_store(path, terrain, n=5)
    with PreferenceStore.open(path, create=True) as store:
        assert store.count() == 5
        store.add_terrain(terrain)  # already known: checked, not duplicated
        row = store.add(judgements(terrain.spec, 1, seed=9)[0])
        assert store.count() == 6
        assert store.delete(row) and not store.delete(row)
        assert len(store.terrains()) == 1


def test_a_killed_writer_loses_nothing_committed(tmp_path: Path) -> None:
    path = tmp_path / "prefs.sqlite"
    script = textwrap.dedent(
        f"""
        import time
        from roughwalk.planning import Foothold, Preference, PreferenceStore
        from roughwalk.terrain import load_terrain
        t = load_terrain({SPEC!r})
        store = PreferenceStore.open({str(path)!r}, create=True)
        store.add_terrain(t)
        for i in range(7):
            store.add(Preference(Foothold(t.spec, 0.2, 0.01 * i), Foothold(t.spec, 0.3, 0.0),
                                 "front", "a"))
            print(i, flush=True)
        time.sleep(60)
        """
    )
    with subprocess.Popen(
        [sys.executable, "-c", script], stdout=subprocess.PIPE, text=True
    ) as proc:
        try:
            assert proc.stdout is not None
            for i in range(7):
                assert proc.stdout.readline().strip() == str(i)
        finally:
            proc.send_signal(signal.SIGKILL)
            proc.wait(timeout=30)
    with PreferenceStore.open(path, readonly=True) as store:
        assert store.count() == 7
        assert [p.a.y for p in store.preferences()] == pytest.approx([0.01 * i for i in range(7)])


def test_empty_file_is_refused_and_left_alone(tmp_path: Path) -> None:
    path = tmp_path / "prefs.sqlite"
    path.touch()
    for kwargs in ({}, {"create": True}, {"readonly": True}):
        with pytest.raises(PreferenceStoreError, match="empty file"):
            PreferenceStore.open(path, **kwargs)
    assert path.stat().st_size == 0


@pytest.mark.parametrize(
    "damage", ["random_bytes", "page_header", "truncated", "text_file"], ids=str
)
def test_corrupt_store_is_refused_and_never_overwritten(
    tmp_path: Path, terrain: Terrain, damage: str
) -> None:
    path = tmp_path / "prefs.sqlite"
    make_store(path, terrain, n=300, bulk=True)
    data = bytearray(path.read_bytes())
    if damage == "random_bytes":
        data = bytearray(np.random.default_rng(0).integers(0, 256, len(data), dtype=np.uint8))
    elif damage == "page_header":
        data[4096 * 2 : 4096 * 2 + 64] = b"\xff" * 64
    elif damage == "truncated":
        data = data[: len(data) // 2]
    else:
        data = bytearray(b"x, y, label\n0.1, 0.2, a\n")
    path.write_bytes(bytes(data))
    before = digest(path)
    with pytest.raises(PreferenceStoreError, match="not an SQLite database|damaged"):
        PreferenceStore.open(path, create=True)
    assert main(["cost", "learn", str(path), "--save", str(tmp_path / "c.json")]) == 1
    assert digest(path) == before
    assert not (tmp_path / "c.json").exists()
    assert not Path(str(path) + "-journal").exists()


def test_newer_schema_and_foreign_databases_are_refused(tmp_path: Path, terrain: Terrain) -> None:
    newer = tmp_path / "newer.sqlite"
    make_store(newer, terrain, n=3)
    conn = sqlite3.connect(newer)
    conn.execute("UPDATE schema_version SET version = 2")
    conn.commit()
    conn.close()
    before = digest(newer)
    with pytest.raises(PreferenceStoreError, match="schema version 2, a newer"):
        PreferenceStore.open(newer)
    assert digest(newer) == before

    foreign = tmp_path / "foreign.sqlite"
    conn = sqlite3.connect(foreign)
    conn.execute("CREATE TABLE photos (id INTEGER PRIMARY KEY, name TEXT)")
    conn.commit()
    conn.close()
    before = digest(foreign)
    with pytest.raises(PreferenceStoreError, match="not a roughwalk preference store.*photos"):
        PreferenceStore.open(foreign, create=True)
    assert digest(foreign) == before


def test_missing_store_and_bad_judgements(tmp_path: Path, terrain: Terrain) -> None:
    with pytest.raises(PreferenceStoreError, match="does not exist"):
        PreferenceStore.open(tmp_path / "nope.sqlite")
    path = tmp_path / "prefs.sqlite"
    make_store(path, terrain, n=2)
    with PreferenceStore.open(path) as store:
        good = judgements(terrain.spec, 1)[0]
        with pytest.raises(InvalidArgumentError, match="unknown label 'left'"):
            store.add(Preference(good.a, good.b, "front", "left"))
        with pytest.raises(InvalidArgumentError, match="unknown leg 'middle'"):
            store.add(Preference(good.a, good.b, "middle", "a"))
        with pytest.raises(PreferenceStoreError, match="not registered"):
            store.add(Preference(Foothold("flat", 0.5, 0.0), good.b, "front", "a"))
        assert store.count() == 2
    with PreferenceStore.open(path, readonly=True) as store:
        with pytest.raises(PreferenceStoreError, match="read-only"):
            store.add(good)


def test_terrain_that_cannot_be_found_names_the_places_looked(
    tmp_path: Path, terrain: Terrain, monkeypatch: pytest.MonkeyPatch, capsys
) -> None:
    work = tmp_path / "work"
    work.mkdir()
    monkeypatch.chdir(work)
    save_npz(terrain, work / "board.npz")
    board = load_terrain("board.npz")
    store_path = tmp_path / "stores" / "prefs.sqlite"
    make_store(store_path, board, n=20)
    before = digest(store_path)
    # Learning from another folder: the relative file is not found.
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    monkeypatch.chdir(elsewhere)
    with PreferenceStore.open(store_path, readonly=True) as store:
        with pytest.raises(TerrainError, match=r"cannot load terrain 'board.npz'.*looked for"):
            PreferenceDataset.from_store(store, (0.01, 0.02))
        # Told where to look, it finds it.
        data = PreferenceDataset.from_store(store, (0.01, 0.02), resolver=TerrainResolver([work]))
        assert len(data) + len(data.skipped) == 20
    assert main(["cost", "learn", str(store_path), "--save", str(tmp_path / "c.json")]) == 1
    assert "board.npz" in capsys.readouterr().err
    assert (
        main(
            [
                "cost",
                "learn",
                str(store_path),
                "--save",
                str(tmp_path / "c.json"),
                "--terrain-dir",
                str(work),
                "--set",
                "radii=0.01,0.02",
            ]
        )
        == 0
    )
    assert digest(store_path) == before

    # The file changed after labelling: refused, not silently relearned.
    heights = board.heights.copy()
    heights[40:60, 40:60] += 0.03
    save_npz(Terrain(heights, board.x0, board.y0, board.dx, board.dy), work / "board.npz")
    with PreferenceStore.open(store_path, readonly=True) as store:
        with pytest.raises(TerrainError, match="differs from the one that was labelled"):
            PreferenceDataset.from_store(store, (0.01, 0.02), resolver=TerrainResolver([work]))
    assert digest(store_path) == before


def test_cost_files_of_another_version_or_kind_are_refused(tmp_path: Path, capsys) -> None:
    good = TerrainCost.load()
    data = good.to_dict()
    wrong_version = tmp_path / "v2.json"
    wrong_version.write_text(json.dumps({**data, "version": 2}))
    with pytest.raises(CostModelError, match="version 2; this roughwalk reads version 1"):
        TerrainCost.load(wrong_version)
    assert main(["cost", "show", "--cost", str(wrong_version), "--terrain", "flat"]) == 1
    assert "version 2" in capsys.readouterr().err

    other = tmp_path / "other.json"
    other.write_text(json.dumps({"schema": "terrain_info", "version": 1}))
    with pytest.raises(CostModelError, match="not a roughwalk terrain cost"):
        TerrainCost.load(other)
    broken = tmp_path / "broken.json"
    broken.write_text('{"schema": "roughwalk_terrain_cost", ')
    with pytest.raises(CostModelError, match="not valid JSON"):
        TerrainCost.load(broken)
    short = tmp_path / "short.json"
    short.write_text(json.dumps({**data, "weights": {"front": [1.0], "hind": [1.0]}}))
    with pytest.raises(CostModelError, match="must be 54 finite numbers"):
        TerrainCost.load(short)
    with pytest.raises(CostModelError, match="does not exist"):
        TerrainCost.load(tmp_path / "none.json")


def test_learn_command_writes_cost_and_report(tmp_path: Path, terrain: Terrain, capsys) -> None:
    path = tmp_path / "prefs.sqlite"
    make_store(path, terrain, n=40)
    before = digest(path)
    cost_path = tmp_path / "cost.json"
    report = tmp_path / "report.json"
    args = ["cost", "learn", str(path), "--save", str(cost_path), "--json", str(report)]
    assert main([*args, "--separate-legs", "--folds", "4", "--set", "radii=0.01,0.03"]) == 0
    out = capsys.readouterr().out
    assert "held out (4-fold cross-validation)" in out
    cost = TerrainCost.load(cost_path)
    assert cost.radii == (0.01, 0.03) and cost.metadata["n_preferences"] > 0
    rep = json.loads(report.read_text())
    assert rep["schema"] == "cost_learn" and rep["report"]["by_leg"]["hind"] > 0
    assert rep["config"]["separate_legs"] is True
    assert digest(path) == before

    empty = tmp_path / "empty.sqlite"
    PreferenceStore.open(empty, create=True).close()
    assert main(["cost", "learn", str(empty), "--save", str(cost_path)]) == 1
    assert "no usable strict judgement" in capsys.readouterr().err
