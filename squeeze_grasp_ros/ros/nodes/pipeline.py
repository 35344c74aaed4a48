# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Topics, QoS, parameters and the lockstep handshake shared by the pipeline nodes.

Topic names are relative (so a namespace or a remap moves them); devices get
``devices/<device>/{setpoint,pose,wrench,tactile}``. QoS (docs/design.md §5): commands,
states and events reliable; sensor streams reliable in simulation (the lockstep loop must not
lose a reading) and ``sensor_data`` (best effort) on hardware, chosen by the ``sensor_qos``
parameter; latched data (the prediction, the object pose) transient-local.

Lockstep start-up (docs/design.md §4): a publisher that reports its subscriber as matched can
still lose the first messages across processes. So the driver (``sim_hardware``, or the
replayer) repeats ``sim/hello`` on a wall-clock timer and starts tick 0 only when every
participant it waits for has answered on ``sim/ready``; a participant answers each hello once
its own lockstep publishers and subscriptions see their peers. Lost ticks are re-sent by the
driver and handled idempotently by stamp in every node.
"""
from __future__ import annotations

import importlib
import math
from collections.abc import Callable, Collection, Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from rcl_interfaces.msg import ParameterDescriptor
from rclpy.clock import Clock, ClockType
from rclpy.event_handler import PublisherEventCallbacks
from rclpy.exceptions import InvalidParameterTypeException
from rclpy.impl.implementation_singleton import rclpy_implementation
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import (
    DurabilityPolicy,
    HistoryPolicy,
    QoSProfile,
    ReliabilityPolicy,
    qos_profile_sensor_data,
)
from rclpy.serialization import deserialize_message, serialize_message
from std_msgs.msg import String

from squeeze_grasp_ros.inputs import shown
from squeeze_grasp_ros.ros.nodes import ParameterError

rcl_time_point = rclpy_implementation.rcl_time_point_t
"""rclpy's time point type (what ``rclpy.time.Time`` wraps)."""

FRAME = "object"
"""Default object frame: x right, y up, the scene's coordinates (m)."""
STREAMS: tuple[str, ...] = ("pose", "wrench", "tactile")
"""Readings a device publishes per tick."""
CLOCK = "/clock"
TICK = "sim/tick"
HELLO = "sim/hello"
READY = "sim/ready"
SIM_STATE = "sim/state"
SIM_EVENTS = "sim/events"
MARKERS = "sim/markers"
RECORDER_PROGRESS = "recorder/progress"
STATUS = "monitor/status"
CONTACT_STATE = "monitor/contact_state"
EVENTS = "monitor/events"
ALARMS = "monitor/alarms"
PREDICTION = "planner/predicted_events"
EXECUTOR_STATUS = "executor/status"
EXECUTOR_CYCLE = "executor/cycle"
"""std_msgs/Header stamped with each tick the executor has answered, once its requests to a
gripper action controller for that tick were acknowledged (the lockstep of the action route)."""
JOINT_STATES = "joint_states"
"""The joint_state_broadcaster's topic (a stock controller's joint feedback)."""
OBJECT_POSE = "object_pose"
GRIPPER_POSE = "gripper_pose"
"""geometry_msgs/PoseStamped of a parallel gripper in the object frame (its centre, x axis the
closing direction: ``plan_gripper_grasp``'s pose), from which the monitor fixes the jaw line."""
ACTION = "executor/execute_grasp"
CAMERA_MASK = "camera/mask"
CAMERA_DEPTH = "camera/depth"
CAMERA_INFO = "camera/camera_info"
CAMERA_POSE = "camera/pose"
OUTLINE = "outline/outline"
SEEN_OUTLINE = "outline/seen"
OUTLINE_ERRORS = "outline/errors"
SHAPE_RESIDUAL = "monitor/shape_residual"
FORCE_RESIDUAL = "monitor/force_residual"
PREDICTED_SHAPES = "planner/predicted_shapes"


def action_name(node: Node, name: str) -> str:
    """The fully qualified name an rclpy action server or client of ``node`` takes for
    ``name``: expanded into the node's namespace, never remapped (rclpy 7.1, Jazzy, applies no
    remap rule to action names). A rule that would rename it is logged as a warning, naming
    the name the action keeps; before, the executor's ready line named the remapped name, where
    no action was.
    """
    expanded = node.resolve_topic_name(name, only_expand=True)
    remapped = node.resolve_topic_name(name)
    if remapped != expanded:
        node.get_logger().warning(
            f"the remap of action {name} to {remapped} is not applied (rclpy remaps no action "
            f"names): the action is {expanded}; move it with the namespace (__ns) instead")
    return expanded


def device_topic(device: str, stream: str) -> str:
    """``devices/<device>/<stream>`` (stream: setpoint, pose, wrench, tactile)."""
    return f"devices/{device}/{stream}"


def loop_topics(devices: Iterable[str], *, silent: Iterable[str] = ()) -> list[str]:
    """The topics every lockstep tick publishes whatever the scene's effects (relative): the
    tick, the ground truth, the monitor's status and contact state, each device's pose and
    setpoint (but not the setpoint of a ``silent`` device, which a stock controller drives).
    A recorder is ready once each has a publisher, so the first tick's messages of every loop
    node reach it (across processes, discovery can match the executor seconds after the
    driver).
    """
    silent = set(silent)
    names = [TICK, SIM_STATE, STATUS, CONTACT_STATE]
    for device in devices:
        names.append(device_topic(device, "pose"))
        if device not in silent:
            names.append(device_topic(device, "setpoint"))
    return names


RECORDED_OUTPUTS: tuple[str, ...] = (SIM_EVENTS, MARKERS, EVENTS, ALARMS, FORCE_RESIDUAL,
                                     EXECUTOR_STATUS)
"""The loop nodes' other recorded topics (relative): published on some ticks only, from the
first (the executor's status at the goal's tick 0). In lockstep their publishers keep them
(:func:`output_qos`) and the lockstep recorder asks for that, so a message published before
the writer had matched the recorder's reader (discovery across processes under load: the
executor's first status was missing from 2 of 40 recordings of two runs at once) still
reaches it.
"""


def output_qos(depth: int, *, lockstep: bool) -> QoSProfile:
    """QoS of a publisher of :data:`RECORDED_OUTPUTS`: :func:`loop_qos`, kept in lockstep
    (a late reader on hardware is not sent old events and alarms).
    """
    return loop_qos(depth, kept=lockstep)


def status_qos(depth: int, *, lockstep: bool) -> QoSProfile:
    """QoS of the executor's status (its state, published on change): :func:`output_qos` in
    lockstep; on hardware :data:`LATCHED`, the current state only, which a reader that starts
    later (``ros2 topic echo``, a dashboard) gets at once. Before, it was volatile on hardware:
    a late reader got nothing until the state next changed (through a whole hold), and one
    asking for transient-local durability matched no publisher at all.
    """
    return output_qos(depth, lockstep=True) if lockstep else LATCHED


SIMULATION_TOPICS = (CLOCK, TICK, SIM_STATE, SIM_EVENTS, MARKERS)
"""The recorded topics only the simulated hardware publishes."""


def pipeline_topics(devices: Iterable[str], *, hidden: bool = False,
                    camera: bool = False, simulation: bool = True) -> dict[str, str]:
    """Topic (fully qualified) -> type of every topic of a run with ``devices``.

    ``hidden`` adds the executor action's hidden topics (``.../_action/feedback`` and
    ``.../_action/status``), which rosbag2 too records only when asked; ``camera`` the camera's
    images, its info and pose, and the monitor's shape residual (scenes with a camera);
    ``simulation`` False leaves out :data:`SIMULATION_TOPICS` (real hardware).
    """
    types = {
        CLOCK: "rosgraph_msgs/msg/Clock",
        TICK: "squeeze_grasp_interfaces/msg/Tick",
        SIM_STATE: "squeeze_grasp_interfaces/msg/SimState",
        SIM_EVENTS: "squeeze_grasp_interfaces/msg/ContactEventArray",
        MARKERS: "visualization_msgs/msg/MarkerArray",
        STATUS: "squeeze_grasp_interfaces/msg/MonitorStatus",
        CONTACT_STATE: "squeeze_grasp_interfaces/msg/ContactState",
        EVENTS: "squeeze_grasp_interfaces/msg/ContactEventArray",
        ALARMS: "squeeze_grasp_interfaces/msg/Alarm",
        FORCE_RESIDUAL: "squeeze_grasp_interfaces/msg/ForceResidual",
        PREDICTION: "squeeze_grasp_interfaces/msg/ContactEventArray",
        EXECUTOR_STATUS: "squeeze_grasp_interfaces/msg/ExecutorStatus",
        OBJECT_POSE: "geometry_msgs/msg/PoseStamped",
    }
    if not simulation:
        for name in SIMULATION_TOPICS:
            del types[name]
    if hidden:
        types[f"{ACTION}/_action/feedback"] = \
            "squeeze_grasp_interfaces/action/ExecuteGrasp_FeedbackMessage"
        types[f"{ACTION}/_action/status"] = "action_msgs/msg/GoalStatusArray"
    if camera:
        types.update({CAMERA_MASK: "sensor_msgs/msg/Image", CAMERA_DEPTH: "sensor_msgs/msg/Image",
                      CAMERA_INFO: "sensor_msgs/msg/CameraInfo",
                      CAMERA_POSE: "geometry_msgs/msg/PoseStamped",
                      SHAPE_RESIDUAL: "squeeze_grasp_interfaces/msg/ShapeResidual",
                      PREDICTED_SHAPES: "squeeze_grasp_interfaces/msg/PredictedShapes"})
    stream_types = {"setpoint": "geometry_msgs/msg/PoseStamped",
                    "pose": "geometry_msgs/msg/PoseStamped",
                    "wrench": "geometry_msgs/msg/WrenchStamped",
                    "tactile": "squeeze_grasp_interfaces/msg/TactileArray"}
    for device in devices:
        for stream, type_name in stream_types.items():
            types[device_topic(device, stream)] = type_name
    return {("/" + k).replace("//", "/"): v for k, v in types.items()}


MESSAGE_PACKAGES: frozenset[str] = frozenset({
    "squeeze_grasp_interfaces", "std_msgs", "geometry_msgs", "sensor_msgs", "visualization_msgs",
    "rosgraph_msgs", "action_msgs", "builtin_interfaces", "unique_identifier_msgs",
    "trajectory_msgs"})
"""Packages whose message types :func:`message_type` resolves: the interfaces this package
uses. A type name is data (a recording, a parameter): no other module is ever imported."""


def message_type(type_name: str) -> type:
    """The Python class of 'pkg/msg/Type' or of an action's 'pkg/action/Name_Suffix' message,
    for the packages of :data:`MESSAGE_PACKAGES` only.

    Raises
    ------
    ValueError
        For another package, another kind, or a name that is not one.
    """
    package, kind, name = (type_name.split("/") + ["", "", ""])[:3]
    if (package not in MESSAGE_PACKAGES or kind not in ("msg", "action")
            or not name.isidentifier() or type_name.count("/") != 2):
        raise ValueError(f"message type {type_name[:80]!r} is not one of this package's "
                         f"(pkg/msg/Type with pkg in {sorted(MESSAGE_PACKAGES)})")
    module = importlib.import_module(f"{package}.{kind}")
    if kind == "action" and "_" in name:
        action, _, part = name.partition("_")
        return getattr(getattr(module, action).Impl, part)
    return getattr(module, name)


def round_trip(messages: Sequence[tuple[str, bytes]]) -> Callable[[], None]:
    """A function that deserialises and re-serialises ``messages`` ((type name, CDR bytes)
    pairs) with rclpy, for timing what rclpy's message conversion costs.
    """
    decoded = [(message_type(type_name), data) for type_name, data in messages]

    def convert() -> None:
        for cls, data in decoded:
            serialize_message(deserialize_message(data, cls))
    return convert


def check_topic(parameter: str, topic: str, *, device: str | None = None) -> str:
    """``topic``, a topic name taken from parameter ``parameter`` (made from its ``device``,
    if given), if ROS takes it as a name.

    Before, a name ROS refuses (``image_topic:=cam-mask``, a device ``left-jaw``) ended the
    node with rclpy's traceback and exit status 1 when the node created its publisher or
    subscription.

    Raises
    ------
    ParameterError
        Naming the parameter, its value and rcl's reason.

    >>> check_topic("image_topic", "camera/mask")
    'camera/mask'
    >>> check_topic("image_topic", "cam-mask")
    Traceback (most recent call last):
    ...
    squeeze_grasp_ros.ros.nodes.ParameterError: parameter 'image_topic': 'cam-mask' is a ...
    """
    error = rclpy_implementation.rclpy_get_validation_error_for_topic_name(topic)
    if error is None:
        return topic
    what = (f"device {device!r} gives the topic name {topic!r}, which ROS refuses"
            if device is not None else f"{topic!r} is a topic name ROS refuses")
    raise ParameterError(f"parameter '{parameter}': {what}: {error[0]}")


def check_devices(parameter: str, devices: Iterable[str]) -> None:
    """Refuse (:func:`check_topic`) a device of parameter ``parameter`` whose topics
    (:func:`device_topic`) ROS refuses as names.

    >>> check_devices("devices", ["barrett_f1", "2jaw"])
    Traceback (most recent call last):
    ...
    squeeze_grasp_ros.ros.nodes.ParameterError: parameter 'devices': device '2jaw' gives ...
    """
    for device in devices:
        check_topic(parameter, device_topic(device, "setpoint"), device=device)


def parse_mapping(entries: Sequence[str], what: str) -> dict[str, str]:
    """``["F1:barrett_f1", ...]`` -> {"F1": "barrett_f1", ...}.

    Raises
    ------
    ValueError
        For an entry without exactly one ':' or a repeated key, or a device that gives no
        valid topic name (:func:`check_devices`).
    """
    out: dict[str, str] = {}
    for entry in entries:
        key, sep, value = entry.partition(":")
        if not sep or not key or not value or ":" in value or key in out:
            raise ValueError(f"{what}: expected distinct 'finger:device' entries, got {entry!r}")
        out[key] = value
    check_devices(what, out.values())
    return out


def loop_qos(depth: int, *, kept: bool = False) -> QoSProfile:
    """Reliable, keep-last ``depth``: commands, states, events, lockstep ticks.

    Volatile, unless ``kept``: then transient-local, so that a reader asking for it that
    matches late still receives the last ``depth`` messages. The publishers of the lockstep
    topics a recorder awaits (:func:`loop_topics`) offer it and the lockstep recorder asks
    for it: across processes the recorder can see a publisher in the graph before that
    publisher's writer has matched the recorder's reader, and a volatile writer drops what it
    sends before the match (the first ticks). Every volatile reader stays compatible.
    """
    durability = DurabilityPolicy.TRANSIENT_LOCAL if kept else DurabilityPolicy.VOLATILE
    return QoSProfile(depth=depth, reliability=ReliabilityPolicy.RELIABLE,
                      history=HistoryPolicy.KEEP_LAST, durability=durability)


def sensor_qos(kind: str, depth: int, *, kept: bool = False) -> QoSProfile:
    """QoS of the sensor streams: "reliable" (simulation) or "sensor_data" (hardware).

    ``kept`` as in :func:`loop_qos` (reliable streams only: best effort keeps nothing).
    """
    if kind == "reliable":
        return loop_qos(depth, kept=kept)
    if kind == "sensor_data":
        return qos_profile_sensor_data
    raise ValueError(f"sensor_qos must be 'reliable' or 'sensor_data', got {kind!r}")


def request_queue(depth: int) -> QoSProfile:
    """QoS of a server's request queues (the planner's services and actions, the executor's
    action): reliable, volatile, keep-all for ``depth`` 0 (no request is ever dropped), else
    keep-last ``depth``.

    rclpy's default for services (keep-last 10) drops the 11th and later requests of a burst
    inside DDS before rclpy sees them; with keep-all a burst of 2,000 ``plan_squeeze`` requests
    was answered in full (``bench ros_services``).

    >>> request_queue(0).history.name, request_queue(100).depth
    ('KEEP_ALL', 100)
    """
    if depth < 0:
        raise ValueError(f"service_queue_depth must be >= 0 (0 = keep all), got {depth}")
    return QoSProfile(history=HistoryPolicy.KEEP_ALL if depth == 0 else HistoryPolicy.KEEP_LAST,
                      depth=depth or 1, reliability=ReliabilityPolicy.RELIABLE,
                      durability=DurabilityPolicy.VOLATILE)


LATCHED = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE,
                     history=HistoryPolicy.KEEP_LAST, durability=DurabilityPolicy.TRANSIENT_LOCAL)
"""Transient-local: late subscribers get the last message (prediction, object pose)."""
CAMERA = QoSProfile(depth=8, reliability=ReliabilityPolicy.RELIABLE,
                    history=HistoryPolicy.KEEP_LAST, durability=DurabilityPolicy.TRANSIENT_LOCAL)
"""The camera's images and info: transient-local like :data:`LATCHED`, but keeping the last 8
frames on both sides, so that a frame still in flight across processes when the next one is
written is not replaced (a history of one lost 1-2 of 7 masks per multi-process run)."""


@dataclass(frozen=True)
class Bound:
    """The range of a numeric parameter: ``low`` <= value (< when ``above``) <= ``high``, and
    finite; ``note`` says what a value means (in parentheses after the range).

    >>> Bound(0.0, above=True, unit="m/s").why("max_velocity", -1.0)
    "parameter 'max_velocity' must be a finite number > 0 m/s, got -1.0"
    >>> Bound(0.0, unit="N", note="0: no pickup test").why("weight", float("nan"))
    "parameter 'weight' must be a finite number >= 0 N (0: no pickup test), got nan"
    >>> Bound(1).why("feedback_every", 10) is None
    True
    """

    low: float
    high: float = math.inf
    above: bool = False
    unit: str = ""
    note: str = ""

    def words(self, value: Any) -> str:
        """What a value of this range is, for a value of ``value``'s type: the words of
        :meth:`why` and of ``ros2 param describe`` (its additional constraints).

        >>> Bound(0.0, 90.0, above=True, unit="deg").words(2.0)
        'a finite number > 0 deg and <= 90 deg'
        >>> Bound(1).words(10)
        'an integer >= 1'
        """
        kind = "an integer" if isinstance(value, int) else "a finite number"
        unit = f" {self.unit}" if self.unit else ""
        upper = f" and <= {self.high:g}{unit}" if self.high < math.inf else ""
        note = f" ({self.note})" if self.note else ""
        return f"{kind} {'>' if self.above else '>='} {self.low:g}{unit}{upper}{note}"

    def why(self, name: str, value: Any) -> str | None:
        """Why ``value`` is out of this range for parameter ``name``, or None."""
        if (not isinstance(value, bool) and isinstance(value, int | float)
                and math.isfinite(value) and (value > self.low if self.above
                                              else value >= self.low) and value <= self.high):
            return None
        return f"parameter '{name}' must be {self.words(value)}, got {value}"


TYPE_WORDS = {
    Parameter.Type.BOOL: "true or false",
    Parameter.Type.INTEGER: "an integer",
    Parameter.Type.DOUBLE: "a number",
    Parameter.Type.STRING: "a string",
    Parameter.Type.BOOL_ARRAY: "a list of true or false",
    Parameter.Type.INTEGER_ARRAY: "a list of integers",
    Parameter.Type.DOUBLE_ARRAY: "a list of numbers",
    Parameter.Type.STRING_ARRAY: "a list of strings",
}
"""What a value of a parameter's type is, in an error message (a float parameter is declared
with dynamic typing and takes any number: :data:`~rclpy.parameter.Parameter.Type.DOUBLE`)."""


def wrong_type(name: str, expected: Parameter.Type, value: Any) -> ParameterError:
    """The error of parameter ``name`` given ``value``, not of the ``expected`` type.

    >>> str(wrong_type("finger_devices", Parameter.Type.STRING_ARRAY, "F1"))
    "parameter 'finger_devices' must be a list of strings, got 'F1'"
    """
    return ParameterError(f"parameter '{name}' must be {TYPE_WORDS[expected]}, got "
                          f"{shown(str(value))}")


READ_AT_START = "read at start-up: restart the node to change it"
"""The constraint ``ros2 param describe`` shows of a read-only parameter."""


def constraints(default: Any, bound: Bound | None, *, read_only: bool) -> str:
    """The additional constraints ``ros2 param describe`` shows of a parameter: its range
    (``bound``, in the words of its errors, for a value of ``default``'s type) and
    :data:`READ_AT_START` when ``read_only``; "" when neither. Before, the ranges the nodes
    enforce were shown nowhere.

    >>> constraints(0.01, Bound(0.0, above=True, unit="m/s"), read_only=True)
    'a finite number > 0 m/s; read at start-up: restart the node to change it'
    >>> constraints(16, Bound(0), read_only=False)
    'an integer >= 0'
    """
    words = [bound.words(default)] if bound else []
    return "; ".join(words + ([READ_AT_START] if read_only else []))


def declare(node: Node, parameters: Mapping[str, tuple[Any, str]], *,
            live: Collection[str] = (), bounds: Mapping[str, Bound] | None = None
            ) -> dict[str, Any]:
    """Declare typed parameters (float ones also accept YAML integers); return their values,
    each of its parameter's type and within its ``bounds`` entry (a :class:`ParameterError`
    names the first that is not, in the words of :data:`TYPE_WORDS` or of :class:`Bound`).

    A default that is a ``Parameter.Type`` declares a parameter of that type without a default
    (its value None unless given). Parameters not named in ``live`` are read once, here, and
    declared read-only: ``ros2 param set`` is refused ("Trying to set a read-only parameter")
    rather than accepted and ignored, with ``ros2 param get`` then showing a value the node
    does not use.
    """
    values = {}
    for name, (default, description) in parameters.items():
        read_only = name not in live
        expected = (default if isinstance(default, Parameter.Type)
                    else Parameter.Type.from_parameter_value(default))
        try:
            node.declare_parameter(name, default, ParameterDescriptor(
                description=description, dynamic_typing=isinstance(default, float),
                read_only=read_only, additional_constraints=constraints(
                    default, (bounds or {}).get(name), read_only=read_only)))
        except InvalidParameterTypeException:
            # rclpy's exception keeps no value: the override it refused is the node's own
            raise wrong_type(name, expected, node._parameter_overrides[name].value) from None
        # None: given an unset value (YAML null), rclpy declares it so, without its default
        value = node.get_parameter_or(name, Parameter(name, value=None)).value
        if isinstance(default, Parameter.Type):
            values[name] = value  # typed without a default: None unless given
            continue
        if isinstance(default, float) and isinstance(value, int | float) \
                and not isinstance(value, bool):
            value = float(value)
        elif value is None or isinstance(default, float):
            # dynamic typing lets any type through: a string must not end in a bare
            # "could not convert string to float" that names no parameter
            raise wrong_type(name, expected, value)
        reason = bounds[name].why(name, value) if bounds and name in bounds else None
        if reason:
            raise ParameterError(reason)
        values[name] = value
    return values


def publish_all(batch: Iterable[tuple[Any, Any]]) -> None:
    """Publish each ``(publisher, message)`` of ``batch`` in order.

    A serialised message (``bytes``, as the lockstep loop's CDR writers give them) goes straight
    to the publisher's rclpy handle (``publish_raw``), without ``Publisher.publish``'s guard and
    type checks around the same call (about 2 us a message, a dozen messages a tick); any other
    message through ``Publisher.publish``.
    """
    for publisher, msg in batch:
        if msg.__class__ is bytes:
            publisher.handle.publish_raw(msg)
        else:
            publisher.publish(msg)


class Heard:
    """Whether an output is worth writing: always (``every``), or while a subscription has
    matched its publisher, as rclpy's matched events count them (once per change, nothing is
    asked per message). Pass :attr:`callbacks` as the publisher's ``event_callbacks``.

    A recorder needs ``every``: a transient-local writer keeps what it published for a reader
    it matches late (across processes, after the recorder answered the handshake), and a
    message skipped before that match would be missing from the recording.
    """

    def __init__(self, *, every: bool) -> None:
        self.every = every
        self.matched = 0
        self.callbacks = PublisherEventCallbacks(matched=self._matched)

    def _matched(self, info: Any) -> None:
        self.matched = info.current_count

    def __bool__(self) -> bool:
        return self.every or self.matched > 0


def wall_timer(node: Node, period: float, callback: Callable[[], None]):
    """A timer on the steady (wall) clock, whatever ``use_sim_time`` says."""
    return node.create_timer(period, callback, clock=Clock(clock_type=ClockType.STEADY_TIME))


class TickClock:
    """A lockstep node's ROS time from the stamps of the ticks it answers, in place of
    ``/clock``: one delivery and one rclpy ``TimeSource`` callback a tick less.

    With ``use_sim_time`` the node's clock reads simulated time, which rclpy sets from every
    ``/clock`` message it takes. A node that answers each tick already has the tick's stamp
    (the clock's value at that tick): the parameter is set false, so rclpy does not subscribe
    to ``/clock``, and :meth:`advance` sets the clock's ROS time to each new stamp, as the
    ``/clock`` of that tick did. Without ``use_sim_time`` the clock is left alone.
    """

    def __init__(self, node: Node) -> None:
        self.handle = None
        """The clock's rcl handle (None: the node is not on sim time)."""
        if node.get_parameter("use_sim_time").value:
            node.set_parameters([Parameter("use_sim_time", value=False)])
            clock = node.get_clock()
            clock._set_ros_time_is_active(True)  # what rclpy's TimeSource does with /clock
            self.handle = clock.handle

    def advance(self, ns: int) -> None:
        """Set the ROS time to ``ns`` (a new tick's stamp), if the node runs on sim time.

        What ``Clock.set_ros_time_override(Time(nanoseconds=ns))`` does, on the clock's rcl
        handle: without the ``Time`` object and its checks (a tick's stamp is a non-negative
        int), half the cost (about 6 us a tick).
        """
        if self.handle is not None:
            with self.handle:
                self.handle.set_ros_time_override(rcl_time_point(ns, ClockType.ROS_TIME))


class TickAnswer:
    """The lockstep bookkeeping of a node that answers each tick once: the stamp it answered
    last and the messages it answered with.

    Ticks are handled idempotently by stamp: a message of the stamp already answered (the driver
    re-sent a lost tick) publishes the same answer again, an older one is ignored, and only a
    newer one is new work (:meth:`is_new`).
    """

    def __init__(self) -> None:
        self.stamp_ns = -1
        self.messages: list[tuple[Any, Any]] = []

    def is_new(self, ns: int) -> bool:
        """True if ``ns`` is after the last answered tick; re-publish the answer if it is that
        tick again.
        """
        if ns == self.stamp_ns:
            publish_all(self.messages)
        return ns > self.stamp_ns

    def answer(self, ns: int, messages: Sequence[tuple[Any, Any]]) -> None:
        """Record and publish the answer (publisher, message pairs) to tick ``ns``."""
        self.stamp_ns, self.messages = ns, list(messages)
        publish_all(self.messages)


def prediction_ready(node: Node, *, seen: bool, awaited: bool) -> bool:
    """Lockstep readiness of a node that judges the run by the planner's latched
    ``planner/predicted_events``: True once it has ``seen`` it, or when it is not ``awaited``
    and nobody publishes one (a launch without a planner).

    "Nobody publishes one" is a statement about this node's view of the graph, which across
    processes can lag the writer: a node that had not yet discovered the run's publisher was
    ready without the prediction and judged the first cycles against none. So a caller that
    knows a prediction comes (``run`` publishes it before its nodes start) sets ``awaited``.
    """
    return seen or (not awaited
                    and node.count_publishers(node.resolve_topic_name(PREDICTION)) == 0)


class Participant:
    """A node's side of the lockstep handshake: answer ``sim/hello`` once its peers are there.

    Parameters
    ----------
    node : Node
    name : str
        Name reported on ``sim/ready`` (the driver's ``participants`` parameter lists it).
    inputs : sequence of str
        Topics this node needs publishers on before it is ready.
    outputs : sequence of Publisher
        Publishers that need a subscriber before it is ready.
    condition : callable, optional
        A further condition of readiness.
    """

    def __init__(self, node: Node, name: str, inputs: Sequence[str], outputs: Sequence, *,
                 condition: Callable[[], bool] | None = None) -> None:
        self.node = node
        self.name = name
        # resolved with the node's remap rules: rclpy's count_publishers applies none, so a
        # remapped input (-r monitor/status:=...) was looked for under its old name and the
        # node never became ready (the lockstep never started)
        self.inputs = [node.resolve_topic_name(t) for t in inputs]
        self.outputs = list(outputs)
        self.condition = condition
        self._ready = node.create_publisher(String, READY, loop_qos(10))
        node.create_subscription(String, HELLO, self._hello, loop_qos(10))

    def ready(self) -> bool:
        """True when every input has a publisher and every output a subscriber."""
        return (all(self.node.count_publishers(t) > 0 for t in self.inputs)
                and all(p.get_subscription_count() > 0 for p in self.outputs)
                and (self.condition is None or self.condition()))

    def _hello(self, _: String) -> None:
        if self.ready():
            self._ready.publish(String(data=self.name))


class Handshake:
    """The driver's side: repeat ``sim/hello`` until every participant answered, then start.

    Parameters
    ----------
    node : Node
    participants : sequence of str
    period : float
        Wall-clock seconds between hellos.
    on_complete : callable
        Called once, when the last participant answered.
    """

    def __init__(self, node: Node, participants: Sequence[str], period: float,
                 on_complete: Callable[[], None]) -> None:
        self.waiting = set(participants)
        self.on_complete = on_complete
        self._hello = node.create_publisher(String, HELLO, loop_qos(10))
        node.create_subscription(String, READY, self._answer, loop_qos(10))
        self._timer = wall_timer(node, period, self._say_hello)
        self.done = False

    def _say_hello(self) -> None:
        if self.waiting:
            self._hello.publish(String(data="hello"))
        else:
            self._finish()

    def _answer(self, msg: String) -> None:
        self.waiting.discard(msg.data)
        if not self.waiting:
            self._finish()

    def _finish(self) -> None:
        if not self.done:
            self.done = True
            self._timer.cancel()
            self.on_complete()
