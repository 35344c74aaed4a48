# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The simulated hardware: Barrett fingers, Cobra arm, pusher and fingertip sensors in lockstep.

Run it with ``ros2 run squeeze_grasp_ros sim_hardware --ros-args --params-file
config/sim_hardware.yaml -p scene:=config/scenes/foam_square.yaml``. It owns ``/clock`` and
advances it in lockstep (docs/design.md §4), driven by messages, never by timers:

1. after the start-up handshake (``sim/hello`` / ``sim/ready``) it publishes tick 0;
2. a tick k is ``/clock`` = t_k, every device's ``pose``, ``wrench`` and ``tactile`` reading
   stamped t_k (a reading dropped by the sensor_dropout effect is skipped), the ground-truth
   events of the tick as one ``sim/events`` array (with the termination reason at the tick the
   world ends, and ``released`` at the tick an ended world releases the object), a simulated
   controller's ``joint_states``, the ground-truth state
   (``sim/state``), markers at ``display_rate``, and last ``sim/tick`` listing the readings it
   published (``joint_states`` among them);
3. when every device's setpoint stamped after t_k has arrived (and the recorder is no more than
   ``recorder_window`` ticks behind), the world steps (:class:`..sim.world.SimWorld`) and
   tick k+1 follows.

If the loop does not close within ``resend_timeout`` wall-clock seconds, tick k is published
again, message for message except the markers (receivers act on stamps, so this is idempotent;
every re-sent topic carries one message per stamp, which is how the recorder drops the copies).
"""
from __future__ import annotations

import math
import sys
import time
from typing import Any

from geometry_msgs.msg import PoseStamped, WrenchStamped
from rclpy.node import Node
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import CameraInfo, Image
from std_msgs.msg import Header
from visualization_msgs.msg import MarkerArray

from squeeze_grasp_interfaces.msg import ContactEventArray, SimState, TactileArray, Tick
from squeeze_grasp_ros.mechanics.vocabulary import ControllerKind, Effect, ImageEncoding
from squeeze_grasp_ros.ros import messages
from squeeze_grasp_ros.ros.messages.images import camera_info_msg, image_msg, pose_of_camera
from squeeze_grasp_ros.ros.nodes import ParameterError, pipeline, run_node
from squeeze_grasp_ros.ros.nodes.sim_controllers import (
    JOINT_STATES,
    SimHandTrajectoryController,
    SimJointTrajectoryController,
)
from squeeze_grasp_ros.ros.refusals import RefusalLog
from squeeze_grasp_ros.scene import GraspSetup, load_scene
from squeeze_grasp_ros.scene.controller import HandController, JawController, scene_controller
from squeeze_grasp_ros.sim.camera import CameraFrame
from squeeze_grasp_ros.sim.world import RELEASED, SimWorld, TickOutput

PARAMETERS: dict[str, tuple[Any, str]] = {
    "scene": ("", "scene YAML file the world is built from (required)"),
    "frame_id": (pipeline.FRAME, "object frame of poses and markers"),
    "sensor_qos": ("reliable", "QoS of the readings: reliable (lockstep) or sensor_data"),
    "qos_depth": (100, "history depth of the reliable topics"),
    "display_rate": (30.0, "MarkerArray rate in Hz of sim time (0: no markers)"),
    "participants": (["monitor", "executor"], "nodes whose sim/ready starts tick 0"),
    "handshake_period": (0.05, "wall-clock seconds between start-up hellos"),
    "resend_timeout": (1.0, "wall-clock seconds without progress before a tick is re-sent"),
    "recorder_window": (20, "ticks the recorder may lag behind (if 'recorder' participates)"),
}
"""Parameter name -> (typed default, description); config/sim_hardware.yaml sets them."""
BOUNDS = {"qos_depth": pipeline.Bound(1), "display_rate": pipeline.Bound(0.0, unit="Hz"),
          "handshake_period": pipeline.Bound(1e-3, unit="s"),  # wall-clock hellos
          "resend_timeout": pipeline.Bound(0.0, above=True, unit="s"),
          "recorder_window": pipeline.Bound(1)}
"""The range of each numeric parameter."""


class SimHardwareNode(Node):
    """Lockstep simulated hardware backed by :class:`..sim.world.SimWorld`.

    Parameters
    ----------
    world : SimWorld, optional
        A prebuilt world (default: built from the ``scene`` parameter).
    **kwargs
        Passed to :class:`rclpy.node.Node`.
    """

    def __init__(self, world: SimWorld | None = None, **kwargs: Any) -> None:
        super().__init__("sim_hardware", **kwargs)
        self.p = pipeline.declare(self, PARAMETERS, bounds=BOUNDS)
        if world is None:
            if not self.p["scene"]:
                raise ParameterError("parameter 'scene' (a scene YAML file) is required: "
                                     "--ros-args -p scene:=/path/to/scene.yaml")
            world = SimWorld(GraspSetup.build(load_scene(self.p["scene"])))
        self.world = world
        self.frame = self.p["frame_id"]
        loop = pipeline.loop_qos(self.p["qos_depth"])
        sensors = pipeline.sensor_qos(self.p["sensor_qos"], self.p["qos_depth"])
        kept = pipeline.loop_qos(self.p["qos_depth"], kept=True)
        kept_sensors = pipeline.sensor_qos(self.p["sensor_qos"], self.p["qos_depth"], kept=True)
        self.devices = {f: world.devices[f].name for f in world.fingers}
        self.labels = {f: (f"{d}/pose", f"{d}/wrench", f"{d}/tactile", f"{f}_tip")
                       for f, d in self.devices.items()}
        """Finger -> its readings' names in ``sim/tick`` (pose, wrench, tactile) and its
        sensors' frame."""
        pub = self.create_publisher
        self.clock_pub = pub(Clock, pipeline.CLOCK, loop)
        self.pose_pubs = {f: pub(PoseStamped, pipeline.device_topic(d, "pose"),
                                     kept_sensors)
                          for f, d in self.devices.items()}
        sensed = world.scene.has(Effect.FORCE_SENSING)
        self.wrench_pubs = {f: pub(WrenchStamped, pipeline.device_topic(d, "wrench"), sensors)
                            for f, d in self.devices.items() if sensed}
        self.tactile_pubs = {f: pub(TactileArray, pipeline.device_topic(d, "tactile"), sensors)
                             for f, d in self.devices.items() if f in world.layouts}
        self.tick_pub = pub(Tick, pipeline.TICK, kept)
        self.state_pub = pub(SimState, pipeline.SIM_STATE, kept)
        outputs = pipeline.output_qos(self.p["qos_depth"], lockstep=True)
        self.event_pub = pub(ContactEventArray, pipeline.SIM_EVENTS, outputs)
        self.marker_pub = pub(MarkerArray, pipeline.MARKERS, outputs)
        self.camera_pubs: dict[str, Any] = {}
        self.first_frame: list = []
        if world.camera is not None:
            self.camera_pubs = camera_publishers(self)
            self.first_frame = camera_messages(self.camera_pubs, world.camera_frame(0, 0))
            for publisher, msg in self.first_frame:
                publisher.publish(msg)
        for finger, device in self.devices.items():
            self.create_subscription(PoseStamped, pipeline.device_topic(device, "setpoint"),
                                     lambda data, f=finger: self._setpoint(f, data), loop,
                                     raw=True)
        jaws = scene_controller(world.scene, self.p["scene"] or ".")
        self.controller = None if jaws is None else sim_controller(jaws)(
            self, world, jaws, loop, now_ns=lambda: self.now_ns, on_command=self._try_step)
        """The simulated stock controller of the scene's gripper (sim_controllers), if any."""
        self.commanded = set(self.devices) - set(jaws.jaws if jaws else ())
        """Fingers commanded by setpoints (the others by the controller)."""
        self.flow_control = "recorder" in self.p["participants"]
        self.recorder_ns = -1
        self.create_subscription(Header, pipeline.RECORDER_PROGRESS, self._progress, loop)
        self.pending: dict = {}
        self.refusals = RefusalLog(self.get_logger().warning)
        """The log of refused setpoints, by finger."""
        self.current: list = []
        self.now_ns = -1
        self.ended = False
        self.last_progress = time.monotonic()
        self.ticks_published = 0
        self.resends = 0
        self.handshake = pipeline.Handshake(self, self.p["participants"],
                                            self.p["handshake_period"], self._start)
        pipeline.wall_timer(self, max(self.p["resend_timeout"] / 2.0, 1e-3), self._check_stalled)


    def ready_summary(self) -> str:
        """What the ready line of ``ros2 run`` says: scene, devices, controller, waiting for
        whom.
        """
        carried = "hand fingers" if isinstance(self.controller, SimHandTrajectoryController) \
            else "jaws"
        jaws = "" if self.controller is None else (
            f", {carried} {list(self.controller.fingers)} by a simulated "
            f"{CONTROLLER_NAMES[self.controller.controller.kind]} on {self.controller.topic}")
        return (f"scene {self.world.scene.name}, fingers {self.devices}{jaws}, "
                f"dt {self.world.dt} s; waiting for {list(self.p['participants'])}")

    # ----------------------------------------------------------------- the loop
    def _start(self) -> None:
        self.get_logger().info(f"lockstep start: fingers {self.devices}, dt {self.world.dt} s")
        self._publish(self.world.start())

    def _setpoint(self, finger: str, data: bytes) -> None:
        """A setpoint, read from its CDR bytes (:mod:`..messages.cdr`). One that is not finite
        is refused with a warning line (at most one per finger and second): the world waits
        for a finite one. Before, the world's step raised on it and the process ended.
        """
        ns, position = messages.pose_position_cdr(data)
        if self.now_ns < 0 or ns <= self.now_ns:
            return
        if not (math.isfinite(position[0]) and math.isfinite(position[1])):
            self.refusals.refused(f"{finger} setpoint", f"the setpoint of {ns * 1e-9:.9f} s is "
                                                        f"not finite: {position.tolist()} m")
            return
        self.pending[finger] = position
        self._try_step()

    def _progress(self, msg: Header) -> None:
        self.recorder_ns = max(self.recorder_ns, messages.stamp_ns(msg.stamp))
        self._try_step()

    def _try_step(self) -> None:
        if not self.commanded <= set(self.pending) or (
                self.controller is not None and not self.controller.commanded):
            return
        window = self.p["recorder_window"] * self.world.dt_ns
        if self.flow_control and self.recorder_ns < self.now_ns - window:
            return
        setpoints, self.pending = self.pending, {}
        if self.controller is not None:
            setpoints.update(self.controller.setpoints(self.now_ns + self.world.dt_ns))
        self._publish(self.world.step(setpoints))

    def _publish(self, out: TickOutput) -> None:
        """Publish tick ``out`` (clock first, sim/tick last) and keep it for a re-send.

        The tick's clock, readings, ground truth and tick message go out as CDR written
        straight from the world's arrays (:mod:`..messages.cdr`); markers are built only at the
        display rate and only while somebody subscribes.
        """
        ns, frame = out.stamp_ns, self.frame
        batch = [(self.clock_pub, messages.clock_cdr(ns))]
        readings = []
        for r in out.readings:
            pose, wrench, tactile, tip = self.labels[r.finger]
            batch.append((self.pose_pubs[r.finger],
                          messages.pose_stamped_cdr(r.position, ns, frame)))
            readings.append(pose)
            if r.force is not None:
                batch.append((self.wrench_pubs[r.finger],
                              messages.wrench_stamped_cdr(r.force, r.torque, ns, tip)))
                readings.append(wrench)
            if r.normal is not None:
                batch.append((self.tactile_pubs[r.finger], messages.tactile_array_cdr(
                    messages.TactileReadings(r.finger, self.world.layouts[r.finger].angles,
                                             r.normal, r.tangential), ns, tip)))
                readings.append(tactile)
        ending = out.termination is not None and not self.ended
        self.ended = (self.ended or ending) and not out.released
        if out.events or ending or out.released:
            batch.append((self.event_pub, messages.sim_events_msg(
                out.events, out.termination if ending else RELEASED if out.released else "",
                out.state, ns)))
        if self.controller is not None:
            batch.append(self.controller.joint_state(out))
            readings.append(JOINT_STATES)
        batch.append((self.state_pub, messages.sim_state_cdr(out.state, self.world.fingers,
                                                             out.termination, ns, frame)))
        if out.index == 0:
            batch += self.first_frame
        elif (frame_out := self.world.camera_frame(out.index, ns)) is not None:
            batch += camera_messages(self.camera_pubs, frame_out)
        tick = (self.tick_pub, messages.tick_cdr(out.index, ns, readings))
        self.current, self.now_ns = batch + [tick], ns
        if self._display_due(out.index) and self.marker_pub.get_subscription_count() > 0:
            batch.append((self.marker_pub, messages.world_markers(self.world.view(), ns, frame)))
        self.last_progress = time.monotonic()
        self.ticks_published += 1
        pipeline.publish_all(batch + [tick])

    def _display_due(self, index: int) -> bool:
        rate = self.p["display_rate"]
        if rate <= 0.0:
            return False
        frames = (index * self.world.dt * rate, (index - 1) * self.world.dt * rate)
        return index == 0 or int(frames[0]) > int(frames[1])

    def _check_stalled(self) -> None:
        """Re-send the current tick if the loop has not closed for ``resend_timeout`` s."""
        if self.current and time.monotonic() - self.last_progress > self.p["resend_timeout"]:
            self.resends += 1
            self.last_progress = time.monotonic()
            pipeline.publish_all(self.current)


CONTROLLER_NAMES = {ControllerKind.JOINT_TRAJECTORY: "JointTrajectoryController",
                    ControllerKind.GRIPPER_ACTION: "GripperActionController",
                    ControllerKind.PARALLEL_GRIPPER: "ParallelGripperController"}
"""The stock controller each ``controller.type`` stands for."""


def sim_controller(jaws: JawController | HandController) -> type:
    """The simulated controller class of a scene's ``controller:`` section.

    Raises
    ------
    ParameterError
        A gripper action controller without control_msgs in the environment.
    """
    if isinstance(jaws, HandController):
        return SimHandTrajectoryController
    if not jaws.kind.is_action:
        return SimJointTrajectoryController
    try:
        from squeeze_grasp_ros.ros.nodes.sim_gripper_action import SimGripperActionController
    except ImportError as exc:
        raise ParameterError(f"controller.type {jaws.kind} needs control_msgs ({exc}): build it "
                             "with squeeze-grasp ros-setup --control-msgs DIR (docs/grippers.md)"
                             ) from None
    return SimGripperActionController


def camera_publishers(node: Node) -> dict[str, Any]:
    """Publishers of the camera topics, transient-local with :data:`.pipeline.CAMERA`'s history
    (a late subscriber gets the frames kept, the first one before tick 0); publishes the
    camera's pose once.
    """
    pubs = {topic: node.create_publisher(msg_type, topic, pipeline.CAMERA)
            for topic, msg_type in ((pipeline.CAMERA_MASK, Image), (pipeline.CAMERA_DEPTH, Image),
                                    (pipeline.CAMERA_INFO, CameraInfo))}
    world = node.world
    pose = PoseStamped(header=messages.header(0, node.frame),
                       pose=pose_of_camera(world.camera.pose))
    node.create_publisher(PoseStamped, pipeline.CAMERA_POSE, pipeline.LATCHED).publish(pose)
    return pubs


def camera_messages(pubs: dict[str, Any], frame: CameraFrame) -> list:
    """(publisher, message) of one camera frame: mask, depth, CameraInfo, stamped alike."""
    ns, camera, views = frame.stamp_ns, frame.views.camera, frame.views
    return [(pubs[pipeline.CAMERA_MASK], image_msg(views.mask, ImageEncoding.MONO8, ns,
                                                   camera.frame_id)),
            (pubs[pipeline.CAMERA_DEPTH], image_msg(views.depth, ImageEncoding.DEPTH_32FC1, ns,
                                                    camera.frame_id)),
            (pubs[pipeline.CAMERA_INFO], camera_info_msg(camera, ns))]


def main(args: list[str] | None = None) -> int:
    """Run the simulated hardware until Ctrl-C or shutdown; return the exit code."""
    return run_node(SimHardwareNode, args)


if __name__ == "__main__":
    sys.exit(main())
