"""The expert's foothold preferences, one SQLite row per judgement.

Zucker 2011, §4.2: the expert is shown pairs of terrain samples and says
which he prefers; learning can be re-run later with more preferences added,
so the store is opened again and again. Every judgement is committed on its
own with ``synchronous=FULL`` (rollback journal): a crash loses at most the
judgement in flight, and the file at rest is a single self-contained file.

Schema (version :data:`STORE_VERSION`, in table ``schema_version``):

* ``terrains``: one row per terrain spec, with a fingerprint of its heights
  (shape, grid, mean and RMS) so that a file that changed after labelling is
  noticed instead of silently giving other features;
* ``preferences``: the two footholds (terrain, x, y [m], heading [rad]), the
  leg ("front"/"hind"), the label ("a": the first is preferred, "b": the
  second, "equal"), the time [s since the epoch], a session id and the source
  ("human" for the labeling app, "scripted" for a scripted expert).

A file that is empty, not SQLite, damaged, of a newer schema version, or not a
roughwalk store is refused with :class:`PreferenceStoreError` and never written to.
"""

from __future__ import annotations

import sqlite3
import threading
import time
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Literal

import numpy as np

from roughwalk.errors import InvalidArgumentError, PlanningError
from roughwalk.planning.terrain_cost import LEGS, check_leg
from roughwalk.terrain.terrain import Terrain

__all__ = [
    "STORE_VERSION",
    "LABELS",
    "Label",
    "PreferenceStoreError",
    "Foothold",
    "Preference",
    "TerrainRecord",
    "PreferenceStore",
    "terrain_fingerprint",
]

STORE_VERSION = 1
_APPLICATION = "roughwalk-preferences"
LABELS = ("a", "b", "equal")
Label = Literal["a", "b", "equal"]
_SQLITE_MAGIC = b"SQLite format 3\x00"

_SCHEMA = """
CREATE TABLE schema_version (
    application TEXT NOT NULL,
    version INTEGER NOT NULL,
    created_at REAL NOT NULL
);
CREATE TABLE terrains (
    id INTEGER PRIMARY KEY,
    spec TEXT NOT NULL UNIQUE,
    name TEXT NOT NULL,
    nx INTEGER NOT NULL,
    ny INTEGER NOT NULL,
    x0 REAL NOT NULL,
    y0 REAL NOT NULL,
    dx REAL NOT NULL,
    dy REAL NOT NULL,
    height_mean REAL NOT NULL,
    height_rms REAL NOT NULL,
    added_at REAL NOT NULL
);
CREATE TABLE preferences (
    id INTEGER PRIMARY KEY AUTOINCREMENT,
    a_terrain INTEGER NOT NULL REFERENCES terrains(id),
    a_x REAL NOT NULL,
    a_y REAL NOT NULL,
    a_heading REAL NOT NULL,
    b_terrain INTEGER NOT NULL REFERENCES terrains(id),
    b_x REAL NOT NULL,
    b_y REAL NOT NULL,
    b_heading REAL NOT NULL,
    leg TEXT NOT NULL CHECK (leg IN ('front', 'hind')),
    label TEXT NOT NULL CHECK (label IN ('a', 'b', 'equal')),
    created_at REAL NOT NULL,
    session TEXT NOT NULL DEFAULT '',
    source TEXT NOT NULL DEFAULT 'human'
);
"""


class PreferenceStoreError(PlanningError):
    """A preference store cannot be opened, read or written safely."""


@dataclass(frozen=True)
class Foothold:
    """A candidate foothold: its terrain spec, position (x, y) [m] and the robot's heading [rad]."""

    terrain: str
    x: float
    y: float
    heading: float = 0.0

    @property
    def xy(self) -> tuple[float, float]:
        """(x, y) [m]."""
        return (self.x, self.y)


@dataclass(frozen=True)
class Preference:
    """One judgement: ``label`` says which of ``a`` and ``b`` the expert prefers for ``leg``."""

    a: Foothold
    b: Foothold
    leg: str
    label: str
    created_at: float = 0.0
    session: str = ""
    source: str = "human"
    id: int | None = None

    @property
    def sign(self) -> int:
        """+1 if ``a`` is preferred, −1 if ``b`` is, 0 if they are equal."""
        return {"a": 1, "b": -1, "equal": 0}[self.label]


@dataclass(frozen=True)
class TerrainRecord:
    """A terrain as the store remembers it: spec and fingerprint."""

    id: int
    spec: str
    name: str
    shape: tuple[int, int]
    grid: tuple[float, float, float, float]
    height_mean: float
    height_rms: float

    def matches(self, terrain: Terrain) -> str | None:
        """None if ``terrain`` has this fingerprint, else a sentence saying what differs."""
        shape, mean, rms = terrain_fingerprint(terrain)
        if shape != self.shape:
            return f"grid shape {shape} instead of {self.shape}"
        grid = (terrain.x0, terrain.y0, terrain.dx, terrain.dy)
        if not np.allclose(grid, self.grid, rtol=0, atol=1e-9):
            return f"grid (x0, y0, dx, dy) {grid} m instead of {self.grid} m"
        # Loose enough for a generator's last-digit differences between platforms,
        # far tighter than any real edit of a board.
        if abs(mean - self.height_mean) > 1e-6 or abs(rms - self.height_rms) > 1e-6:
            return (
                f"heights with mean {mean:.6g} m and RMS {rms:.6g} m "
                f"instead of {self.height_mean:.6g} m and {self.height_rms:.6g} m"
            )
        return None


def terrain_fingerprint(terrain: Terrain) -> tuple[tuple[int, int], float, float]:
    """Grid shape, mean and RMS of the heights [m]: enough to notice a changed terrain."""
    h = terrain.heights
    return terrain.shape, float(np.mean(h)), float(np.sqrt(np.mean(h**2)))


def _check_is_sqlite(path: Path) -> None:
    """Refuse files that are not SQLite databases before SQLite touches them."""
    size = path.stat().st_size
    if size == 0:
        raise PreferenceStoreError(
            f"preference store '{path}' is an empty file (0 bytes), not a roughwalk preference "
            "store; remove it or give another path (a new store is created where no file exists)"
        )
    with path.open("rb") as f:
        head = f.read(len(_SQLITE_MAGIC))
    if head != _SQLITE_MAGIC:
        raise PreferenceStoreError(
            f"preference store '{path}' is not an SQLite database (it starts with {head[:8]!r}); "
            "it was left untouched"
        )


class PreferenceStore:
    """A SQLite file of foothold preferences (see the module docstring for the schema).

    Open with :meth:`open` (existing store, or ``create=True`` to make a new one
    where no file exists). Thread-safe: one connection guarded by a lock, as the
    labeling server's handler threads share it. Use as a context manager or call
    :meth:`close`.
    """

    def __init__(self, path: Path, connection: sqlite3.Connection, readonly: bool) -> None:
        self.path = path
        self._conn = connection
        self._lock = threading.RLock()
        self.readonly = readonly

    # ------------------------------------------------------------- opening
    @classmethod
    def open(
        cls, path: str | Path, *, create: bool = False, readonly: bool = False
    ) -> PreferenceStore:
        """Open the store at ``path``.

        Parameters
        ----------
        path:
            The SQLite file.
        create:
            Make a new store if no file exists at ``path`` (an existing file is
            never replaced or re-initialised).
        readonly:
            Open without write access (for learning).

        Raises
        ------
        PreferenceStoreError
            The file is missing (and ``create`` is False), empty, not SQLite,
            damaged, of another schema version, or not a roughwalk store.

        """
        p = Path(path)
        if p.is_dir():
            raise PreferenceStoreError(f"preference store '{p}' is a directory, not a file")
        if not p.exists():
            if not create or readonly:
                raise PreferenceStoreError(f"preference store '{p}' does not exist")
            return cls._create(p)
        _check_is_sqlite(p)
        mode = "ro" if readonly else "rw"
        try:
            conn = sqlite3.connect(
                f"{p.resolve().as_uri()}?mode={mode}",
                uri=True,
                check_same_thread=False,
                isolation_level=None,
            )
        except sqlite3.Error as e:
            raise PreferenceStoreError(f"cannot open preference store '{p}': {e}") from None
        try:
            cls._validate(p, conn)
            if not readonly:
                conn.execute("PRAGMA journal_mode=DELETE")
            conn.execute("PRAGMA synchronous=FULL")
            conn.execute("PRAGMA foreign_keys=ON")
        except sqlite3.DatabaseError as e:
            conn.close()
            raise PreferenceStoreError(
                f"preference store '{p}' is damaged or not a database ({e}); it was left "
                "untouched. Keep a copy; `sqlite3 FILE .recover` may save its rows"
            ) from None
        except PreferenceStoreError:
            conn.close()
            raise
        return cls(p, conn, readonly)

    @classmethod
    def _create(cls, p: Path) -> PreferenceStore:
        p.parent.mkdir(parents=True, exist_ok=True)
        # mode=rwc on a path that did not exist a moment ago; a file that appears
        # in between is caught by the schema check below rather than initialised.
        conn = sqlite3.connect(
            f"{p.resolve().as_uri()}?mode=rwc",
            uri=True,
            check_same_thread=False,
            isolation_level=None,
        )
        try:
            conn.execute("PRAGMA journal_mode=DELETE")
            conn.execute("PRAGMA synchronous=FULL")
            conn.execute("PRAGMA foreign_keys=ON")
            conn.execute("BEGIN IMMEDIATE")
            tables = conn.execute("SELECT name FROM sqlite_master").fetchall()
            if tables:
                conn.execute("ROLLBACK")
                raise PreferenceStoreError(
                    f"preference store '{p}' appeared while being created; not touching it"
                )
            for statement in _SCHEMA.split(";"):
                if statement.strip():
                    conn.execute(statement)
            conn.execute(
                "INSERT INTO schema_version VALUES (?, ?, ?)",
                (_APPLICATION, STORE_VERSION, time.time()),
            )
            conn.execute("COMMIT")
        except BaseException:
            conn.close()
            raise
        return cls(p, conn, readonly=False)

    @staticmethod
    def _validate(p: Path, conn: sqlite3.Connection) -> None:
        check = conn.execute("PRAGMA quick_check").fetchone()
        if not check or check[0] != "ok":
            raise sqlite3.DatabaseError(f"integrity check failed: {check[0] if check else '?'}")
        tables = {r[0] for r in conn.execute("SELECT name FROM sqlite_master WHERE type='table'")}
        if "schema_version" not in tables:
            what = ", ".join(sorted(tables)) or "no tables"
            raise PreferenceStoreError(
                f"'{p}' is an SQLite database but not a roughwalk preference store "
                f"(it has {what}); it was left untouched"
            )
        row = conn.execute("SELECT application, version FROM schema_version").fetchone()
        if row is None or row[0] != _APPLICATION:
            raise PreferenceStoreError(
                f"'{p}' is not a roughwalk preference store (application {row and row[0]!r})"
            )
        if row[1] != STORE_VERSION:
            newer = "a newer" if int(row[1]) > STORE_VERSION else "an unknown"
            raise PreferenceStoreError(
                f"preference store '{p}' has schema version {row[1]}, {newer} version; this "
                f"roughwalk reads version {STORE_VERSION} only (upgrade roughwalk); "
                "it was left untouched"
            )
        missing = {"terrains", "preferences"} - tables
        if missing:
            raise PreferenceStoreError(
                f"preference store '{p}' lacks the table(s) {sorted(missing)}; "
                "it was left untouched"
            )

    def close(self) -> None:
        """Close the connection (every judgement is already committed)."""
        with self._lock:
            self._conn.close()

    def __enter__(self) -> PreferenceStore:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    @contextmanager
    def _write(self) -> Iterator[sqlite3.Connection]:
        if self.readonly:
            raise PreferenceStoreError(f"preference store '{self.path}' was opened read-only")
        with self._lock:
            try:
                self._conn.execute("BEGIN IMMEDIATE")
                yield self._conn
                self._conn.execute("COMMIT")
            except BaseException:
                if self._conn.in_transaction:
                    self._conn.execute("ROLLBACK")
                raise

    # ------------------------------------------------------------ terrains
    def add_terrain(self, terrain: Terrain) -> TerrainRecord:
        """Register ``terrain`` by its spec (or check it against the stored fingerprint).

        Raises :class:`PreferenceStoreError` if a terrain with the same spec was
        stored with other heights (the file changed since it was labelled).
        """
        known = self.terrain(terrain.spec)
        if known is not None:
            diff = known.matches(terrain)
            if diff is not None:
                raise PreferenceStoreError(
                    f"terrain '{terrain.spec}' in store '{self.path}' was labelled with other "
                    f"heights: it now has {diff}. Give the changed terrain another name"
                )
            return known
        _, mean, rms = terrain_fingerprint(terrain)
        with self._write() as conn:
            conn.execute(
                "INSERT INTO terrains (spec, name, nx, ny, x0, y0, dx, dy, height_mean, "
                "height_rms, added_at) VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)",
                (
                    terrain.spec,
                    terrain.name,
                    terrain.shape[0],
                    terrain.shape[1],
                    terrain.x0,
                    terrain.y0,
                    terrain.dx,
                    terrain.dy,
                    mean,
                    rms,
                    time.time(),
                ),
            )
        record = self.terrain(terrain.spec)
        assert record is not None
        return record

    def terrain(self, spec: str) -> TerrainRecord | None:
        """The stored record of terrain ``spec``, or None."""
        with self._lock:
            row = self._conn.execute(
                "SELECT id, spec, name, nx, ny, x0, y0, dx, dy, height_mean, height_rms "
                "FROM terrains WHERE spec = ?",
                (spec,),
            ).fetchone()
        return None if row is None else _record(row)

    def terrains(self) -> list[TerrainRecord]:
        """Every terrain the store knows, in the order they were added."""
        with self._lock:
            rows = self._conn.execute(
                "SELECT id, spec, name, nx, ny, x0, y0, dx, dy, height_mean, height_rms "
                "FROM terrains ORDER BY id"
            ).fetchall()
        return [_record(r) for r in rows]

    # --------------------------------------------------------- preferences
    def add(self, preference: Preference) -> int:
        """Commit one judgement durably and return its row id.

        Both footholds' terrains must have been registered with :meth:`add_terrain`.
        """
        p = preference
        check_leg(p.leg)
        if p.label not in LABELS:
            raise InvalidArgumentError(f"unknown label {p.label!r}; known: {', '.join(LABELS)}")
        values = [p.a.x, p.a.y, p.a.heading, p.b.x, p.b.y, p.b.heading]
        if not all(np.isfinite(values)):
            raise InvalidArgumentError(f"foothold coordinates must be finite, got {values}")
        ids = []
        for f in (p.a, p.b):
            record = self.terrain(f.terrain)
            if record is None:
                raise PreferenceStoreError(
                    f"terrain '{f.terrain}' is not registered in '{self.path}'; add_terrain() first"
                )
            ids.append(record.id)
        with self._write() as conn:
            cursor = conn.execute(
                "INSERT INTO preferences (a_terrain, a_x, a_y, a_heading, b_terrain, b_x, b_y, "
                "b_heading, leg, label, created_at, session, source) "
                "VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)",
                (
                    ids[0],
                    p.a.x,
                    p.a.y,
                    p.a.heading,
                    ids[1],
                    p.b.x,
                    p.b.y,
                    p.b.heading,
                    p.leg,
                    p.label,
                    p.created_at or time.time(),
                    p.session,
                    p.source,
                ),
            )
            row_id = cursor.lastrowid
        assert row_id is not None
        return int(row_id)

    def add_many(self, preferences: Sequence[Preference]) -> None:
        """Add several judgements in one transaction (for scripted experts)."""
        for p in preferences:
            check_leg(p.leg)
            if p.label not in LABELS:
                raise InvalidArgumentError(f"unknown label {p.label!r}; known: {LABELS}")
        with self._write() as conn:
            ids = {r.spec: r.id for r in self.terrains()}
            rows = []
            for p in preferences:
                for f in (p.a, p.b):
                    if f.terrain not in ids:
                        raise PreferenceStoreError(
                            f"terrain '{f.terrain}' is not registered in '{self.path}'"
                        )
                rows.append(
                    (
                        ids[p.a.terrain],
                        p.a.x,
                        p.a.y,
                        p.a.heading,
                        ids[p.b.terrain],
                        p.b.x,
                        p.b.y,
                        p.b.heading,
                        p.leg,
                        p.label,
                        p.created_at,
                        p.session,
                        p.source,
                    )
                )
            conn.executemany(
                "INSERT INTO preferences (a_terrain, a_x, a_y, a_heading, b_terrain, b_x, b_y, "
                "b_heading, leg, label, created_at, session, source) "
                "VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)",
                rows,
            )

    def delete(self, row_id: int) -> bool:
        """Delete the judgement ``row_id`` (an undo); True if it existed."""
        with self._write() as conn:
            cursor = conn.execute("DELETE FROM preferences WHERE id = ?", (int(row_id),))
            return cursor.rowcount > 0

    def count(self) -> int:
        """Number of judgements stored."""
        with self._lock:
            return int(self._conn.execute("SELECT COUNT(*) FROM preferences").fetchone()[0])

    def preferences(self) -> list[Preference]:
        """Every judgement, oldest first."""
        with self._lock:
            rows = self._conn.execute(
                "SELECT p.id, ta.spec, p.a_x, p.a_y, p.a_heading, tb.spec, p.b_x, p.b_y, "
                "p.b_heading, p.leg, p.label, p.created_at, p.session, p.source "
                "FROM preferences p JOIN terrains ta ON ta.id = p.a_terrain "
                "JOIN terrains tb ON tb.id = p.b_terrain ORDER BY p.id"
            ).fetchall()
        return [
            Preference(
                a=Foothold(r[1], r[2], r[3], r[4]),
                b=Foothold(r[5], r[6], r[7], r[8]),
                leg=r[9],
                label=r[10],
                created_at=r[11],
                session=r[12],
                source=r[13],
                id=r[0],
            )
            for r in rows
        ]

    def legs_used(self) -> tuple[str, ...]:
        """The legs that have at least one judgement, in :data:`LEGS` order."""
        with self._lock:
            used = {r[0] for r in self._conn.execute("SELECT DISTINCT leg FROM preferences")}
        return tuple(leg for leg in LEGS if leg in used)

    def __repr__(self) -> str:
        return f"PreferenceStore('{self.path}', {self.count()} judgements)"


def _record(row: Sequence[object]) -> TerrainRecord:
    return TerrainRecord(
        id=int(row[0]),  # type: ignore[call-overload]
        spec=str(row[1]),
        name=str(row[2]),
        shape=(int(row[3]), int(row[4])),  # type: ignore[call-overload]
        grid=tuple(float(v) for v in row[5:9]),  # type: ignore[arg-type]
        height_mean=float(row[9]),  # type: ignore[arg-type]
        height_rms=float(row[10]),  # type: ignore[arg-type]
    )
