"""Configuration by data: frozen dataclasses, TOML files and dotted overrides.

Every tunable part of roughwalk exposes a frozen dataclass whose fields state
their units. Users change them without code, from the CLI with
``--config FILE.toml`` and repeatable ``--set key=value`` (dotted keys reach
nested dataclasses: ``--set sdf.resolution=0.004``), or from Python with
:func:`override`.
"""

from __future__ import annotations

import dataclasses
import tomllib
import types
import typing
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any, TypeVar

from roughwalk.errors import ConfigError

__all__ = ["override", "parse_set", "load_toml", "configure", "to_dict"]

C = TypeVar("C")


def to_dict(config: Any) -> dict[str, Any]:
    """Return a dataclass config as a plain, JSON-ready dict."""
    return dataclasses.asdict(config)


def _coerce(value: Any, annotation: Any, key: str) -> Any:
    """Convert ``value`` (a TOML value or a --set string) to the field's type."""
    origin = typing.get_origin(annotation)
    args = typing.get_args(annotation)
    if origin in (typing.Union, types.UnionType):
        if value is None or (isinstance(value, str) and value.lower() == "none"):
            if type(None) in args:
                return None
        errors = []
        for a in args:
            if a is type(None):
                continue
            try:
                return _coerce(value, a, key)
            except ConfigError as e:
                errors.append(str(e))
        raise ConfigError(f"{key}: cannot read {value!r} as {annotation}")
    if origin in (tuple, list):
        if isinstance(value, str):
            items: list[Any] = [v for v in value.strip("()[] ").split(",") if v.strip()]
        elif isinstance(value, Iterable):
            items = list(value)
        else:
            raise ConfigError(f"{key}: expected a list, got {value!r}")
        inner = args[0] if args else Any
        return (tuple if origin is tuple else list)(_coerce(v, inner, key) for v in items)
    if annotation is bool:
        if isinstance(value, bool):
            return value
        if isinstance(value, str) and value.lower() in ("true", "1", "yes", "on"):
            return True
        if isinstance(value, str) and value.lower() in ("false", "0", "no", "off"):
            return False
        raise ConfigError(f"{key}: expected true or false, got {value!r}")
    if annotation in (int, float):
        try:
            out = annotation(value.strip() if isinstance(value, str) else value)
        except (TypeError, ValueError):
            raise ConfigError(
                f"{key}: expected a number ({annotation.__name__}), got {value!r}"
            ) from None
        if isinstance(out, float) and out != out:
            raise ConfigError(f"{key}: NaN is not a valid value")
        return out
    if annotation is str:
        return str(value)
    return value


def override(config: C, changes: Mapping[str, Any]) -> C:
    """Return a copy of the frozen dataclass ``config`` with dotted-key ``changes`` applied.

    Raises :class:`ConfigError` naming the key when a field does not exist
    (listing the valid ones) or a value cannot be converted.
    """
    if not dataclasses.is_dataclass(config) or isinstance(config, type):
        raise ConfigError(f"expected a dataclass config instance, got {type(config).__name__}")
    nested: dict[str, dict[str, Any]] = {}
    direct: dict[str, Any] = {}
    hints = typing.get_type_hints(type(config))
    names = [f.name for f in dataclasses.fields(config)]
    for key, value in changes.items():
        head, _, rest = key.partition(".")
        if head not in names:
            raise ConfigError(
                f"unknown config field '{key}' for {type(config).__name__}; "
                f"known: {', '.join(names)}"
            )
        if rest:
            nested.setdefault(head, {})[rest] = value
        else:
            current = getattr(config, head)
            if dataclasses.is_dataclass(current) and isinstance(value, Mapping):
                nested.setdefault(head, {}).update(value)
            else:
                direct[head] = _coerce(value, hints[head], key)
    for head, sub in nested.items():
        direct[head] = override(getattr(config, head), sub)
    try:
        return dataclasses.replace(config, **direct)
    except (ValueError, TypeError) as e:
        raise ConfigError(f"{type(config).__name__}: {e}") from None


def _flatten(table: Mapping[str, Any], prefix: str = "") -> dict[str, Any]:
    out: dict[str, Any] = {}
    for k, v in table.items():
        key = f"{prefix}{k}"
        if isinstance(v, Mapping):
            out.update(_flatten(v, key + "."))
        else:
            out[key] = v
    return out


def load_toml(path: str | Path) -> dict[str, Any]:
    """Read a TOML config file into flat dotted keys."""
    p = Path(path)
    if not p.is_file():
        raise ConfigError(f"config file '{p}' does not exist")
    try:
        with p.open("rb") as f:
            return _flatten(tomllib.load(f))
    except tomllib.TOMLDecodeError as e:
        raise ConfigError(f"config file '{p}' is not valid TOML: {e}") from None


def parse_set(items: Iterable[str]) -> dict[str, str]:
    """Parse repeated ``key=value`` strings from ``--set``."""
    out: dict[str, str] = {}
    for item in items:
        key, sep, value = item.partition("=")
        if not sep or not key.strip():
            raise ConfigError(f"--set expects key=value, got {item!r}")
        out[key.strip()] = value.strip()
    return out


def configure(config: C, config_file: str | Path | None = None, sets: Iterable[str] = ()) -> C:
    """Apply a TOML file and then ``--set`` overrides to ``config`` (later wins)."""
    if config_file is not None:
        config = override(config, load_toml(config_file))
    return override(config, parse_set(sets))
