# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""A run's isolation: its own namespace, and a watch on it for traffic it did not start.

A run's nodes (its planner, the pipeline nodes, its client) live in a namespace of their own
(:func:`run_namespace`), and ``/clock`` is remapped into it, so every topic, service and action
of the run carries the run's identity in its name and two runs on one ROS domain never see each
other's traffic. :class:`GraphWatch` checks that namespace: a publisher the run did not start on
one of its topics, or a second node with the name of one of its nodes, ends the run with
:class:`.options.RunError` (exit 4), never a success.
"""
from __future__ import annotations

import os
import secrets
import time
from collections import Counter
from collections.abc import Callable, Iterable

from rclpy.node import Node

from squeeze_grasp_ros.mechanics.vocabulary import Effect
from squeeze_grasp_ros.ros.nodes import pipeline
from squeeze_grasp_ros.ros.run.options import RunError, controller_topics
from squeeze_grasp_ros.scene import Scene, finger_devices

__all__ = ["GRAPH_CHECK_PERIOD", "UNKNOWN_NODE", "UNKNOWN_NODE_GRACE", "GraphWatch",
           "node_topic", "run_namespace", "run_topics"]

GRAPH_CHECK_PERIOD = 1.0
"""Wall-clock seconds between two checks of the run's namespace for foreign traffic."""
UNKNOWN_NODE = "_NODE_NAME_UNKNOWN_"
"""The node name rmw reports for a publisher discovered before its node's graph information."""
UNKNOWN_NODE_GRACE = 10.0
"""Wall-clock seconds a publisher may stay without a node name before it counts as foreign (a
plain DDS writer never gets one)."""


def run_namespace() -> str:
    """A namespace no other run uses: ``/squeeze_grasp/run_<pid>_<8 random hex digits>``."""
    return f"/squeeze_grasp/run_{os.getpid()}_{secrets.token_hex(4)}"


def run_topics(scene: Scene) -> list[str]:
    """Every topic of a run of ``scene`` (action topics and handshake included), relative
    (``/clock`` as ``clock``: it is remapped into the run's namespace).
    """
    devices = finger_devices(scene).values()
    names = list(pipeline.pipeline_topics(devices, hidden=True,
                                          camera=scene.has(Effect.CAMERA)))
    names += [f"/{t}" for t in (pipeline.HELLO, pipeline.READY, pipeline.RECORDER_PROGRESS)]
    if scene.controller is not None:
        names += [f"/{topic.split()[0]}" for topic in controller_topics(scene.controller)]
    return [t.lstrip("/") for t in names]


def node_topic(namespace: str, topic: str) -> str:
    """``topic`` (relative) in ``namespace``.

    >>> node_topic("/lab/run_1", "sim/tick"), node_topic("/", "sim/tick")
    ('/lab/run_1/sim/tick', '/sim/tick')
    """
    return f"{namespace.rstrip('/')}/{topic}"


class GraphWatch:
    """The check of a run's namespace for foreign traffic.

    Parameters
    ----------
    node : Node
        The run's client node (it asks the ROS graph).
    namespace : str
        The run's namespace.
    topics : iterable of str
        The run's topics, relative (:func:`run_topics`).
    """

    def __init__(self, node: Node, namespace: str, topics: Iterable[str]) -> None:
        self.node = node
        self.namespace = namespace
        self.topics = [node_topic(namespace, t) for t in topics]
        """The run's topics, fully qualified: the ones :meth:`check` watches."""
        self.ours = {node.get_name()}
        """Names of the nodes this run started in its namespace (grows as they start)."""
        self.checked = -float("inf")
        self.unknown_since: dict[bytes, float] = {}
        """Publisher GID -> when it was first seen without a node name (discovery pending)."""

    def due(self) -> bool:
        """True when the last check is older than :data:`GRAPH_CHECK_PERIOD`."""
        return time.monotonic() > self.checked + GRAPH_CHECK_PERIOD

    def check(self) -> bool:
        """Raise :class:`RunError` if anything foreign takes part in the run.

        Foreign: a publisher on one of the run's topics (the pipeline's, resolved in the run's
        namespace) from a node this run did not start, or a second node with the name of one
        of the run's nodes in its namespace (another run, or a planner answering in its
        place). Subscribers (a viewer) and other nodes are not the run's business.

        Returns
        -------
        bool
            Whether a publisher on the run's topics is still unnamed (discovered before its
            node, and younger than :data:`UNKNOWN_NODE_GRACE`): neither cleared nor foreign yet.
        """
        self.checked = now = time.monotonic()
        ns, node, pending = self.namespace, self.node, False
        names = Counter(n for n, space in node.get_node_names_and_namespaces()
                        if space == ns and n in self.ours)
        foreign = [f"{k} nodes named {ns.rstrip('/')}/{n}" for n, k in names.items() if k > 1]
        for topic in self.topics:
            for info in node.get_publishers_info_by_topic(topic):
                if info.node_name == UNKNOWN_NODE:  # discovered before its node's name
                    first = self.unknown_since.setdefault(bytes(info.endpoint_gid), now)
                    if now - first < UNKNOWN_NODE_GRACE:
                        pending = True
                        continue
                elif info.node_namespace == ns and info.node_name in self.ours:
                    continue
                foreign.append(f"{info.node_namespace.rstrip('/')}/{info.node_name} "
                               f"publishing on {topic}")
        if foreign:
            raise RunError(
                f"foreign traffic in this run's namespace {ns}: {'; '.join(sorted(foreign)[:3])}"
                f"{' and more' if len(foreign) > 3 else ''}; the run's results cannot be "
                "trusted, so it is stopped"
            )
        return pending

    def check_before_success(self, spin_once: Callable[[], None]) -> None:
        """The last :meth:`check` before a result is reported: a publisher still unnamed is
        waited for (``spin_once`` between checks) until it is named (ours) or its grace ends
        (foreign: raised), so a run that ends inside an intruder's grace never reports success.
        """
        while self.check():
            spin_once()
