# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The tracker's short cut for a tick whose patches keep their taxels (``same_spans``) against
the full grouping (``connected_groups``), and the events of both paths on random taxel readings.
"""
from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from squeeze_grasp_ros.control import tracker as tracker_module
from squeeze_grasp_ros.control.tracker import (
    ContactTracker,
    FingerSample,
    Patch,
    TrackerConfig,
    connected_groups,
    same_spans,
)

TAXELS = 24


def _patches(loaded: list[bool]) -> list[Patch]:
    """The patches of a loaded-taxel mask (each maximal run of loaded taxels)."""
    out, start = [], None
    for k, on in enumerate([*loaded, False]):
        if on and start is None:
            start = k
        elif not on and start is not None:
            out.append(Patch("F1", 0.0, 1.0, 0.0, "stick", 0, start, k - 1))
            start = None
    return out


@settings(max_examples=300, deadline=None)
@given(st.lists(st.booleans(), min_size=TAXELS, max_size=TAXELS),
       st.lists(st.booleans(), min_size=TAXELS, max_size=TAXELS), st.integers(0, 2))
def test_same_spans_is_the_one_to_one_grouping(before, after, margin):
    """Where the short cut applies, the full grouping pairs patch k with patch k and nothing
    else; where the grouping is one to one in order with equal ranges, the short cut applies.
    """
    previous, current = _patches(before), _patches(after)
    groups = connected_groups(previous, current, margin)
    one_to_one = [([k], [k]) for k in range(len(current))]
    equal = len(previous) == len(current) and all(
        (p.first, p.last) == (c.first, c.last) for p, c in zip(previous, current))
    if same_spans(previous, current, margin):
        assert groups == one_to_one
    else:
        assert not (equal and groups == one_to_one)


def _readings(rng: np.random.Generator, ticks: int) -> list[FingerSample]:
    """Tactile readings of one finger whose loaded taxels mostly stay put and whose patches
    change mode now and then (every event type occurs).
    """
    angles = np.linspace(-1.0, 1.0, TAXELS)
    loaded = rng.random(TAXELS) < 0.5
    out = []
    for tick in range(ticks):
        if rng.random() < 0.2:
            loaded = loaded ^ (rng.random(TAXELS) < 0.1)
        normal = np.where(loaded, 0.01 + rng.random(TAXELS), 0.0)
        tangential = normal * 0.4 * rng.choice([-1.0, -0.5, 0.5, 1.0], TAXELS)
        out.append(FingerSample(position=np.array([1e-4 * tick, 0.0]), normal=normal,
                                tangential=tangential, angles=angles,
                                tactile_stamp_ns=tick * 1_000_000))
    return out


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(0, 2))
def test_events_equal_with_and_without_the_short_cut(seed, margin):
    """Every tick's events and patches are the same when the tracker always groups in full."""
    samples = _readings(np.random.default_rng(seed), 40)
    config = TrackerConfig(mu=0.4, match_margin=margin)
    fast = ContactTracker(config, ["F1"], ["tactile"])
    outputs = [fast.update(s.tactile_stamp_ns, {"F1": s}) for s in samples]
    original = tracker_module.same_spans
    tracker_module.same_spans = lambda *_: False
    try:
        full = ContactTracker(config, ["F1"], ["tactile"])
        expected = [full.update(s.tactile_stamp_ns, {"F1": s}) for s in samples]
    finally:
        tracker_module.same_spans = original
    assert [o.events for o in outputs] == [o.events for o in expected]
    assert [o.patches for o in outputs] == [o.patches for o in expected]
    if margin == 0:  # wider margins merge this finger's close patches into groups
        assert any(o.events for o in outputs)
