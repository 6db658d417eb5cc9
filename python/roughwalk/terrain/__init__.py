"""Terrain: height fields, loaders, generators, signed distance fields and features.

This wing knows no robot. Start with :func:`load_terrain`.
"""

from roughwalk.terrain.spec import TerrainPart, load_terrain, parse_spec
from roughwalk.terrain.terrain import MujocoHeightField, Terrain

__all__ = [
    "Terrain",
    "MujocoHeightField",
    "TerrainPart",
    "load_terrain",
    "parse_spec",
]
