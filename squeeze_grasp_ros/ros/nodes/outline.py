# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The outline node: a top-down camera's mask or depth image -> the object's outline.

Run it with ``ros2 run squeeze_grasp_ros outline --ros-args -p camera_pose:="[0.0, 0.0, 0.5,
3.14159265, 0.0, 0.0]" -p object_height:=0.0254``. It subscribes to

- ``camera/mask`` (parameter ``image_topic``): ``sensor_msgs/Image``, ``mono8`` mask (``8UC1``
  read as ``mono8``), or a ``16UC1``/``32FC1`` depth image (the encoding decides);
- ``camera/camera_info``: ``sensor_msgs/CameraInfo`` (pinhole, plumb-bob), the newest one is
  used for each image (both reliable; ``sensor_qos:=sensor_data`` reads a camera driver that
  publishes them best effort, which a reliable subscription never matches);
- ``camera/pose`` (latched ``geometry_msgs/PoseStamped``, optional): the camera's optical
  frame in the plane frame; it replaces the ``camera_pose`` parameter once it arrives, and its
  ``header.frame_id`` must be the node's ``frame_id``: after a refused one, images are refused
  until a usable one arrives (the camera may have moved).

For each image it runs :func:`~squeeze_grasp_ros.perception.extract.extract_outline` and
publishes ``outline/outline`` (``geometry_msgs/PolygonStamped``: the outer boundary, m, in
``frame_id``, z at the top face; what RViz and Foxglove draw) and ``outline/seen``
(``SeenOutline``: the same with the holes, area, tolerance and pixel size; what a client
passes on to ``load_object``). A view that would give a wrong outline (no object, an object
cut by the border, two similar blobs, a tilted support, NaNs next to the object, a wrong
image size, an image whose ``header.frame_id`` is not its camera_info's) publishes nothing on
those topics: its reason goes to ``outline/errors``
(``std_msgs/String``, stamped in the text) and to the log (once until the reason changes).
"""
from __future__ import annotations

import sys
from typing import Any

from geometry_msgs.msg import PolygonStamped, PoseStamped
from rclpy.node import Node
from sensor_msgs.msg import CameraInfo, Image
from std_msgs.msg import String

from squeeze_grasp_interfaces.msg import SeenOutline
from squeeze_grasp_ros.mechanics.errors import InvalidInputError, NumericalError
from squeeze_grasp_ros.perception.camera import CameraPose
from squeeze_grasp_ros.perception.extract import extract_outline
from squeeze_grasp_ros.ros import messages
from squeeze_grasp_ros.ros.messages.images import image_array
from squeeze_grasp_ros.ros.nodes import ParameterError, pipeline, run_node
from squeeze_grasp_ros.ros.nodes.camera_inputs import CameraInputs

PARAMETERS: dict[str, tuple[Any, str]] = {
    "image_topic": (pipeline.CAMERA_MASK,
                    "image to read: mono8 (or 8UC1) mask, 16UC1 or 32FC1 depth"),
    "camera_pose": ([0.0] * 6, "camera optical frame in the plane frame: x y z roll pitch yaw "
                               "(m, rad) or x y z qx qy qz qw; all zeros = wait for "
                               "camera/pose"),
    "frame_id": (pipeline.FRAME, "plane frame: the outline's frame (z = 0 on the support)"),
    "object_height": (0.0, "mask: height of the object's top face above the plane, m"),
    "tolerance": (0.0, "simplification tolerance, m (0: 0.15 pixel footprints)"),
    "min_height": (0.004, "depth: a pixel this far above the support is object, m"),
    "plane_tolerance": (0.002, "depth: largest offset and unevenness of the support, m"),
    "max_tilt_deg": (2.0, "depth: largest tilt of the support, deg"),
    "min_area_px": (9, "blobs and holes smaller than this are ignored, px"),
    "ambiguous_ratio": (0.8, "refuse a view whose second blob has this fraction of the "
                             "object's area"),
    "qos_depth": (10, "history depth of the image and outline topics"),
    "sensor_qos": ("reliable", "QoS of the image and camera_info subscriptions: reliable, or "
                               "sensor_data (best effort, depth 5) for a camera driver that "
                               "publishes them best effort"),
}
"""Parameter name -> (typed default, description)."""
BOUNDS = {"object_height": pipeline.Bound(0.0, unit="m"),
          "tolerance": pipeline.Bound(0.0, unit="m"),
          "min_height": pipeline.Bound(0.0, above=True, unit="m"),
          "plane_tolerance": pipeline.Bound(0.0, above=True, unit="m"),
          "max_tilt_deg": pipeline.Bound(0.0, 90.0, above=True, unit="deg"),
          "min_area_px": pipeline.Bound(1),
          "ambiguous_ratio": pipeline.Bound(0.0, 1.0, above=True),
          "qos_depth": pipeline.Bound(1)}
"""The range of each numeric parameter (those of :func:`~.extract.extract_outline` as it
checks them)."""


def pose_parameter(values: list[float]) -> CameraPose | None:
    """The ``camera_pose`` parameter as a pose; None when all zeros (wait for the topic)."""
    if not any(values):
        return None
    try:
        if len(values) == 6:
            return CameraPose.from_xyz_rpy(*values)
        if len(values) == 7:
            return CameraPose.from_xyz_quaternion(*values)
    except InvalidInputError as error:
        raise ParameterError(f"parameter camera_pose: {error}") from None
    raise ParameterError(f"parameter camera_pose takes 6 numbers (x y z roll pitch yaw) or 7 "
                         f"(x y z qx qy qz qw), got {len(values)}")


class OutlineNode(Node):
    """Outline extraction on a camera stream."""

    def __init__(self, **kwargs: Any) -> None:
        super().__init__("outline", **kwargs)
        self.p = p = pipeline.declare(self, PARAMETERS, bounds=BOUNDS)
        self.inputs = CameraInputs(p["frame_id"], pose_parameter(list(p["camera_pose"])),
                                   "parameter camera_pose or camera/pose")
        self.last_error = ""
        self.logged: dict[str, str] = {}
        """Stream (``camera_info``, ``camera/pose``, ``image``) -> the reason last logged for
        it: each stream's refusals are logged once until they change. With one "last reason"
        for all, a refused camera_info and the images it left unusable alternated, and every
        message logged a line."""
        depth = p["qos_depth"]
        # a reliable reader never matches a best-effort writer (a camera driver on sensor-data
        # QoS): before this parameter, such a camera's images never reached the node
        camera = pipeline.sensor_qos(p["sensor_qos"], depth)
        self.create_subscription(Image, pipeline.check_topic("image_topic", p["image_topic"]),
                                 self._image, camera)
        self.create_subscription(CameraInfo, pipeline.CAMERA_INFO, self._info, camera)
        self.create_subscription(PoseStamped, pipeline.CAMERA_POSE, self._pose, pipeline.LATCHED)
        self.outline_pub = self.create_publisher(PolygonStamped, pipeline.OUTLINE, depth)
        self.seen_pub = self.create_publisher(SeenOutline, pipeline.SEEN_OUTLINE, depth)
        self.error_pub = self.create_publisher(String, pipeline.OUTLINE_ERRORS, depth)

    def ready_summary(self) -> str:
        """What the ready line says: the image topic, the pose source and the frame."""
        known = self.inputs.pose
        pose = ("camera/pose" if known is None
                else f"camera at {', '.join(f'{v:g}' for v in known.position)} m")
        return f"{self.p['image_topic']}, {pose}, frame {self.p['frame_id']}"

    def _info(self, msg: CameraInfo) -> None:
        if reason := self.inputs.take_info(msg):
            self._refuse(msg.header.stamp, reason, stream="camera_info")
        else:
            self.logged.pop("camera_info", None)

    def _pose(self, msg: PoseStamped) -> None:
        if reason := self.inputs.take_pose(msg):  # the camera may have moved: no outline
            self._refuse(msg.header.stamp, reason, stream="camera/pose")  # until a usable pose
        else:
            self.logged.pop("camera/pose", None)

    def _image(self, msg: Image) -> None:
        if reason := self.inputs.image_problem(msg):
            self._refuse(msg.header.stamp, reason)
            return
        p = self.p
        try:
            pixels, encoding = image_array(msg)
            seen = extract_outline(
                pixels, encoding, self.inputs.camera, self.inputs.pose,
                tolerance_m=p["tolerance"] or None, object_height_m=p["object_height"],
                min_height_m=p["min_height"],
                plane_tolerance_m=p["plane_tolerance"], max_tilt_deg=p["max_tilt_deg"],
                min_area_px=p["min_area_px"], ambiguous_ratio=p["ambiguous_ratio"],
                frame_id=p["frame_id"])
        except (InvalidInputError, NumericalError) as error:  # e.g. undistortion diverged
            self._refuse(msg.header.stamp, str(error))
            return
        self.last_error = ""
        self.logged.pop("image", None)
        out = messages.seen_outline_msg(
            seen.outline, frame_id=seen.frame_id, ns=messages.stamp_ns(msg.header.stamp),
            encoding=seen.encoding, plane_height=seen.plane_height,
            tolerance=seen.tolerance_m, pixel_size=seen.pixel_size_m,
            other_blobs=len(seen.others), shape=seen.shape.value,
            fit_residual=0.0 if seen.primitive is None else seen.primitive.residual_m)
        self.outline_pub.publish(out.outline)
        self.seen_pub.publish(out)

    def _refuse(self, stamp: Any, reason: str, *, stream: str = "image") -> None:
        """Publish ``reason`` on outline/errors; log it when it differs from the last one
        logged for ``stream`` (:attr:`logged`).
        """
        ns = messages.stamp_ns(stamp)
        self.error_pub.publish(String(data=f"{ns * 1e-9:.6f} s: {reason}"))
        self.last_error = reason
        if self.logged.get(stream) != reason:
            self.get_logger().warning(f"no outline: {reason}")
            self.logged[stream] = reason


def main(args: list[str] | None = None) -> int:
    """Run the outline node until Ctrl-C or shutdown; return the exit code."""
    return run_node(OutlineNode, args)


if __name__ == "__main__":
    sys.exit(main())
