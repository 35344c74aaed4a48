# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
r"""Reading untrusted input: bounded file reads, YAML without aliases, confined paths.

Scenes, outlines and sweep specs come from users and, through the planner's services, from any
ROS client. Reading them must not exhaust memory (a file is read up to a byte limit, YAML
aliases are refused so a small document cannot expand into a huge one), must not leak what
other files hold (no error message quotes file contents), and, for paths a service accepts,
must not reach outside the folders the operator allows.

>>> load_yaml("a: 1", what="scene")
{'a': 1}
>>> load_yaml("a: &x [1]\nb: *x", what="scene")  # doctest: +IGNORE_EXCEPTION_DETAIL
Traceback (most recent call last):
InputError: scene: YAML aliases (*name) are not accepted (line 2, column 4)
"""
from __future__ import annotations

import os
import stat
from collections.abc import Iterable
from pathlib import Path
from typing import Any

import yaml

__all__ = ["InputError", "MAX_FILE_BYTES", "MAX_TEXT_BYTES", "SHOWN_CHARS", "confine",
           "load_yaml", "read_bytes", "read_text", "shown", "yaml11_number"]

SHOWN_CHARS = 40
"""Most characters of a client's string that a message or log line quotes."""


def shown(value: str, limit: int = SHOWN_CHARS) -> str:
    """``repr(value)``, cut after ``limit`` characters with the full length said.

    >>> shown("F" * 50, 4)
    "'FFFF...' (50 characters)"
    """
    if len(value) <= limit:
        return repr(value)
    text = repr(value[:limit])
    return f"{text[:-1]}...{text[-1]} ({len(value)} characters)"


def yaml11_number(value: Any) -> Any:
    """``value`` as a float when it is text that reads as a number, else ``value`` unchanged.

    YAML 1.1 (PyYAML) reads a number with an exponent as a float only with both a dot and a
    signed exponent (``5.0e+4``), so ``5e4``, ``1e-3`` and ``5.0e4`` arrive as strings; a parsed
    YAML value passes through this before its type is checked.

    >>> yaml11_number("5e4"), yaml11_number(3), yaml11_number("five")
    (50000.0, 3, 'five')
    """
    if isinstance(value, str):
        try:
            return float(value)
        except ValueError:
            return value
    return value


MAX_FILE_BYTES = 8 * 1024 * 1024
"""Bytes read at most from a scene, spec or outline file (8 MiB)."""
MAX_TEXT_BYTES = 1024 * 1024
"""Bytes of YAML text accepted at most in one document or service request field (1 MiB)."""


class InputError(ValueError):
    """Input that cannot be read safely; the message never quotes the input's contents."""


class _NoAliasLoader(yaml.SafeLoader):
    """The safe loader, refusing aliases: no document can expand beyond its own size."""

    def compose_node(self, parent, index):  # noqa: D102 (PyYAML hook)
        if self.check_event(yaml.AliasEvent):
            mark = self.peek_event().start_mark
            raise InputError(f"YAML aliases (*name) are not accepted (line {mark.line + 1}, "
                             f"column {mark.column + 1})")
        return super().compose_node(parent, index)


def load_yaml(text: str, *, what: str, max_bytes: int = MAX_TEXT_BYTES) -> Any:
    """Parse one YAML document with the safe loader, without aliases, up to ``max_bytes``.

    Raises
    ------
    InputError
        Too large, an alias, or not YAML; the message gives line and column, never the text.
    """
    if len(text.encode("utf-8", "surrogatepass")) > max_bytes:
        raise InputError(f"{what}: YAML text is larger than the {max_bytes}-byte limit")
    try:
        return yaml.load(text, Loader=_NoAliasLoader)  # noqa: S506 (a SafeLoader subclass)
    except InputError as exc:
        raise InputError(f"{what}: {exc}") from None
    except yaml.MarkedYAMLError as exc:
        where = (f" at line {exc.problem_mark.line + 1}, column {exc.problem_mark.column + 1}"
                 if exc.problem_mark else "")
        raise InputError(f"{what}: invalid YAML{where}: {exc.problem}") from None
    except yaml.YAMLError:
        raise InputError(f"{what}: invalid YAML") from None
    except RecursionError:
        raise InputError(f"{what}: YAML nested too deeply") from None


def read_bytes(path: str | Path, *, what: str, max_bytes: int = MAX_FILE_BYTES) -> bytes:
    """The bytes of a regular file, read up to ``max_bytes``.

    The file is opened without blocking and checked on the open descriptor, so a FIFO, a device
    or a folder is refused at once (a FIFO named like a manifest used to hang the reader in
    ``open()``), and a sparse file of gigabytes is refused after ``max_bytes + 1`` bytes.

    Raises
    ------
    InputError
        Missing, not a regular file, unreadable or too large.
    """
    path = Path(path)
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
    except FileNotFoundError:
        raise InputError(f"{what} file not found: {path}") from None
    except OSError as exc:
        raise InputError(f"{what} file cannot be read: {path} ({exc.strerror})") from None
    try:
        info = os.fstat(fd)
        if not stat.S_ISREG(info.st_mode):
            raise InputError(f"{what} path is not a regular file: {path}")
        if info.st_size > max_bytes:
            raise InputError(f"{what} file is larger than the {max_bytes}-byte limit: {path}")
        with os.fdopen(os.dup(fd), "rb") as fh:
            data = fh.read(max_bytes + 1)
    except OSError as exc:
        raise InputError(f"{what} file cannot be read: {path} ({exc.strerror})") from None
    finally:
        os.close(fd)
    if len(data) > max_bytes:
        raise InputError(f"{what} file is larger than the {max_bytes}-byte limit: {path}")
    return data


def read_text(path: str | Path, *, what: str, max_bytes: int = MAX_FILE_BYTES) -> str:
    """The UTF-8 text of a regular file, read up to ``max_bytes`` (:func:`read_bytes`).

    Raises
    ------
    InputError
        Missing, not a regular file, unreadable, too large or not UTF-8 text.
    """
    data = read_bytes(path, what=what, max_bytes=max_bytes)
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise InputError(f"{what} file is not UTF-8 text (byte {exc.start}): {path}") from None


def confine(path: str | Path, roots: Iterable[str | Path], *, what: str) -> Path:
    """``path`` resolved (symlinks and ``..`` followed), if it lies inside one of ``roots``.

    Relative paths are taken from the current working directory.

    Raises
    ------
    InputError
        The resolved path is outside every root; the message names the roots, not the file.
    """
    resolved = Path(os.path.realpath(path))
    allowed = [Path(os.path.realpath(r)) for r in roots]
    if not any(resolved == root or root in resolved.parents for root in allowed):
        raise InputError(f"{what} {str(path)!r} is outside the allowed folders "
                         f"{[str(r) for r in allowed]} (planner parameter allowed_roots)")
    return resolved
