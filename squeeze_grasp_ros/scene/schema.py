# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The typed-YAML schema engine shared by scenes and sweep specs.

A schema is a tree of frozen dataclasses. Each field is declared with :func:`spec`, which
keeps its documentation, unit, range and allowed choices in the field's ``metadata``, so the
parser (:func:`parse_section`), its error messages and the key reference
(:func:`key_reference`, what ``squeeze-grasp scene-help`` and ``sweep-help`` print) share one
source of truth. Parsing is strict: an unknown key, a wrong type, a value out of range or a
missing required key raises the caller's error class (a :class:`SchemaError`) naming the key
(``fingers.F1.tip_radius``).

>>> from dataclasses import dataclass
>>> @dataclass(frozen=True)
... class Tip:
...     radius: float = spec("fingertip radius", "m", lo=0.0, default=0.0)
>>> parse_section(Tip, {"radius": 0.02}, "tip")
Tip(radius=0.02)
>>> parse_section(Tip, {"radius": -1}, "tip")
Traceback (most recent call last):
...
squeeze_grasp_ros.scene.schema.SchemaError: tip.radius must be >= 0.0 m, got -1.0
"""

from __future__ import annotations

import dataclasses
import difflib
import types
import typing
from collections.abc import Mapping
from enum import Enum
from typing import Any

import numpy as np

from squeeze_grasp_ros.inputs import yaml11_number
from squeeze_grasp_ros.mechanics.errors import InvalidInputError

__all__ = ["MAX_INT", "SchemaError", "describe_range", "key_reference", "parse_section",
           "spec", "unknown_key"]

MAX_INT = 2**53
"""Largest integer an entry may hold (exactly representable as a float)."""


class SchemaError(InvalidInputError):
    """An entry of a typed YAML document is unknown, of the wrong type, out of range or
    contradictory.
    """


def spec(
    doc: str,
    unit: str = "",
    lo: float | None = None,
    hi: float | None = None,
    lo_open: bool = False,
    choices: tuple = (),
    *,
    hi_open: bool = False,
    why: str = "",
    **kw,
) -> Any:
    """A dataclass field with documentation, unit, range and allowed choices for the parser.

    Parameters
    ----------
    doc : str
        One line for the key reference.
    unit : str
        SI unit of a number ("" for none).
    lo, hi : float, optional
        Range of a number (inclusive unless ``lo_open`` / ``hi_open``).
    choices : tuple of str
        Allowed values of a string (an enum-typed field takes its members' values by default).
        A mapping (``dict`` or ``Mapping[K, V]``) is checked to be one and kept as given: its
        document's parser types its keys and values (e.g. a scene's fingers).
    hi_open, why : bool, str
        An open upper bound; why the range is what it is, said with a value out of it.
    **kw
        ``default`` or ``default_factory`` of :func:`dataclasses.field`.
    """
    meta = {"doc": doc, "unit": unit, "lo": lo, "hi": hi, "lo_open": lo_open, "hi_open": hi_open,
            "why": why, "choices": choices}
    return dataclasses.field(metadata=meta, **kw)


def _number(x: float) -> str:
    """A bound as messages show it: 0.5, 1e-06, 1e+13 (not 10000000000000.0)."""
    return repr(x) if x == 0 or 1e-4 <= abs(x) < 1e6 else f"{x:g}"


def describe_range(meta: dict) -> str:
    """The range of an entry in words ("in (0.0, 1.0]", "in [0.0, 1.0)", ">= 0", "a finite
    number").
    """
    lo, hi = meta.get("lo"), meta.get("hi")
    lo = None if lo is None else _number(lo)
    hi = None if hi is None else _number(hi)
    if lo is not None and hi is not None:
        opening, closing = "([" [not meta.get("lo_open")], ")]" [not meta.get("hi_open")]
        return f"in {opening}{lo}, {hi}{closing}"
    if lo is not None:
        return f"{'>' if meta.get('lo_open') else '>='} {lo}"
    if hi is not None:
        return f"{'<' if meta.get('hi_open') else '<='} {hi}"
    return "a finite number"


def _choices(tp: Any, meta: dict) -> tuple[str, ...]:
    """The allowed values of a string entry: its ``choices``, else an enum type's values."""
    if meta.get("choices"):
        return tuple(meta["choices"])
    if isinstance(tp, type) and issubclass(tp, Enum):
        return tuple(m.value for m in tp)
    return ()


def _check_range(value: float, meta: dict, where: str, error: type[SchemaError]) -> None:
    lo, hi = meta.get("lo"), meta.get("hi")
    unit = f" {meta['unit']}" if meta.get("unit") else ""
    if abs(value) > MAX_INT and isinstance(value, int):
        raise error(f"{where} must be an integer of at most {MAX_INT}, got {value!r}")
    if not np.isfinite(float(value)):
        raise error(f"{where} must be a finite number{unit}, got {value!r}")
    bad = (lo is not None and (value < lo or (meta.get("lo_open") and value == lo))) or (
        hi is not None and (value > hi or (meta.get("hi_open") and value == hi))
    )
    if bad:
        why = f" ({meta['why']})" if meta.get("why") else ""
        raise error(f"{where} must be {describe_range(meta)}{unit}{why}, got {value!r}")


def _convert(tp: Any, value: Any, meta: dict, where: str, error: type[SchemaError]) -> Any:
    origin = typing.get_origin(tp)
    if origin in (typing.Union, types.UnionType):
        args = [a for a in typing.get_args(tp) if a is not type(None)]
        return None if value is None else _convert(args[0], value, meta, where, error)
    if dataclasses.is_dataclass(tp):
        return parse_section(tp, value, where, error=error)
    if origin is tuple:
        args = typing.get_args(tp)
        if not isinstance(value, (list, tuple)):
            raise error(f"{where} must be a list, got {value!r}")
        if args[-1] is not Ellipsis and len(value) != len(args):
            raise error(f"{where} must have {len(args)} entries, got {len(value)}")
        inner = args[0]
        return tuple(_convert(inner, v, meta, f"{where}[{k}]", error)
                     for k, v in enumerate(value))
    if tp is float:
        value = yaml11_number(value)
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise error(f"{where} must be a number, got {value!r}")
        value = float(value)
        _check_range(value, meta, where, error)
        return value
    if tp is int:
        if isinstance(value, bool) or not isinstance(value, int):
            raise error(f"{where} must be an integer, got {value!r}")
        _check_range(value, meta, where, error)
        return value
    if tp is str or (isinstance(tp, type) and issubclass(tp, Enum)):
        if not isinstance(value, str):
            raise error(f"{where} must be a string, got {value!r}")
        allowed = _choices(tp, meta)
        if allowed and value not in allowed:
            raise error(f"{where} must be one of {list(allowed)}, got {value!r}")
        return value if tp is str else tp(value)
    if tp is bool:
        if not isinstance(value, bool):
            raise error(f"{where} must be true or false, got {value!r}")
        return value
    if tp is dict or origin in (dict, Mapping):
        if not isinstance(value, dict):
            raise error(f"{where} must be a mapping, got {value!r}")
        return value
    raise TypeError(f"unsupported schema field type {tp!r} at {where}")


def unknown_key(where: str, key: Any, allowed: typing.Iterable[str], *, context: str = "") -> str:
    """The message for ``key``, not a key of the mapping at ``where``: its path, the allowed
    key it is most likely a misspelling of (if one is close) and every allowed key.

    Parameters
    ----------
    where : str
        Key path of the mapping ("" for the top level).
    key : Any
        The unknown key (YAML keys need not be strings).
    allowed : iterable of str
        The keys the mapping takes.
    context : str
        Said after the path (e.g. ``" for type disk"``).

    >>> unknown_key("object", "materal", ["material", "mesh", "shape"])
    "unknown key object.materal: did you mean 'material'? (allowed: ['material', 'mesh', \
'shape'])"
    """
    allowed = sorted(allowed)
    path = f"{where}.{key}" if where else str(key)
    close = difflib.get_close_matches(str(key), allowed, n=1)
    guess = f": did you mean {close[0]!r}?" if close else ""
    return f"unknown key {path}{context}{guess} (allowed: {allowed})"


def parse_section(cls: type, data: Any, where: str, *,
                  error: type[SchemaError] = SchemaError) -> Any:
    """Parse mapping ``data`` into dataclass ``cls``; errors name ``where.<field>``.

    Parameters
    ----------
    cls : type
        A dataclass whose fields are declared with :func:`spec`.
    data : Any
        The YAML value (must be a mapping).
    where : str
        Key path of ``data`` in its document ("" for the top level).
    error : type of SchemaError
        The exception raised for a bad entry (e.g. ``SceneError``).
    """
    if not isinstance(data, dict):
        raise error(f"{where} must be a mapping, got {data!r}")
    hints = typing.get_type_hints(cls)
    fields = {f.name: f for f in dataclasses.fields(cls)}
    unknown = sorted(set(data) - set(fields), key=str)
    if unknown:
        raise error(unknown_key(where, unknown[0], fields))
    kwargs = {}
    for name, f in fields.items():
        path = f"{where}.{name}" if where else name
        if name not in data:
            if f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING:
                raise error(f"missing required key {path}")
            continue
        kwargs[name] = _convert(hints[name], data[name], dict(f.metadata), path, error)
    return cls(**kwargs)


def _default(value: Any) -> str:
    """``default X`` for a field's scalar default as YAML writes it (an enum by its value, a
    bool as true/false, a number as :func:`_number`), "" for none, None, "" or a section.

    >>> _default(1e-3), _default(4), _default(False), _default(None), _default("")
    ('default 0.001', 'default 4', 'default false', '', '')
    """
    if isinstance(value, Enum):
        value = value.value
    if isinstance(value, bool):
        return f"default {str(value).lower()}"
    if isinstance(value, (int, float)):
        return f"default {value if isinstance(value, int) else _number(value)}"
    if isinstance(value, str) and value:
        return f"default {value}"
    return ""


def key_reference(
    cls: type, prefix: str = "", width: int = 38, nested: dict[str, tuple[type, str]] | None = None
) -> list[str]:
    """One line per key of dataclass ``cls`` (and its sections): path, doc, unit, range, default.

    Lists of sections (``tuple[Section, ...]``) are shown as ``key[]``; ``nested`` maps a key
    path to (section class, prefix) for mappings whose values are sections.
    """
    nested = nested or {}
    lines: list[str] = []
    hints = typing.get_type_hints(cls)
    for f in dataclasses.fields(cls):
        meta = f.metadata
        tp = hints[f.name]
        inner = ([a for a in typing.get_args(tp) if a is not type(None)] or [tp])[0]
        path = f"{prefix}{f.name}"
        if typing.get_origin(inner) is tuple and dataclasses.is_dataclass(
            typing.get_args(inner)[0]
        ):
            inner, path = typing.get_args(inner)[0], path + "[]"
        element = (typing.get_args(inner) or (inner,))[0]
        req = f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING
        ranged = meta.get("lo") is not None or meta.get("hi") is not None
        choices = _choices(element, dict(meta))
        extra = [
            x
            for x in (
                meta.get("unit"),
                describe_range(dict(meta)) if ranged else "",
                "one of " + "/".join(choices) if choices else "",
                "required" if req else _default(f.default),
            )
            if x
        ]
        lines.append(
            f"{path:{width}s} {meta.get('doc', '')}" + (f" [{', '.join(extra)}]" if extra else "")
        )
        if dataclasses.is_dataclass(inner):
            lines += key_reference(inner, path + ".", width, nested)
        if path in nested:
            lines += key_reference(nested[path][0], nested[path][1], width, nested)
    return lines
