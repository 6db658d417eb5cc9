"""Terrain generators: seeded, parameterised in physical units, registered by name.

``generate("large_rocks", seed=3, max_height=0.08)`` (or the spec
``large_rocks:seed=3,max_height=0.08`` given to :func:`load_terrain`) builds
a :class:`~roughwalk.terrain.Terrain` whose ``spec`` regenerates it.
:func:`list_generators` gives every generator with its parameters, defaults
and units (``roughwalk terrain list`` prints them).

Families:

* LittleDog scale (a 2 m × 0.6 m course, flat pads at both ends, features up
  to 10.8 cm): ``flat``, ``large_rocks``, ``round_rocks``, ``sloped_rocks``,
  ``logs``, ``gap``, ``barrier``, ``steps``, ``stairs``, ``stepping_stones``;
* Melon et al. 2020 pallets: ``single_pallet``, ``double_pallet``;
* TOWR's test terrains: ``towr_block``, ``towr_stairs``, ``towr_gap``,
  ``towr_slope``.

A new generator is one function with a frozen-dataclass config, decorated
with :func:`register`, in a module imported here.
"""

from roughwalk.terrain.generators.registry import (
    GENERATORS,
    GeneratorInfo,
    GeneratorParameter,
    GeneratorParams,
    generate,
    generator_info,
    list_generators,
    param,
    register,
)

# Importing the families registers their generators; the import order is the
# order `roughwalk terrain list` shows them in.
# isort: off
from roughwalk.terrain.generators import flat as _flat
from roughwalk.terrain.generators import littledog_rocks as _rocks
from roughwalk.terrain.generators import littledog_blocks as _blocks
from roughwalk.terrain.generators import pallets as _pallets
from roughwalk.terrain.generators import towr as _towr

# isort: on

__all__ = [
    "GENERATORS",
    "GeneratorInfo",
    "GeneratorParameter",
    "GeneratorParams",
    "generate",
    "generator_info",
    "list_generators",
    "param",
    "register",
]

del _flat, _rocks, _blocks, _pallets, _towr
