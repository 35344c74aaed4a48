# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The planner's services on real rclpy: round trip over the bare mechanics call.

Three questions, each answered in one run:

1. What does a service round trip add to the mechanics? ``plan_squeeze`` on a cached object,
   in one process (SingleThreadedExecutor, the planner's, and EventsExecutor for comparison)
   and across processes (the planner as its own process). A request for an unknown object
   measures the bare service overhead (no mechanics).
2. How long does a cached-object stable squeeze take end to end as the mesh grows?
3. Does a long request block quick ones? A GraspMap goal that loads a large mesh runs on the
   planner's worker, first alone (the executor thread's CPU time shows whether the executor
   waits or spins), then while ``plan_squeeze`` requests keep arriving.
4. Is every request of a burst answered? One client sends N requests (or goals) at once to the
   planner process, with rclpy's default request queue and with the planner's keep-all one.

Targets: overhead < 2 ms in one process, < 5 ms across processes, a cached stable
squeeze request < 10 ms end to end. Without rclpy and the interfaces ``squeeze-grasp bench``
skips this section and says what to install (``bench.REQUIREMENTS``).
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from squeeze_grasp_ros.bench.table import Table

TITLE = "ROS services: round trip over the bare mechanics call"


def run(quick: bool, out_dir: Path, progress: Callable[[str], None]) -> list[Table]:
    """Measure the three tables in one run."""
    from squeeze_grasp_ros.ros.service_latency import (
        burst_rows,
        localhost_only,
        long_request_rows,
        overhead_rows,
    )

    sizes = (500, 2000) if quick else (500, 2000, 8000, 20000)
    count = 200 if quick else 1000
    with localhost_only() as namespace:
        overhead, by_size = overhead_rows(namespace, sizes, count, progress)
        long_rows = long_request_rows(namespace, 8000 if quick else 20000, progress)
        bursts = burst_rows(namespace, (10, 50, 200) if quick else (10, 50, 200, 1000),
                            progress)
    return [
        Table(
            TITLE,
            [
                "route",
                "executor",
                "error reply [ms]",
                "stable squeeze reply [ms]",
                "callback work [ms]",
                "mechanics [ms]",
                "overhead over mechanics [ms]",
                "reply / mechanics",
            ],
            overhead,
            f"Medians of {count} calls of ~/plan_squeeze on a cached {sizes[0]}-node object "
            "(two point contacts, rho = 4 mm). Error reply = a request for an unknown object: "
            "the service overhead alone. Mechanics = reduced stiffness + stable squeeze + "
            "boundary displacement; callback work adds validation and message building. "
            "Targets: overhead < 2 ms in one process, < 5 ms across processes.",
        ),
        Table(
            "ROS services: cached-object stable squeeze end to end vs mesh size",
            [
                "nodes n",
                "boundary b",
                "mechanics [ms]",
                "one process [ms]",
                "two processes [ms]",
                "two processes < 10 ms",
            ],
            by_size,
            "Medians of the ~/plan_squeeze round trip (SingleThreadedExecutor) after the "
            "object is loaded: the cached boundary compliance makes it independent of n.",
        ),
        Table(
            "ROS services: quick requests beside a long goal",
            [
                "executor",
                "goal mesh nodes",
                "goal time [s]",
                "executor CPU during goal [s/s]",
                "spin_once returns during goal [1/s]",
                "replies during a second goal",
                "median reply [ms]",
                "p99 reply [ms]",
                "max reply [ms]",
                "median reply, idle [ms]",
                "p99 < 10 ms",
            ],
            long_rows,
            "A GraspMap goal that loads (mesh, factorisation, boundary compliance) and maps a "
            "large object runs on the planner's worker. First alone: executor CPU = CPU time "
            "of the thread spinning the executor per wall second (0 = it waits; 1 = it "
            "spins); then again while ~/plan_squeeze requests are sent back to back from the "
            "same process (client and planner share the executor). Target: p99 of the quick "
            "replies under 10 ms while the goal runs.",
        ),
        Table(
            "ROS services: requests answered in a burst",
            [
                "request queue",
                "burst N",
                "plan_squeeze answered",
                "plan_squeeze burst [s]",
                "load_object answered",
                "grasp_map goal responses",
                "grasp_map results",
                "all N answered",
            ],
            bursts,
            "One client (keep-all queues of its own) sends N requests at once to the planner "
            "in its own process: plan_squeeze on a cached 500-node object, load_object under "
            "N distinct ids (at most max_pending = 16 run; the others are answered BUSY), "
            "grasp_map goals on the cached object (beyond max_pending: accepted, then "
            "ABORTED with BUSY). Unanswered 10 s after the last answer = lost. The planner's "
            "parameter service_queue_depth sets its request queues (services and the "
            "actions' goal, cancel and result services): 10 is rclpy's default, 0 (keep "
            "all, the default) drops none.",
        ),
    ]
