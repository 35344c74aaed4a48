# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Complete ``ros2msg`` message definitions and RIHS01 type hashes from installed interfaces.

rosbag2 stores a *complete message definition* per type in the MCAP schema record: the type's
``.msg`` text first, then every type it uses (recursively, each once, in order of first use),
each preceded by a line of 80 ``=`` and a line ``MSG: <package>/msg/<Type>``
(ros2/rosbag2 docs/message_definition_encoding.md). The texts come from the ``.msg`` files
every interface package installs under ``share/<package>/msg`` (and ``.action`` files for the
messages an action generates); the type hash from the generated ``.json`` type description.
Install prefixes are searched in ``AMENT_PREFIX_PATH`` order, then ``sys.prefix`` (the pip
route installs everything there).
"""
from __future__ import annotations

import functools
import json
import os
import re
import sys
from pathlib import Path

PRIMITIVES = frozenset({
    "bool", "byte", "char", "float32", "float64", "int8", "uint8", "int16", "uint16", "int32",
    "uint32", "int64", "uint64", "string", "wstring"})
SEPARATOR = "=" * 80
CONSTANT = re.compile(r"^\S+\s+\w+\s*=")
"""A constant line: ``<type> NAME=value``."""
ACTION_PARTS = {"_Goal": 0, "_Result": 1, "_Feedback": 2}
"""Message of an action -> its section of the ``.action`` file."""
ACTION_WRAPPERS = {
    "_FeedbackMessage":
        "unique_identifier_msgs/UUID goal_id\n{package}/action/{action}_Feedback feedback\n",
}
"""Messages rosidl wraps around an action's sections (their definition, formatted)."""


class SchemaError(LookupError):
    """An interface definition is not installed."""


def prefixes() -> list[Path]:
    """Install prefixes searched for ``share/<package>`` (AMENT_PREFIX_PATH, then sys.prefix)."""
    paths = [Path(p) for p in os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep) if p]
    return paths + [Path(sys.prefix)]


def interface_file(package: str, kind: str, name: str, suffix: str) -> Path:
    """``share/<package>/<kind>/<name><suffix>`` in the first prefix that has it."""
    for prefix in prefixes():
        path = prefix / "share" / package / kind / f"{name}{suffix}"
        if path.is_file():
            return path
    raise SchemaError(f"{package}/{kind}/{name}{suffix} is not installed under "
                      f"{[str(p) for p in prefixes()]}")


def split_type(type_name: str) -> tuple[str, str, str]:
    """'pkg/msg/Type' (or 'pkg/Type') -> (pkg, kind, Type)."""
    parts = type_name.split("/")
    if len(parts) == 2:
        return parts[0], "msg", parts[1]
    if len(parts) == 3:
        return parts[0], parts[1], parts[2]
    raise SchemaError(f"not an interface type name: {type_name!r}")


@functools.lru_cache(maxsize=None)
def own_text(type_name: str) -> str:
    """The ``.msg`` text of one type (no dependencies)."""
    package, kind, name = split_type(type_name)
    if kind == "msg":
        return interface_file(package, "msg", name, ".msg").read_text()
    for suffix, template in ACTION_WRAPPERS.items():
        if name.endswith(suffix):
            return template.format(package=package, action=name[: -len(suffix)])
    for suffix, index in ACTION_PARTS.items():
        if name.endswith(suffix):
            text = interface_file(package, "action", name[: -len(suffix)], ".action").read_text()
            section = re.split(r"^---\s*$", text, flags=re.MULTILINE)[index].strip("\n") + "\n"
            return qualify(section, package)
    raise SchemaError(f"no definition for {type_name!r}")


def _fields(text: str) -> list[list[str]]:
    """Tokens of the field lines of a ``.msg`` text (comments, blanks and constants dropped)."""
    out = []
    for raw in text.splitlines():
        line = raw.split("#", 1)[0].strip()
        if line and not CONSTANT.match(line):
            out.append(line.split())
    return out


def qualify(text: str, package: str) -> str:
    """An action section's text with same-package field types written ``package/Type``.

    Inside an ``.action`` file a bare ``Type`` names ``package/msg/Type``; readers that resolve
    bare names against the enclosing type's namespace (``package/action``) need it spelled out.
    """
    out = []
    for line in text.splitlines(keepends=True):
        code = line.split("#", 1)[0]
        tokens = code.split()
        base = re.split(r"[\[<]", tokens[0], maxsplit=1)[0] if tokens else ""
        if tokens and not CONSTANT.match(code.strip()) and base not in PRIMITIVES and "/" not in base:
            line = line.replace(tokens[0], f"{package}/{tokens[0]}", 1)
        out.append(line)
    return "".join(out)


def field_types(text: str, package: str) -> list[str]:
    """Full names 'pkg/msg/Type' of the non-primitive field types of a ``.msg`` text, in order."""
    out = []
    for tokens in _fields(text):
        base = re.split(r"[\[<]", tokens[0], maxsplit=1)[0]
        if base in PRIMITIVES:
            continue
        if "/" not in base:
            base = f"{package}/{base}"
        pkg, _, name = base.rpartition("/")
        kind = "action" if pkg.endswith("/action") else "msg"
        out.append(f"{pkg.split('/')[0]}/{kind}/{name}")
    return out


def message_definition(type_name: str) -> str:
    """The complete ``ros2msg`` definition of ``type_name`` ('pkg/msg/Type')."""
    seen: list[str] = []

    def visit(name: str) -> None:
        for dep in field_types(own_text(name), split_type(name)[0]):
            if dep not in seen and dep != type_name:
                seen.append(dep)
                visit(dep)

    visit(type_name)
    parts = [own_text(type_name).rstrip("\n")]
    for dep in seen:
        package, kind, name = split_type(dep)
        parts.append(f"{SEPARATOR}\nMSG: {package}/{kind}/{name}\n{own_text(dep).rstrip(chr(10))}")
    return "\n".join(parts) + "\n"


@functools.lru_cache(maxsize=None)
def type_hash(type_name: str) -> str:
    """The RIHS01 type hash of ``type_name`` from its installed type description ('' if none)."""
    package, kind, name = split_type(type_name)
    stem = name
    if kind == "action":
        stem = next((name[: -len(s)] for s in (*ACTION_WRAPPERS, *ACTION_PARTS)
                     if name.endswith(s)), name)
    try:
        data = json.loads(interface_file(package, kind, stem, ".json").read_text())
    except SchemaError:
        return ""
    wanted = f"{package}/{kind}/{name}"
    return next((h["hash_string"] for h in data.get("type_hashes", ())
                 if h["type_name"] == wanted), "")


def starts_with_stamp(type_name: str) -> bool:
    """True if the type's first field is a ``std_msgs/Header`` or ``builtin_interfaces/Time``.

    Its CDR then carries the stamp right after the 4-byte encapsulation header.
    """
    fields = _fields(own_text(type_name))
    return bool(fields) and fields[0][0] in ("std_msgs/Header", "builtin_interfaces/Time")
