# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The table of docs/perception.md: seen against true mixed outlines, event by event.

``python test/mixed_events.py`` (about two minutes; needs the perception extra) squeezes the
stadium, the rounded rectangle and the D of ``test_perception_mixed.py`` both ways at 1,000
nodes (10 %) and 2,000 nodes (12 %), as the truth and as seen in three camera views, and prints
per squeeze: the truth's events and those of the truth moved by 10 um (shifted by 10 um in x or
y, turned by 10 um at its ends, or moved along its normals by 10 um cos(k theta) or sin(k theta),
k = 0..4: 24 moves), then per view the seen events (``=`` the truth's, ``~`` a moved truth's,
``x`` neither), the boundary nodes, the farthest final contact node from the other squeeze's
(boundary spacings) and the largest finger force difference.
"""
from __future__ import annotations

import numpy as np
from test_perception_mixed import (
    FINGERS,
    along_normals,
    counts,
    seen_shapes,
    squeezer,
    true_shape,
)

MOVE = 1e-5
"""How far the truth is moved, m."""


def moved_truths(name: str) -> list[dict]:
    """The true shape of ``name`` moved by :data:`MOVE` in 24 ways (module docstring)."""
    shape = true_shape(name)
    points = np.array(shape["points"])
    centre = points.mean(axis=0)
    theta = np.arctan2(*(points - centre).T[::-1])
    turn = 2.0 * MOVE / np.ptp(points, axis=0).max()
    c, s = np.cos(turn), np.sin(turn)
    out = [{**shape, "points": (points + shift).tolist()}
           for shift in ((MOVE, 0), (-MOVE, 0), (0, MOVE), (0, -MOVE))]
    out += [{**shape, "points": ((points - centre) @ turned + centre).tolist()}
            for turned in (np.array([[c, s], [-s, c]]), np.array([[c, -s], [s, c]]))]
    for k in range(5):
        for wave in ((np.cos,) if k == 0 else (np.cos, np.sin)):
            out += [along_normals(shape, sign * MOVE * wave(k * theta)) for sign in (1, -1)]
    return out


def main() -> None:
    """Print the table (module docstring)."""
    seen = {name: seen_shapes(name) for name, _ in FINGERS}
    for nodes, depth in ((1000, 0.10), (2000, 0.12)):
        for name, direction in FINGERS:
            squeezed = squeezer(name, direction, nodes, depth)
            true_mesh, truth = squeezed(true_shape(name))
            moved = {counts(squeezed(m)[1]) for m in moved_truths(name)} - {counts(truth)}
            loop = true_mesh.nodes[true_mesh.boundary]
            spacing = np.median(np.linalg.norm(np.diff(loop, axis=0), axis=1))
            a = true_mesh.nodes[[c.node for c in truth.state.contacts]]
            forces = np.array([np.linalg.norm(truth.finger_force[f])
                               for f in sorted(truth.finger_force)])
            rows = []
            for shape in seen[name]:
                mesh, squeeze = squeezed(shape)
                b = mesh.nodes[[c.node for c in squeeze.state.contacts]]
                far = max(np.linalg.norm(p[:, None] - q[None], axis=2).min(axis=1).max()
                          for p, q in ((a, b), (b, a))) / spacing
                force = np.abs(np.array([np.linalg.norm(squeeze.finger_force[f]) for f in
                                         sorted(squeeze.finger_force)]) / forces - 1).max()
                mark = ("=" if counts(squeeze) == counts(truth)
                        else "~" if counts(squeeze) in moved else "x")
                rows.append(f"{counts(squeeze)} {mark} b{len(mesh.boundary)} "
                            f"{far:.2f} sp {100 * force:.2f} %")
            print(f"{name} {direction} ({nodes}, {100 * depth:.0f} %): truth {counts(truth)} "
                  f"b{len(true_mesh.boundary)}, moved 10 um: {' '.join(sorted(moved)) or '-'}")
            print("    " + " | ".join(rows), flush=True)


if __name__ == "__main__":
    main()
