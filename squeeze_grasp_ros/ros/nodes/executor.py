# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The executor: an ``ExecuteGrasp`` action server streaming fingertip setpoints to the devices.

Run it with ``ros2 run squeeze_grasp_ros executor --ros-args --params-file config/executor.yaml``.
A goal (a squeeze, then optionally a resistance) becomes a
:class:`..control.motion.GraspProgram`; every control cycle turns the monitor's
``monitor/status`` into one ``geometry_msgs/PoseStamped`` setpoint per device
(``devices/<device>/setpoint``: fingertip centre in the object frame ``frame_id``; the object
frame's pose in ``base_frame`` is the ``object_pose`` parameter, published latched on
``object_pose`` for the drivers), with the velocity and acceleration limits, the holds on stale
data and slip alarms, and the program's reactions (a redirection, or a release and a re-squeeze
after a slip alarm, :mod:`..control.motion`).

- Lockstep (simulation): a cycle runs when the status of tick t arrives; the setpoints are
  stamped t + ``period``. While no goal runs the executor does not answer, so simulated time
  waits for the next goal (a run does not depend on when the goal arrived). A repeated status
  (a re-sent tick) gets the same setpoints again.
- Hardware (``lockstep: false``): a wall-clock timer at 1 / ``period`` runs the cycle on the
  newest status.

Stock controller (``controller_scene``: a scene with a ``controller:`` section, docs/grippers.md):
the jaws' setpoints become one aperture on the jaw line (fixed by the jaws' measured tips when
a goal starts) and are sent through the gripper's transmission as ``trajectory_msgs/
JointTrajectory`` on ``<controller>/joint_trajectory``, one point per control cycle
(:mod:`.jaw_commands`; a goal whose planned jaw force is beyond the device's ``max_force`` is
refused ``invalid_goal``); or, under a gripper action controller, the planned aperture and effort
are one ``control_msgs`` GripperCommand / ParallelGripperCommand goal on
``<controller>/gripper_cmd`` whose result ends the grasp goal (:mod:`.jaw_action`; a re-squeeze
adds a release goal and a second squeeze's goal). The other
fingers keep their setpoint topics.

Feedback (every ``feedback_every`` cycles): state, measured depth and forces, events since the
previous feedback. Cancel: the next cycle holds the measured positions and the goal ends
``canceled`` (a goal that has had no cycle yet ends at once, having commanded nothing). Only
one goal runs at a time; others are rejected, also in a burst (the action's request queues keep
every request). On hardware, a goal that sees no ``monitor/status`` at all within
``stale_budget`` s ends ``stale_data``.
"""
from __future__ import annotations

import math
import sys
import time
from typing import Any

from geometry_msgs.msg import PoseStamped
from rclpy.action import ActionServer, CancelResponse, GoalResponse
from rclpy.action.server import ServerGoalHandle
from rclpy.node import Node
from rclpy.serialization import deserialize_message
from rclpy.task import Future

from squeeze_grasp_interfaces.action import ExecuteGrasp
from squeeze_grasp_interfaces.msg import ExecutorStatus, MonitorStatus
from squeeze_grasp_ros.control.motion import (
    Command,
    GraspProgram,
    MotionLimits,
    Observation,
    goal_problem,
)
from squeeze_grasp_ros.inputs import shown
from squeeze_grasp_ros.ros import messages
from squeeze_grasp_ros.ros.nodes import ParameterError, pipeline, run_node, spin_until
from squeeze_grasp_ros.ros.nodes.jaw_commands import HandCommands, JawCommands
from squeeze_grasp_ros.scene import load_scene
from squeeze_grasp_ros.scene.controller import HandController, JawController, scene_controller

PARAMETERS: dict[str, tuple[Any, str]] = {
    "finger_devices": (["F1:barrett_f1", "F2:barrett_f3"], "finger:device of every fingertip"),
    "frame_id": (pipeline.FRAME, "object frame of the setpoints"),
    "base_frame": ("base_link", "robot base frame"),
    "object_pose": ([0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0],
                    "pose of the object frame in base_frame: x y z (m) qx qy qz qw"),
    "max_velocity": (0.01, "largest fingertip speed, m/s"),
    "max_acceleration": (0.1, "largest fingertip acceleration, m/s^2"),
    "position_tolerance": (1e-7, "a phase ends when every moving tip is this close, m"),
    "redirect_grace": (20, "cycles the slip alarm is ignored after a redirection"),
    "stale_budget": (0.1, "longest hold for stale sensor data, s; past it the goal ends "
                          "stale_data (hardware mode: also the longest monitor silence, not "
                          "counting the executor's own stalls)"),
    "lift_watch": (0.0, "after picked_up, hold this long watching for weight_slip before the "
                        "goal ends picked_up, s (0: end at picked_up)"),
    "period": (0.001, "control cycle, s (lockstep: the simulated tick)"),
    "feedback_every": (10, "cycles between action feedback messages"),
    "lockstep": (True, "cycle on each monitor status (simulation: the statuses' stamps are "
                       "the executor's time, use_sim_time is set false and /clock not taken) "
                       "or on a wall-clock timer"),
    "qos_depth": (100, "history depth of the reliable topics"),
    "controller_scene": ("", "scene file whose controller: section drives the jaws through "
                             "a stock controller (empty: setpoint topics only)"),
    "await_prediction": (False, "lockstep, jaws under a stock controller: ready only once "
                                "planner/predicted_events has arrived (run sets it: it "
                                "publishes one before the nodes start)"),
    "stall_timeout": (30.0, "longest the moving fingers may stand still short of their "
                            "setpoints, s; past it the goal ends gripper_stalled holding "
                            "(an inactive JointTrajectoryController drops every trajectory; "
                            "0: no limit)"),
    "gripper_timeout": (30.0, "longest a gripper action goal may run without a result, s; "
                              "past it the grasp goal ends gripper_aborted and the gripper "
                              "goal is canceled (an inactive stock GripperActionController "
                              "accepts goals and never ends them; 0: no limit)"),
}
"""Parameter name -> (typed default, description); config/executor.yaml sets them."""
BOUNDS = {"max_velocity": pipeline.Bound(0.0, above=True, unit="m/s"),
          "max_acceleration": pipeline.Bound(0.0, above=True, unit="m/s^2"),
          "position_tolerance": pipeline.Bound(0.0, above=True, unit="m"),
          "redirect_grace": pipeline.Bound(0), "stale_budget": pipeline.Bound(0.0, unit="s"),
          "lift_watch": pipeline.Bound(0.0, unit="s"),
          "period": pipeline.Bound(1e-6, unit="s"),  # whole nanoseconds within 0.05 %
          "feedback_every": pipeline.Bound(1), "qos_depth": pipeline.Bound(1),
          "gripper_timeout": pipeline.Bound(0.0, unit="s"),
          "stall_timeout": pipeline.Bound(0.0, unit="s")}
"""The range of each numeric parameter."""

STALL_FLOOR = 0.05
"""s: hardware mode, a gap between two runs of the control timer shorter than this (or than two
periods) is lateness, not a stall of the executor's own process."""
STALL_WARNING = 0.1
"""s: hardware mode, a stall of the executor's own control timer longer than this is logged."""
RATE_WINDOW = 0.5
"""s: hardware mode, a goal at least this long whose control cycles ran below
:data:`SLOW_RATE` of the rate ``period`` asks is logged."""
SLOW_RATE = 0.75
"""The fraction of the asked control rate below which a hardware goal's cycles are logged."""

SUCCESS = (ExecuteGrasp.Result.DEPTH_REACHED, ExecuteGrasp.Result.RESISTED,
           ExecuteGrasp.Result.PICKED_UP)
"""Terminations that count as success."""
HOLDS = (ExecuteGrasp.Result.CANCELED, ExecuteGrasp.Result.SLIP_ALARM,
         ExecuteGrasp.Result.STALE_DATA)
"""Terminations after which the executor reports that it holds position."""


class _Goal:
    """The running goal: program, handle, completion future and the events seen."""

    def __init__(self, program: GraspProgram, handle: ServerGoalHandle) -> None:
        self.program = program
        self.handle = handle
        self.done = Future()
        self.events: list = []
        self.since_feedback: list = []
        self.start_ns: int | None = None
        self.waiting_since_ns: int | None = None
        self.stalled = 0.0
        """Hardware mode: s the executor's own control timer stood still during the goal
        (:meth:`ExecutorNode._own_stall`)."""
        self.waiting_since: float | None = None
        """Wall-clock (monotonic) s since which the goal waits for any monitor status
        (hardware mode)."""
        self.releasing = False
        """The action route's gripper goal is a release's (its result is not the goal's)."""
        self.lifting = False
        """The action route's jaws hold while the arm lifts (the gripper goal was canceled, or
        reached a squeeze's depth under weight): its result is not the goal's."""


_ZERO = (0.0, 0.0)
"""The force of a finger a status does not list (the control step reads it so)."""


def _finite(vector: Any) -> bool:
    """Whether planar ``vector`` (or None) is there and finite (cheaper than numpy on two
    numbers: it is checked for every finger at every control cycle).
    """
    return vector is not None and math.isfinite(vector[0]) and math.isfinite(vector[1])


class ExecutorNode(Node):
    """Grasp executor action server."""

    def ready_summary(self) -> str:
        """What the ready line of ``ros2 run`` says: devices, clock and limits."""
        clock = "lockstep on the monitor's statuses" if self.p["lockstep"] else "wall-clock timer"
        driver = self.jaws or self.jaw_action
        carried = "hand fingers" if isinstance(driver, HandCommands) else "jaws"
        jaws = f"{carried} {list(driver.fingers)} on {driver.topic}, " if driver else ""
        return (f"fingers {self.devices}, {jaws}{clock}, "
                f"period {self.p['period']} s, max velocity {self.p['max_velocity']} m/s; "
                f"action {self.action}")

    def __init__(self, **kwargs: Any) -> None:
        super().__init__("executor", **kwargs)
        self.p = p = pipeline.declare(self, PARAMETERS, bounds=BOUNDS)
        try:
            pose = messages.pose_in_base(p["object_pose"], p["base_frame"])
        except ValueError as error:
            raise ParameterError(f"parameter 'object_pose': {error}") from None
        self.devices = pipeline.parse_mapping(p["finger_devices"], "finger_devices")
        self.limits = MotionLimits(p["max_velocity"], p["max_acceleration"],
                                   p["position_tolerance"], p["redirect_grace"],
                                   float(p["stale_budget"]), float(p["lift_watch"]),
                                   float(p["stall_timeout"]))
        self.period_ns = int(round(p["period"] * 1e9))
        loop = pipeline.loop_qos(p["qos_depth"])
        controller = scene_controller(load_scene(p["controller_scene"]), p["controller_scene"]) \
            if p["controller_scene"] else None
        action = controller is not None and controller.kind.is_action
        if isinstance(controller, JawController) and not p["lockstep"] \
                and controller.gripper.transmission.position_limits is None:
            self.get_logger().warning(
                f"the device {controller.gripper.name} gives no transmission.position_limits: "
                "a transmission that closes the wrong way (position_per_aperture's sign, or the "
                "offset) cannot be caught before the jaws move; give the joint's limits (the "
                "URDF's) in its device file")
        self.jaws = None
        if isinstance(controller, HandController):
            self.jaws = HandCommands(self, controller, p["period"], loop)
        elif controller is not None and not action:
            self.jaws = JawCommands(self, controller, p["period"], loop,
                                    awaited=p["await_prediction"])
        self.jaw_action = jaw_action(self, controller, loop, awaited=p["await_prediction"]) \
            if action else None
        """The scene's gripper under a JointTrajectoryController (jaws) or a gripper action
        controller (jaw_action), if any."""
        jaw_fingers = controller.jaws if controller is not None else ()
        self.setpoint_pubs = {f: self.create_publisher(PoseStamped,
                                                       pipeline.device_topic(d, "setpoint"),
                                                       pipeline.loop_qos(p["qos_depth"],
                                                                         kept=True))
                              for f, d in self.devices.items() if f not in jaw_fingers}
        self.status_pub = self.create_publisher(
            ExecutorStatus, pipeline.EXECUTOR_STATUS,
            pipeline.status_qos(p["qos_depth"], lockstep=p["lockstep"]))
        if not p["lockstep"]:  # the state a late reader gets before the first goal
            self.status_pub.publish(messages.executor_status_msg(
                ExecutorStatus.IDLE, 0.0, "", self.get_clock().now().nanoseconds))
        pose_pub = self.create_publisher(PoseStamped, pipeline.OBJECT_POSE, pipeline.LATCHED)
        pose_pub.publish(pose)
        self.create_subscription(MonitorStatus, pipeline.STATUS, self._status, loop, raw=True)
        # keep-all request queues (rclpy's default of 10 dropped the 11th and later goals of a
        # burst unanswered: 10 answers to 30 goals sent at once)
        queues = {f"{kind}_service_qos_profile": pipeline.request_queue(0)
                  for kind in ("goal", "cancel", "result")}
        self.action = pipeline.action_name(self, pipeline.ACTION)
        """The action's fully qualified name (:func:`.pipeline.action_name`)."""
        self.server = ActionServer(self, ExecuteGrasp, self.action, self._execute,
                                   goal_callback=self._accept_goal,
                                   cancel_callback=self._accept_cancel, **queues)
        self.goal: _Goal | None = None
        self.accepted = False
        """A goal was accepted and has not ended yet (its execution may not have started:
        rclpy runs it as a later task, after more goal requests may have been taken)."""
        self.latest: bytes | None = None
        """The newest status, serialised (a raw subscription: :meth:`_cycle` reads it)."""
        self.latest_at = 0.0
        """Hardware mode: when it arrived (``time.monotonic``, s), moved on by the executor's
        own stalls (:meth:`_own_stall`)."""
        self.timer_at: float | None = None
        """Hardware mode: when the control timer last ran (``time.monotonic``, s)."""
        self.allowance = max(2.0 * p["period"], STALL_FLOOR)
        """Hardware mode: s between two runs of the control timer beyond which the executor
        itself stood still (a late timer that runs on is not a stall)."""
        self.answered = pipeline.TickAnswer()
        self.state = ExecutorStatus.IDLE
        self.tick_clock = pipeline.TickClock(self) if p["lockstep"] else None
        """In lockstep the clock follows the statuses' stamps, not ``/clock``."""
        if p["lockstep"]:
            self.participant = pipeline.Participant(self, "executor", [pipeline.STATUS],
                                                    list(self.setpoint_pubs.values())
                                                    + ([self.jaws.publisher] if self.jaws else [])
                                                    + ([self.jaw_action.publisher]
                                                       if self.jaw_action else []),
                                                    condition=self.jaw_action.ready
                                                    if self.jaw_action else
                                                    self.jaws.ready if self.jaws else None)
        else:
            self.create_timer(p["period"], self._timer)

    # ----------------------------------------------------------------- action
    def destroy_node(self) -> None:
        """Destroy the action server too: rclpy's ``destroy_node`` leaves waitables to the garbage
        collector, and a still-referenced server keeps answering goals of a later run in the same
        process ("more than one action server").
        """
        self.server.destroy()
        super().destroy_node()

    def drain(self, executor: Any, timeout: float = 1.0) -> None:
        """End the goal in flight when the node stops (SIGINT, SIGTERM): ABORTED, termination
        ``canceled``, "the executor is shutting down"; spin ``executor`` until its result is
        sent, ``timeout`` s at most. (Before, the node ended without ending the goal, and its
        client waited for a result for ever.) Nothing more is commanded: a joint trajectory's
        one point ends a period later, and a gripper action controller's goal is canceled first
        (the stock controllers hold the measured position), waiting ``timeout`` s at most for
        the controller's answer.
        """
        goal = self.goal
        if goal is None or goal.done.done():
            return
        self.goal = None
        message = "the executor is shutting down: it sends no more commands"
        answered: list[bool] = []
        if self.jaw_action is not None and self.jaw_action.cancel(lambda: answered.append(True)):
            message += ("; it canceled the gripper goal (the controller holds position)"
                        if spin_until(executor, lambda: bool(answered), timeout) else
                        f"; the gripper controller did not answer the cancel of its goal within "
                        f"{timeout:g} s")
        latest = messages.cdr_stamp_ns(self.latest) if self.latest is not None else None
        self._end_holding(goal, ExecuteGrasp.Result.CANCELED, message,
                          0.0 if goal.start_ns is None or latest is None else
                          max(latest - goal.start_ns, 0) * 1e-9)
        # then the result request the ended goal answers
        spin_until(executor, lambda: not self.accepted, timeout, then=4)

    def _accept_goal(self, _: ExecuteGrasp.Goal) -> GoalResponse:
        """One goal at a time: reject while one is accepted, running or not started yet
        (before, checking only the running goal, a burst of goals at an idle executor on
        ``EventsExecutor`` had 10 of 10 answered goals accepted; each replaced the previous,
        whose result never came).
        """
        if self.accepted:
            return GoalResponse.REJECT
        self.accepted = True
        return GoalResponse.ACCEPT

    def _accept_cancel(self, handle: ServerGoalHandle) -> CancelResponse:
        """Accept every cancel. The running goal ends at its next cycle; one that has had no
        cycle yet (no monitor status since it was accepted) ends now, having commanded nothing
        (before, it waited for a status that, with the monitor or the loop stopped, never
        came: the cancel was accepted and the goal never ended).
        """
        goal = self.goal
        if goal is not None and goal.handle is handle and goal.start_ns is None:
            self._cancel_unstarted(goal)
        return CancelResponse.ACCEPT

    def _cancel_unstarted(self, goal: _Goal) -> None:
        """End ``goal``, canceled before its first control cycle."""
        self._end_holding(goal, ExecuteGrasp.Result.CANCELED,
                          "canceled before its first control cycle; nothing was commanded")

    def _end_holding(self, goal: _Goal, termination: str, message: str,
                     elapsed: float = 0.0) -> None:
        """End ``goal`` outside a control cycle (it has commanded nothing, or the node stops)
        with ``termination``, holding, after ``elapsed`` s, with the events it has seen.
        """
        self.goal = None
        goal.done.set_result(messages.grasp_result(
            goal.program, Command({}, "holding", termination, message), None, goal.events,
            elapsed, SUCCESS))

    async def _execute(self, handle: ServerGoalHandle) -> ExecuteGrasp.Result:
        try:
            return await self._run_goal(handle)
        finally:
            self.accepted = False

    async def _run_goal(self, handle: ServerGoalHandle) -> ExecuteGrasp.Result:
        goal = messages.grasp_goal(handle.request)
        problem = (messages.goal_msg_problem(handle.request)
                   or goal_problem(goal, list(self.devices)))
        if problem is None and self.jaws is not None:
            problem = self.jaws.effort_problem(goal)
        if problem is None and self.jaw_action is not None:
            problem = self.jaw_action.tolerance_problem(goal)
        if problem is not None:
            handle.abort()
            return messages.invalid_goal_result(problem)
        self.goal = running = _Goal(GraspProgram(goal, self.limits, list(self.devices)), handle)
        done = self.goal.done
        if handle.is_cancel_requested:  # taken before this task ran: _accept_cancel saw no goal
            self._cancel_unstarted(self.goal)
        elif self.p["lockstep"] and self.latest is not None and \
                messages.cdr_stamp_ns(self.latest) > self.answered.stamp_ns:
            self._cycle(self.latest)
        result = await done
        self._check_rate(result, running)
        if result.termination == ExecuteGrasp.Result.CANCELED and handle.is_cancel_requested:
            handle.canceled()
        elif result.success:
            handle.succeed()
        else:
            handle.abort()
        return result

    # ----------------------------------------------------------------- cycles
    def _status(self, data: bytes) -> None:
        ns = messages.cdr_stamp_ns(data)
        if not self.p["lockstep"]:
            self._hardware_status(ns, data)
            return
        if not self.answered.is_new(ns):
            return
        self.tick_clock.advance(ns)
        self.latest = data
        if self.goal is not None:
            self._cycle(data)

    def _hardware_status(self, ns: int, data: bytes) -> None:
        """Hardware mode: the newest status by arrival is the one the timer's cycles read,
        whatever its stamp, and its arrival time says whether the monitor still speaks.

        Before, a status stamped before the last one was dropped as an old tick: after the
        monitor's clock stepped back (a restart on sim time, an NTP step) every later status
        was, and the goal ran on the last one, deaf to its alarms (a ``slip_imminent`` went
        unheard for as long as the test waited, 5 s).
        """
        if self.latest is not None and ns < messages.cdr_stamp_ns(self.latest):
            self.get_logger().warning(
                f"{self.resolve_topic_name(pipeline.STATUS)} went back from "
                f"{messages.cdr_stamp_ns(self.latest) * 1e-9:.9f} s to {ns * 1e-9:.9f} s (the "
                "monitor's clock stepped back, or it restarted): taking it as the newest",
                throttle_duration_sec=1.0)
        self.latest, self.latest_at = data, time.monotonic()

    def _timer(self) -> None:
        now = time.monotonic()
        lost = self._own_stall(now)
        goal = self.goal
        if goal is None:
            return
        if lost:    # the silence clocks do not run while the executor itself could not run
            self.latest_at = min(self.latest_at + lost, now)
            if goal.waiting_since is not None:
                goal.waiting_since = min(goal.waiting_since + lost, now)
            goal.stalled += lost
            if lost > STALL_WARNING:
                self.get_logger().warning(
                    f"the control timer did not run for {lost + self.allowance:.3f} s "
                    f"(period {self.p['period']} s): this process stood still (garbage "
                    "collection, a starved CPU); no setpoint went out meanwhile, and the stall "
                    "does not count as monitor silence", throttle_duration_sec=1.0)
        if self.latest is not None:
            silent = now - self.latest_at
            if silent <= self.p["stale_budget"]:
                self._cycle(self.latest, self.get_clock().now().nanoseconds)
            else:  # before, the goal ran on the last status after the monitor had stopped
                self._end_holding(goal, ExecuteGrasp.Result.STALE_DATA,
                                  f"no {self.resolve_topic_name(pipeline.STATUS)} message for "
                                  f"{silent:.3f} s, more than stale_budget "
                                  f"{self.p['stale_budget']} s (is the monitor running?); "
                                  "holding")
            return
        # no monitor status at all yet: wait stale_budget of wall-clock time, then end
        goal.waiting_since = now if goal.waiting_since is None else goal.waiting_since
        if now - goal.waiting_since > self.p["stale_budget"]:
            self._end_holding(goal, ExecuteGrasp.Result.STALE_DATA,
                              f"no {self.resolve_topic_name(pipeline.STATUS)} message within "
                              f"stale_budget {self.p['stale_budget']} s of the goal (is the "
                              "monitor running?); nothing was commanded")

    def _check_rate(self, result: ExecuteGrasp.Result, goal: _Goal) -> None:
        """Hardware mode: warn when ``goal``'s control cycles ran below :data:`SLOW_RATE` of
        the rate ``period`` asks, over at least :data:`RATE_WINDOW` s of its ``result``'s
        duration outside the executor's own stalls (logged apart). A cycle advances the motion
        and the time budgets by one period, so a timer that cannot keep up slows the squeeze
        and stretches stale_budget and stall_timeout in wall time.
        """
        running = result.duration - goal.stalled
        if self.p["lockstep"] or running < RATE_WINDOW or not result.ticks:
            return
        rate, asked = result.ticks / running, 1.0 / self.p["period"]
        if rate < SLOW_RATE * asked:
            self.get_logger().warning(
                f"the goal ran {result.ticks} control cycles in {running:.3f} s"
                + (f" (and {goal.stalled:.3f} s of stalls)" if goal.stalled else "") + ": "
                f"{rate:.4g} a second against the {asked:.4g} that period {self.p['period']} s "
                f"asks; the motion ran and its time budgets counted at {100 * rate / asked:.0f} "
                "% of wall time: give a period this machine keeps")

    def _own_stall(self, now: float) -> float:
        """How long the executor itself stood still before this timer callback (``now``,
        monotonic s): the part of the gap since the last callback beyond :attr:`allowance` (the
        silence clocks run at most that much between two callbacks).

        A process stalled by the garbage collector, the GIL or a starved CPU hears nothing, and
        its monitor (in the same process, or queued behind the stall) could not speak: that
        silence says nothing of the monitor. Before, a 1.3 s stall of the process ended a
        hardware goal ``stale_data`` at stale_budget 1 s, blaming the monitor.
        """
        last, self.timer_at = self.timer_at, now
        return 0.0 if last is None else max(now - last - self.allowance, 0.0)

    def _cycle(self, data: bytes, now_ns: int | None = None) -> None:
        """One control cycle on the serialised status ``data``; publish the setpoints, finish
        the goal if done.

        A status without events and alarms (most ticks) is read from its bytes
        (:func:`..messages.observation_cdr`); one with any is deserialised, and its events are
        kept for the result.
        """
        goal = self.goal
        obs = messages.observation_cdr(data)
        msg = None if obs is not None else deserialize_message(data, MonitorStatus)
        obs = obs or messages.observation(msg)
        ns = obs.stamp_ns
        if self._unwatched(goal, obs):
            return
        if goal.start_ns is None:
            if not self.p["lockstep"] and self._unseen(
                    goal, msg or deserialize_message(data, MonitorStatus), ns):
                return
            goal.start_ns = ns
            driver = self.jaws or self.jaw_action
            problem = None if driver is None else driver.start(obs, goal.program.goal)
            if problem is not None:
                self._end_holding(goal, ExecuteGrasp.Result.INVALID_GOAL,
                                  f"{problem}; nothing was commanded")
                return
        if msg is not None:
            goal.events += msg.events
            goal.since_feedback += msg.events
        if goal.handle.is_cancel_requested:
            goal.program.cancel()
        command = goal.program.step(obs, self.p["period"])
        if self.jaw_action is not None:
            self._action_cycle(goal, command, obs, ns, now_ns)
            return
        stamp = ns + self.period_ns if now_ns is None else now_ns
        batch = self._setpoints(command, stamp)
        if self.jaws is not None:
            batch.append(self.jaws.trajectory(command.setpoints, ns if now_ns is None else 0))
        self.answered.answer(ns, batch)
        self._report(command, obs, ns)
        if command.termination is not None:
            self.goal = None
            goal.done.set_result(messages.grasp_result(
                goal.program, command, obs, goal.events, (ns - goal.start_ns) * 1e-9, SUCCESS))

    def _unwatched(self, goal: _Goal, obs: Observation) -> bool:
        """True, and ``goal`` ended ``stale_data``, when status ``obs`` has no finite position
        and force of a finger the executor drives (a monitor whose ``finger_devices`` leave out
        one of the executor's, a status whose arrays are shorter than its ``fingers``, NaN).
        Before, a missing finger made the control step raise KeyError, which ended the executor
        process, and a NaN position made the goal's work NaN.
        """
        missing = [f for f in goal.program.fingers
                   if not _finite(obs.positions.get(f)) or not _finite(obs.forces.get(f, _ZERO))]
        if not missing:
            return False
        elapsed = 0.0 if goal.start_ns is None else (obs.stamp_ns - goal.start_ns) * 1e-9
        self._end_holding(goal, ExecuteGrasp.Result.STALE_DATA,
                          f"{self.resolve_topic_name(pipeline.STATUS)} of "
                          f"{obs.stamp_ns * 1e-9:.9f} s has no finite position and force of "
                          f"{', '.join(missing)} (it lists {shown(', '.join(obs.positions))}; "
                          "the monitor must watch every finger of the executor's finger_devices); "
                          "nothing more was commanded", elapsed)
        return True

    def _setpoints(self, command: Command, stamp: int) -> list:
        """(publisher, serialised PoseStamped) of each commanded finger with a setpoint topic,
        stamped ``stamp`` (:mod:`..messages.cdr`).
        """
        frame = self.p["frame_id"]
        return [(self.setpoint_pubs[f], messages.pose_stamped_cdr(xy, stamp, frame))
                for f, xy in command.setpoints.items() if f in self.setpoint_pubs]

    def _unseen(self, goal: _Goal, msg: MonitorStatus, ns: int) -> bool:
        """True while a finger of the goal has no reading yet (hardware mode: a goal sent before
        the monitor saw the fingers, whose status reports them at the origin): the goal waits,
        commanding nothing, and ends ``stale_data`` after ``stale_budget``. Not in lockstep,
        where every tick must be answered: there the program's own stale check ends the goal.
        """
        unseen = [f for f, age in zip(msg.fingers, msg.sensor_age)
                  if f in goal.program.fingers and not age < messages.UNSEEN_AGE]
        if not unseen:
            return False
        goal.waiting_since_ns = ns if goal.waiting_since_ns is None else goal.waiting_since_ns
        if (ns - goal.waiting_since_ns) * 1e-9 > self.p["stale_budget"]:
            self.goal = None
            goal.done.set_result(messages.grasp_result(
                goal.program, Command({}, "holding", ExecuteGrasp.Result.STALE_DATA,
                                      f"no reading of {', '.join(unseen)} within stale_budget "
                                      f"{self.p['stale_budget']} s of the goal; nothing was "
                                      "commanded"),
                None, [], (ns - goal.waiting_since_ns) * 1e-9, SUCCESS))
        return True

    def _action_cycle(self, goal: _Goal, command: Command, obs, ns: int,
                      now_ns: int | None) -> None:
        """A cycle of the action route (:mod:`.jaw_action`): the jaws' goal at the first cycle,
        a cancel on the program's reactions, the end on the gripper goal's result; the other
        fingers' setpoints as usual. In lockstep the tick is answered once the request is.
        """
        action = self.jaw_action
        stamp = ns + self.period_ns if now_ns is None else now_ns
        batch = self._setpoints(command, stamp)
        batch.append(action.cycle_msg(ns))
        self.answered.answer(ns, [])

        def answer() -> None:
            if self.answered.stamp_ns == ns:
                self.answered.answer(ns, batch)

        end, program = None, goal.program
        if command.termination not in (None, ExecuteGrasp.Result.DEPTH_REACHED):
            end = (command.termination, command.termination in SUCCESS, command.message)
            waiting = action.cancel(answer)
        elif program.ticks == 1:
            position, effort = action.target(program.goal, obs)
            action.send(position, effort, answer, at_ns=ns)
            waiting = True
        elif program.phase == "lift" and not goal.lifting:
            goal.lifting = True  # picked up: the controller holds while the arm lifts
            waiting = action.cancel(answer)
        elif command.state == ExecutorStatus.RELEASING and not goal.releasing:
            goal.releasing, goal.lifting = True, False
            opening = action.opening(dict(zip(program.goal.fingers,
                                              program.release_positions())))

            def release() -> None:
                action.send(opening, 0.0, answer, at_ns=ns)

            if not action.cancel(release):
                release()
            waiting = True
        elif goal.releasing and command.state == ExecutorStatus.SQUEEZING:
            goal.releasing = False
            position, effort = action.squeeze(
                program.goal, dict(zip(program.goal.fingers, program.first_contact)),
                program.planned_depth)
            if program.under_weight:
                effort = 0.0  # deeper than the plan's force curve: the controller's own limit
            action.send(position, effort, answer, at_ns=ns)
            waiting = True
        else:
            end, waiting = (None if goal.releasing or goal.lifting else action.outcome), False
            overdue = action.overdue(ns, self.p["gripper_timeout"])
            if end is None and overdue is not None:
                end = (ExecuteGrasp.Result.GRIPPER_ABORTED, False, overdue)
                waiting = action.cancel(answer)
            elif end is not None and program.under_weight and end[1]:
                # a squeeze deeper under weight reached its depth: hold and watch the lift
                command, end, goal.lifting = program.lift(obs), None, True
        if not waiting:
            answer()
        termination = None if end is None else end[0]
        report = Command(command.setpoints, "holding" if end else "squeezing", termination,
                         "" if end is None else end[2])
        self._report(report, obs, ns)
        if end is not None:
            self.goal = None
            result = messages.grasp_result(goal.program, report, obs, goal.events,
                                           (ns - goal.start_ns) * 1e-9, SUCCESS)
            result.success = bool(end[1])
            goal.done.set_result(result)

    def _report(self, command: Command, obs, ns: int) -> None:
        """Executor status on state changes; action feedback every ``feedback_every`` cycles."""
        goal = self.goal
        state = command.state
        if command.termination in SUCCESS:
            state = ExecutorStatus.IDLE
        elif command.termination not in (None, *HOLDS):
            state = ExecutorStatus.ABORTED
        if state != self.state:
            self.state = state
            self.status_pub.publish(messages.executor_status_msg(
                state, goal.program.depth(obs), command.message, ns))
        program = goal.program
        if program.ticks % self.p["feedback_every"] == 0 or command.termination is not None:
            goal.handle.publish_feedback(messages.grasp_feedback(
                command.state, obs, program.fingers, goal.since_feedback,
                program.goal.relative_per_depth, program.attempts, program.depth(obs)))
            goal.since_feedback = []


def jaw_action(node: Node, controller: JawController, qos: Any, *, awaited: bool) -> Any:
    """The executor's side of a gripper action controller (:class:`.jaw_action.JawAction`;
    ``awaited`` as there).

    Raises
    ------
    ParameterError
        Without control_msgs in the environment.
    """
    try:
        from squeeze_grasp_ros.ros.nodes.jaw_action import JawAction
    except ImportError as exc:
        raise ParameterError(f"controller.type {controller.kind} needs control_msgs ({exc}): "
                             "build it with squeeze-grasp ros-setup --control-msgs DIR "
                             "(docs/grippers.md)") from None
    return JawAction(node, controller, qos, awaited=awaited)


def main(args: list[str] | None = None) -> int:
    """Run the executor until Ctrl-C or shutdown; return the exit code."""
    return run_node(ExecutorNode, args)


if __name__ == "__main__":
    sys.exit(main())
