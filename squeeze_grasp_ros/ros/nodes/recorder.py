# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The recorder: every topic of a run, as raw CDR, into a rosbag2 bag with MCAP storage.

Run it with ``ros2 run squeeze_grasp_ros recorder --ros-args --params-file config/recorder.yaml
-p output:=runs/foam``. It subscribes with ``raw=True`` to the pipeline topics of its
``devices`` (:func:`.pipeline.pipeline_topics`) plus ``extra_topics`` and writes the bytes DDS
delivered with :class:`..recording.bag.BagWriter`; each topic's channel is created at its first
message with the QoS its publishers offer.

Log times: a message whose type starts with a header or a time (nearly all of them) is logged
at its own stamp, the sim time of its tick, so the same run gives the same recording whatever
the arrival order; others (action feedback and status, markers) at the recorder's clock.
Every stamped topic but ``monitor/alarms`` carries at most one message per stamp, so a message
whose stamp is among the last few of its topic is a re-sent copy (a lost tick re-sent by
``sim_hardware``, the status or setpoints answering it) and is not written again. (Comparing
bytes would not do: the CDR alignment padding is not zeroed, so two serialisations of one
message can differ.)

In lockstep it takes part in the start-up handshake and reports on ``recorder/progress`` the
newest tick it has written, every ``progress_every`` ticks, so ``sim_hardware`` never runs more
than its ``recorder_window`` ahead (what a stalled recorder process has not taken yet stays
within what the middleware holds for it, docs/pipeline.md); a wall-clock timer
repeats the newest tick 20 times a second, so the report of the last tick of a run arrives even
if one copy is lost. On Ctrl-C / SIGINT it first writes what has
already arrived, then ``close`` writes the MCAP summary and ``metadata.yaml``.

A message the middleware reports lost (``message_lost``: a reliable writer gave up a message
before this reader received it, its history having moved on, or a message sent before the
writer matched this reader) is counted per topic, logged as an error at the end and listed in
``metadata.yaml`` under ``custom_data.messages_lost`` (:data:`..recording.bag.LOST_KEY`), so a
recording with a gap says so. A publisher whose QoS this reader cannot take (a volatile
publisher of a topic the lockstep recorder reads transient-local, a best-effort one of a
reliable topic: the middleware never matches them) is logged as an error when discovered and
listed under ``custom_data.incompatible_publishers`` (:data:`..recording.bag.INCOMPATIBLE_KEY`):
nothing it publishes is recorded, and the recording says so.
"""
from __future__ import annotations

import sys
import time
from collections import Counter, deque
from collections.abc import Mapping
from typing import Any

import yaml
from rclpy.event_handler import (
    QoSMessageLostInfo,
    QoSRequestedIncompatibleQoSInfo,
    SubscriptionEventCallbacks,
)
from rclpy.node import Node
from rclpy.qos import (
    DurabilityPolicy,
    HistoryPolicy,
    QoSPolicyKind,
    QoSProfile,
    ReliabilityPolicy,
)
from std_msgs.msg import Header

from squeeze_grasp_ros.ros import messages
from squeeze_grasp_ros.ros.nodes import ParameterError, pipeline, run_node
from squeeze_grasp_ros.ros.recording.bag import (
    INCOMPATIBLE_KEY,
    LOST_KEY,
    BagWriter,
    qos_dict,
)
from squeeze_grasp_ros.ros.recording.schema import starts_with_stamp

PARAMETERS: dict[str, tuple[Any, str]] = {
    "output": ("", "bag folder to create (required; must not exist or be empty)"),
    "devices": (["barrett_f1", "barrett_f3"], "devices whose topics are recorded"),
    "extra_topics": ([""], "more topics to record, as 'name pkg/msg/Type' ('' = none)"),
    "lockstep_topics": ([""], "extra topics every lockstep tick publishes from a "
                        "transient-local publisher (a stock controller's joint_states and its "
                        "command): awaited and read transient-local like the pipeline's "
                        "('' = none)"),
    "silent_setpoints": ([""], "devices whose setpoint topics have no publisher (a stock "
                               "controller drives them; '' = none): not awaited at start-up"),
    "camera": (False, "also record the camera's images, info and pose, and the shape residual"),
    "include_hidden_topics": (False, "also record the executor action's hidden topics "
                                     "(_action/feedback, _action/status), as rosbag2 does only "
                                     "with --include-hidden-topics"),
    "compression": ("zstd", "chunk compression: zstd, lz4 or none"),
    "chunk_size": (262144, "uncompressed chunk size written out when full, bytes"),
    "custom_data": ("{}", "YAML mapping of strings stored in metadata.yaml custom_data"),
    "lockstep": (True, "take part in the start-up handshake and report progress on "
                       "recorder/progress"),
    "simulation": (True, "also record the simulated hardware's topics (/clock, sim/tick, "
                         "sim/state, sim/events, sim/markers); false on real hardware, where "
                         "nothing publishes them"),
    "progress_every": (5, "ticks between recorder/progress reports"),
    "sensor_qos": ("reliable", "QoS of the readings: reliable (lockstep) or sensor_data"),
    "qos_depth": (1000, "history depth of the subscriptions"),
}
"""Parameter name -> (typed default, description); config/recorder.yaml sets them."""
BOUNDS = {"chunk_size": pipeline.Bound(1, unit="bytes"), "progress_every": pipeline.Bound(1),
          "qos_depth": pipeline.Bound(1)}
"""The range of each numeric parameter."""

DUPLICATE_WINDOW = 16
"""Stamps per topic remembered to drop re-sent copies."""
POLICY_NAMES = {
    "history": {HistoryPolicy.KEEP_LAST: "keep_last", HistoryPolicy.KEEP_ALL: "keep_all"},
    "reliability": {ReliabilityPolicy.RELIABLE: "reliable",
                    ReliabilityPolicy.BEST_EFFORT: "best_effort"},
    "durability": {DurabilityPolicy.VOLATILE: "volatile",
                   DurabilityPolicy.TRANSIENT_LOCAL: "transient_local"},
}
"""rclpy QoS policies -> the names rosbag2 v9 writes (per policy: their integer values overlap)."""


class RecorderNode(Node):
    """Raw-subscription recorder writing a rosbag2 MCAP bag."""

    acknowledged_at_end = False
    """Its one publication, ``recorder/progress``, is flow control nobody needs once it ends:
    :func:`..nodes.run_node` does not wait for its readers (a wait ends only at the writer's
    next heartbeat, up to 3 s)."""

    def __init__(self, **kwargs: Any) -> None:
        super().__init__("recorder", **kwargs)
        self.p = p = pipeline.declare(self, PARAMETERS, bounds=BOUNDS)
        if not p["output"]:
            raise ParameterError("parameter 'output' (the bag folder) is required: "
                                 "--ros-args -p output:=/path/to/bag")
        custom = yaml.safe_load(p["custom_data"]) or {}
        self.writer = BagWriter(p["output"], p["compression"], p["chunk_size"],
                                {str(k): str(v) for k, v in custom.items()})
        pipeline.check_devices("devices", p["devices"])
        pipeline.check_devices("silent_setpoints", [d for d in p["silent_setpoints"] if d])
        topics = pipeline.pipeline_topics(p["devices"], hidden=p["include_hidden_topics"],
                                          camera=p["camera"], simulation=p["simulation"])
        self.sources = {name: name.lstrip("/") for name in topics}
        """Recorded name -> the name subscribed to: the pipeline's topics relative to the
        node's namespace (a run in a namespace records '/sim/tick' from '<ns>/sim/tick'),
        extra topics as given, a relative one recorded as the pipeline's are ('joint_states'
        as '/joint_states', the name a viewer's layout uses)."""
        for entry in p["extra_topics"]:
            if entry.strip():
                name, type_name = entry.split()
                pipeline.check_topic("extra_topics", name)
                recorded = name if name.startswith("/") else "/" + name
                topics[recorded] = type_name
                self.sources[recorded] = name
        self.types = topics
        self.stamped = {name: starts_with_stamp(t) for name, t in topics.items()}
        self.unique = {name for name, stamped in self.stamped.items()
                       if stamped and name != "/" + pipeline.ALARMS}
        self.recent = {name: deque(maxlen=DUPLICATE_WINDOW) for name in self.unique}
        self.duplicates = 0
        self.written = 0
        self.lost: Counter[str] = Counter()
        """Recorded topic -> messages the middleware reported lost on its way here."""
        self.incompatible: dict[str, str] = {}
        """Recorded topic -> the QoS policy of a publisher this reader could not take."""
        self.ticks = 0
        self.newest_tick_ns = -1
        self.reported_ns = -1
        latched = {"/" + pipeline.PREDICTION, "/" + pipeline.OBJECT_POSE,
                   f"/{pipeline.ACTION}/_action/status"} | {
                       "/" + t for t in (pipeline.CAMERA_POSE, pipeline.PREDICTED_SHAPES)}
        camera = {"/" + t for t in (pipeline.CAMERA_MASK, pipeline.CAMERA_DEPTH,
                                    pipeline.CAMERA_INFO)}
        sensors = {name for name in topics if name.rsplit("/", 1)[-1] in pipeline.STREAMS}
        extra_loop = [pipeline.check_topic("lockstep_topics", t) for t in p["lockstep_topics"]
                      if t.strip()]
        kept = ({"/" + t.lstrip("/") for t in [*pipeline.loop_topics(p["devices"]), *extra_loop,
                                               *pipeline.RECORDED_OUTPUTS]}
                if p["lockstep"] else set())
        """Lockstep topics whose publishers keep their last messages for a late reader."""
        for name, type_name in topics.items():
            qos = (pipeline.LATCHED if name in latched
                   else pipeline.CAMERA if name in camera
                   else pipeline.sensor_qos(p["sensor_qos"], p["qos_depth"], kept=name in kept)
                   if name in sensors
                   else pipeline.loop_qos(p["qos_depth"], kept=name in kept))
            self.create_subscription(
                pipeline.message_type(type_name), self.sources[name],
                lambda data, n=name: self._record(n, data), qos, raw=True,
                event_callbacks=SubscriptionEventCallbacks(
                    message_lost=lambda info, n=name: self._lost(n, info),
                    incompatible_qos=lambda info, n=name, q=qos: self._incompatible(n, q, info)))
        self.progress_pub = self.create_publisher(Header, pipeline.RECORDER_PROGRESS,
                                                  pipeline.loop_qos(10)) \
            if p["lockstep"] else None
        """The lockstep handshake's flow control (no publisher without the handshake)."""
        if p["lockstep"]:
            awaited = pipeline.loop_topics(p["devices"],
                                           silent=[d for d in p["silent_setpoints"] if d])
            awaited += extra_loop
            self.participant = pipeline.Participant(self, "recorder", awaited,
                                                    [self.progress_pub])
            pipeline.wall_timer(self, 0.05, self._repeat_report)


    def ready_summary(self) -> str:
        """What the ready line of ``ros2 run`` says: the bag and how many topics."""
        return f"recording {len(self.types)} topics into {self.p['output']}"

    def _offered_qos(self, topic: str) -> list[dict]:
        def name(policy: str, value) -> str:
            return POLICY_NAMES[policy].get(value, "unknown")
        return [qos_dict(name("history", q.history), q.depth, name("reliability", q.reliability),
                         name("durability", q.durability))
                for q in (i.qos_profile
                          for i in self.get_publishers_info_by_topic(
                              self.resolve_topic_name(self.sources[topic])))]

    def _record(self, topic: str, data: bytes) -> None:
        ns = (messages.cdr_stamp_ns(data) if self.stamped[topic]
              else self.get_clock().now().nanoseconds)
        if topic in self.unique:
            if ns in self.recent[topic]:
                self.duplicates += 1
                return
            self.recent[topic].append(ns)
        if topic not in self.writer.topics:
            self.writer.add_topic(topic, self.types[topic], self._offered_qos(topic))
        self.writer.write(topic, data, ns)
        if self.writer.failure is None:
            self.written += 1
        elif self.writer.dropped == 1:
            self.get_logger().error(
                f"recording stopped: {self.writer.failure}; {self.p['output']} keeps every "
                "message up to the last complete chunk and is finished at shutdown")
        if topic == "/" + pipeline.TICK:
            self.ticks += 1
            self.newest_tick_ns = ns
            if self.ticks % self.p["progress_every"] == 0:
                self._report()

    def _lost(self, topic: str, info: QoSMessageLostInfo) -> None:
        self.lost[topic] += info.total_count_change

    def _incompatible(self, topic: str, qos: QoSProfile,
                      info: QoSRequestedIncompatibleQoSInfo) -> None:
        policy = QoSPolicyKind(info.last_policy_kind).name.lower()
        if topic in self.incompatible:
            return
        self.incompatible[topic] = policy
        asked = ", ".join(POLICY_NAMES[kind].get(value, "unknown") for kind, value in
                          (("reliability", qos.reliability), ("durability", qos.durability)))
        self.get_logger().error(
            f"{topic}: a publisher offers a QoS the recorder cannot take ({policy}; the "
            f"recorder asks {asked}): nothing it publishes is recorded")

    def _report(self) -> None:
        """Publish the newest tick written, if not reported yet."""
        if self.newest_tick_ns > self.reported_ns:
            self._repeat_report()

    def _repeat_report(self) -> None:
        """Publish the newest tick written (again: a lost report is repeated by the timer)."""
        if self.newest_tick_ns >= 0 and self.progress_pub is not None:
            self.reported_ns = self.newest_tick_ns
            self.progress_pub.publish(messages.header(self.newest_tick_ns))

    def drain(self, executor, idle: float = 0.05) -> None:
        """Write what has already arrived: spin ``executor`` until ``idle`` wall-clock seconds
        pass without a new message written.

        Idleness is judged by what is written, not by the executor returning early: timers
        (this node's progress timer has a period of ``idle``) and re-sent ticks (dropped as
        duplicates) keep an executor busy forever. The executor is always spun with the same
        timeout (``SingleThreadedExecutor`` discards its ready entities when it changes).
        """
        while True:
            written, until = self.written, time.monotonic() + idle
            while time.monotonic() < until:
                executor.spin_once(idle / 5.0)
            if self.written == written:
                return

    def close(self) -> None:
        """Finish the recording (summary and metadata.yaml, with the messages reported lost);
        safe to call twice.
        """
        if self.lost and not self.writer.closed:
            self.writer.custom_data[LOST_KEY] = lost_text(self.lost)
            self.get_logger().error(f"{self.p['output']} misses messages the middleware "
                                    f"reported lost: {lost_text(self.lost)}")
        if self.incompatible and not self.writer.closed:
            self.writer.custom_data[INCOMPATIBLE_KEY] = lost_text(self.incompatible)
        self.writer.close()


def lost_text(lost: Mapping[str, Any]) -> str:
    """``{topic: value, ...}`` (YAML flow mapping, by topic): the messages lost, or the
    policies of incompatible publishers.
    """
    return yaml.safe_dump(dict(sorted(lost.items())), default_flow_style=True,
                          width=1 << 16).strip()


def main(args: list[str] | None = None) -> int:
    """Record until Ctrl-C or shutdown, then finish the bag; return the exit code."""
    return run_node(RecorderNode, args)


if __name__ == "__main__":
    sys.exit(main())
