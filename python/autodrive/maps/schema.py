"""Builds the description dataclasses from parsed YAML, strictly by their field types: an unknown
key, a missing key or a value of the wrong type raises MapDescriptionError naming the file and the
dotted key (e.g. "parking_slots[2].size_m")."""

from __future__ import annotations

import dataclasses
import math
import types
import typing
from pathlib import Path
from typing import Any, Literal, TypeVar, Union

from autodrive.maps.model import MapDescriptionError

T = TypeVar("T")


def fail(source: Path, key: str, what: str) -> MapDescriptionError:
    return MapDescriptionError(f"{source}: {key or '(top level)'}: {what}")


def _join(key: str, sub: str) -> str:
    return f"{key}.{sub}" if key else sub


def _describe(value: Any) -> str:
    return f"{type(value).__name__} {value!r}" if value is not None else "nothing (null)"


def build(cls: type[T], data: Any, source: Path, key: str = "") -> T:
    """An instance of the dataclass cls from a YAML mapping; fields named source are skipped."""
    if not isinstance(data, dict):
        raise fail(source, key, f"expected a mapping, got {_describe(data)}")
    hints = typing.get_type_hints(cls)
    fields = [f for f in dataclasses.fields(cls) if f.name != "source"]  # type: ignore[arg-type]
    names = {f.name for f in fields}
    for k in data:
        if k not in names:
            raise fail(source, _join(key, str(k)), f"unknown key (expected one of {sorted(names)})")
    values = {}
    for f in fields:
        sub = _join(key, f.name)
        if f.name not in data:
            if f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING:
                raise fail(source, sub, "missing key")
            continue
        values[f.name] = _value(hints[f.name], data[f.name], source, sub)
    return cls(**values)


def _value(tp: Any, value: Any, source: Path, key: str) -> Any:
    origin = typing.get_origin(tp)
    args = typing.get_args(tp)
    if origin in (Union, types.UnionType) and type(None) in args:  # Optional[X]
        inner = next(a for a in args if a is not type(None))
        return None if value is None else _value(inner, value, source, key)
    if tp is float:
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise fail(source, key, f"expected a number, got {_describe(value)}")
        if not math.isfinite(value):
            raise fail(source, key, f"expected a finite number, got {value!r}")
        return float(value)
    if tp is bool:
        if not isinstance(value, bool):
            raise fail(source, key, f"expected true or false, got {_describe(value)}")
        return value
    if tp is int:
        if isinstance(value, bool) or not isinstance(value, int):
            raise fail(source, key, f"expected a whole number, got {_describe(value)}")
        return value
    if tp is str:
        if not isinstance(value, str) or not value:
            raise fail(source, key, f"expected a non-empty text, got {_describe(value)}")
        return value
    if origin is Literal:
        if value not in args:
            raise fail(source, key, f"expected one of {list(args)}, got {_describe(value)}")
        return value
    if origin is tuple:
        if not isinstance(value, list) or len(value) != len(args):
            raise fail(
                source, key, f"expected a list of {len(args)} numbers, got {_describe(value)}"
            )
        return tuple(
            _value(a, v, source, f"{key}[{i}]") for i, (a, v) in enumerate(zip(args, value))
        )
    if origin is list:
        if not isinstance(value, list):
            raise fail(source, key, f"expected a list, got {_describe(value)}")
        return [_value(args[0], v, source, f"{key}[{i}]") for i, v in enumerate(value)]
    if origin is dict:
        if not isinstance(value, dict) or not value:
            raise fail(source, key, f"expected a non-empty mapping, got {_describe(value)}")
        return {str(k): _value(args[1], v, source, _join(key, str(k))) for k, v in value.items()}
    if dataclasses.is_dataclass(tp):
        return build(tp, value, source, key)  # type: ignore[arg-type]
    raise TypeError(f"schema: unsupported field type {tp!r} at {key}")  # a bug here, not input
