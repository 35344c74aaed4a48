# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Event-driven squeeze (Algorithm 1): full foam-square squeeze, time per event vs mesh size, and
the speed-up over the paper's literal fixed-step route at matched event-location accuracy.
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Callable, Sequence

import numpy as np

from squeeze_grasp_ros.bench.table import Table
from squeeze_grasp_ros.mechanics.elastic import shapes
from squeeze_grasp_ros.mechanics.elastic.compliance import ElasticObject
from squeeze_grasp_ros.mechanics.elastic.material import Material
from squeeze_grasp_ros.mechanics.elastic.mesh import generate_mesh, target_max_area
from squeeze_grasp_ros.mechanics.squeeze.events import EventSqueeze, event_squeeze

TITLE = "Event-driven squeeze (Sec. 5, Algorithm 1)"
FOAM = Material(5e4, 0.3, 0.0254)
SIDE = 0.1
RADIUS = 0.02
RELATIVE_DEPTH = 0.12
SQUEEZE_COLUMNS = [
    "mu",
    "nodes n",
    "boundary b",
    "final contacts m",
    "events A/B/C/D",
    "precompute [s]",
    "squeeze [s]",
    "total [s]",
    "per event [ms]",
    "substeps",
    "root evaluations",
]
REFERENCE_COLUMNS = [
    "route",
    "step h [L]",
    "event tol [L]",
    "events",
    "same events",
    "max event depth error [L]",
    "squeeze [s]",
    "speed-up",
]


def foam_square(nodes: int) -> tuple[ElasticObject, tuple[int, int]]:
    """Sec. 5.5's square meshed with about ``nodes`` nodes, and the boundary nodes nearest the
    midpoints of its left and right sides (not precomputed).
    """
    outline = shapes.rectangle(SIDE, SIDE)
    obj = ElasticObject(generate_mesh(outline, target_max_area(outline, nodes)), FOAM)
    b = obj.mesh.boundary
    pts = obj.mesh.nodes[b]
    ends = tuple(
        int(b[np.argmin(np.linalg.norm(pts - p, axis=1))])
        for p in ([-SIDE / 2, 0.0], [SIDE / 2, 0.0])
    )
    return obj, ends


def timed_squeeze(
    obj: ElasticObject, contacts, mu: float, repeat: int = 3, **kw
) -> tuple[EventSqueeze, float]:
    """(result, best wall time in s) of the 12 % stable squeeze; every repeat starts with an
    empty contact-set cache (a new model), the object's compliance stays cached.
    """
    best, res = np.inf, None
    for _ in range(repeat):
        start = time.perf_counter()
        res = event_squeeze(obj, contacts, RADIUS, mu, relative_depth=RELATIVE_DEPTH, **kw)
        best = min(best, time.perf_counter() - start)
    return res, best


def squeeze_rows(
    sizes: Sequence[int],
    mus: Sequence[float] = (0.4, 0.05),
    event_tol: float = 1e-9,
    progress: Callable[[str], None] = lambda _: None,
) -> list[list]:
    """One row per mesh size and friction coefficient (columns :data:`SQUEEZE_COLUMNS`).

    "precompute" is stiffness assembly + factorisation + boundary compliance (once per mesh);
    "squeeze" the whole event-driven squeeze to 12 % with events located to ``event_tol`` L,
    including the final full displacement field and grasp-health numbers.
    """
    rows = []
    for target in sizes:
        progress(f"events: foam square n ~ {target}")
        obj, contacts = foam_square(target)
        start = time.perf_counter()
        obj.precompute()
        t_pre = time.perf_counter() - start
        for mu in mus:
            res, t = timed_squeeze(obj, contacts, mu, event_tol=event_tol)
            c = res.event_counts
            n_events = max(sum(c.values()), 1)
            rows.append(
                [
                    mu,
                    obj.mesh.n,
                    len(obj.mesh.boundary),
                    len(res.state.contacts),
                    "/".join(str(n) for n in c.values()),
                    t_pre,
                    t,
                    t_pre + t,
                    1e3 * t / n_events,
                    res.diagnostics["substeps"],
                    res.diagnostics["root_evaluations"],
                ]
            )
    return rows


def event_error(res: EventSqueeze, truth: EventSqueeze, scale: float) -> tuple[bool, float]:
    """(same events, max |depth - true depth| / L over matched events).

    Events are matched by (type, node, occurrence): simultaneous events that a fixed step
    detects at one step end may be listed in another order.
    """

    def keyed(events):
        seen: dict = {}
        out = {}
        for e in events:
            k = (e.type, e.node)
            seen[k] = seen.get(k, 0) + 1
            out[(*k, seen[k])] = e.depth
        return out

    mine, ref = keyed(res.events), keyed(truth.events)
    err = max((abs(mine[k] - ref[k]) for k in mine.keys() & ref.keys()), default=0.0) / scale
    return mine.keys() == ref.keys(), float(err)


def reference_rows(
    nodes: int,
    mu: float,
    accuracy: float,
    steps: Sequence[float],
    progress: Callable[[str], None] = lambda _: None,
) -> tuple[list[list], str]:
    """Located engine at ``accuracy`` vs the literal fixed-step reference at each step h.

    The truth is the located engine at 1e-12 L. Returns the rows (columns
    :data:`REFERENCE_COLUMNS`) and a sentence naming the largest step whose events match the
    accuracy, with the speed-up there.
    """
    obj, contacts = foam_square(nodes)
    obj.precompute()
    scale = obj.scale
    truth, _ = timed_squeeze(obj, contacts, mu, repeat=1, event_tol=1e-12)
    fast, t_fast = timed_squeeze(obj, contacts, mu, event_tol=accuracy)
    same, err = event_error(fast, truth, scale)
    rows = [
        ["located (cached compliance)", 1e-3, accuracy, len(fast.events), same, err, t_fast, 1.0]
    ]
    needed = None
    for h in steps:
        progress(f"events: reference route, h = {h:g} L")
        ref, t_ref = timed_squeeze(obj, contacts, mu, repeat=1, step=h, reference=True)
        same_r, err_r = event_error(ref, truth, scale)
        rows.append(
            [
                "fixed step, full solves (paper)",
                h,
                "-",
                len(ref.events),
                same_r,
                err_r,
                t_ref,
                t_ref / t_fast,
            ]
        )
        if needed is None and same_r and err_r <= accuracy:
            needed = (h, t_ref / t_fast)
    if needed is None:
        note = (
            f"No reference step in {list(steps)} reached {accuracy:g} L event accuracy; the "
            f"finest was {rows[-1][6] / t_fast:.0f}x slower than the located engine"
        )
    else:
        note = (
            f"The reference needed h = {needed[0]:g} L for {accuracy:g} L event accuracy: "
            f"{needed[1]:.0f}x slower than the located engine (n = {obj.mesh.n})"
        )
    return rows, note


def run(quick: bool, out_dir: Path, progress) -> list[Table]:
    """Three tables: the 2,000-node squeeze, time per event vs n, and the reference route."""
    main = squeeze_rows((2000,), progress=progress)
    sizes = (500, 1000, 2000, 5000) if quick else (500, 1000, 2000, 5000, 10000, 20000)
    scaling = squeeze_rows(sizes, mus=(0.05,), progress=progress)
    steps = (1e-3, 1e-4, 1e-5)
    ref, note = reference_rows(2000, 0.4, 1e-5, steps, progress)
    return [
        Table(
            f"{TITLE}: foam square, 12 % stable squeeze, events to 1e-9 L",
            SQUEEZE_COLUMNS,
            main,
            "Target: under 2 s for n ~ 2,000 (precompute + squeeze).",
        ),
        Table(
            f"{TITLE}: time per event vs mesh size (mu = 0.05)",
            SQUEEZE_COLUMNS,
            scaling,
            "After the precompute a step costs O(m^3 + b m): the time per event should stay "
            "essentially flat from 500 to 20,000 nodes.",
        ),
        Table(
            f"{TITLE}: located engine vs the paper's fixed-step route (n ~ 2,000, mu = 0.4)",
            REFERENCE_COLUMNS,
            ref,
            "Event depths compared with the located engine at 1e-12 L. The reference takes "
            "a full displacement solve per step and detects events at step ends only. "
            + note
            + ".",
        ),
    ]
