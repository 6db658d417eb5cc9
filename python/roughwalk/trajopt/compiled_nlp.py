"""An on-disk cache of the NLP's functions compiled to C, keyed by the problem's structure.

Building the NLP (CasADi graphs and their derivatives in Python) costs
0.3–1 s per structure and process. CasADi can write the functions IPOPT
calls as C (:class:`casadi.CodeGenerator`); compiled with the system's C
compiler into a shared library and stored under :func:`cache_dir`, a later
process with the same structure loads them with :func:`casadi.external`
and builds no expression at all (only the variable layout and bounds).

The key (:func:`structure_digest`) hashes everything that defines the
functions: the body, the contact schedule, the terrain's heights, the full
config, CasADi's version, the compiler flags and the source of the whole
``trajopt`` package, so that a code edit never loads a stale library.

An entry is a directory written under a temporary name and renamed into
place, so that a reader never sees a partial one and two writers of one key
cannot corrupt it (the second rename fails and its copy is dropped). Its
metadata holds the library's digest, checked before loading: a corrupt or
truncated library is removed and rebuilt, never loaded.
"""

from __future__ import annotations

import functools
import hashlib
import json
import os
import resource
import shutil
import subprocess
import tempfile
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import casadi as ca
import numpy as np
from numpy.typing import NDArray

from roughwalk.config import to_dict
from roughwalk.errors import InvalidArgumentError

__all__ = [
    "CompiledNlp",
    "CompileError",
    "cache_dir",
    "structure_digest",
    "load",
    "compile_and_store",
    "failed_before",
]

COMPILER_FLAGS = ("-O1",)
"""gcc's flags. The generated C is large (4.9 MB for TOWR's flat 16-step trot
with fixed durations, 20 MB with optimised ones) and its Jacobian is one
function of 150 000 operations. On the trot, with CasADi's default of one
local variable per operation, ``-O1`` took 129 s of CPU and ``-O0`` 13 s
(1.5 GB), but -O0's functions ran at half the speed of CasADi's virtual
machine (45 against 24 ms of function CPU a solve, 22 iterations): a cached
problem lost its saved build after three solves. With the work vector
instead of locals (``avoid_stack``), ``-O1`` takes 38 s and 1.5 GB and runs
as fast as the virtual machine (25 ms); -O0 then runs slower still (73 ms).
The functions are about a tenth of an iteration (IPOPT and MUMPS are the
rest), so compiling buys the build, not faster iterations."""

_CODEGEN_OPTIONS = {"with_header": False, "avoid_stack": True}

COMPILER_MEMORY_BYTES = 6 * 1024**3
"""gcc's address-space limit. With optimised phase durations TOWR's flat walk
gives 20 MB of C whose compilation grew past 23 GB at -O0 until the kernel
killed it (and could take other processes with it); capped, it fails alone and
the NLP is built as expressions instead."""

COMPILER_CPU_SECONDS = 240
"""gcc's CPU limit [s]: the optimised-durations walk at -O1 was still compiling
after 218 s of CPU (3.6 GB); such a problem is built as expressions instead."""

_LIBRARY = "nlp.so"
_FAILED = ".failed"
_META = "meta.json"
_FUNCTIONS = ("nlp", "nlp_jac_g", "nlp_grad_f", "nlp_hess_l", "evaluate")


def cache_dir() -> Path:
    """``$ROUGHWALK_CACHE/nlp``, else ``~/.cache/roughwalk/nlp``."""
    root = os.environ.get("ROUGHWALK_CACHE")
    base = Path(root) if root else Path.home() / ".cache" / "roughwalk"
    return base / "nlp"


@functools.cache
def _source_digest() -> str:
    """Digest of every Python file of the trajopt package (path and content)."""
    package = Path(__file__).resolve().parent
    digest = hashlib.blake2b(digest_size=16)
    for path in sorted(package.rglob("*.py")):
        digest.update(str(path.relative_to(package)).encode())
        digest.update(path.read_bytes())
    return digest.hexdigest()


def structure_digest(
    body: Any, terrain_key: tuple[Any, ...], schedule: Any, config: Any, kind: str = "compiled"
) -> str:
    """The cache key of one NLP structure (hex) for entries of ``kind``.

    The config decides the cost set and with it the Hessian (exact or L-BFGS).
    Of the solver's options only ``hessian`` is part of the key: the others
    (iteration and time limits, IPOPT's options) change how the functions are
    solved, not the functions, and a solve with ``--max-iter`` (or ``roughwalk
    cache warm``, which takes no iteration) must find the entry of the same
    structure. Nor are ``init`` (where the first guess comes from),
    ``guess_projection`` (how it is moved before the solve) and
    ``sample_rate_hz`` (how the result is sampled): heuristic and learned solves
    of one structure share its entry. ``kind`` is "compiled" (here) or "serialized"
    (:mod:`.serialized_nlp`): the two kinds of one structure are separate entries.
    """
    described = to_dict(config)
    for unused in ("compiled", "init", "sample_rate_hz", "guess_projection"):
        described.pop(unused, None)
    described["solver"] = {"hessian": described["solver"]["hessian"]}
    description = {
        "kind": kind,
        "body": repr(body),
        "terrain": repr(terrain_key),
        "schedule": repr(
            (schedule.name, schedule.durations, schedule.in_contact_at_start, schedule.steps)
        ),
        # The whole config but the switch that chose the cache and how IPOPT runs.
        "config": json.dumps(described, sort_keys=True, default=repr),
        "casadi": ca.CasadiMeta.version(),
        "flags": (COMPILER_FLAGS, sorted(_CODEGEN_OPTIONS.items())) if kind == "compiled" else None,
        "source": _source_digest(),
    }
    text = json.dumps(description, sort_keys=True, default=repr)
    return hashlib.blake2b(text.encode(), digest_size=20).hexdigest()


@dataclass
class CompiledNlp:
    """The compiled functions of one NLP and the layout of its rows.

    Attributes
    ----------
    functions:
        ``nlp`` (x, p → f, g), ``nlp_jac_g``, ``nlp_grad_f``, ``evaluate``
        (x, p → f, g, costs) and, with the exact Hessian, ``nlp_hess_l``.
    lbg, ubg:
        Constraint bounds.
    row_layout:
        (constraint name, row count) in the order of g.
    cost_names:
        The cost terms in the order of ``evaluate``'s costs.
    n_variables:
        Number of decision variables (checked against the layout).

    """

    functions: dict[str, ca.Function]
    lbg: NDArray[np.float64]
    ubg: NDArray[np.float64]
    row_layout: list[tuple[str, int]]
    cost_names: list[str]
    n_variables: int


def _file_digest(path: Path) -> str:
    return hashlib.blake2b(path.read_bytes(), digest_size=20).hexdigest()


def _discard(entry: Path) -> None:
    """Remove a bad entry; renamed first so that no reader sees it half removed."""
    trash = entry.with_name(f"{entry.name}.bad-{os.getpid()}")
    try:
        entry.rename(trash)
    except OSError:
        return
    shutil.rmtree(trash, ignore_errors=True)


def load(key: str, root: Path | None = None) -> CompiledNlp | None:
    """The entry ``key`` if it is complete and intact; None otherwise (a bad one is removed)."""
    entry = (root or cache_dir()) / key
    if not entry.is_dir():
        return None
    try:
        meta = json.loads((entry / _META).read_text())
        library = entry / _LIBRARY
        if (
            meta.get("key") != key
            or meta.get("kind", "compiled") != "compiled"
            or _file_digest(library) != meta["library_digest"]
        ):
            raise ValueError("digest mismatch")
        functions = {
            name: ca.external(name, str(library))
            for name in _FUNCTIONS
            if name in meta["functions"]
        }
        return nlp_of_entry(functions, meta)
    except (OSError, ValueError, KeyError, TypeError, RuntimeError):
        _discard(entry)
        return None


def nlp_of_entry(functions: dict[str, ca.Function], meta: dict[str, Any]) -> CompiledNlp:
    """A loaded entry: its ``functions`` and the layout recorded by :func:`write_entry`."""
    return CompiledNlp(
        functions=functions,
        lbg=np.asarray(meta["lbg"], dtype=float),
        ubg=np.asarray(meta["ubg"], dtype=float),
        row_layout=[(str(n), int(s)) for n, s in meta["row_layout"]],
        cost_names=[str(n) for n in meta["cost_names"]],
        n_variables=int(meta["n_variables"]),
    )


def write_entry(
    key: str, base: Path, layout: dict[str, Any], fill: Callable[[Path], dict[str, Any]]
) -> Path:
    """Write entry ``key`` under ``base`` whole or not at all; return its path.

    ``fill(folder)`` writes the entry's files into a temporary folder and
    returns its kind's metadata; the layout (``lbg``, ``ubg``, ``row_layout``,
    ``cost_names``, ``n_variables``) is added here and the folder renamed into
    place. When another process stored the key first, its entry is kept.
    """
    entry = base / key
    tmp = Path(tempfile.mkdtemp(prefix=f"{key}.tmp-", dir=base))
    try:
        meta = {
            "key": key,
            **fill(tmp),
            "lbg": _bound(layout["lbg"]),
            "ubg": _bound(layout["ubg"]),
            "row_layout": [[n, int(s)] for n, s in layout["row_layout"]],
            "cost_names": list(layout["cost_names"]),
            "n_variables": int(layout["n_variables"]),
        }
        (tmp / _META).write_text(json.dumps(meta))
        try:
            tmp.rename(entry)
        except OSError:
            # Another process stored this key first: its entry is as good as ours.
            shutil.rmtree(tmp, ignore_errors=True)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    return entry


def failed_before(key: str, root: Path | None = None) -> bool:
    """Whether compiling ``key`` failed in an earlier process (it is not tried again)."""
    return ((root or cache_dir()) / f"{key}{_FAILED}").is_file()


class CompileError(InvalidArgumentError):
    """The NLP could not be compiled (no gcc, or too large for its memory or CPU limit)."""


def _limit_compiler() -> None:
    resource.setrlimit(resource.RLIMIT_AS, (COMPILER_MEMORY_BYTES, COMPILER_MEMORY_BYTES))
    resource.setrlimit(resource.RLIMIT_CPU, (COMPILER_CPU_SECONDS, COMPILER_CPU_SECONDS))


def _write_atomic(path: Path, text: str, directory: Path) -> None:
    handle, name = tempfile.mkstemp(prefix=f"{path.name}.tmp-", dir=directory)
    with os.fdopen(handle, "w") as out:
        out.write(text)
    os.replace(name, path)


def _bound(values: NDArray[np.float64]) -> list[float | str]:
    """Bounds for JSON (±inf as strings)."""
    return [float(v) if np.isfinite(v) else ("inf" if v > 0 else "-inf") for v in values]


def compile_and_store(
    key: str, functions: dict[str, ca.Function], layout: dict[str, Any], root: Path | None = None
) -> Path:
    """Generate C for ``functions``, compile it and store it as entry ``key``; return its path.

    ``layout`` holds ``lbg``, ``ubg``, ``row_layout``, ``cost_names`` and
    ``n_variables``. The entry is written in a temporary directory and
    renamed into place; when another process stored the key first, its
    entry is kept.
    """
    base = root or cache_dir()
    base.mkdir(parents=True, exist_ok=True)
    failed = base / f"{key}{_FAILED}"
    if failed.is_file():
        raise CompileError(f"compiling this NLP failed before: {failed.read_text()[:500]}")

    def fill(tmp: Path) -> dict[str, Any]:
        generator = ca.CodeGenerator("nlp.c", _CODEGEN_OPTIONS)
        for name, function in functions.items():
            if function.name() != name:
                raise InvalidArgumentError(f"function '{function.name()}' stored as '{name}'")
            generator.add(function)
        generator.generate(str(tmp) + os.sep)
        try:
            subprocess.run(
                ["gcc", "-fPIC", "-shared", *COMPILER_FLAGS, "nlp.c", "-o", _LIBRARY, "-lm"],
                cwd=tmp,
                check=True,
                capture_output=True,
                preexec_fn=_limit_compiler,
            )
        except (OSError, subprocess.CalledProcessError) as e:
            detail = (getattr(e, "stderr", b"") or b"").decode(errors="replace")[-500:]
            message = f"gcc failed ({e}); {detail}"
            # Remembered, so that later processes do not spend minutes failing again.
            _write_atomic(failed, message, base)
            raise CompileError(f"compiling the NLP failed: {message}") from None
        (tmp / "nlp.c").unlink()
        return {
            "kind": "compiled",
            "functions": sorted(functions),
            "library_digest": _file_digest(tmp / _LIBRARY),
        }

    return write_entry(key, base, layout, fill)
