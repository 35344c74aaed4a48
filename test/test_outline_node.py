# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The outline node on real rclpy (issue 32, item 2): rendered mask and depth images of a
ring-like object published as ``sensor_msgs/Image`` + ``CameraInfo`` come back as the outline
(PolygonStamped and SeenOutline with its hole) within a pixel of the truth; bad views are
refused on ``outline/errors``; the image conversions round-trip both byte orders.
"""
from __future__ import annotations

import time

import numpy as np
import pytest
from perception_support import CAMERA, pose, skimage_or_skip
from scipy.spatial.distance import directed_hausdorff

from squeeze_grasp_ros.mechanics.elastic import shapes
from squeeze_grasp_ros.mechanics.elastic.shapes import resample
from squeeze_grasp_ros.mechanics.vocabulary import ImageEncoding
from squeeze_grasp_ros.perception.render import render_views

HEIGHT = 0.02


def hausdorff(a: np.ndarray, b: np.ndarray) -> float:
    a, b = resample(a, 2e-4), resample(b, 2e-4)
    return max(directed_hausdorff(a, b)[0], directed_hausdorff(b, a)[0])


def test_images_round_trip_through_messages():
    from squeeze_grasp_ros.ros.messages.images import image_array, image_msg

    rng = np.random.default_rng(3)
    for encoding, pixels in ((ImageEncoding.MONO8, rng.integers(0, 255, (5, 7), np.uint8)),
                             (ImageEncoding.DEPTH_16UC1, rng.integers(0, 60000, (5, 7),
                                                                      np.uint16)),
                             (ImageEncoding.DEPTH_32FC1, rng.random((5, 7), np.float32))):
        msg = image_msg(pixels, encoding, 7, "cam")
        back, got = image_array(msg)
        assert got == encoding and np.array_equal(back, pixels)
    big = image_msg(pixels, ImageEncoding.DEPTH_32FC1, 0, "cam")
    big.is_bigendian, big.data = 1, pixels.astype(">f4").tobytes()
    assert np.array_equal(image_array(big)[0], pixels)
    padded = image_msg(pixels, ImageEncoding.DEPTH_32FC1, 0, "cam")
    padded.step = 7 * 4 + 4
    padded.data = np.pad(pixels.view(np.uint8).reshape(5, 28), ((0, 0), (0, 4))).tobytes()
    assert np.array_equal(image_array(padded)[0], pixels)
    padded.data = padded.data[:-1]
    with pytest.raises(ValueError, match="step x height"):
        image_array(padded)


def test_an_8uc1_mask_reads_as_mono8_and_other_encodings_are_named():
    """Segmentation nodes publish one-channel 8-bit masks as ``8UC1`` as often as ``mono8``."""
    from squeeze_grasp_ros.ros.messages.images import image_array, image_msg

    mask = np.zeros((6, 9), np.uint8)
    mask[2:5, 3:7] = 1
    msg = image_msg(mask, ImageEncoding.MONO8, 0, "cam")
    msg.encoding = "8UC1"
    back, got = image_array(msg)
    assert got == ImageEncoding.MONO8 and np.array_equal(back, mask)
    msg.encoding = "bgr8"
    with pytest.raises(ValueError, match=r"'mono8', '16UC1', '32FC1', '8UC1'\], got 'bgr8'"):
        image_array(msg)


def test_the_outline_node_publishes_the_seen_outline(ros_context):
    skimage_or_skip()
    import rclpy
    from geometry_msgs.msg import PolygonStamped
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.parameter import Parameter
    from sensor_msgs.msg import CameraInfo, Image
    from std_msgs.msg import String

    from squeeze_grasp_interfaces.msg import SeenOutline
    from squeeze_grasp_ros.ros.messages.images import camera_info_msg, image_msg
    from squeeze_grasp_ros.ros.messages.objects import polygon_points
    from squeeze_grasp_ros.ros.nodes.outline import OutlineNode

    truth = shapes.annulus(0.05, 0.02)
    view_pose = pose(0.01, -0.01, 0.3)
    views = render_views(truth, CAMERA, view_pose, top_height=HEIGHT)
    rpy = [0.01, -0.01, 0.5, np.pi + 0.04, -0.02, 0.3]
    node = OutlineNode(context=ros_context, parameter_overrides=[
        Parameter("camera_pose", value=rpy), Parameter("object_height", value=HEIGHT)])
    client = rclpy.create_node("outline_test", context=ros_context)
    executor = SingleThreadedExecutor(context=ros_context)
    for n in (node, client):
        executor.add_node(n)
    got: dict[str, list] = {"seen": [], "outline": [], "errors": []}
    client.create_subscription(SeenOutline, "outline/seen", got["seen"].append, 10)
    client.create_subscription(PolygonStamped, "outline/outline", got["outline"].append, 10)
    client.create_subscription(String, "outline/errors", got["errors"].append, 10)
    images = client.create_publisher(Image, "camera/mask", 10)
    infos = client.create_publisher(CameraInfo, "camera/camera_info", 10)

    def spin_until(done, what):
        deadline = time.monotonic() + 30
        while not done():
            assert time.monotonic() < deadline, f"timed out waiting for {what}"
            executor.spin_once(0.05)

    try:
        spin_until(lambda: images.get_subscription_count() and infos.get_subscription_count(),
                   "the node's subscriptions")
        images.publish(image_msg(views.mask, ImageEncoding.MONO8, 1_000, CAMERA.frame_id))
        spin_until(lambda: got["errors"], "the refusal without camera_info")
        assert "no camera_info yet" in got["errors"][0].data
        infos.publish(camera_info_msg(CAMERA, 2_000))
        spin_until(lambda: node.inputs.camera is not None, "the camera info")
        images.publish(image_msg(views.mask, ImageEncoding.MONO8, 3_000, CAMERA.frame_id))
        spin_until(lambda: got["seen"] and got["outline"], "the outline")
        seen = got["seen"][0]
        assert seen.outline.header.frame_id == "object" and seen.encoding == "mono8"
        assert seen.outline.header.stamp.nanosec == 3_000
        assert len(seen.holes) == 1 and seen.other_blobs == 0
        assert seen.shape == "annulus" and 0 < seen.fit_residual < 0.3 * seen.pixel_size
        assert seen.area == pytest.approx(truth.area, rel=0.005)
        pixel = seen.pixel_size
        outer = np.asarray(polygon_points(seen.outline.polygon))
        hole = np.asarray(polygon_points(seen.holes[0]))
        assert hausdorff(outer, truth.points) < 0.5 * pixel
        assert hausdorff(hole, truth.holes[0]) < 0.5 * pixel
        assert np.allclose([p.z for p in seen.outline.polygon.points], HEIGHT, atol=1e-6)
        assert polygon_points(got["outline"][0].polygon) == polygon_points(seen.outline.polygon)

        depth = render_views(truth, CAMERA, view_pose, top_height=HEIGHT,
                             depth_noise_m=0.0005, seed=2)
        images.publish(image_msg(depth.depth_mm(), ImageEncoding.DEPTH_16UC1, 4_000,
                                 CAMERA.frame_id))
        spin_until(lambda: len(got["seen"]) == 2, "the outline of the depth image")
        empty = np.zeros_like(views.mask)
        images.publish(image_msg(empty, ImageEncoding.MONO8, 5_000, CAMERA.frame_id))
        spin_until(lambda: len(got["errors"]) == 2, "the empty view's refusal")
        assert "no object" in got["errors"][1].data and len(got["seen"]) == 2
        cut = np.zeros_like(views.mask)
        cut[:, :100] = 255
        images.publish(image_msg(cut, ImageEncoding.MONO8, 6_000, CAMERA.frame_id))
        spin_until(lambda: len(got["errors"]) == 3, "the border view's refusal")
        assert "border" in got["errors"][2].data
    finally:
        executor.shutdown()
        client.destroy_node()
        node.destroy_node()


def test_a_bad_camera_pose_parameter_is_refused():
    from squeeze_grasp_ros.ros.nodes import ParameterError
    from squeeze_grasp_ros.ros.nodes.outline import pose_parameter

    assert pose_parameter([0.0] * 6) is None
    with pytest.raises(ParameterError, match="6 numbers .* or 7"):
        pose_parameter([1.0, 2.0])
    with pytest.raises(ParameterError, match="camera_pose: .*above the support plane"):
        pose_parameter([0.0, 0.0, -0.5, np.pi, 0.0, 0.0])


def test_a_camera_whose_undistortion_diverges_is_refused_not_raised(ros_context):
    """A CameraInfo with distortion too strong to invert (k1 = k2 = k3 = 100) made the image
    callback raise NumericalError out of the node; now the frame is refused on outline/errors.
    """
    skimage_or_skip()
    from dataclasses import replace

    from rclpy.parameter import Parameter

    from squeeze_grasp_ros.ros.messages.images import image_msg
    from squeeze_grasp_ros.ros.nodes.outline import OutlineNode

    views = render_views(shapes.rectangle(0.1, 0.1), CAMERA, pose(), top_height=HEIGHT)
    node = OutlineNode(context=ros_context, parameter_overrides=[
        Parameter("camera_pose", value=[0.0, 0.0, 0.5, np.pi, 0.0, 0.0])])
    try:
        node.inputs.camera = replace(CAMERA, distortion=(100.0, 100.0, 0.0, 0.0, 100.0))
        node._image(image_msg(views.mask, ImageEncoding.MONO8, 1_000, "cam"))
        assert "undistortion did not converge" in node.last_error
    finally:
        node.destroy_node()


def test_an_image_from_another_camera_than_its_camera_info_is_refused(ros_context):
    """An image whose ``header.frame_id`` is not its camera_info's was read with that other
    camera's calibration, and its outline published; now it is refused by both frames. An
    image or camera_info that names no frame is read as before.
    """
    skimage_or_skip()
    from rclpy.parameter import Parameter

    from squeeze_grasp_ros.ros.messages.images import camera_info_msg, image_msg
    from squeeze_grasp_ros.ros.nodes.outline import OutlineNode

    views = render_views(shapes.rectangle(0.1, 0.1), CAMERA, pose(), top_height=HEIGHT)
    node = OutlineNode(context=ros_context, parameter_overrides=[
        Parameter("camera_pose", value=[0.0, 0.0, 0.5, np.pi + 0.04, -0.02, 0.0]),
        Parameter("object_height", value=HEIGHT)])
    seen = []
    node.seen_pub.publish = seen.append
    try:
        info = camera_info_msg(CAMERA, 1_000)
        info.header.frame_id = "top_optical"
        node._info(info)
        node._image(image_msg(views.mask, ImageEncoding.MONO8, 2_000, "side_optical"))
        assert not seen
        assert node.last_error == ("image header.frame_id 'side_optical' is not the "
                                   "camera_info's 'top_optical': the image and the calibration "
                                   "come from different cameras (publish both in the camera's "
                                   "optical frame)")
        for frame in ("top_optical", ""):
            node._image(image_msg(views.mask, ImageEncoding.MONO8, 3_000, frame))
        info.header.frame_id = ""
        node._info(info)
        node._image(image_msg(views.mask, ImageEncoding.MONO8, 4_000, "side_optical"))
        assert len(seen) == 3
    finally:
        node.destroy_node()


def test_images_after_a_refused_camera_info_say_why(ros_context):
    """After a camera_info with fx = 0, each image was refused as 'no camera_info yet', though
    one had arrived; now the refusal says the newest was refused and why.
    """
    skimage_or_skip()
    from rclpy.parameter import Parameter

    from squeeze_grasp_ros.ros.messages.images import camera_info_msg, image_msg
    from squeeze_grasp_ros.ros.nodes.outline import OutlineNode

    views = render_views(shapes.rectangle(0.1, 0.1), CAMERA, pose(), top_height=HEIGHT)
    node = OutlineNode(context=ros_context, parameter_overrides=[
        Parameter("camera_pose", value=[0.0, 0.0, 0.5, np.pi + 0.04, -0.02, 0.0]),
        Parameter("object_height", value=HEIGHT)])
    try:
        node._image(image_msg(views.mask, ImageEncoding.MONO8, 1_000, CAMERA.frame_id))
        assert node.last_error == "no camera_info yet"
        info = camera_info_msg(CAMERA, 2_000)
        info.k[0] = 0.0
        node._info(info)
        node._image(image_msg(views.mask, ImageEncoding.MONO8, 3_000, CAMERA.frame_id))
        assert node.last_error == ("no usable camera_info: the newest was refused (camera_info: "
                                   "camera fx must be a positive focal length in px, got 0.0)")
        node._info(camera_info_msg(CAMERA, 4_000))
        node._image(image_msg(views.mask, ImageEncoding.MONO8, 5_000, CAMERA.frame_id))
        assert node.last_error == ""
    finally:
        node.destroy_node()


def test_a_refused_camera_info_and_the_images_it_leaves_unusable_log_once(ros_context, capfd):
    """Seen with ``ros2 topic pub -r 2`` of a camera_info the node refuses and of a mask: each
    camera_info logged its refusal and each image "no usable camera_info: ...", alternating
    for ever (one "last reason" for all streams); now each stream logs once until its reason
    changes, while every refusal still goes to ``outline/errors``.
    """
    from rclpy.parameter import Parameter

    from squeeze_grasp_ros.ros.messages.images import camera_info_msg, image_msg
    from squeeze_grasp_ros.ros.nodes.outline import OutlineNode

    node = OutlineNode(context=ros_context, parameter_overrides=[
        Parameter("camera_pose", value=[0.0, 0.0, 0.5, np.pi, 0.0, 0.0])])
    errors = []
    node.error_pub.publish = errors.append
    empty = np.zeros((CAMERA.height, CAMERA.width), np.uint8)
    try:
        capfd.readouterr()
        for k in range(3):
            info = camera_info_msg(CAMERA, 2 * k)
            info.k[0] = 0.0
            node._info(info)
            node._image(image_msg(empty, ImageEncoding.MONO8, 2 * k + 1, CAMERA.frame_id))
        logged = [line for line in capfd.readouterr().err.splitlines() if "no outline:" in line]
        assert len(errors) == 6 and len(logged) == 2, logged
        assert "camera fx must be a positive focal length" in logged[0]
        assert "no usable camera_info: the newest was refused" in logged[1]
    finally:
        node.destroy_node()


def test_images_after_a_refused_camera_pose_are_refused_until_a_usable_one(ros_context):
    """A camera/pose in another frame (or not a rotation) was refused once, and the images
    after it were read with the last pose, though the camera may have moved; now they are
    refused, naming why, until a usable pose arrives.
    """
    skimage_or_skip()
    from geometry_msgs.msg import PoseStamped
    from rclpy.parameter import Parameter

    from squeeze_grasp_ros.ros import messages
    from squeeze_grasp_ros.ros.messages.images import camera_info_msg, image_msg, pose_of_camera
    from squeeze_grasp_ros.ros.nodes.outline import OutlineNode

    view = pose()
    views = render_views(shapes.rectangle(0.1, 0.1), CAMERA, view, top_height=HEIGHT)
    node = OutlineNode(context=ros_context, parameter_overrides=[
        Parameter("object_height", value=HEIGHT)])
    seen = []
    node.seen_pub.publish = seen.append
    try:
        node._info(camera_info_msg(CAMERA, 1_000))
        moved = PoseStamped(header=messages.header(2_000, "world"), pose=pose_of_camera(view))
        node._pose(PoseStamped(header=messages.header(2_000, "object"),
                               pose=pose_of_camera(view)))
        node._pose(moved)
        node._image(image_msg(views.mask, ImageEncoding.MONO8, 3_000, CAMERA.frame_id))
        assert not seen and node.last_error == (
            "no usable camera pose: the newest was refused (camera/pose is in frame 'world', "
            "not the plane frame 'object')")
        node._pose(PoseStamped(header=messages.header(4_000, "object"),
                               pose=pose_of_camera(view)))
        node._image(image_msg(views.mask, ImageEncoding.MONO8, 5_000, CAMERA.frame_id))
        assert len(seen) == 1 and node.last_error == ""
    finally:
        node.destroy_node()


def test_sensor_qos_reads_a_camera_that_publishes_best_effort(ros_context):
    """A camera driver on sensor-data QoS (best effort) never reached the node: its subscriptions
    were reliable, which no best-effort publisher matches (rclpy warned "offering incompatible
    QoS", and nothing came). With ``sensor_qos:=sensor_data`` its camera_info and images arrive.
    """
    skimage_or_skip()
    import rclpy
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.parameter import Parameter
    from rclpy.qos import ReliabilityPolicy, qos_profile_sensor_data
    from sensor_msgs.msg import CameraInfo, Image
    from std_msgs.msg import String

    from squeeze_grasp_ros.ros.messages.images import camera_info_msg, image_msg
    from squeeze_grasp_ros.ros.nodes.outline import OutlineNode

    node = OutlineNode(context=ros_context, parameter_overrides=[
        Parameter("camera_pose", value=[0.0, 0.0, 0.5, np.pi, 0.0, 0.0]),
        Parameter("sensor_qos", value="sensor_data")])
    client = rclpy.create_node("best_effort_camera", context=ros_context)
    executor = SingleThreadedExecutor(context=ros_context)
    for n in (node, client):
        executor.add_node(n)
    errors: list = []
    client.create_subscription(String, "outline/errors", errors.append, 10)
    images = client.create_publisher(Image, "camera/mask", qos_profile_sensor_data)
    infos = client.create_publisher(CameraInfo, "camera/camera_info", qos_profile_sensor_data)
    try:
        for topic in ("camera/mask", "camera/camera_info"):
            (info,) = node.get_subscriptions_info_by_topic(topic)
            assert info.qos_profile.reliability == ReliabilityPolicy.BEST_EFFORT
        deadline = time.monotonic() + 30
        empty = np.zeros((CAMERA.height, CAMERA.width), np.uint8)
        while not any("no object" in e.data for e in errors):  # read with a camera_info
            assert time.monotonic() < deadline, "the best-effort camera never reached the node"
            infos.publish(camera_info_msg(CAMERA, 1_000))
            images.publish(image_msg(empty, ImageEncoding.MONO8, 2_000, CAMERA.frame_id))
            executor.spin_once(0.05)
        assert node.inputs.camera is not None
    finally:
        executor.shutdown()
        client.destroy_node()
        node.destroy_node()
