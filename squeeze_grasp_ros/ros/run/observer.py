# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""What a run's client receives while the goal runs: the ground truth (``sim/state``,
``sim/events``), the monitor's events and alarms, the recorder's progress and the goal's
feedback. :meth:`Observer.observed` turns it into the :class:`.summary.Observed` of the summary.
"""
from __future__ import annotations

from collections import Counter
from collections.abc import Callable
from typing import Any

from rclpy.node import Node
from rclpy.qos import DurabilityPolicy
from rclpy.serialization import deserialize_message
from std_msgs.msg import Header

from squeeze_grasp_interfaces.action import ExecuteGrasp
from squeeze_grasp_interfaces.msg import Alarm, ContactEvent, ContactEventArray, SimState
from squeeze_grasp_ros.ros import messages
from squeeze_grasp_ros.ros.messages.cdr import cdr_stamp_ns
from squeeze_grasp_ros.ros.nodes import pipeline
from squeeze_grasp_ros.ros.run.summary import GRASP_HELD, Observed
from squeeze_grasp_ros.sim.world import RELEASED

__all__ = ["Observer", "Progress"]

Progress = Callable[[dict], None]
"""Called with ``{"state", "depth", "relative_depth", "forces", "events"}`` at every feedback."""


class Observer:
    """The run client's subscriptions to the outcome topics, and what they received.

    Parameters
    ----------
    node : Node
        The run's client node.
    progress : callable, optional
        Called at every feedback of the goal (:data:`Progress`).
    kept : bool
        Subscribe transient-local to the outcome topics, as their lockstep publishers offer
        (:func:`.pipeline.output_qos`): a run's own nodes. Across processes this client can see
        a publisher before that publisher's writer has matched this client's reader (discovery
        is not symmetric), and a volatile reader loses what the writer sent before the match
        (seen under load: a ``--processes`` run's first four monitor events). Not for attached
        nodes, whose history may hold an earlier run's outcome.
    """

    def __init__(self, node: Node, progress: Progress | None = None, *,
                 kept: bool = False, on_state: Callable[[], None] = lambda: None) -> None:
        self.node = node
        self.on_state = on_state
        self.progress = progress
        self.kept = kept
        self.sim_events: list[ContactEvent] = []
        self.world_end: dict | None = None
        """``{"termination", "depth", "stamp_ns"}`` once the world ended (the last end)."""
        self.world_releases: list[dict] = []
        """``{"stamp_ns", "after"}`` of every release of the object (after: the end it
        follows, as ``world_end``)."""
        self.monitor_events: list[ContactEvent] = []
        self.alarms: Counter = Counter()
        self.first_alarm: dict[str, dict] = {}
        self.sim_state_data: list[bytes] = []
        """Every ground-truth state received, serialised (decoded on demand)."""
        self.sim_state_ns = -1
        self.recorder_ns = -1
        self.feedback: list[ExecuteGrasp.Feedback] = []
        loop = pipeline.loop_qos(1000, kept=kept)
        self.subscriptions = [
            node.create_subscription(ContactEventArray, pipeline.SIM_EVENTS, self._sim_events,
                                     loop),
            node.create_subscription(ContactEventArray, pipeline.EVENTS,
                                     lambda msg: self.monitor_events.extend(msg.events), loop),
            node.create_subscription(Alarm, pipeline.ALARMS, self._alarm, loop),
            node.create_subscription(SimState, pipeline.SIM_STATE, self._state, loop, raw=True),
        ]
        """The subscriptions to the outcome topics (they must match before the goal is sent)."""
        node.create_subscription(Header, pipeline.RECORDER_PROGRESS, self._recorder_progress,
                                 pipeline.loop_qos(1000))

    # ----------------------------------------------------------------- callbacks
    def _sim_events(self, msg: ContactEventArray) -> None:
        self.sim_events += msg.events
        if msg.termination == RELEASED:
            self.world_releases.append({"stamp_ns": messages.stamp_ns(msg.header.stamp),
                                        "after": self.world_end})
            self.world_end = None
        elif msg.termination:
            self.world_end = {
                "termination": msg.termination,
                "depth": float(msg.depth),
                "stamp_ns": messages.stamp_ns(msg.header.stamp),
            }

    def _alarm(self, msg: Alarm) -> None:
        self.alarms[msg.type] += 1
        self.first_alarm.setdefault(
            msg.type,
            {
                "stamp_ns": messages.stamp_ns(msg.header.stamp),
                "finger": msg.finger,
                "message": msg.message,
            },
        )

    def _state(self, data: bytes) -> None:
        self.sim_state_data.append(data)
        self.sim_state_ns = cdr_stamp_ns(data)
        self.on_state()

    def _recorder_progress(self, msg: Header) -> None:
        self.recorder_ns = max(self.recorder_ns, messages.stamp_ns(msg.stamp))

    def on_feedback(self, msg: Any) -> None:
        """The goal's feedback callback (records it, reports progress)."""
        fb = msg.feedback
        self.feedback.append(fb)
        if self.progress is not None:
            self.progress(
                {
                    "state": fb.state,
                    "depth": fb.depth,
                    "relative_depth": fb.relative_depth,
                    "forces": {f: [v.x, v.y] for f, v in zip(fb.fingers, fb.forces)},
                    "events": len(self.monitor_events),
                }
            )

    # ----------------------------------------------------------------- what was received
    def matched(self) -> bool:
        """True once every outcome subscription has a publisher."""
        return all(s.get_publisher_count() > 0 for s in self.subscriptions)

    def incompatible(self) -> list[str]:
        """``topic (node)`` of every outcome publisher that this client, subscribed kept,
        never receives from: a volatile one (a loop node not in lockstep).
        """
        if not self.kept:
            return []
        return [
            f"{sub.topic_name} ({info.node_namespace.rstrip('/')}/{info.node_name})"
            for sub in self.subscriptions
            for info in self.node.get_publishers_info_by_topic(sub.topic_name)
            if info.qos_profile.durability != DurabilityPolicy.TRANSIENT_LOCAL
        ]

    def world_failed(self) -> bool:
        """True once the simulated world has ended with a termination that loses the grasp."""
        return self.world_end is not None and self.world_end["termination"] not in GRASP_HELD

    @property
    def sim_state(self) -> SimState | None:
        """The newest ground-truth state, or None before tick 0."""
        return (
            deserialize_message(self.sim_state_data[-1], SimState) if self.sim_state_data else None
        )

    @property
    def sim_states(self) -> list[SimState]:
        """Every ground-truth state received, in order (one per tick, re-sent ticks repeated)."""
        return [deserialize_message(data, SimState) for data in self.sim_state_data]

    def observed(self) -> Observed:
        """What was received, for the summary."""
        return Observed(self.sim_state, list(self.sim_events), self.world_end,
                        list(self.monitor_events), self.alarms, self.first_alarm,
                        list(self.world_releases))
