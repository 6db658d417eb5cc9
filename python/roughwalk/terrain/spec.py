"""Terrain specs: the strings that name a terrain on the command line and in JSON.

A spec is one of

* a file path (``terrainA.mat``, ``step.png``, ``heights.npz``, ``board.stl``);
* a generator name with parameters (``large_rocks:seed=3,max_height=0.08``);
* a course: parts joined by ``+``, each optionally rotated by a multiple of
  90° with ``@`` (``a.mat+b.mat@180+c.mat``).

Every JSON result stores the spec, so the next command rebuilds the same
terrain from it.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from roughwalk.errors import TerrainError
from roughwalk.terrain.terrain import Terrain

__all__ = ["TerrainPart", "parse_spec", "load_terrain"]

_FILE_SUFFIXES = {".mat", ".png", ".npy", ".npz", ".stl", ".obj", ".ply"}


@dataclass(frozen=True)
class TerrainPart:
    """One board of a spec: a file or a generator call, and its rotation [deg]."""

    source: str
    params: dict[str, str] = field(default_factory=dict)
    rotation_deg: int = 0
    is_file: bool = False


def _parse_part(text: str) -> TerrainPart:
    text = text.strip()
    if not text:
        raise TerrainError("empty part in terrain spec (two '+' in a row, or a trailing '+')")
    rotation = 0
    m = re.fullmatch(r"(.*)@(-?\d+)", text)
    if m:
        text, rotation = m.group(1), int(m.group(2))
        if rotation % 90 != 0:
            raise TerrainError(
                f"rotation @{rotation} in terrain spec: only multiples of 90 degrees are allowed"
            )
    path = Path(text)
    if path.suffix.lower() in _FILE_SUFFIXES or path.exists():
        return TerrainPart(text, {}, rotation % 360, is_file=True)
    name, _, args = text.partition(":")
    params: dict[str, str] = {}
    if args:
        for item in args.split(","):
            key, sep, value = item.partition("=")
            if not sep or not key.strip():
                raise TerrainError(
                    f"generator parameters must be key=value, got {item!r} in {text!r}"
                )
            params[key.strip()] = value.strip()
    return TerrainPart(name.strip(), params, rotation % 360, is_file=False)


def parse_spec(spec: str) -> list[TerrainPart]:
    """Split a terrain spec into its parts (boards of a course)."""
    if not isinstance(spec, str) or not spec.strip():
        raise TerrainError(f"a terrain spec must be a non-empty string, got {spec!r}")
    return [_parse_part(p) for p in spec.split("+")]


def _load_part(part: TerrainPart, options: dict[str, Any]) -> Terrain:
    if part.is_file:
        from roughwalk.terrain.loaders import load_file

        return load_file(part.source, **options)
    from roughwalk.terrain.generators import generate

    return generate(part.source, **part.params)


def load_terrain(spec: str | Path, **options: Any) -> Terrain:
    """Load or generate the terrain named by ``spec``.

    ``options`` go to the file loaders (``resolution`` and ``scale`` for PNG
    elevation maps, ``origin``, ...) and, for courses, to
    :func:`roughwalk.terrain.course.make_course` (``resolution``,
    ``pad_before``, ``pad_after``). A single board keeps its own grid.
    """
    spec_str = str(spec)
    parts = parse_spec(spec_str)
    course_keys = {"course_resolution", "pad_before", "pad_after"}
    course_opts = {k: v for k, v in options.items() if k in course_keys}
    load_opts = {k: v for k, v in options.items() if k not in course_keys}
    if len(parts) == 1 and parts[0].rotation_deg == 0 and not course_opts:
        t = _load_part(parts[0], load_opts)
        t.spec = spec_str
        return t
    from roughwalk.terrain.course import make_course

    boards = [_load_part(p, load_opts) for p in parts]
    return make_course(
        boards,
        rotations=[p.rotation_deg for p in parts],
        resolution=course_opts.get("course_resolution"),
        pad_before=float(course_opts.get("pad_before", 0.0)),
        pad_after=float(course_opts.get("pad_after", 0.0)),
        spec=spec_str,
    )
