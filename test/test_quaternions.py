# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""One quaternion policy at every place a pose comes in (``mechanics.errors.unit_quaternion``):
a quaternion whose squared norm is within tf2's tolerance (0.01) of 1 is normalised and used,
as tf2 itself takes it; a zero, non-finite or far-from-unit one is refused in one wording that
names the field and the norm.

Before, there were four policies: the executor's ``object_pose`` wanted the norm 1 to 1e-3
(refusing what tf2 accepts), a camera pose and a gripper pose took any nonzero quaternion (a
norm of 2 was a rotation), and a typed object's ``frame_pose`` took any nonzero one and read
all zeros as the identity.
"""
from __future__ import annotations

import math
import re
import time

import numpy as np
import pytest
import rclpy
from geometry_msgs.msg import Pose, PoseStamped
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor
from rclpy.parameter import Parameter

from squeeze_grasp_interfaces.msg import Alarm
from squeeze_grasp_ros import cli
from squeeze_grasp_ros.mechanics.errors import (
    QUATERNION_TOLERANCE,
    InvalidInputError,
    unit_quaternion,
)
from squeeze_grasp_ros.perception.camera import CameraPose
from squeeze_grasp_ros.planning import ErrorCode, FramePose, PlannerError
from squeeze_grasp_ros.resources import config_dir
from squeeze_grasp_ros.ros import messages
from squeeze_grasp_ros.ros.messages.images import camera_pose
from squeeze_grasp_ros.ros.nodes import ParameterError, pipeline
from squeeze_grasp_ros.ros.nodes.executor import ExecutorNode
from squeeze_grasp_ros.ros.nodes.outline import pose_parameter
from squeeze_grasp_ros.ros.nodes.shape_watcher import ShapeWatcher

DOWN = (1.0, 0.0, 0.0, 0.0)
"""A camera looking down (roll pi) as a quaternion (x, y, z, w)."""
QUARTER = (0.0, 0.0, math.sin(math.pi / 8), math.cos(math.pi / 8))
"""A 45 degree turn about z."""
SCALE = 1.004
"""A norm tf2 accepts (squared 1.008) and the executor's old 1e-3 check refused."""
POLICY = "must be a unit quaternion (x, y, z, w): finite, its squared norm within 0.01 of 1 " \
         "(as tf2 takes it), got "


def scaled(q, factor: float = SCALE) -> list[float]:
    return [factor * v for v in q]


def refusal(name: str, values, norm: str) -> str:
    """The one wording of a refused quaternion."""
    return f"{name} {POLICY}{values} of norm {norm}"


@pytest.mark.parametrize("values, norm", [
    ([0.0, 0.0, 0.0, 0.0], "0"),
    ([2.0, 0.0, 0.0, 0.0], "2"),
    ([0.0, 0.0, 0.0, 0.9], "0.9"),
    ([0.0, 0.0, math.nan, 1.0], "nan"),
    ([0.0, math.inf, 0.0, 1.0], "inf"),
])
def test_a_zero_non_finite_or_far_from_unit_quaternion_is_refused_by_name_and_norm(values,
                                                                                    norm):
    with pytest.raises(InvalidInputError) as refused:
        unit_quaternion("pose.orientation", values)
    assert str(refused.value) == refusal("pose.orientation", values, norm)


def test_the_tolerance_is_tf2s_on_the_squared_norm_and_what_passes_is_normalised():
    inside = [math.sqrt(1.0 + sign * 0.99 * QUATERNION_TOLERANCE) for sign in (1, -1)]
    outside = [math.sqrt(1.0 + sign * 1.01 * QUATERNION_TOLERANCE) for sign in (1, -1)]
    for factor in (*inside, SCALE):
        q = unit_quaternion("q", scaled(QUARTER, factor))
        assert np.linalg.norm(q) == pytest.approx(1.0, abs=1e-15)
        np.testing.assert_allclose(q, QUARTER, atol=1e-15)
    for factor in outside:
        with pytest.raises(InvalidInputError, match="must be a unit quaternion"):
            unit_quaternion("q", scaled(QUARTER, factor))


def test_pose_in_base_takes_what_tf2_takes_and_publishes_it_normalised():
    """The executor's ``object_pose``: a norm of 1.004 was refused (1e-3 before)."""
    msg = messages.pose_in_base([0.1, 0.2, 0.3, *scaled(QUARTER)], "base_link")
    q = msg.pose.orientation
    np.testing.assert_allclose([q.x, q.y, q.z, q.w], QUARTER, atol=1e-15)
    assert (msg.pose.position.x, msg.header.frame_id) == (0.1, "base_link")
    with pytest.raises(ValueError) as refused:
        messages.pose_in_base([0.0, 0.0, 0.0, 2.0, 0.0, 0.0, 0.0], "base_link")
    assert str(refused.value) == refusal("its orientation qx qy qz qw", [2.0, 0.0, 0.0, 0.0],
                                         "2")


def test_the_executor_publishes_a_slightly_off_object_pose_normalised(ros_context: Context):
    node = ExecutorNode(context=ros_context, parameter_overrides=[
        Parameter("object_pose", value=[0.0, 0.0, 0.0, *scaled(QUARTER)])])
    user = rclpy.create_node("object_pose_user", context=ros_context)
    executor = SingleThreadedExecutor(context=ros_context)
    received: list[PoseStamped] = []
    user.create_subscription(PoseStamped, pipeline.OBJECT_POSE, received.append,
                             pipeline.LATCHED)
    try:
        for each in (node, user):
            executor.add_node(each)
        deadline = time.monotonic() + 30.0
        while not received and time.monotonic() < deadline:
            executor.spin_once(0.1)
        q = received[0].pose.orientation
        np.testing.assert_allclose([q.x, q.y, q.z, q.w], QUARTER, atol=1e-15)
    finally:
        executor.shutdown()
        for each in (node, user):
            each.destroy_node()
    with pytest.raises(ParameterError) as refused:
        ExecutorNode(context=ros_context, parameter_overrides=[
            Parameter("object_pose", value=[0.0] * 7)])
    assert str(refused.value) == "parameter 'object_pose': " + refusal(
        "its orientation qx qy qz qw", [0.0, 0.0, 0.0, 0.0], "0")


def test_a_camera_pose_takes_what_tf2_takes_and_refuses_a_norm_of_2():
    """Before, (2, 0, 0, 0) was taken as (1, 0, 0, 0)."""
    exact = CameraPose.from_xyz_quaternion(0.0, 0.0, 0.5, *DOWN)
    near = CameraPose.from_xyz_quaternion(0.0, 0.0, 0.5, *scaled(DOWN))
    np.testing.assert_allclose(near.matrix, exact.matrix, atol=1e-15)
    with pytest.raises(InvalidInputError) as refused:
        CameraPose.from_xyz_quaternion(0.0, 0.0, 0.5, 2.0, 0.0, 0.0, 0.0)
    assert str(refused.value) == refusal("the camera pose's orientation", [2.0, 0.0, 0.0, 0.0],
                                         "2")


def test_the_camera_pose_topic_parameter_and_option_refuse_a_norm_of_2(capsys):
    """The three routes to a camera pose: ``camera/pose`` (a ``Pose``), the outline node's
    ``camera_pose`` parameter and ``--camera-pose``.
    """
    msg = Pose()
    msg.position.z = 0.5
    msg.orientation.x, msg.orientation.w = 2.0, 0.0
    with pytest.raises(InvalidInputError, match=re.escape("the camera pose's orientation " +
                                                          POLICY)):
        camera_pose(msg)
    with pytest.raises(ParameterError) as refused:
        pose_parameter([0.0, 0.0, 0.5, 2.0, 0.0, 0.0, 0.0])
    assert str(refused.value) == "parameter camera_pose: " + refusal(
        "the camera pose's orientation", [2.0, 0.0, 0.0, 0.0], "2")
    info = str(config_dir() / "examples" / "camera_top.yaml")
    code = cli.main(["outline", "mask.npy", "--camera-info", info, "--camera-pose", "0", "0",
                     "0.5", "2", "0", "0", "0"])
    err = capsys.readouterr().err
    assert code == 2 and "the camera pose's orientation " + POLICY in err, err


def test_a_frame_pose_takes_what_tf2_takes_and_refuses_a_zero_quaternion():
    """Before, all zeros was the identity and (0, 0, 2, 0) a half turn."""
    R, t = FramePose((0.1, 0.2, 0.0), tuple(scaled(QUARTER))).planar()
    np.testing.assert_allclose(R, [[math.sqrt(0.5), -math.sqrt(0.5)],
                                   [math.sqrt(0.5), math.sqrt(0.5)]], atol=1e-15)
    np.testing.assert_allclose(t, [0.1, 0.2])
    for q, norm in (((0.0, 0.0, 0.0, 0.0), "0"), ((0.0, 0.0, 2.0, 0.0), "2")):
        with pytest.raises(PlannerError) as refused:
            FramePose((0.0, 0.0, 0.0), q).planar()
        assert refused.value.code == ErrorCode.INVALID_ARGUMENT
        assert str(refused.value) == refusal("object.frame_pose.orientation", list(q), norm)
    with pytest.raises(PlannerError, match=r"object.frame_pose.position must be finite"):
        FramePose((math.nan, 0.0, 0.0)).planar()


def test_a_gripper_pose_takes_what_tf2_takes_and_refuses_a_norm_of_2():
    """Before, any nonzero quaternion was a rotation."""
    msg = PoseStamped()
    msg.header.frame_id = "object"
    msg.pose.position.x = 0.01
    o = msg.pose.orientation
    o.x, o.y, o.z, o.w = scaled(QUARTER)
    centre, yaw = messages.gripper_line_pose(msg, "object")
    assert list(centre) == [0.01, 0.0] and yaw == pytest.approx(math.pi / 4, abs=1e-12)
    o.x, o.y, o.z, o.w = 0.0, 0.0, 2.0, 0.0
    with pytest.raises(ValueError) as refused:
        messages.gripper_line_pose(msg, "object")
    assert str(refused.value) == refusal("the gripper pose's orientation", [0.0, 0.0, 2.0, 0.0],
                                         "2")
    msg.pose.position.y = math.nan
    with pytest.raises(ValueError, match=r"position \(0.01, nan\) must be finite"):
        messages.gripper_line_pose(msg, "object")


def test_the_shape_watch_ignores_a_camera_pose_that_is_no_rotation(ros_context: Context):
    """The monitor's shape watch on ``camera/pose``: a zero quaternion raised out of the
    subscription's callback (ending the monitor), and (2, 0, 0, 0) was a rotation.
    """
    node = rclpy.create_node("shape_watch_pose", context=ros_context)
    try:
        watcher = ShapeWatcher(node, node.create_publisher(Alarm, "alarms", 10), threshold=1e-3,
                               at_force_threshold=1e-3, object_height=0.0, min_force=0.05)
        msg = PoseStamped()
        msg.header.frame_id = "object"
        msg.pose.position.z = 0.5
        o = msg.pose.orientation
        for q in ((0.0, 0.0, 0.0, 0.0), (2.0, 0.0, 0.0, 0.0)):
            o.x, o.y, o.z, o.w = q
            watcher._pose(msg)
            assert watcher.inputs.pose is None and watcher.inputs.pose_refused
        o.x, o.y, o.z, o.w = scaled(DOWN)
        watcher._pose(msg)
        assert watcher.inputs.pose_refused == ""
        np.testing.assert_allclose(watcher.inputs.pose.matrix, np.diag([1.0, -1.0, -1.0]),
                                   atol=1e-15)
    finally:
        node.destroy_node()


def test_the_shape_watch_ignores_a_camera_info_it_cannot_use(ros_context: Context, capfd):
    """The shape watch's other camera input, ``camera/camera_info``: an uncalibrated one (k all
    zero, as a driver without a calibration publishes) raised out of the subscription's
    callback and ended the monitor, as a bad pose did; now it is logged once, and frames are
    not matched until a usable one arrives (as the outline node refuses them).
    """
    from squeeze_grasp_ros.perception.camera import CameraModel
    from squeeze_grasp_ros.ros.messages.images import camera_info_msg

    node = rclpy.create_node("shape_watch_info", context=ros_context)
    try:
        watcher = ShapeWatcher(node, node.create_publisher(Alarm, "alarms", 10), threshold=1e-3,
                               at_force_threshold=1e-3, object_height=0.0, min_force=0.05)
        good = camera_info_msg(CameraModel(640, 480, 500.0, 500.0, 320.0, 240.0), 0)
        watcher._info(good)
        camera = watcher.inputs.camera
        bad = camera_info_msg(camera, 0)
        bad.k = [0.0] * 9
        for _ in range(3):
            watcher._info(bad)
        assert watcher.inputs.camera is None
        assert capfd.readouterr().err.count("shape watch: frames are not matched: camera_info: "
                                            "the camera is uncalibrated") == 1
        watcher._info(good)
        assert watcher.inputs.camera == camera and watcher.inputs.camera_refused == ""
    finally:
        node.destroy_node()

