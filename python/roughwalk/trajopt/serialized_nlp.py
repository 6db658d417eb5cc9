"""An on-disk cache of the NLP's functions in CasADi's own serialised form (no compiler).

The second kind of entry of the NLP cache (:mod:`.compiled_nlp` is the
first): the functions IPOPT and the results call, written with
:class:`casadi.FileSerializer` and read back with
:class:`casadi.FileDeserializer`. Reading is CasADi's virtual-machine code
read from a file, not expressions built in Python and differentiated, and
needs no gcc; but CasADi reads about a microsecond per instruction, close to
what building costs, so it saves a fifth to two fifths of the build, not all
of it. Build CPU [s] of TOWR's 16-step tasks (cold minus warm solve, session
10): flat trot 0.28–0.33 built, 0.18 read; flat walk 0.31–0.32, 0.21; the
walk with optimised durations 0.93–0.96, 0.68; block 1.5 m 0.37, 0.30;
Melon's single pallet (exact Hessian, which gcc cannot compile) 1.89–1.91,
1.12. Writing costs 0.13–1.2 s once per structure and the entries are large
(15 MB for the flat trot, 95 MB for the single pallet), which is why nothing
is written unless the config asks for it.

Entries share the compiled cache's directory, key scheme (with the kind in
the key) and safety: written under a temporary name and renamed into place,
the file's checksum checked before it is read, a bad entry removed and rebuilt.
``nlp`` (x, p → f, g) is not stored: it is ``evaluate`` without the costs,
and storing both would read the same graph twice.
"""

from __future__ import annotations

import json
import zlib
from pathlib import Path
from typing import Any

import casadi as ca

from roughwalk.errors import InvalidArgumentError
from roughwalk.trajopt.compiled_nlp import (
    CompiledNlp,
    _discard,
    cache_dir,
    nlp_of_entry,
    write_entry,
)

__all__ = ["KIND", "load", "store"]

KIND = "serialized"
"""The ``kind`` in an entry's metadata and in its key (:func:`.compiled_nlp.structure_digest`)."""

_FILE = "nlp.casadi"
_META = "meta.json"
_CHUNK = 1 << 22  # [B] read at a time by the checksum


def _checksum(path: Path) -> str:
    """CRC-32 of the file (hex).

    It guards against truncation and damage, not against an adversary (the
    cache is the user's own), and costs a fifth of BLAKE2b's CPU: 0.024
    against 0.12 s on the single pallet's 95 MB, which are read at every load.
    """
    crc = 0
    with path.open("rb") as handle:
        while chunk := handle.read(_CHUNK):
            crc = zlib.crc32(chunk, crc)
    return f"{crc:08x}"


def _nlp_of(evaluate: ca.Function) -> ca.Function:
    """``nlp`` (x, p → f, g) from ``evaluate`` (x, p → f, g, costs)."""
    x = ca.MX.sym("x", evaluate.sparsity_in(0))
    p = ca.MX.sym("p", evaluate.sparsity_in(1))
    f, g, _ = evaluate(x, p)
    return ca.Function("nlp", [x, p], [f, g], ["x", "p"], ["f", "g"])


def load(key: str, root: Path | None = None) -> CompiledNlp | None:
    """The entry ``key`` if it is complete, intact and serialised; None otherwise.

    A bad entry is removed, so that the next writer replaces it.
    """
    entry = (root or cache_dir()) / key
    if not entry.is_dir():
        return None
    try:
        meta = json.loads((entry / _META).read_text())
        data = entry / _FILE
        if (
            meta.get("key") != key
            or meta.get("kind") != KIND
            or _checksum(data) != meta["file_crc32"]
        ):
            raise ValueError("checksum mismatch")
        reader = ca.FileDeserializer(str(data))
        functions: dict[str, ca.Function] = {}
        for name in meta["functions"]:
            function = reader.unpack()
            if not isinstance(function, ca.Function) or function.name() != name:
                raise ValueError(f"expected function '{name}'")
            functions[name] = function
        functions["nlp"] = _nlp_of(functions["evaluate"])
        return nlp_of_entry(functions, meta)
    except (OSError, ValueError, KeyError, TypeError, RuntimeError):
        _discard(entry)
        return None


def exists(key: str, root: Path | None = None) -> bool:
    """Whether entry ``key`` is stored (whole or not: :func:`load` checks that)."""
    return ((root or cache_dir()) / key).is_dir()


def store(
    key: str, functions: dict[str, ca.Function], layout: dict[str, Any], root: Path | None = None
) -> Path:
    """Serialise ``functions`` (all but ``nlp``) as entry ``key``; return its path.

    ``layout`` holds ``lbg``, ``ubg``, ``row_layout``, ``cost_names`` and
    ``n_variables``. When another process stored the key first, its entry is kept.
    """
    base = root or cache_dir()
    base.mkdir(parents=True, exist_ok=True)
    entry = base / key
    if entry.is_dir():
        return entry  # stored by another process (a bad one is removed by the next load)
    names = sorted(name for name in functions if name != "nlp")
    if "evaluate" not in names:
        raise InvalidArgumentError("a serialised NLP needs its 'evaluate' function")

    def fill(tmp: Path) -> dict[str, Any]:
        writer = ca.FileSerializer(str(tmp / _FILE))
        for name in names:
            if functions[name].name() != name:
                raise InvalidArgumentError(
                    f"function '{functions[name].name()}' stored as '{name}'"
                )
            writer.pack(functions[name])
        del writer  # flushes and closes the file
        return {"kind": KIND, "functions": names, "file_crc32": _checksum(tmp / _FILE)}

    return write_entry(key, base, layout, fill)
