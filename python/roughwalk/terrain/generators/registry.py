"""The generator registry: names, parameter configs, validation and specs.

A generator is a function ``f(params) -> Terrain`` whose ``params`` is a
frozen dataclass subclassing :class:`GeneratorParams`. Each field declares its
unit, a one-line doc and a range check through :func:`param`; the registry
reads them to list generators, to convert spec strings
(``large_rocks:seed=3,max_height=0.08``) to typed values, and to write the
canonical spec back onto the terrain it makes.
"""

from __future__ import annotations

import dataclasses
import functools
import math
import numbers
import typing
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, TypeVar

from roughwalk.errors import TerrainError
from roughwalk.terrain.terrain import Terrain

__all__ = [
    "GeneratorParams",
    "GeneratorParameter",
    "GeneratorInfo",
    "GENERATORS",
    "param",
    "register",
    "generate",
    "generator_info",
    "list_generators",
]

# Range checks a field may declare (see :func:`param`).
_CHECKS: dict[str, tuple[Callable[[float], bool], str]] = {
    "any": (lambda v: True, "any finite value"),
    "positive": (lambda v: v > 0, "a positive value"),
    "nonnegative": (lambda v: v >= 0, "a value ≥ 0"),
    "fraction": (lambda v: 0 <= v <= 1, "a value in [0, 1]"),
}


def param(default: Any, unit: str, doc: str, check: str = "any") -> Any:
    """Declare a generator parameter: a dataclass field with unit, doc and range check.

    Parameters
    ----------
    default:
        The default value; its Python type (int, float, bool) is the declared type.
    unit:
        The unit, without brackets ("m", "rad", "" for counts and seeds).
    doc:
        One line saying what the parameter does.
    check:
        One of "any", "positive", "nonnegative", "fraction".

    """
    if check not in _CHECKS:
        raise ValueError(f"unknown check {check!r}; known: {', '.join(_CHECKS)}")
    return dataclasses.field(default=default, metadata={"unit": unit, "doc": doc, "check": check})


@dataclass(frozen=True)
class GeneratorParams:
    """Base of every generator's parameter config; validates fields on construction."""

    def __post_init__(self) -> None:
        hints = typing.get_type_hints(type(self))
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            kind = hints[f.name]
            if kind is bool:
                if not isinstance(value, bool):
                    raise TerrainError(f"parameter '{f.name}' must be true or false, got {value!r}")
                continue
            if kind is int and (isinstance(value, bool) or not isinstance(value, numbers.Integral)):
                raise TerrainError(f"parameter '{f.name}' must be an integer, got {value!r}")
            if kind is float and (isinstance(value, bool) or not isinstance(value, numbers.Real)):
                raise TerrainError(f"parameter '{f.name}' must be a number, got {value!r}")
            if not math.isfinite(value):
                raise TerrainError(f"parameter '{f.name}' must be finite, got {value!r}")
            ok, what = _CHECKS[f.metadata.get("check", "any")]
            if not ok(value):
                raise TerrainError(f"parameter '{f.name}' must be {what}, got {value!r}")
        self.validate()

    def validate(self) -> None:
        """Check relations between fields; raise :class:`TerrainError` naming them."""


P = TypeVar("P", bound=GeneratorParams)


@dataclass(frozen=True)
class GeneratorParameter:
    """One parameter of a generator, as listed by ``roughwalk terrain list``."""

    name: str
    type: type
    default: Any
    unit: str
    doc: str

    def to_dict(self) -> dict[str, Any]:
        """Return plain, JSON-ready data."""
        return {
            "name": self.name,
            "type": self.type.__name__,
            "default": self.default,
            "unit": self.unit,
            "doc": self.doc,
        }


@dataclass(frozen=True)
class GeneratorInfo:
    """A registered generator: its name, function, parameter config and description."""

    name: str
    function: Callable[..., Terrain]
    config: type[GeneratorParams]
    description: str
    family: str
    randomized: bool

    @property
    def parameters(self) -> tuple[GeneratorParameter, ...]:
        """The parameters with their declared types, defaults, units and docs."""
        hints = typing.get_type_hints(self.config)
        return tuple(
            GeneratorParameter(
                f.name, hints[f.name], f.default, f.metadata["unit"], f.metadata["doc"]
            )
            for f in dataclasses.fields(self.config)
        )

    def default_config(self) -> GeneratorParams:
        """Return the parameter config with every default."""
        return self.config()

    def make_config(self, **params: Any) -> GeneratorParams:
        """Build the config from keyword values, converting strings to the declared types."""
        hints = typing.get_type_hints(self.config)
        names = [f.name for f in dataclasses.fields(self.config)]
        values = {}
        for key, value in params.items():
            if key not in hints:
                raise TerrainError(
                    f"unknown parameter '{key}' for generator '{self.name}'; "
                    f"valid: {', '.join(names)}"
                )
            values[key] = _convert(value, hints[key], key)
        return self.config(**values)

    def spec(self, config: GeneratorParams) -> str:
        """Write the canonical spec that regenerates ``config`` (non-default values only)."""
        items = []
        for f in dataclasses.fields(config):
            value = getattr(config, f.name)
            if value != f.default:
                items.append(f"{f.name}={_format(value)}")
        return self.name + (":" + ",".join(items) if items else "")

    def to_dict(self) -> dict[str, Any]:
        """Return plain, JSON-ready data (for ``roughwalk terrain list --json``)."""
        return {
            "name": self.name,
            "family": self.family,
            "description": self.description,
            "randomized": self.randomized,
            "params": [p.to_dict() for p in self.parameters],
        }


GENERATORS: dict[str, GeneratorInfo] = {}


def _convert(value: Any, kind: type, key: str) -> Any:
    """Convert a spec string (or a number) to the declared ``kind`` of parameter ``key``."""
    if isinstance(value, str):
        text = value.strip()
        if kind is bool:
            lowered = text.lower()
            if lowered in ("true", "1", "yes", "on"):
                return True
            if lowered in ("false", "0", "no", "off"):
                return False
            raise TerrainError(f"parameter '{key}' must be true or false, got {value!r}")
        if kind is int:
            try:
                return int(text)
            except ValueError:
                raise TerrainError(f"parameter '{key}' must be an integer, got {value!r}") from None
        if kind is float:
            try:
                return float(text)
            except ValueError:
                raise TerrainError(f"parameter '{key}' must be a number, got {value!r}") from None
        return text
    if kind is int and isinstance(value, numbers.Real) and not isinstance(value, bool):
        # 3.0 is an integer seed, 3.5 is not.
        number = float(value)
        if math.isfinite(number) and number.is_integer():
            return int(number)
        raise TerrainError(f"parameter '{key}' must be an integer, got {value!r}")
    if kind is float and isinstance(value, numbers.Real) and not isinstance(value, bool):
        return float(value)
    return value


def _format(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return repr(value)
    return str(value)


def register(
    name: str, config: type[P], description: str, family: str, randomized: bool = False
) -> Callable[[Callable[[P], Terrain]], Callable[[P | None], Terrain]]:
    """Register a generator function under ``name``.

    The decorated function takes its ``config`` instance; the returned function
    also accepts ``None`` (all defaults) and stamps ``name`` and the canonical
    ``spec`` on the terrain, so a direct call and :func:`generate` agree.
    """

    def decorate(fn: Callable[[P], Terrain]) -> Callable[[P | None], Terrain]:
        if name in GENERATORS:
            raise TerrainError(f"generator '{name}' is registered twice")

        @functools.wraps(fn)
        def wrapper(params: P | None = None) -> Terrain:
            cfg = config() if params is None else params
            if not isinstance(cfg, config):
                raise TerrainError(
                    f"generator '{name}' takes a {config.__name__}, got {type(cfg).__name__}"
                )
            terrain = fn(cfg)
            terrain.name = name
            terrain.spec = info.spec(cfg)
            return terrain

        info = GeneratorInfo(name, wrapper, config, description, family, randomized)
        GENERATORS[name] = info
        return wrapper

    return decorate


def _lookup(name: str) -> GeneratorInfo:
    try:
        return GENERATORS[name]
    except KeyError:
        raise TerrainError(
            f"unknown terrain generator '{name}'; known: {', '.join(GENERATORS)}"
        ) from None


def generate(name: str, **params: Any) -> Terrain:
    """Build the terrain of generator ``name`` with ``params`` (strings are converted).

    Raises :class:`TerrainError` for an unknown generator (listing the known
    ones), an unknown parameter (listing the valid ones) or a bad value
    (naming the parameter).
    """
    info = _lookup(name)
    return info.function(info.make_config(**params))


def list_generators() -> list[GeneratorInfo]:
    """List every registered generator, in registration order."""
    return list(GENERATORS.values())


def generator_info(name: str) -> GeneratorInfo:
    """Look up ``name`` (raises :class:`TerrainError` listing the known ones)."""
    return _lookup(name)
