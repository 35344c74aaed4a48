# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The domain vocabulary reaches the code: distinct names never compare equal or share a hash,
the result types carry the enums, and no module spells a domain word as a string literal
(issue 30 §3).
"""

from __future__ import annotations

import ast
import dataclasses
import itertools
import json
import typing
from enum import Enum
from pathlib import Path

import pytest

import squeeze_grasp_ros
from squeeze_grasp_ros.mechanics import vocabulary
from squeeze_grasp_ros.mechanics.ring.squeeze import RingGrasp
from squeeze_grasp_ros.mechanics.squeeze.contact_state import ContactNode, Event
from squeeze_grasp_ros.mechanics.squeeze.events import EventSqueeze
from squeeze_grasp_ros.mechanics.vocabulary import (
    ContactKind,
    ContactMode,
    Effect,
    EventType,
    Finger,
    RingLimit,
    SqueezeKind,
    Termination,
)
from squeeze_grasp_ros.resources import scene_file
from squeeze_grasp_ros.scene import load_scene

PACKAGE = Path(squeeze_grasp_ros.__file__).parent
VOCABULARIES = [v for v in vars(vocabulary).values()
                if isinstance(v, type) and issubclass(v, Enum)
                and v.__module__ == vocabulary.__name__ and len(v)]


def test_distinct_vocabularies_never_compare_equal_on_a_shared_string():
    """Finger.A and EventType.A, Termination.STRAIN_LIMIT and Effect.STRAIN_LIMIT, ContactKind
    and Effect FRICTION, ShapeFit and RingLimit NONE: the same string, different things; unequal
    both ways, other hashes.
    """
    shared = 0
    for a, b in itertools.combinations(VOCABULARIES, 2):
        for x, y in itertools.product(a, b):
            if x.value == y.value and (issubclass(a, vocabulary._Code)
                                       or issubclass(b, vocabulary._Code)):
                shared += 1
                assert x != y and y != x and hash(x) != hash(y), (x, y)
                assert {x: 1}.get(y) is None
    assert shared == 4
    assert Finger.A != EventType.A and Termination.STRAIN_LIMIT != Effect.STRAIN_LIMIT


def test_a_string_two_vocabularies_share_is_a_code_in_one_of_them():
    """Two string enums are equal on a shared string (each equals the plain string), so a
    shared string makes one of its vocabularies a code.
    """
    for a, b in itertools.combinations(VOCABULARIES, 2):
        shared = set(a.values()) & set(b.values())
        assert not shared or issubclass(a, vocabulary._Code) or issubclass(b, vocabulary._Code), (
            a.__name__, b.__name__, shared)


def test_codes_are_their_strings_in_files_and_messages():
    assert [f"{t}" for t in EventType] == ["A", "B", "C", "D"]
    assert json.dumps([t.value for t in EventType]) == '["A", "B", "C", "D"]'
    assert EventType("C") is EventType.C and Effect("pickup") is Effect.PICKUP
    with pytest.raises(ValueError):
        EventType("F1")
    with pytest.raises(TypeError, match="Effect"):
        load_scene(scene_file("foam_square_strain_limit")).has(Termination.STRAIN_LIMIT)


def test_squeeze_kinds_that_may_be_asked_for():
    assert SqueezeKind.planned() == ("stable", "pure")
    assert SqueezeKind.CUSTOM.value not in SqueezeKind.planned()


@pytest.mark.parametrize("cls, name, vocabulary_type", [
    (Event, "type", EventType), (Event, "finger", Finger), (ContactNode, "mode", ContactMode),
    (EventSqueeze, "termination", Termination), (EventSqueeze, "kind", SqueezeKind),
    (RingGrasp, "limit", RingLimit),
])
def test_result_fields_are_typed_with_the_vocabulary(cls, name, vocabulary_type):
    hints = typing.get_type_hints(cls)
    assert hints[name] is vocabulary_type


def test_results_carry_enum_members(tmp_path):
    from squeeze_grasp_ros.scene import GraspSetup

    setup = GraspSetup.build(load_scene(scene_file("resist_fig10")))
    res = setup.event_squeeze()
    assert res.kind is SqueezeKind.CUSTOM and isinstance(res.termination, Termination)
    assert all(type(e.type) is EventType and isinstance(e.finger, Finger) for e in res.events)
    assert all(type(c.mode) is ContactMode for c in res.state.contacts)
    assert setup.scene.adversary.contacts is ContactKind.FRICTION
    assert set(res.event_counts) == set(EventType.values())


def test_bare_dict_fields_are_gone_from_the_results():
    """Results and specs hold typed mappings (``Mapping[Finger, ...]``), not bare ``dict``."""
    from squeeze_grasp_ros.mechanics.resistance.frictional import FrictionalResistance
    from squeeze_grasp_ros.mechanics.resistance.optimal import Resistance, ResistanceGrasp
    from squeeze_grasp_ros.scene import Scene

    bare = [f"{cls.__name__}.{f.name}" for cls in (EventSqueeze, FrictionalResistance,
                                                    Resistance, ResistanceGrasp, Scene)
            for f in dataclasses.fields(cls) if typing.get_type_hints(cls)[f.name] is dict]
    assert bare == []


# --------------------------------------------------------------------------- domain literals


NOT_DOMAIN: dict[tuple[str, str], str] = {
    ("bench/__init__.py", "ring"): "the benchmark section named after rings",
    ("commands/__init__.py", "ring"): "the CLI verb named after rings",
    ("bench/material_models.py", "disk"): "the shipped scene's file name",
    ("commands/calibrate.py", "friction"): "the calibrate JSON key of the measured mu",
    ("mechanics/squeeze/contact_state.py", "slip"): "the JSON key of the slip direction field",
    ("mechanics/squeeze/events.py", "slip"): "the JSON key of the slip direction field",
    ("planning/requests.py", "strain_limit"): "the request field named in its error",
    ("planning/gripper.py", "strain_limit"): "the request field named in its error",
    ("ros/messages/contacts.py", "B"): "the array typecode of unsigned bytes",
    ("scene/checks.py", "friction"): "a scene section name (SECTION_EFFECT's keys)",
    ("scene/checks.py", "strain_limit"): "a scene section name (SECTION_EFFECT's keys)",
    ("scene/checks.py", "pickup"): "a scene section name (SECTION_EFFECT's keys)",
    ("scene/checks.py", "adversary"): "a scene section name (SECTION_EFFECT's keys)",
    ("scene/goal.py", "adversary"): "the executor goal's field",
    ("sweep/evaluate.py", "picked_up"): "the dataset column",
    ("sweep/spec.py", "friction"): "the sweep spec's key",
    ("mechanics/squeeze/events.py", "strain_limit"): "the squeeze JSON's key of its limit",
    ("commands/squeeze.py", "strain_limit"): "the squeeze JSON's key of its limit",
    ("perception/camera_info.py", "D"): "the CameraInfo field of the distortion coefficients",
    ("extras.py", "cholmod"): "the pip extra named after CHOLMOD",
    ("extras.py", "qdldl"): "the Python module qdldl (a required dependency)",
    ("scene/specs.py", "adversary"): "the scene section name in a field path",
    ("sweep/plan.py", "friction"): "the sweep's parameter axis (the spec's key)",
    ("commands/render.py", "camera"): "the render JSON's key of the camera info",
    ("ros/nodes/recorder.py", "camera"): "the recorder parameter named after the camera",
    ("scene/checks.py", "camera"): "a scene section name (SECTION_EFFECT's keys)",
    ("planning/typed_objects.py", "point"): "the placement key of a scene finger",
    ("planning/typed_objects.py", "friction"): "a scene section name",
    ("api.py", "polygon"): "the name of the polygon() constructor in __all__",
}
"""Literals that spell a vocabulary word but mean something else, with what they mean."""
NOT_COUNTED = {RingLimit.NONE.value: "the English word (messages, matplotlib colours, a world "
                                     "that never ended)"}
"""Vocabulary values not counted anywhere, and why."""


def _docstrings(tree: ast.Module) -> set[int]:
    out = set()
    for node in ast.walk(tree):
        body = getattr(node, "body", None)
        if not isinstance(body, list):
            continue
        for k, child in enumerate(body):
            doc = (isinstance(child, ast.Expr) and isinstance(child.value, ast.Constant)
                   and isinstance(child.value.value, str))
            first = k == 0 and isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef,
                                                 ast.AsyncFunctionDef))
            after_assignment = k > 0 and isinstance(body[k - 1], (ast.Assign, ast.AnnAssign))
            if doc and (first or after_assignment):
                out.add(id(child.value))
    return out


def _skipped(tree: ast.Module) -> set[int]:
    """Docstrings, the literal parts of f-strings, and the member values of enum classes."""
    out = _docstrings(tree)
    for node in ast.walk(tree):
        if isinstance(node, ast.JoinedStr):
            out.update(id(v) for v in node.values if isinstance(v, ast.Constant))
        if isinstance(node, ast.ClassDef) and any(
                isinstance(b, ast.Name) and b.id in ("Enum", "str") or
                isinstance(b, ast.Attribute) and b.attr == "Enum" for b in node.bases):
            out.update(id(c) for c in ast.walk(node) if isinstance(c, ast.Constant))
    return out


def domain_literals() -> list[str]:
    words = {m.value for v in VOCABULARIES for m in v} - set(NOT_COUNTED)
    sites = []
    for path in sorted(PACKAGE.rglob("*.py")):
        rel = path.relative_to(PACKAGE).as_posix()
        if rel == "mechanics/vocabulary.py":
            continue
        tree = ast.parse(path.read_text(encoding="utf-8"))
        skipped = _skipped(tree)
        for node in ast.walk(tree):
            if (isinstance(node, ast.Constant) and isinstance(node.value, str)
                    and node.value in words and id(node) not in skipped
                    and (rel, node.value) not in NOT_DOMAIN):
                sites.append(f"{rel}:{node.lineno}: {node.value!r}")
    return sites


def test_no_domain_word_is_spelled_as_a_literal():
    """Fingers, event letters, modes, kinds, effects, models, shapes, contact kinds and limits
    are written through their enums everywhere outside ``mechanics/vocabulary.py`` (JSON keys
    too); the few literals that spell such a word but mean something else are listed with
    their meaning.
    """
    found = domain_literals()
    assert found == [], "\n".join(found)


def test_the_literal_count_is_not_vacuous():
    """The counter finds a literal where one is written."""
    tree = ast.parse('x = {"F1": 1}\nif kind == "stable": pass\nf"C{k}"\n')
    skipped = _skipped(tree)
    found = [n.value for n in ast.walk(tree) if isinstance(n, ast.Constant)
             and isinstance(n.value, str) and id(n) not in skipped]
    assert sorted(found) == ["F1", "stable"]
    assert len(VOCABULARIES) >= 12
