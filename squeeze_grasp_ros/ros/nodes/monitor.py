# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The monitor: contact configuration, events and alarms from fingertip wrenches and taxels.

Run it with ``ros2 run squeeze_grasp_ros monitor --ros-args --params-file config/monitor.yaml``.
Per finger (``finger_devices``) it subscribes to ``devices/<device>/{pose,wrench,tactile}``
and runs :class:`..control.tracker.ContactTracker` once per tick:

- lockstep (simulation): a tick closes when its ``sim/tick`` has arrived together with every
  reading it lists (readings are matched by stamp, whatever order they arrive in); a reading
  that was dropped is simply not listed, and the tracker judges staleness by stamps;
- hardware (``lockstep: false``): a wall-clock timer at ``rate`` Hz uses the newest readings.

Each tick it publishes the tick's events as one ``monitor/events`` array (when there are
any), one ``monitor/alarms`` message per alarm episode (when an alarm of a type and finger
becomes active; ``monitor/status`` lists the alarms active at every tick), the reconstructed
``monitor/contact_state`` and, last, the ``monitor/status`` the executor acts on. A repeated
``sim/tick`` (a re-sent tick) gets the same status again, nothing else. The planner's
prediction (``planner/predicted_events``, latched) is compared with the observed
events. With ``shape_watch`` the camera's frames are matched against the predicted deformed
boundary (:mod:`.shape_watcher`): ``monitor/shape_residual`` and the ``shape_mismatch`` alarm.
With ``force_watch`` (on by default) the measured finger forces are compared with the
prediction's force curve (:mod:`.force_watcher`): ``monitor/force_residual`` and the
``force_mismatch`` alarm (a wrong E: the shape at a depth cannot show it, the forces do, and
so does the shape at the measured force, the shape watch's second residual).

Joint feedback (``controller_scene``: a scene whose ``controller:`` section maps the jaws to a
parallel gripper, and no ``wrench`` or ``tactile`` stream): the jaws' only sensor is the
controller's ``joint_states`` (``sensor_msgs/JointState``, listed in each tick's readings). The
aperture and jaw force come through the transmission (:mod:`..control.joint_feedback`): the
jaws' positions on the jaw line (fixed by the gripper's pose: the ``gripper_pose`` parameter, else
the ``gripper_pose`` topic, else the jaws' first pose readings) give
the depth, the force ``wrench`` stands in for, first touch, ``contact_lost`` and the slip watch's
``slip_imminent`` (the jaws close while the force stops rising), and with a ``weight`` the
lift's verdict (:class:`..control.joint_feedback.WeightWatch`: the ``picked_up`` event once
2 mu F >= ``weight_margin`` w, then ``weight_slip`` while 2 mu F < w); events A-D need taxels,
so none are tracked and the prediction's events are not compared (the force watch is).

The Barrett hand under a JointTrajectoryController (``controller: {device: bh8, ...}``): the
carried fingers' positions come from ``joint_states`` through the hand's forward kinematics
(:mod:`..control.barrett`) in place of their pose readings; their force and tactile sensors
are read as on the setpoint route, or, without them, their forces come from the joint efforts
(J^T F = tau per finger; a posture where that is ill-conditioned is refused) with the slip
watch on fingers 1 and 2 as on a gripper's jaws.
"""
from __future__ import annotations

import math
import sys
from typing import Any

import numpy as np
from geometry_msgs.msg import PoseStamped, WrenchStamped
from rclpy.node import Node
from rclpy.parameter import Parameter
from sensor_msgs.msg import JointState

from squeeze_grasp_interfaces.msg import (
    Alarm,
    ContactEventArray,
    ContactState,
    MonitorStatus,
    TactileArray,
    Tick,
)
from squeeze_grasp_ros.control.barrett import MAX_CONDITION, SingularPosture
from squeeze_grasp_ros.control.joint_feedback import (
    DEFAULT_WEIGHT_MARGIN,
    JointSlipWatch,
    WeightWatch,
    weight_problem,
)
from squeeze_grasp_ros.control.joint_trajectory import JawLine
from squeeze_grasp_ros.control.tracker import (
    ContactTracker,
    FingerSample,
    TrackedEvent,
    TrackerConfig,
)
from squeeze_grasp_ros.inputs import shown
from squeeze_grasp_ros.mechanics.vocabulary import Termination
from squeeze_grasp_ros.ros import messages
from squeeze_grasp_ros.ros.nodes import ParameterError, pipeline, run_node
from squeeze_grasp_ros.ros.nodes.force_watcher import ForceWatcher
from squeeze_grasp_ros.ros.nodes.shape_watcher import ShapeWatcher
from squeeze_grasp_ros.ros.nodes.sim_controllers import JOINT_STATES
from squeeze_grasp_ros.ros.refusals import LimitedWarnings, RefusalLog
from squeeze_grasp_ros.scene import load_scene
from squeeze_grasp_ros.scene.controller import (
    HandController,
    JawController,
    JointReadingError,
    scene_controller,
)

PARAMETERS: dict[str, tuple[Any, str]] = {
    "finger_devices": (["F1:barrett_f1", "F2:barrett_f3"], "finger:device of every fingertip"),
    "streams": (["wrench", "tactile"], "sensor streams each finger has, among wrench and "
                                      "tactile ([\"\"]: none; staleness test)"),
    "mu": (0.4, "friction coefficient of the fingertips"),
    "load_threshold": (0.002, "a taxel (joint feedback: a jaw) is loaded above this normal "
                              "force, N"),
    "edge_tolerance": (1e-4, "a patch slides at cone usage >= 1 - edge_tolerance"),
    "alarm_ratio": (0.9, "cone usage of every loaded taxel that raises slip_imminent"),
    "match_margin": (0, "taxels by which patch ranges are widened to connect them over ticks"),
    "stale_after": (0.0025, "age of a finger's newest reading that makes it stale, s"),
    "weight": (0.0, "object weight for the pickup test, N (0: no pickup test)"),
    "weight_margin": (DEFAULT_WEIGHT_MARGIN, "joint feedback: picked_up once 2 mu F >= "
                                             "weight_margin * weight (>= 1)"),
    "prediction_tolerance": (5e-4, "depth tolerance of the prediction comparison, m"),
    "await_prediction": (False, "lockstep: ready only once planner/predicted_events has "
                                "arrived (run sets it: it publishes one before the nodes start)"),
    "relative_per_depth": (0.0, "relative depth per unit depth, 1/m (reports)"),
    "mirror_tolerance": (0.05, "patches mirrored about the finger's force line within this "
                               "fraction of their separation are a tie (no C/D mismatch)"),
    "lockstep": (True, "close ticks on sim/tick (simulation: the ticks' stamps are the "
                 "monitor's time, use_sim_time is set false and /clock not taken) or on a "
                 "wall-clock timer"),
    "rate": (100.0, "hardware mode: status rate, Hz"),
    "frame_id": (pipeline.FRAME, "object frame"),
    "sensor_qos": ("reliable", "QoS of the readings: reliable (lockstep) or sensor_data"),
    "qos_depth": (100, "history depth of the reliable topics"),
    "shape_watch": (False, "match camera frames against planner/predicted_shapes (App. C)"),
    "shape_mismatch_threshold": (5e-4, "equal-depth RMS residual that raises shape_mismatch, m"),
    "shape_at_force_threshold": (1.5e-4, "equal-force RMS residual (the seen outline against the "
                                         "boundary predicted for the measured force) that "
                                         "raises shape_mismatch, m"),
    "shape_min_force": (0.05, "shape watch: smallest pair force matched at equal force, N"),
    "object_height": (0.0, "shape watch: height of the object's top face above the plane, m"),
    "every_output": (True, "publish monitor/contact_state and monitor/force_residual every "
                           "tick (a recorder takes them); false: only while a subscription "
                           "has matched them (run without recording)"),
    "force_watch": (True, "compare finger forces with the prediction's force curve"),
    "force_tolerance": (0.1, "relative force error that raises force_mismatch"),
    "force_min_fraction": (0.01, "force watch: fraction of the predicted depth not judged"),
    "controller_scene": ("", "scene file whose controller: section's jaws report on "
                             "joint_states (used without wrench and tactile streams)"),
    "joint_slip_window": (1e-4, "joint feedback: closing over which the jaw stiffness is "
                                "measured, m"),
    "joint_slip_ratio": (0.5, "joint feedback: tangent / secant jaw stiffness below which "
                              "slip_imminent is raised"),
    "hand_max_condition": (MAX_CONDITION, "Barrett hand on joint efforts: largest condition "
                                          "number of a finger's J^T at which its tip force is "
                                          "read"),
    "gripper_pose": (Parameter.Type.DOUBLE_ARRAY,
                     "joint feedback: the gripper's centre and closing direction in the object "
                     "frame, [x m, y m, yaw deg], fixing the jaw line (else the gripper_pose "
                     "topic, else the jaws' pose readings)"),
}
"""Parameter name -> (typed default, description); config/monitor.yaml sets them."""
BOUNDS = {"mu": pipeline.Bound(0.0, note="0: no friction"),
          "weight": pipeline.Bound(0.0, unit="N", note="0: no pickup test"),
          "load_threshold": pipeline.Bound(0.0, unit="N"),
          "edge_tolerance": pipeline.Bound(0.0), "alarm_ratio": pipeline.Bound(0.0, above=True),
          "match_margin": pipeline.Bound(0),
          "stale_after": pipeline.Bound(0.0, above=True, unit="s"),
          "prediction_tolerance": pipeline.Bound(0.0, above=True, unit="m"),
          "relative_per_depth": pipeline.Bound(0.0, unit="1/m"),
          "mirror_tolerance": pipeline.Bound(0.0),
          "rate": pipeline.Bound(0.0, above=True, unit="Hz"), "qos_depth": pipeline.Bound(1),
          "shape_mismatch_threshold": pipeline.Bound(0.0, above=True, unit="m"),
          "shape_at_force_threshold": pipeline.Bound(0.0, above=True, unit="m"),
          "shape_min_force": pipeline.Bound(0.0, unit="N"),
          "object_height": pipeline.Bound(0.0, unit="m"),
          "force_tolerance": pipeline.Bound(0.0, above=True),
          "force_min_fraction": pipeline.Bound(0.0, 1.0),
          "joint_slip_window": pipeline.Bound(0.0, above=True, unit="m"),
          "joint_slip_ratio": pipeline.Bound(0.0, above=True)}
"""The range of each numeric parameter (``weight_margin`` and ``hand_max_condition`` are
checked where they are used, by the routes that take them)."""
PENDING_STAMPS = 64
"""Lockstep: the most stamps whose readings wait for their tick, and the most ticks that wait
for their readings. In a loop one stamp waits at a time; readings under stamps no tick ever
closes (a publisher of its own clock) were kept for ever: 10 kHz of them grew the monitor by
380 MB in 40 s."""
POSE_JOINT_TOLERANCE = 1e-5
"""m: the largest gap between the jaws' aperture of their first pose readings and of the first
joint state that passes without a warning."""


def _pose(data: bytes) -> tuple[int, dict[str, Any]]:
    ns, position = messages.pose_position_cdr(data)
    return ns, {"position": position}


def _wrench(data: bytes) -> tuple[int, dict[str, Any]]:
    ns, force = messages.wrench_force_cdr(data)
    return ns, {"force": force, "force_stamp_ns": ns}


def _tactile(data: bytes) -> tuple[int, dict[str, Any]]:
    ns, taxels = messages.tactile_readings_cdr(data)
    return ns, {"angles": taxels.angles, "normal": taxels.normal,
                "tangential": taxels.tangential, "tactile_stamp_ns": ns}


READINGS = {"pose": _pose, "wrench": _wrench, "tactile": _tactile}
"""Stream -> reader of its raw CDR bytes: (stamp ns, the tracker's ``FingerSample`` fields).
The device readings are taken raw and read with :mod:`..messages.cdr`, not turned into
message objects (six readings a tick; rclpy's conversion cost 6-17 times as much)."""


def make_room(pending: dict[int, Any], ns: int, limit: int = PENDING_STAMPS) -> bool:
    """Make room for stamp ``ns`` in ``pending`` (stamp -> what waits under it) of at most
    ``limit`` stamps, dropping the farthest stamp: the nearest are the next ticks'.

    Returns
    -------
    bool
        False when ``ns`` is itself the farthest and there is no room (do not store it).

    Examples
    --------
    >>> pending = {1: "a", 2: "b"}
    >>> make_room(pending, 3, limit=2), pending
    (False, {1: 'a', 2: 'b'})
    >>> make_room(pending, 0, limit=2), pending
    (True, {1: 'a'})
    >>> make_room(pending, 1, limit=1)
    True
    """
    if ns in pending or len(pending) < limit:
        return True
    farthest = max(pending)
    if ns > farthest:
        return False
    del pending[farthest]
    return True


def reading_problem(fields: dict[str, Any]) -> str | None:
    """Why the tracker cannot take a device reading's ``FingerSample`` fields, or None.

    A position or force that is not finite, or taxel arrays that are empty, of different
    lengths or not finite, are refused here: the tracker would raise on them (an empty or
    ragged ``TactileArray`` ended the monitor process with a ValueError) or carry NaN into
    every status.

    Parameters
    ----------
    fields : dict
        The fields a :data:`READINGS` reader returned.

    Returns
    -------
    str or None
        The reason in one line, naming the message field; None for a usable reading.

    Examples
    --------
    >>> reading_problem({"force": np.array([0.0, np.nan, 0.0]), "force_stamp_ns": 1})
    'wrench.force is not finite: [0.0, nan, 0.0] N'
    >>> reading_problem({"angles": np.zeros(3), "normal": np.zeros(2), "tangential": np.zeros(0),
    ...                  "tactile_stamp_ns": 1})
    'taxel_angles, normal_forces and tangential_forces must have one value per taxel (at least \
one), got 3, 2 and 0 values'
    >>> reading_problem({"position": np.array([0.01, 0.0])}) is None
    True
    """
    # math.isfinite over the values' list: a fifth of np.isfinite's cost on these short
    # arrays (six readings a tick)
    for name, label, unit in (("position", "pose.position", "m"), ("force", "wrench.force", "N")):
        value = fields.get(name)
        if value is not None and not all(map(math.isfinite, value.tolist())):
            return f"{label} is not finite: {value.tolist()} {unit}"
    if "normal" not in fields:
        return None
    arrays = [fields["angles"], fields["normal"], fields["tangential"]]
    counts = [len(a) for a in arrays]
    if not counts[0] or counts.count(counts[0]) < 3:
        return ("taxel_angles, normal_forces and tangential_forces must have one value per taxel "
                f"(at least one), got {counts[0]}, {counts[1]} and {counts[2]} values")
    if not all(all(map(math.isfinite, a.tolist())) for a in arrays):
        return "taxel_angles, normal_forces or tangential_forces are not finite"
    return None


STREAMS = ("wrench", "tactile")
"""The sensor streams a finger may have (its ``pose`` is always read)."""


def sensor_streams(names: list[str]) -> list[str]:
    """The ``streams`` parameter's sensor streams (an empty name stands for none).

    >>> sensor_streams(["wrench", ""])
    ['wrench']
    >>> sensor_streams(["wrench", "force"])
    Traceback (most recent call last):
    ...
    squeeze_grasp_ros.ros.nodes.ParameterError: parameter 'streams' must list sensor streams \
among ('wrench', 'tactile') (or [""] for none), each once, got 'force'
    """
    streams = [name for name in names if name]
    for k, name in enumerate(streams):
        if name not in STREAMS or name in streams[:k]:
            # a stream nobody publishes was expected for ever: every goal ended stale_data
            raise ParameterError(f"parameter 'streams' must list sensor streams among "
                                 f"{STREAMS} (or [\"\"] for none), each once, got "
                                 f"{shown(name)}")
    return streams


class MonitorNode(Node):
    """Reactive contact-event tracker on fingertip sensors."""

    def __init__(self, **kwargs: Any) -> None:
        super().__init__("monitor", **kwargs)
        self.p = p = pipeline.declare(self, PARAMETERS, bounds=BOUNDS)
        self.fingers = pipeline.parse_mapping(p["finger_devices"], "finger_devices")
        streams = sensor_streams(p["streams"])
        self.jaws = JointFeedback.of(p, streams)
        """The jaws on joint feedback (None: the sensors' route)."""
        self.hand = HandFeedback.of(p, streams) if self.jaws is None else None
        """The Barrett hand's fingers positioned by its joint states (None: their poses)."""
        self.joint_forces = self.jaws is not None or (self.hand is not None
                                                      and self.hand.watch is not None)
        """The forces come from joint efforts (no fingertip sensor: no events A-D)."""
        self.tracker = ContactTracker(TrackerConfig(
            p["mu"], p["load_threshold"], p["edge_tolerance"], p["alarm_ratio"],
            p["match_margin"], p["stale_after"], p["weight"] or None,
            p["prediction_tolerance"], p["relative_per_depth"], p["mirror_tolerance"]),
            list(self.fingers), ["wrench"] if self.joint_forces else streams)
        loop = pipeline.loop_qos(p["qos_depth"])
        sensors = pipeline.sensor_qos(p["sensor_qos"], p["qos_depth"])
        types = {"pose": PoseStamped, "wrench": WrenchStamped, "tactile": TactileArray}
        self.keys: dict[str, tuple[str, str]] = {}
        self.refusals = RefusalLog(self.get_logger().warning)
        """The log of refused readings, by device stream."""
        self.joint_log = LimitedWarnings(self.get_logger(), self.refusals, JOINT_STATES)
        """The joint-state feedback's logger: its warnings at most one line a second."""
        for finger, device in self.fingers.items():
            for stream, msg_type in types.items():
                key = f"{device}/{stream}"
                self.keys[key] = (finger, stream)
                self.create_subscription(
                    msg_type, pipeline.device_topic(device, stream),
                    lambda data, k=key, read=READINGS[stream]: self._device_reading(k,
                                                                                    read(data)),
                    sensors, raw=True)
        if self.jaws is not None:
            self.create_subscription(PoseStamped, pipeline.GRIPPER_POSE,
                                     lambda msg: self.jaws.set_pose(msg, p["frame_id"],
                                                                    self.get_logger()),
                                     pipeline.LATCHED)
        if self.jaws is not None or self.hand is not None:
            self.keys[JOINT_STATES] = ("", JOINT_STATES)
            self.create_subscription(
                JointState, JOINT_STATES,
                lambda msg: self._reading(JOINT_STATES, messages.stamp_ns(msg.header.stamp), msg),
                sensors)
        self.prediction_seen = False
        """Whether ``planner/predicted_events`` has arrived."""
        self.create_subscription(ContactEventArray, pipeline.PREDICTION, self._prediction,
                                 pipeline.LATCHED)
        outputs = pipeline.output_qos(p["qos_depth"], lockstep=p["lockstep"])
        self.event_pub = self.create_publisher(ContactEventArray, pipeline.EVENTS, outputs)
        self.alarm_pub = self.create_publisher(Alarm, pipeline.ALARMS, outputs)
        kept = pipeline.loop_qos(p["qos_depth"], kept=True)
        self.state_heard = pipeline.Heard(every=p["every_output"])
        self.state_pub = self.create_publisher(ContactState, pipeline.CONTACT_STATE, kept,
                                               event_callbacks=self.state_heard.callbacks)
        self.status_pub = self.create_publisher(MonitorStatus, pipeline.STATUS, kept)
        self.lockstep = p["lockstep"]
        self.latest: dict[str, Any] = {}
        self.buffer: dict[int, dict[str, Any]] = {}
        self.expected: dict[int, set[str]] = {}
        self.answered = pipeline.TickAnswer()
        self.active_alarms: set[tuple[str, str]] = set()
        self.shapes = (ShapeWatcher(
            self, self.alarm_pub, threshold=p["shape_mismatch_threshold"],
            at_force_threshold=p["shape_at_force_threshold"], object_height=p["object_height"],
            min_force=p["shape_min_force"], frame_id=p["frame_id"]) if p["shape_watch"]
            else None)
        self.forces = (ForceWatcher(self, p["force_tolerance"], p["force_min_fraction"], outputs,
                                    every=p["every_output"])
                       if p["force_watch"] else None)
        if p["lockstep"]:
            # the ticks' stamps are the monitor's time and it reads no clock: use_sim_time off,
            # so it does not take /clock (one delivery a tick); the parameter says so
            if self.get_parameter("use_sim_time").value:
                self.set_parameters([Parameter("use_sim_time", value=False)])
            self.create_subscription(Tick, pipeline.TICK, self._tick, loop, raw=True)
            self.participant = pipeline.Participant(self, "monitor", [pipeline.TICK],
                                                    [self.status_pub],
                                                    condition=self._has_prediction)
        else:
            self.create_timer(1.0 / p["rate"], self._timer)

    # ----------------------------------------------------------------- inputs

    def ready_summary(self) -> str:
        """What the ready line of ``ros2 run`` says: fingers, streams, friction, clock."""
        clock = "lockstep" if self.p["lockstep"] else f"rate {self.p['rate']} Hz"
        streams = [s for s in self.p["streams"] if s] if self.jaws is None else [
            f"{JOINT_STATES} of {self.jaws.controller.spec.name} ({self.jaws.source()})"]
        if self.hand is not None:
            read = "positions" if self.hand.watch is None else "positions and efforts"
            streams.append(f"{JOINT_STATES} of {self.hand.controller.spec.name} ({read})")
        return f"fingers {self.fingers}, streams {streams}, mu {self.p['mu']}, {clock}"

    def _has_prediction(self) -> bool:
        """Lockstep readiness: the prediction is here, or none is awaited and nobody publishes
        one. Across processes the monitor can be ready before the run's latched prediction
        has reached it; its first events were then judged against no prediction
        (``prediction_mismatch`` of the first 3 events in 1 of 40 runs, two at once).
        """
        return pipeline.prediction_ready(self, seen=self.prediction_seen,
                                         awaited=self.p["await_prediction"])

    def _prediction(self, msg: ContactEventArray) -> None:
        self.prediction_seen = True
        if not self.joint_forces:
            self.tracker.set_prediction(messages.predicted_events(msg))
        if self.forces is not None:
            self.forces.set_prediction(msg)

    def _device_reading(self, key: str, read: tuple[int, dict[str, Any]]) -> None:
        """A device reading ``read`` (stamp ns, fields) of ``key``: refused with a warning (at
        most one line per device stream and second, :class:`..refusals.RefusalLog`) when
        :func:`reading_problem` finds one, so that finger's readings go stale; else taken.
        """
        problem = reading_problem(read[1])
        if problem is None:
            self._reading(key, *read)
        else:
            self.refusals.refused(key, f"the reading of {read[0] * 1e-9:.9f} s: {problem}")

    def _reading(self, key: str, ns: int, msg: Any) -> None:
        """A reading stamped ``ns``: the tracker's sample fields of a device stream, or the
        joint state message.

        On hardware a reading stamped more than ``stale_after`` ahead of the monitor's clock is
        refused: it counted as fresh until its stamp (a driver's clock one hour ahead kept its
        finger fresh for an hour after the driver stopped, the executor squeezing on).
        """
        if not self.lockstep:
            ahead = (ns - self.get_clock().now().nanoseconds) * 1e-9
            if ahead > self.p["stale_after"]:
                self.refusals.refused(key, f"the reading of {ns * 1e-9:.9f} s is stamped "
                                           f"{ahead:.6g} s ahead of the monitor's clock, more "
                                           f"than stale_after ({self.p['stale_after']} s): are "
                                           "the driver's and the monitor's clocks the same?")
                return
            self.latest[key] = msg
            return
        if ns <= self.answered.stamp_ns:
            return
        if not make_room(self.buffer, ns):
            self.refusals.refused("pending", f"more than {PENDING_STAMPS} stamps wait for their "
                                             f"tick: dropped {key} of {ns * 1e-9:.9f} s")
            return
        self.buffer.setdefault(ns, {})[key] = msg
        if ns in self.expected:  # its tick is here: the reading may close it
            self._try_close(ns)

    def _tick(self, data: bytes) -> None:
        """A ``sim/tick``, read from its CDR bytes (:mod:`..messages.cdr`)."""
        ns, readings = messages.tick_readings_cdr(data)
        if not self.answered.is_new(ns):
            return
        if not make_room(self.expected, ns):
            self.refusals.refused("pending", f"more than {PENDING_STAMPS} ticks wait for their "
                                             f"readings: dropped the tick of {ns * 1e-9:.9f} s")
            return
        self.expected[ns] = set(readings) & self.keys.keys()
        self._try_close(ns)

    def _try_close(self, ns: int) -> None:
        """Answer tick ``ns`` if it and all its readings are here; then drop what waits under
        older stamps (no tick closes them any more: they were kept for ever).
        """
        expected = self.expected.get(ns)
        if expected is None or not expected <= self.buffer.get(ns, {}).keys():
            return
        self.latest.update(self.buffer.pop(ns, {}))
        del self.expected[ns]
        self._process(ns)
        for pending in (self.buffer, self.expected):
            for old in [k for k in pending if k < ns]:
                del pending[old]

    def _timer(self) -> None:
        self._process(self.get_clock().now().nanoseconds)

    # ----------------------------------------------------------------- one tick
    def _samples(self) -> dict[str, FingerSample]:
        """The newest reading of every finger and stream as tracker samples."""
        fields: dict[str, dict[str, Any]] = {f: {} for f in self.fingers}
        for key, reading in self.latest.items():
            finger, stream = self.keys[key]
            if stream != JOINT_STATES:
                fields[finger].update(reading)
        if self.jaws is not None:
            self.jaws.replace(fields, self.latest.get(JOINT_STATES), self.joint_log)
        if self.hand is not None:
            self.hand.replace(fields, self.latest.get(JOINT_STATES), self.joint_log)
        return {f: FingerSample(**v) for f, v in fields.items()}

    def _process(self, ns: int) -> None:
        samples = self._samples()
        out = self.tracker.update(ns, samples)
        watched = self.jaws or self.hand
        if watched is not None and watched.alarms:
            out = out._replace(alarms=out.alarms + watched.alarms)
        if self.jaws is not None and self.jaws.take_picked_up():
            out = out._replace(events=out.events + (TrackedEvent(
                Termination.PICKED_UP, "", out.depth, out.relative_depth, 0.0),))
        frame = self.p["frame_id"]
        batch = [(self.event_pub, messages.tracked_events_msg(out))] if out.events else []
        if self.forces is not None:
            residual, alarms = self.forces.tick(out, samples, frame)
            batch += residual
            if alarms:
                out = out._replace(alarms=out.alarms + alarms)
        active = {(a.type, a.finger) for a in out.alarms}
        batch += [(self.alarm_pub, messages.alarm_msg(a, ns)) for a in out.alarms
                  if (a.type, a.finger) not in self.active_alarms]
        self.active_alarms = active
        if self.state_heard:
            batch.append((self.state_pub, messages.patches_state_cdr(out, frame)))
        pipeline.publish_all(batch)
        self.answered.answer(ns, [(self.status_pub, messages.monitor_status_cdr(out, frame))])
        if self.shapes is not None:
            self.shapes.tick(ns, out, samples)


class HandFeedback:
    """The Barrett hand's carried fingers positioned by ``joint_states`` through the forward
    kinematics, in place of their pose readings; without fingertip sensors (``watch`` given),
    also their forces from the joint efforts (J^T F = tau per finger,
    :meth:`..control.barrett.BarrettHand.tip_force`) in place of their wrenches, and the slip
    watch on the two fingers as on a gripper's jaws (:class:`..control.joint_feedback.
    JointSlipWatch`: the distance between the tips' centres for the aperture, the mean of the
    two pushes along the line between them for the jaw force).

    Parameters
    ----------
    controller : HandController
    watch : JointSlipWatch, optional
        The slip watch of the two carried fingers (None: their force sensors are read).
    max_condition : float
        The largest condition number of a finger's J^T whose efforts are read.
    """

    def __init__(self, controller: HandController, watch: JointSlipWatch | None = None, *,
                 max_condition: float = MAX_CONDITION) -> None:
        self.controller, self.watch, self.max_condition = controller, watch, max_condition
        self.stamp_ns: int | None = None
        self.watched_ns: int | None = None
        self.singular = False
        self.alarms: tuple = ()
        """The slip watch's alarms of the newest joint state."""

    @classmethod
    def of(cls, p: dict[str, Any], streams: list[str]) -> HandFeedback | None:
        """The hand's feedback of the monitor's parameters ``p``: None unless the
        ``controller_scene``'s controller is the Barrett hand; its efforts are read without a
        ``wrench`` or ``tactile`` stream.
        """
        if not p["controller_scene"]:
            return None
        controller = scene_controller(load_scene(p["controller_scene"]), p["controller_scene"])
        if not isinstance(controller, HandController):
            return None
        max_condition = p.get("hand_max_condition", MAX_CONDITION)
        if not max_condition >= 1.0:
            raise ParameterError(f"hand_max_condition must be >= 1 (a condition number), got "
                                 f"{max_condition}")
        watch = None if {"wrench", "tactile"} & set(streams) else JointSlipWatch(
            controller.jaws, contact_force=p["load_threshold"], window=p["joint_slip_window"],
            ratio=p["joint_slip_ratio"])
        return cls(controller, watch, max_condition=max_condition)

    def replace(self, fields: dict[str, dict[str, Any]], msg: JointState | None,
                logger: Any) -> None:
        """Put the carried fingers' tip positions (and, reading efforts, forces) of joint state
        ``msg`` into the tracker's sample ``fields``; a state without every hand joint, not
        finite, or (reading efforts) at a posture whose efforts do not determine a tip force is
        ignored with a warning (the readings go stale).
        """
        if msg is None:
            return
        ns = messages.stamp_ns(msg.header.stamp)
        hand, fingers = self.controller.hand, self.controller.fingers
        joints = dict(zip(msg.name, msg.position))
        try:
            if len(msg.position) != len(msg.name) or not np.all(np.isfinite(msg.position)):
                raise ValueError(f"positions {list(msg.position)} are not one finite value per "
                                 f"name {list(msg.name)}")
            tips = hand.forward(joints)
            pushes = {} if self.watch is None else self._pushes(msg, joints)
        except SingularPosture as exc:
            if not self.singular:
                logger.warning(f"ignored the joint states from {ns * 1e-9:.3f} s on: {exc}")
            self.singular = True
            return
        except ValueError as exc:
            if ns != self.stamp_ns:
                logger.warning(f"ignored the joint state of {ns * 1e-9:.3f} s: {exc}")
                self.stamp_ns = ns
            return
        self.singular = False
        for finger, hand_finger in fingers.items():
            fields[finger]["position"] = tips[hand_finger]
            if self.watch is not None:
                # the wrench of the object on the finger: minus the finger's push
                fields[finger].update(force=np.append(-pushes[finger], 0.0), force_stamp_ns=ns)
        if self.watch is not None and ns != self.watched_ns:
            self.watched_ns = ns
            first, second = (tips[fingers[f]] for f in self.controller.jaws)
            distance = float(np.hypot(*(second - first)))
            u = (second - first) / distance
            one, other = (pushes[f] for f in self.controller.jaws)
            force = 0.5 * float(np.dot(one, u) - np.dot(other, u))
            touched = self.watch.first_touch
            self.alarms = self.watch.update(distance, force)
            if touched is None and self.watch.first_touch is not None:
                logger.info(f"first touch of the hand's fingers at tip distance "
                            f"{self.watch.first_touch * 1e3:.4f} mm (force {force:.4g} N)")

    def _pushes(self, msg: JointState, joints: dict[str, float]) -> dict[str, np.ndarray]:
        """Each carried finger's push on the object (N) from the efforts of ``msg``."""
        if len(msg.effort) != len(msg.name) or not np.all(np.isfinite(msg.effort)):
            raise ValueError(f"efforts {list(msg.effort)} are not one finite value per name "
                             f"{list(msg.name)}")
        efforts = dict(zip(msg.name, msg.effort))
        return {finger: self.controller.hand.tip_force(
                    hand_finger, joints, efforts, max_condition=self.max_condition).force
                for finger, hand_finger in self.controller.fingers.items()}


class JointFeedback:
    """The jaws' readings from ``joint_states`` in place of their wrench and pose.

    Parameters
    ----------
    controller : JawController
    watch : JointSlipWatch
    weight : WeightWatch, optional
        The lift's watch (with the monitor's ``weight``): ``picked_up`` and ``weight_slip``.
    pose : (centre (2,) m, yaw rad), optional
        The gripper's pose fixing the jaw line.
    """

    def __init__(self, controller: JawController, watch: JointSlipWatch, *,
                 weight: WeightWatch | None = None,
                 pose: tuple[np.ndarray, float] | None = None) -> None:
        self.controller, self.watch, self.weight = controller, watch, weight
        self.picked_up = False
        """The weight watch reported ``picked_up`` at the newest joint state, not yet taken."""
        self.posed: JawLine | None = None
        """The jaw line of the gripper's pose (parameter or topic; None: the jaws' poses)."""
        if pose is not None:
            self.posed = JawLine.at_pose(*pose, reach=controller.gripper.pad.contact_radius)
        self.line: JawLine | None = None
        self.stamp_ns: int | None = None
        self.alarms: tuple = ()
        """The slip watch's alarms of the newest joint state."""

    @classmethod
    def of(cls, p: dict[str, Any], streams: list[str]) -> JointFeedback | None:
        """The jaws' joint feedback of the monitor's parameters ``p``: None without a
        ``controller_scene`` whose scene has a controller, or with a wrench or tactile stream.
        """
        if not p["controller_scene"] or {"wrench", "tactile"} & set(streams):
            return None
        controller = scene_controller(load_scene(p["controller_scene"]), p["controller_scene"])
        if not isinstance(controller, JawController):
            return None
        pose = p.get("gripper_pose")
        if pose is not None:
            if len(pose) != 3 or not np.all(np.isfinite(pose)):
                raise ParameterError(f"gripper_pose must be [x m, y m, yaw deg], three finite "
                                     f"numbers, got {list(pose)}")
            pose = (np.array(pose[:2], float), float(np.deg2rad(pose[2])))
        weight = None
        if p.get("weight"):
            margin = p.get("weight_margin", DEFAULT_WEIGHT_MARGIN)
            problem = weight_problem(p["weight"], mu=p["mu"], margin=margin)
            if problem is not None:
                raise ParameterError(problem)
            weight = WeightWatch(controller.jaws, mu=p["mu"], weight=p["weight"], margin=margin,
                                 contact_force=p["load_threshold"])
        return cls(controller, JointSlipWatch(
            controller.jaws, contact_force=p["load_threshold"], window=p["joint_slip_window"],
            ratio=p["joint_slip_ratio"]), weight=weight, pose=pose)

    def take_picked_up(self) -> bool:
        """Whether the weight watch reported ``picked_up`` since the last call."""
        picked, self.picked_up = self.picked_up, False
        return picked

    def set_pose(self, msg: PoseStamped, frame_id: str, logger: Any) -> None:
        """Take the gripper's pose from a ``gripper_pose`` message (it replaces the parameter);
        a pose in another frame, not finite or tilted out of the plane is ignored with a
        warning.
        """
        try:
            centre, yaw = messages.gripper_line_pose(msg, frame_id)
        except ValueError as exc:
            logger.warning(f"ignored the {pipeline.GRIPPER_POSE} message: {exc}")
            return
        self.posed = JawLine.at_pose(centre, yaw,
                                     reach=self.controller.gripper.pad.contact_radius)
        logger.info(f"{pipeline.GRIPPER_POSE}: {self.source()}")

    def source(self) -> str:
        """Where the jaw line comes from (the ready line)."""
        if self.posed is not None:
            c, d = self.posed.centre, self.posed.direction
            return (f"jaw line at ({c[0]:.6g}, {c[1]:.6g}) m, yaw "
                    f"{np.rad2deg(np.arctan2(d[1], d[0])):.6g} deg")
        return f"jaw line from {pipeline.GRIPPER_POSE} or the jaws' poses"

    def replace(self, fields: dict[str, dict[str, Any]], msg: JointState | None,
                logger: Any) -> None:
        """Put the jaws' position and force of joint state ``msg`` into the tracker's sample
        ``fields`` (finger -> FingerSample keywords); run the slip watch on a new state.
        """
        first, second = self.controller.jaws
        if msg is None:
            return
        if self.posed is not None:
            self.line = self.posed
        fixed = self.line is None
        if fixed:
            if any("position" not in fields[j] for j in (first, second)):
                return
            self.line = self.controller.jaw_line({j: fields[j]["position"]
                                                  for j in (first, second)})
        ns = messages.stamp_ns(msg.header.stamp)
        try:
            reading = self.controller.reading(msg.name, msg.position, msg.effort)
        except JointReadingError as exc:
            if ns != self.stamp_ns:
                logger.warning(f"ignored the joint state of {ns * 1e-9:.3f} s: {exc}")
                self.stamp_ns = ns
            return
        if fixed:
            posed = self.line.aperture(fields[first]["position"], fields[second]["position"])
            if abs(posed - reading.aperture) > POSE_JOINT_TOLERANCE:
                logger.warning(
                    f"the jaws' pose readings put the pad faces {posed * 1e3:.4f} mm apart, "
                    f"joint_states {reading.aperture * 1e3:.4f} mm: the jaws jump to the joint "
                    "reading, and a depth measured from the poses counts the jump (publish the "
                    "tips' centres: the pad faces plus the edge radius)")
        if ns != self.stamp_ns:
            self.stamp_ns = ns
            touched = self.watch.first_touch
            self.alarms = self.watch.update(reading.aperture, reading.force)
            if self.weight is not None:
                picked, alarms = self.weight.update(reading.force)
                self.alarms += alarms
                self.picked_up = self.picked_up or picked
                if picked:
                    logger.info(f"picked up: jaw force {reading.force:.4g} N carries "
                                f"{self.weight.margin:g} x the weight {self.weight.weight:g} N "
                                f"(needs {self.weight.need:.4g} N at mu {self.weight.mu:g})")
            if touched is None and self.watch.first_touch is not None:
                logger.info(f"first touch of the jaws at aperture "
                            f"{self.watch.first_touch * 1e3:.4f} mm (jaw force "
                            f"{reading.force:.4g} N at {reading.aperture * 1e3:.4f} mm)")
        push = reading.force * self.line.direction
        for jaw, position, sign in zip((first, second), self.line.positions(reading.aperture),
                                       (1.0, -1.0)):
            # the wrench of the object on the jaw: minus the jaw's push on the object
            fields[jaw].update(position=position, force=np.append(-sign * push, 0.0),
                               force_stamp_ns=ns)


def main(args: list[str] | None = None) -> int:
    """Run the monitor until Ctrl-C or shutdown; return the exit code."""
    return run_node(MonitorNode, args)


if __name__ == "__main__":
    sys.exit(main())
