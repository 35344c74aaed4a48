# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Time one workload with whichever ``squeeze_grasp_ros`` is first on ``sys.path``.

:mod:`~.pinned` runs this file as a script in a child process, with ``PYTHONPATH`` set to this
tree or to a pinned copy of an older commit, so that both are timed by the same code in the
same minutes. It imports the package only inside the workloads, and only names that the pinned
commit has too (the sweep's ``parse_sweep_spec``, ``plan_tasks``, ``prepare``,
``run_task``, ``clear_cache``; the event bench's ``foam_square`` and ``event_squeeze``).
It prints one JSON line: the workload's size and its CPU seconds (best of the passes).

    python timing_driver.py evaluations SPEC PASSES TASKS   # TASKS 0: all of them
    python timing_driver.py foam-square NODES REPEATS
"""
from __future__ import annotations

import json
import sys
import time
from collections.abc import Iterator
from pathlib import Path


def evaluations(spec: Path, passes: int, tasks: int) -> dict:
    """CPU seconds of all evaluations of ``spec``'s first ``tasks`` tasks (all if 0), best of
    ``passes``, after one untimed task; each pass starts from fresh groups, each prepared
    untimed just before its first task (:func:`prepared_tasks`).
    """
    import yaml

    from squeeze_grasp_ros.sweep.evaluate import clear_cache, prepare, run_task
    from squeeze_grasp_ros.sweep.plan import plan_tasks
    from squeeze_grasp_ros.sweep.spec import parse_sweep_spec

    every = list(plan_tasks(parse_sweep_spec(yaml.safe_load(spec.read_text()), spec.parent)))
    every = every[:tasks] if tasks else every
    run_task(every[0])  # numba's code loaded or compiled; imports done
    best, count = float("inf"), 0
    for _ in range(passes):
        clear_cache()
        cpu, count = 0.0, 0
        for task in prepared_tasks(every, prepare):
            start = time.process_time()
            count += len(run_task(task)["rows"])
            cpu += time.process_time() - start
        best = min(best, cpu)
    return {"count": count, "cpu_s": best}


def prepared_tasks(every: list, prepare) -> Iterator:
    """The tasks in order, each yielded once ``prepare`` has put its group in the sweep's
    group cache (the caller times what it does with the task, not the preparation).

    Preparing every group first and then running the tasks does not keep the preparation out:
    the cache holds a few groups (least recently used out), so a spec with more groups than
    that prepared them all again inside the timed pass (the example sweep's six groups, about
    0.6 ms of meshing, factorisation and grasp map per evaluation, on both sides of a ratio).
    """
    for task in every:
        prepare(task)
        yield task


def foam_square(nodes: int, repeats: int) -> dict:
    """CPU seconds of the foam square's 12 % squeeze (linear, mu 0.4, events to 1e-9 L) on a
    mesh of about ``nodes`` nodes, precomputed, after one untimed squeeze; best of ``repeats``.
    """
    from squeeze_grasp_ros.bench import events
    from squeeze_grasp_ros.mechanics.squeeze.events import event_squeeze

    obj, contacts = events.foam_square(nodes)
    obj.precompute()

    def squeeze():
        return event_squeeze(obj, contacts, events.RADIUS, 0.4,
                             relative_depth=events.RELATIVE_DEPTH, event_tol=1e-9)

    result, best = squeeze(), float("inf")
    for _ in range(repeats):
        start = time.process_time()
        squeeze()
        best = min(best, time.process_time() - start)
    return {"count": int(obj.mesh.n), "events": int(sum(result.event_counts.values())),
            "cpu_s": best}


def main(argv: list[str]) -> None:
    """Run the workload ``argv`` names and print its JSON line."""
    kind, *args = argv
    if kind == "evaluations":
        out = evaluations(Path(args[0]), int(args[1]), int(args[2]))
    elif kind == "foam-square":
        out = foam_square(int(args[0]), int(args[1]))
    else:
        raise SystemExit(f"unknown workload {kind!r}: evaluations or foam-square")
    print(json.dumps(out))


if __name__ == "__main__":
    main(sys.argv[1:])
