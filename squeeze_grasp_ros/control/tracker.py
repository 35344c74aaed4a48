# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The monitor's contact tracker: contact configuration and events from taxels and wrenches.

Taxels are not mesh nodes: a contact node between two taxels loads both, and sliding nodes move
across taxels. The tracker therefore reconstructs *contact patches*: maximal runs of
neighbouring loaded taxels (normal force above ``load_threshold``). A patch has the summed
normal force F_n and tangential force F_t of its taxels and their F_n-weighted mean angle. With
taxels finer than half the node spacing on the fingertip, every contact node forms its own patch
(the shipped scenes are built so); coarser arrays merge neighbouring nodes into one patch.

Per tick and finger, a patch and a patch of the previous tick are *connected* when their taxel
ranges overlap (widened by ``match_margin`` taxels on each side); the connected groups give the
events (types as in the paper):

- A (new contact): a patch connected to no previous patch, on a finger already in contact (the
  first patches of a finger are its initial contact, not an event, as in the paper);
- B (contact break): a previous patch connected to no patch;
- C (stick -> slip): a one-to-one connected patch whose cone usage |F_t| / (mu F_n) reached
  1 - ``edge_tolerance``;
- D (slip -> stick): a one-to-one connected patch whose cone usage fell below it again.

Patches that merge or split (sliding nodes moving across the taxels) are connected groups of
several patches and raise no event.

Events of one tick are ordered by finger (F1, F2, A), then B < D < C < A (the stepper's
``PROCESSING_ORDER``), then angle. Alarms (active while their condition holds):

- ``slip_imminent``: every loaded taxel of the finger uses at least ``alarm_ratio`` of its
  friction cone, all pushing the same way (a finger slips when all its contact nodes slide the
  same way, Sec. 5.1; the alarm comes first because alarm_ratio < 1). Off without friction.
- ``stale_sensor``: a sensor stream of the finger has no reading newer than ``stale_after`` s.
- ``contact_lost``: the finger had loaded taxels and has none now.
- ``prediction_mismatch`` (at the tick it is found): an observed event of a type and finger the
  planner did not predict within ``prediction_tolerance`` of depth, or a predicted one that
  the depth passed without being observed. Stick-slip events of *mirror patches* are exempt
  (below).

Mirror patches. A finger loaded symmetrically (a fingertip squeezing a symmetric object along
its symmetry axis) has pairs of contact patches mirrored about its force line, the direction of
the resultant of its patch forces: two patches on opposite sides of it whose mean angle lies
within ``mirror_tolerance`` of their angular separation from it. The tolerance follows from
the mesh and the outline (:func:`mirror_tolerance_for`): (e + R dtheta / 2) / (2 h) for
boundary spacing h, outline error e, fingertip radius R and taxel pitch dtheta, 0.05-0.07 for
the foam ring seen by the shipped camera (the default 0.05; measured on that ring: 0.01
squeezed along its symmetry axis, and 0.25 for the nearest pair of F1 touching 1 cm off it).
Which patch of a mirror pair sticks and which
slides is a tie: the mechanics decides it by round-off, so a mesh a few micrometres different
(an outline seen by a camera) decides it the other way, for the rest of the squeeze (the foam
ring on its axis: the world's side node of F2 sticks at 0.7-0.999 of its cone from 2.7 to
7.4 mm of depth where the planner's slides from 2.4 mm). The tie decides which patch of the
pair slides and when, not whether the finger has stick-slip events: an unpredicted C or D event
of a patch with a mirror partner at its tick raises no alarm when the prediction has C or D
events on that finger, and a predicted C or D the depth passed unobserved raises none while
its finger holds a mirror pair. New contacts and breaks (A, B) are always compared, and so are
C and D of fingers loaded off their symmetry line and of fingers the planner predicts none for.

Pickup (effect ``pickup``): the tracker reports a ``picked_up`` event when every finger in
contact can supply its share w / n_f of vertical friction, sum over its sticking taxels of
sqrt(mu^2 f_n^2 - f_t^2) (the stepper's criterion, on taxels instead of nodes).

Depth is the path length of the stacked measured fingertip translations (the stepper's depth).
Forces are those of the fingers *on the object* (the negated wrench, else the taxel sum).
"""
from __future__ import annotations

import functools
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np

from squeeze_grasp_ros.mechanics.errors import InvalidInputError
from squeeze_grasp_ros.mechanics.squeeze.event_key import PROCESSING_ORDER, processing_rank
from squeeze_grasp_ros.mechanics.vocabulary import (
    AlarmType,
    ContactMode,
    EventType,
    Finger,
    Termination,
)

STICK_SLIP = (EventType.C, EventType.D)
"""The events of a contact's mode (stick -> slip, slip -> stick)."""
STICK_TO_SLIP = (ContactMode.STICK, ContactMode.SLIP)
SLIP_TO_STICK = (ContactMode.SLIP, ContactMode.STICK)
"""A patch's (previous, current) modes at a C and at a D event."""


@dataclass(frozen=True)
class TrackerConfig:
    """Monitor parameters.

    Attributes
    ----------
    mu : float
        Friction coefficient of the fingertips (0: frictionless, no slip alarm).
    load_threshold : float
        A taxel is loaded above this normal force, N.
    edge_tolerance : float
        A patch slides when its cone usage is at least 1 - edge_tolerance.
    alarm_ratio : float
        Cone usage of every loaded taxel that raises ``slip_imminent`` (< 1).
    match_margin : int
        Taxels by which patch ranges are widened before testing them for overlap.
    stale_after : float
        Age of a finger's newest reading that makes it stale, s.
    weight : float or None
        Object weight for the pickup test, N (None: no pickup test).
    prediction_tolerance : float
        Depth tolerance when matching observed events to the prediction, m.
    relative_per_depth : float
        Relative depth per unit depth, 1/m (for reports).
    mirror_tolerance : float
        Two patches of a finger are a mirror pair when the mean of their angles lies within
        this fraction of their angular separation from the finger's force line (0: exact
        mirror images only; 0.5 at most; :func:`mirror_tolerance_for` derives it from the
        mesh spacing, the outline's error and the taxel pitch).
    """

    mu: float
    load_threshold: float = 0.002
    edge_tolerance: float = 1e-4
    alarm_ratio: float = 0.9
    match_margin: int = 0
    stale_after: float = 0.0025
    weight: float | None = None
    prediction_tolerance: float = 5e-4
    relative_per_depth: float = 0.0
    mirror_tolerance: float = 0.05


class FingerSample(NamedTuple):
    """The newest readings of one finger at a tick (object frame for positions and forces; a
    named tuple: two are built per tick, a frozen dataclass took 4 us for each).

    Attributes
    ----------
    position : (2,) ndarray or None
        Measured fingertip centre, m.
    force : (3,) ndarray or None
        Wrench force the object applies to the fingertip, N.
    force_stamp_ns : int or None
        Stamp of that wrench.
    angles, normal, tangential : (n,) ndarray or None
        Taxel angles (rad, fingertip frame) and forces (N).
    tactile_stamp_ns : int or None
        Stamp of those taxels.
    """

    position: np.ndarray | None = None
    force: np.ndarray | None = None
    force_stamp_ns: int | None = None
    angles: np.ndarray | None = None
    normal: np.ndarray | None = None
    tangential: np.ndarray | None = None
    tactile_stamp_ns: int | None = None


class Patch(NamedTuple):
    """A contact patch: a run of neighbouring loaded taxels (a named tuple: a few are built
    per finger and tick).

    Attributes
    ----------
    finger : str
    angle : float
        F_n-weighted mean taxel angle, rad.
    normal, tangential : float
        Summed taxel forces, N.
    mode : {"stick", "slip"}
    slip : int
        +1 / -1: direction of sliding in polar angle (-sign F_t); 0 while sticking.
    first, last : int
        Its taxels (inclusive).
    """

    finger: str
    angle: float
    normal: float
    tangential: float
    mode: str
    slip: int
    first: int = 0
    last: int = 0


@dataclass(frozen=True)
class TrackedEvent:
    """An event found by the tracker: a contact event (A, B, C, D) or picked_up.

    ``mirrored``: a C or D event of a patch with a mirror partner (a tie, see the module).
    """

    type: EventType | Termination
    finger: Finger | str
    depth: float
    relative_depth: float
    angle: float
    mirrored: bool = False


@dataclass(frozen=True)
class TrackedAlarm:
    """An alarm active at a tick."""

    type: str
    finger: str
    value: float
    message: str


@dataclass(frozen=True)
class PredictedEvent:
    """An event of the planner's prediction."""

    type: EventType
    finger: Finger
    depth: float


class TrackerOutput(NamedTuple):
    """The tracker's result for one tick (SI, object frame; a named tuple: one is built per
    tick, ``_replace`` gives one with more events or alarms).

    Attributes
    ----------
    stamp_ns : int
    fingers : tuple of str
    positions, forces, normals : dict of str to (2,) ndarray
        Measured tip centres, forces on the object, unit contact normals (into the object;
        zero without loaded taxels).
    ages : dict of str to float
        Age of the stalest sensor stream of each finger, s.
    patches : tuple of Patch
    events : tuple of TrackedEvent
    alarms : tuple of TrackedAlarm
    depth, relative_depth : float
    """

    stamp_ns: int
    fingers: tuple[str, ...]
    positions: Mapping[str, np.ndarray]
    forces: Mapping[str, np.ndarray]
    normals: Mapping[str, np.ndarray]
    ages: Mapping[str, float]
    patches: tuple[Patch, ...]
    events: tuple[TrackedEvent, ...]
    alarms: tuple[TrackedAlarm, ...]
    depth: float
    relative_depth: float


class LoadedTaxels(NamedTuple):
    """The loaded taxels (normal force above the threshold) of one finger's reading (a named
    tuple: two are built per tick, a frozen dataclass took 4-5 us for each).

    Attributes
    ----------
    index : (k,) ndarray of int
        Their indices, increasing.
    normal, tangential : (k,) ndarray
        Their forces, N.
    angles, cos, sin : (k,) ndarray
        Their polar angles (rad) and its cosine and sine.
    """

    index: np.ndarray
    normal: np.ndarray
    tangential: np.ndarray
    angles: np.ndarray
    cos: np.ndarray
    sin: np.ndarray


def loaded_taxels(sample: FingerSample, threshold: float,
                  trig: tuple[np.ndarray, np.ndarray]) -> LoadedTaxels:
    """The loaded taxels of a reading with tactile data (``trig``: cos and sin of all its
    taxel angles).
    """
    index = (sample.normal > threshold).nonzero()[0]
    cos, sin = trig
    return LoadedTaxels(index, sample.normal[index], sample.tangential[index],
                        sample.angles[index], cos[index], sin[index])


_NO_SAMPLE = FingerSample()
"""The sample of a finger without readings at a tick."""
_FIRST = np.zeros(1, dtype=np.intp)
"""The first run's start in :func:`patches_of`."""


def patches_of(finger: str, taxels: LoadedTaxels, config: TrackerConfig) -> list[Patch]:
    """Contact patches of one finger: its maximal runs of neighbouring loaded taxels, each
    summed in one ``reduceat`` pass.
    """
    index = taxels.index
    if not len(index):
        return []
    starts, firsts, lasts = _runs(index.tobytes())
    sums = np.add.reduceat(np.array((taxels.normal, taxels.tangential,
                                     taxels.normal * taxels.angles)), starts, axis=1)
    mu, edge = config.mu, 1.0 - config.edge_tolerance
    out = []
    for first, last, normal, tangential, moment in zip(firsts, lasts, *sums.tolist()):
        sliding = mu == 0.0 or abs(tangential) >= edge * mu * normal
        slip = (-1 if tangential > 0.0 else 1 if tangential < 0.0 else 0) \
            if sliding and mu > 0.0 else 0
        out.append(Patch(finger, moment / normal, normal, tangential,
                         _SLIP if sliding else _STICK, slip, first, last))
    return out


@functools.lru_cache(maxsize=256)
def _runs(index: bytes) -> tuple[np.ndarray, tuple[int, ...], tuple[int, ...]]:
    """(starts, first taxels, last taxels) of the maximal runs of neighbouring taxels among
    loaded taxels ``index`` (the bytes of their increasing indices; kept: a finger's loaded
    taxels stay the same over most ticks).
    """
    index = np.frombuffer(index, np.intp)
    breaks = ((index[1:] - index[:-1]) > 1).nonzero()[0] + 1
    starts = np.concatenate((_FIRST, breaks))
    starts.flags.writeable = False
    lasts = np.concatenate((index[breaks - 1], index[-1:]))
    return starts, tuple(index[starts].tolist()), tuple(lasts.tolist())


_SLIP, _STICK = ContactMode.SLIP, ContactMode.STICK
"""The modes, looked up once (an enum member's attribute access is a Python call)."""
_MIN, _MAX = np.minimum.reduce, np.maximum.reduce
"""An array's least and greatest element (``ndarray.min`` and ``max`` without their Python
wrappers)."""


def mirror_tolerance_for(spacing: float, outline_error: float, *, tip_radius: float,
                         taxel_pitch: float) -> float:
    """The mirror rule's tolerance (:func:`mirrored_patches`) for a mesh and an outline.

    The nearest mirror pair are the neighbours of the contact node on the force line, a
    boundary spacing ``h`` either side of it: on a fingertip of radius ``R`` their angles from
    the line are about -h / R and +h / R, their separation 2 h / R. A squeeze symmetric about
    the object's axis is so only to within the outline's error ``e`` (the planner's outline,
    on which the fingers are placed, is that far from the world's: the contact moves along the
    boundary by up to e), and each patch's angle is a taxel-weighted mean, off by at most half
    a taxel pitch ``dtheta``. The pair's mean angle then lies within e / R + dtheta / 2 of the
    line, a fraction

        tolerance = (e + R dtheta / 2) / (2 h)

    of the separation. Farther pairs (k spacings out) have k times the separation and fall
    inside it more easily; a finger off the axis by more than the tolerance's e is no tie.

    Parameters
    ----------
    spacing : float
        Boundary node spacing h of the mesh, m.
    outline_error : float
        Largest distance e of the planner's outline from the world's, m (0 when the planner is
        given the world's outline; on the camera route the extraction's tolerance).
    tip_radius : float
        Fingertip radius R, m.
    taxel_pitch : float
        Angle dtheta between neighbouring taxels, rad.

    Returns
    -------
    float
        The tolerance, capped at 0.5 (beyond it any two patches on opposite sides would pair).

    Examples
    --------
    The foam ring (96 boundary nodes on a 5 cm radius) seen by the shipped camera (extraction
    tolerance 0.152 mm), fingertips of 2 cm with 96 taxels over 150 degrees:

    >>> from math import pi, radians
    >>> round(mirror_tolerance_for(2 * pi * 0.05 / 96, 0.152e-3, tip_radius=0.02,
    ...                            taxel_pitch=radians(150 / 95)), 3)
    0.065
    """
    for name, value in (("spacing", spacing), ("tip_radius", tip_radius)):
        if not (np.isfinite(value) and value > 0):
            raise InvalidInputError(f"{name} must be a positive length in m, got {value!r}")
    for name, value in (("outline_error", outline_error), ("taxel_pitch", taxel_pitch)):
        if not (np.isfinite(value) and value >= 0):
            raise InvalidInputError(f"{name} must be >= 0, got {value!r}")
    return min(0.5, (outline_error + 0.5 * tip_radius * taxel_pitch) / (2.0 * spacing))


def mirrored_patches(patches: Sequence[Patch], tolerance: float) -> frozenset[int]:
    """Indices of the patches of one finger that have a mirror partner about its force line.

    The force line is the direction of the resultant of the patch forces (normal along the
    patch angle, tangential along the angle's positive tangent). Patches i and j are mirror
    images when they lie on opposite sides of it and the mean of their angles is within
    ``tolerance`` times their angular separation of it.

    Examples
    --------
    >>> from squeeze_grasp_ros.control.tracker import Patch, mirrored_patches
    >>> side = [Patch("F1", a, 0.45, t, "stick", 0) for a, t in ((-0.16, 0.18), (0.16, -0.18))]
    >>> sorted(mirrored_patches([side[0], Patch("F1", 0.0, 0.63, 0.0, "stick", 0), side[1]], 0.25))
    [0, 2]
    >>> sorted(mirrored_patches([side[0], Patch("F1", 0.4, 0.6, 0.0, "stick", 0)], 0.25))
    []
    """
    if len(patches) < 2:
        return frozenset()
    angle, normal, tangential = np.array(tuple(zip(*patches))[1:4], dtype=float)
    c, s = np.cos(angle), np.sin(angle)
    line = np.arctan2(normal @ s + tangential @ c, normal @ c - tangential @ s)
    offset = np.angle(np.exp(1j * (angle - line)))
    i, j = _pairs(len(patches))
    pair = (offset[i] * offset[j] < 0.0) & (
        np.abs(offset[i] + offset[j]) <= tolerance * np.abs(offset[i] - offset[j]))
    return frozenset(i[pair].tolist() + j[pair].tolist())


@functools.lru_cache(maxsize=64)
def _pairs(count: int) -> tuple[np.ndarray, np.ndarray]:
    """The index pairs (i < j) of ``count`` patches (``np.triu_indices``, kept: a finger has
    the same few patches tick after tick).
    """
    pairs = np.triu_indices(count, 1)
    for index in pairs:
        index.flags.writeable = False
    return pairs


def same_spans(previous: Sequence[Patch], current: Sequence[Patch], margin: int) -> bool:
    """Whether the patches of two ticks cover the same taxel ranges, each patch apart from its
    neighbours even widened by ``margin``: then :func:`connected_groups` pairs them one to one,
    in order (the usual tick: the contact nodes stay on their taxels).
    """
    if len(previous) != len(current):
        return False
    last = None
    for old, new in zip(previous, current):
        if old.first != new.first or old.last != new.last or \
                (last is not None and new.first - last <= 2 * margin):
            return False
        last = new.last
    return True


def connected_groups(previous: Sequence[Patch], current: Sequence[Patch],
                     margin: int) -> list[tuple[list[int], list[int]]]:
    """Groups (previous indices, current indices) of patches linked by overlapping taxel ranges.

    Patches of one tick never overlap each other, so the groups are the runs of the union of
    all (widened) ranges: one sweep in order of the first taxel.
    """
    spans = sorted([(p.first - margin, p.last + margin, 0, i) for i, p in enumerate(previous)]
                   + [(c.first - margin, c.last + margin, 1, j) for j, c in enumerate(current)])
    groups: list[tuple[list[int], list[int]]] = []
    end = None
    for first, last, side, index in spans:
        if end is None or first > end:
            groups.append(([], []))
            end = last
        end = max(end, last)
        groups[-1][side].append(index)
    return groups


@dataclass
class _FingerTrack:
    """Mutable per-finger memory of the tracker."""

    patches: list = field(default_factory=list)
    position: np.ndarray | None = None
    force: np.ndarray = field(default_factory=lambda: np.zeros(2))
    normal: np.ndarray = field(default_factory=lambda: np.zeros(2))
    had_contact: bool = False
    stamps: dict[str, int] = field(default_factory=dict)
    trig_key: bytes = b""
    trig: tuple = ()
    mirror_of: list | None = None
    mirrored: frozenset = frozenset()


class ContactTracker:
    """Event tracker over ticks of tactile and wrench readings (the monitor's logic).

    Parameters
    ----------
    config : TrackerConfig
    fingers : sequence of str
        Fingers to track, in their canonical order.
    streams : sequence of str
        Sensor streams expected per finger ("wrench", "tactile") for the staleness test.
    prediction : sequence of PredictedEvent
        The planner's predicted events (may be empty).
    """

    def __init__(self, config: TrackerConfig, fingers: Sequence[str],
                 streams: Sequence[str] = ("wrench", "tactile"),
                 prediction: Sequence[PredictedEvent] = ()) -> None:
        order = {n: k for k, n in enumerate(Finger.values())}
        self.config = config
        self.fingers = tuple(sorted(fingers, key=lambda n: order.get(n, len(order))))
        self.streams = tuple(streams)
        self.tracks = {f: _FingerTrack() for f in self.fingers}
        self.depth = 0.0
        self.picked_up = False
        self.set_prediction(prediction)

    def set_prediction(self, prediction: Sequence[PredictedEvent]) -> None:
        """Replace the prediction the observed events are compared with."""
        self.prediction = list(prediction)
        self.unmatched = list(range(len(self.prediction)))
        self.stick_slip_fingers = {p.finger for p in self.prediction if p.type in STICK_SLIP}
        """The fingers the prediction has C or D events for."""

    def update(self, stamp_ns: int, samples: Mapping[str, FingerSample]) -> TrackerOutput:
        """Process the readings of one tick (newest reading per finger and stream)."""
        cfg = self.config
        self._advance_depth(samples)
        relative = self.depth * cfg.relative_per_depth
        events: list[TrackedEvent] = []
        alarms: list[TrackedAlarm] = []
        patches: list[Patch] = []
        loaded: dict[str, LoadedTaxels] = {}
        positions, forces, normals, ages = {}, {}, {}, {}
        for name in self.fingers:
            sample = samples.get(name, _NO_SAMPLE)
            track = self.tracks[name]
            self._note_stamps(track, sample)
            taxels, trig = None, None
            if sample.normal is not None:
                trig = self._trig(track, sample)
                taxels = loaded_taxels(sample, cfg.load_threshold, trig)
                current = patches_of(name, taxels, cfg)
                events += self._events(name, track.patches, current, relative)
                track.patches = current
                track.had_contact = track.had_contact or bool(current)
                loaded[name] = taxels
            patches += track.patches
            track.force = self._force(sample, trig, track.force)
            track.normal = self._normal(taxels, track.normal)
            ages[name] = age = self._age(track, stamp_ns)
            alarms += self._alarms(name, track, taxels, age)
            if track.position is not None:
                positions[name] = track.position
            forces[name], normals[name] = track.force.copy(), track.normal.copy()
        if cfg.weight is not None and not self.picked_up and self._can_lift(loaded):
            self.picked_up = True
            events.append(TrackedEvent(Termination.PICKED_UP, "", self.depth, relative, 0.0))
        alarms += self._compare(events)
        return TrackerOutput(
            stamp_ns,
            self.fingers,
            positions,
            forces,
            normals,
            ages,
            tuple(patches),
            tuple(events),
            tuple(alarms),
            self.depth,
            relative,
        )

    # ----------------------------------------------------------------- pieces
    def _advance_depth(self, samples: Mapping[str, FingerSample]) -> None:
        step = 0.0
        for name in self.fingers:
            sample = samples.get(name)
            if sample is None or sample.position is None:
                continue
            track = self.tracks[name]
            position = np.asarray(sample.position, float)
            if track.position is not None:
                d = position - track.position
                step += float(d @ d)
            track.position = position
        self.depth += float(np.sqrt(step))

    def _mirrored(self, track: _FingerTrack, patches: list[Patch]) -> frozenset[int]:
        """Indices of ``patches`` (a finger's current ones) with a mirror partner
        (:func:`mirrored_patches`), computed when first asked for this list: only a C or D
        event, or a predicted one the depth passed, needs them.
        """
        if track.mirror_of is not patches:
            track.mirror_of = patches
            track.mirrored = mirrored_patches(patches, self.config.mirror_tolerance)
        return track.mirrored

    @staticmethod
    def _trig(track: _FingerTrack, sample: FingerSample) -> tuple[np.ndarray, np.ndarray]:
        """Cos and sin of the finger's taxel angles, recomputed only when the angles change."""
        key = sample.angles.tobytes()
        if track.trig_key != key:
            track.trig_key, track.trig = key, (np.cos(sample.angles), np.sin(sample.angles))
        return track.trig

    @staticmethod
    def _note_stamps(track: _FingerTrack, sample: FingerSample) -> None:
        if sample.force_stamp_ns is not None:
            track.stamps["wrench"] = sample.force_stamp_ns
        if sample.tactile_stamp_ns is not None:
            track.stamps["tactile"] = sample.tactile_stamp_ns

    def _age(self, track: _FingerTrack, stamp_ns: int) -> float:
        """Age of the stalest expected stream, s (inf before its first reading)."""
        ages = [(stamp_ns - track.stamps[s]) * 1e-9 if s in track.stamps else float("inf")
                for s in self.streams]
        return max(ages, default=0.0)

    def _events(self, name: str, previous: list[Patch], current: list[Patch],
                relative: float) -> list[TrackedEvent]:
        found = []
        if same_spans(previous, current, self.config.match_margin):
            # one to one: only a patch whose mode changed has an event (C or D)
            for k, (old, new) in enumerate(zip(previous, current)):
                if old.mode != new.mode:
                    kind = EventType.C if old.mode == _STICK else EventType.D
                    found.append((kind, new.angle, k in self._mirrored(self.tracks[name],
                                                                       current)))
            found.sort(key=lambda e: (processing_rank(e[0]), e[1]))
            return [TrackedEvent(kind, name, self.depth, relative, angle, mirrored)
                    for kind, angle, mirrored in found]
        for before, after in connected_groups(previous, current, self.config.match_margin):
            if not after:
                found += [(EventType.B, previous[i].angle, False) for i in before]
            elif not before:
                if self.tracks[name].had_contact:
                    found += [(EventType.A, current[j].angle, False) for j in after]
            elif len(before) == len(after) == 1:
                old, new = previous[before[0]], current[after[0]]
                kind = (EventType.C if (old.mode, new.mode) == STICK_TO_SLIP else
                        EventType.D if (old.mode, new.mode) == SLIP_TO_STICK else None)
                if kind is not None:
                    mirrored = after[0] in self._mirrored(self.tracks[name], current)
                    found.append((kind, new.angle, mirrored))
        found.sort(key=lambda e: (processing_rank(e[0]), e[1]))
        return [TrackedEvent(kind, name, self.depth, relative, angle, mirrored)
                for kind, angle, mirrored in found]

    @staticmethod
    def _force(sample: FingerSample, trig: tuple[np.ndarray, np.ndarray] | None,
               previous: np.ndarray) -> np.ndarray:
        """Force of the finger on the object (2,), N: -wrench force, else the taxel sum
        (``trig``: cos and sin of the taxel angles, given with tactile data).
        """
        if sample.force is not None:
            return -np.asarray(sample.force[:2], float)
        if sample.normal is not None:
            c, s = trig
            return np.array([sample.normal @ c - sample.tangential @ s,
                             sample.normal @ s + sample.tangential @ c])
        return previous

    @staticmethod
    def _normal(taxels: LoadedTaxels | None, previous: np.ndarray) -> np.ndarray:
        """Unit contact normal into the object from the loaded taxels (zero without any)."""
        if taxels is None:
            return previous
        if not len(taxels.index):
            return np.zeros(2)
        w = taxels.normal
        v = np.array([w @ taxels.cos, w @ taxels.sin])
        return v / math.sqrt(v @ v)

    def _alarms(self, name: str, track: _FingerTrack, taxels: LoadedTaxels | None,
                age: float) -> list[TrackedAlarm]:
        """The finger's alarms at a tick (``age``: its stalest stream's, s)."""
        cfg = self.config
        out = []
        if age > cfg.stale_after:
            # never any reading: the age is infinite ("inf ms old" before)
            out.append(TrackedAlarm(AlarmType.STALE_SENSOR, name, age,
                                    f"no {name} reading yet" if math.isinf(age)
                                    else f"newest {name} reading is {age * 1e3:.3g} ms old"))
        if track.had_contact and not track.patches:
            out.append(TrackedAlarm(Termination.CONTACT_LOST, name, 0.0, f"{name} has no loaded "
                                                                         "taxel"))
        usage = self._cone_usage(taxels)
        if usage is not None:
            out.append(TrackedAlarm(AlarmType.SLIP_IMMINENT, name, usage,
                                    f"every loaded taxel of {name} uses >= {usage:.3f} of its "
                                    "friction cone in one direction"))
        return out

    def _cone_usage(self, taxels: LoadedTaxels | None) -> float | None:
        """Smallest cone usage if every loaded taxel is past alarm_ratio one way, else None."""
        cfg = self.config
        if cfg.mu == 0.0 or taxels is None or not len(taxels.index):
            return None
        usage = -taxels.tangential / (cfg.mu * taxels.normal)
        low, high = float(_MIN(usage)), float(_MAX(usage))
        if low >= cfg.alarm_ratio or high <= -cfg.alarm_ratio:
            return min(abs(low), abs(high))
        return None

    def _can_lift(self, loaded: Mapping[str, LoadedTaxels]) -> bool:
        """Every finger with loaded taxels can supply w / n_f of vertical friction."""
        cfg = self.config
        supply = []
        for taxels in loaded.values():
            if not len(taxels.index):
                continue
            fn, ft = taxels.normal, taxels.tangential
            sticking = np.abs(ft) < (1.0 - cfg.edge_tolerance) * cfg.mu * fn
            supply.append(float(np.sqrt(np.maximum(cfg.mu ** 2 * fn[sticking] ** 2
                                                   - ft[sticking] ** 2, 0.0)).sum()))
        return bool(supply) and min(supply) >= cfg.weight / len(supply)

    def _compare(self, events: list[TrackedEvent]) -> list[TrackedAlarm]:
        """Match observed events to the prediction; mismatch alarms for surprises and misses."""
        if not self.prediction:
            return []
        tol = self.config.prediction_tolerance
        out = []
        for e in events:
            if e.type not in PROCESSING_ORDER:
                continue
            hit = next((k for k in self.unmatched if self.prediction[k].type == e.type
                        and self.prediction[k].finger == e.finger
                        and abs(self.prediction[k].depth - e.depth) <= tol), None)
            if hit is None and not (e.mirrored and e.finger in self.stick_slip_fingers):
                out.append(TrackedAlarm(AlarmType.PREDICTION_MISMATCH, e.finger, e.depth,
                                        f"event {e.type} on {e.finger} at depth {e.depth:.6g} m "
                                        "was not predicted"))
            elif hit is not None:
                self.unmatched.remove(hit)
        for k in [k for k in self.unmatched if self.prediction[k].depth + tol < self.depth]:
            p = self.prediction[k]
            self.unmatched.remove(k)
            track = self.tracks.get(p.finger)
            if p.type in STICK_SLIP and track and self._mirrored(track, track.patches):
                continue
            out.append(TrackedAlarm(AlarmType.PREDICTION_MISMATCH, p.finger, p.depth,
                                    f"predicted event {p.type} on {p.finger} at depth "
                                    f"{p.depth:.6g} m was not observed"))
        return out
