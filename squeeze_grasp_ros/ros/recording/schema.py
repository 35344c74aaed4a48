# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Complete ``ros2msg`` message definitions and RIHS01 type hashes from installed interfaces.

The MCAP schema record of a type holds its *complete message definition*, written exactly as
rosbag2 (Jazzy, ``rosbag2_cpp::LocalMessageDefinitionSource``) writes it, so that every reader
that understands rosbag2's bags (Foxglove, ``mcap_ros2``, rosbags) understands ours:

* the root type's ``.msg`` file, verbatim (comments and constants included);
* then, depth first, each type it uses, once: a newline, a line of 80 ``=``, a line
  ``MSG: <package>/<Type>`` (the name as the field spells it; a bare ``Type`` becomes
  ``<package>/<Type>`` of the enclosing package, never ``<package>/msg/<Type>``) and that
  type's ``.msg`` file verbatim. The types a definition uses are visited in sorted order.

The texts come from the ``.msg`` files every interface package installs under
``share/<package>/msg``. rosbag2 writes no definition for the messages an action generates
(``_action/feedback``), and does not record those hidden topics unless asked; when asked, we
compose their definitions from the ``.action`` file, naming them as rosidl does
(``<package>/action/<Action>_Feedback``) so that the type hashes readers recompute from the
text match the recorded ones. Foxglove and rosbags decode them; ``mcap_ros2`` (0.6) cannot,
because it accepts only message names matching ``[A-Z][A-Za-z0-9]*`` and rosidl's action
messages have an underscore. Install prefixes are searched in ``AMENT_PREFIX_PATH``
order, then ``sys.prefix`` (the pip route installs everything there).

>>> print(message_definition("std_msgs/msg/Header").split(SEPARATOR)[1].splitlines()[1])
MSG: builtin_interfaces/Time
"""

from __future__ import annotations

import functools
import json
import os
import re
import sys
from pathlib import Path

PRIMITIVES = frozenset(
    {
        "bool",
        "byte",
        "char",
        "float32",
        "float64",
        "int8",
        "uint8",
        "int16",
        "uint16",
        "int32",
        "uint32",
        "int64",
        "uint64",
        "string",
        "wstring",
    }
)
SEPARATOR = "=" * 80
FIELD_TYPE = re.compile(r"(?:^|\n)\s*([a-zA-Z0-9_/]+)(?:\[[^\]]*\])?\s+")
"""The type token at the start of a line, as rosbag2's dependency scan reads it."""
CONSTANT = re.compile(r"^\S+\s+\w+\s*=")
"""A constant line: ``<type> NAME=value``."""
ACTION_PARTS = {"_Goal": 0, "_Result": 1, "_Feedback": 2}
"""Message of an action -> its section of the ``.action`` file."""
ACTION_WRAPPERS = {
    "_FeedbackMessage": "unique_identifier_msgs/UUID goal_id\n{package}/action/{action}_Feedback "
                        "feedback\n",
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
    raise SchemaError(
        f"{package}/{kind}/{name}{suffix} is not installed under {[str(p) for p in prefixes()]}"
    )


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
    """The definition text of one type (no dependencies): its ``.msg`` file, or the section of
    the ``.action`` file (or rosidl's wrapper) for a message an action generates.
    """
    package, kind, name = split_type(type_name)
    if kind == "msg":
        try:
            return interface_file(package, "msg", name, ".msg").read_text()
        except SchemaError:
            if not name.endswith((*ACTION_WRAPPERS, *ACTION_PARTS)):
                raise
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
        if (
            tokens
            and not CONSTANT.match(code.strip())
            and base not in PRIMITIVES
            and "/" not in base
        ):
            line = line.replace(tokens[0], f"{package}/{tokens[0]}", 1)
        out.append(line)
    return "".join(out)


def dependencies(text: str, package: str) -> list[str]:
    """Types a definition text uses, as rosbag2 names them ('pkg/Type'), sorted, each once."""
    found = set()
    for match in FIELD_TYPE.finditer(text):
        base = match.group(1)
        if base in PRIMITIVES:
            continue
        found.add(base if "/" in base else f"{package}/{base}")
    return sorted(found)


def message_definition(type_name: str) -> str:
    """The complete ``ros2msg`` definition of ``type_name`` ('pkg/msg/Type'), as rosbag2 writes
    it.
    """
    seen: set[str] = set()

    def text_with_dependencies(name: str) -> str:
        own = own_text(name)
        parts = [own]
        for dep in dependencies(own, split_type(name)[0]):
            if dep not in seen:
                seen.add(dep)
                parts.append(f"\n{SEPARATOR}\nMSG: {dep}\n{text_with_dependencies(dep)}")
        return "".join(parts)

    return text_with_dependencies(type_name)


@functools.lru_cache(maxsize=None)
def type_hash(type_name: str) -> str:
    """The RIHS01 type hash of ``type_name`` from its installed type description ('' if none)."""
    package, kind, name = split_type(type_name)
    stem = name
    if kind == "action":
        stem = next(
            (name[: -len(s)] for s in (*ACTION_WRAPPERS, *ACTION_PARTS) if name.endswith(s)), name
        )
    try:
        data = json.loads(interface_file(package, kind, stem, ".json").read_text())
    except SchemaError:
        return ""
    wanted = f"{package}/{kind}/{name}"
    return next(
        (h["hash_string"] for h in data.get("type_hashes", ()) if h["type_name"] == wanted), ""
    )


def starts_with_stamp(type_name: str) -> bool:
    """True if the type's first field is a ``std_msgs/Header`` or ``builtin_interfaces/Time``.

    Its CDR then carries the stamp right after the 4-byte encapsulation header.
    """
    fields = _fields(own_text(type_name))
    return bool(fields) and fields[0][0] in ("std_msgs/Header", "builtin_interfaces/Time")
