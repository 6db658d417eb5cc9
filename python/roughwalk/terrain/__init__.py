"""Terrain: height fields, loaders, generators, signed distance fields and features.

This wing knows no robot. Start with :func:`load_terrain`.
"""

from roughwalk.terrain.features import TerrainFeatures, compute_features, orient_features
from roughwalk.terrain.generators import generate, list_generators
from roughwalk.terrain.sdf import SdfConfig, SignedDistanceField
from roughwalk.terrain.spec import TerrainPart, load_terrain, parse_spec
from roughwalk.terrain.terrain import MujocoHeightField, Terrain

__all__ = [
    "Terrain",
    "MujocoHeightField",
    "TerrainPart",
    "load_terrain",
    "parse_spec",
    "SignedDistanceField",
    "SdfConfig",
    "generate",
    "list_generators",
    "TerrainFeatures",
    "compute_features",
    "orient_features",
]
