"""What the on-disk NLP cache holds, and emptying it (``roughwalk cache``).

The cache (:func:`.compiled_nlp.cache_dir`) holds one directory per stored
NLP structure — compiled to C (:mod:`.compiled_nlp`) or in CasADi's
serialised form (:mod:`.serialized_nlp`) — plus a ``KEY.failed`` marker per
structure gcc could not compile. Entries are written by solves whose config
sets ``compiled`` to "auto" or "on"; this module only reads and removes them.
"""

from __future__ import annotations

import json
import shutil
import time
from dataclasses import dataclass
from pathlib import Path

from roughwalk.trajopt.compiled_nlp import _discard, cache_dir

__all__ = ["CacheEntry", "entries", "clear", "STALE_WRITE_S"]

STALE_WRITE_S = 3600.0
"""Age [s] after which a writer's temporary directory counts as a crashed
writer's leftover ("unfinished"): writing takes at most the compiler's CPU
limit (240 s), a serialised entry about a second."""


@dataclass(frozen=True)
class CacheEntry:
    """One stored NLP structure.

    Attributes
    ----------
    key:
        The structure's digest (the directory's name).
    kind:
        "compiled", "serialized", "failed" (gcc failed on it; nothing
        stored), "unreadable" (no or bad metadata, removed by the next
        load) or "unfinished" (a writer's temporary directory older than
        :data:`STALE_WRITE_S`: the writer was killed; nothing reads it).
    size_bytes:
        Bytes on disk [B].
    n_variables:
        Decision variables of the NLP (0 when unknown).
    path:
        The directory (or the marker file).

    """

    key: str
    kind: str
    size_bytes: int
    n_variables: int
    path: Path


def _size(path: Path) -> int:
    if path.is_file():
        return path.stat().st_size
    return sum(p.stat().st_size for p in path.rglob("*") if p.is_file())


def entries(root: Path | None = None, *, now: float | None = None) -> list[CacheEntry]:
    """The cache's entries, by key.

    Temporary directories of writers at work (younger than
    :data:`STALE_WRITE_S` at ``now``, default the current time) are left out.
    """
    base = root or cache_dir()
    if not base.is_dir():
        return []
    now = time.time() if now is None else now
    out = []
    for path in sorted(base.iterdir()):
        if ".bad-" in path.name:  # being removed (see clear)
            continue
        if ".tmp-" in path.name:
            try:
                stale = now - path.stat().st_mtime > STALE_WRITE_S
            except OSError:  # finished or removed meanwhile
                continue
            if stale:
                key = path.name.split(".tmp-")[0]
                out.append(CacheEntry(key, "unfinished", _size(path), 0, path))
            continue
        if path.is_file() and path.suffix == ".failed":
            out.append(CacheEntry(path.stem, "failed", _size(path), 0, path))
            continue
        if not path.is_dir():
            continue
        try:
            meta = json.loads((path / "meta.json").read_text())
            kind = str(meta.get("kind", "compiled"))
            n_variables = int(meta["n_variables"])
        except (OSError, ValueError, KeyError, TypeError):
            kind, n_variables = "unreadable", 0
        out.append(CacheEntry(path.name, kind, _size(path), n_variables, path))
    return out


def clear(
    root: Path | None = None, kind: str | None = None, *, now: float | None = None
) -> list[CacheEntry]:
    """Remove the entries (only those of ``kind`` when given); return what was removed.

    A directory is renamed before it is deleted, so that a process reading
    the cache meanwhile sees either the whole entry or none. A live
    writer's temporary directory is kept (see :func:`entries`).
    """
    removed = []
    for entry in entries(root, now=now):
        if kind is not None and entry.kind != kind:
            continue
        if entry.path.is_dir():
            _discard(entry.path)
        else:
            entry.path.unlink(missing_ok=True)
        removed.append(entry)
    base = root or cache_dir()
    if kind is None and base.is_dir():
        # Leftovers of writers that crashed (a live writer's directory is young and small).
        for leftover in base.glob("*.bad-*"):
            shutil.rmtree(leftover, ignore_errors=True)
    return removed
