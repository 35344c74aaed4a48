# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""An object's outline in metres from a top-down mask or depth image (issue 32, item 2).

The object is the largest blob (:mod:`.blobs`); its boundary is traced to sub-pixel accuracy
by marching squares (``skimage.measure.find_contours``) at an iso-level, each contour point is
undistorted and its ray met with the plane of the object's top face, and the curves are
simplified by Douglas-Peucker (:mod:`.simplify`) to a stated tolerance in metres; corners where
straight stretches meet are rebuilt as the intersection of lines fitted to them (an iso-contour
cuts a corner short). Closed holes become holes of the outline (a ring or annulus-like object).
A circle, an ellipse or a circle with a concentric circular hole that fits the traced points
within :data:`PRIMITIVE_TOLERANCE_PX` is recognised as a ``disk``, ``ellipse`` or ``annulus``
(:mod:`.primitives`). Outlines whose rebuilt corners join straight edges are polygons; the
others are splines (``spline``): a smoothing spline fitted to the trace
(:func:`.simplify.smoothed_curve`), pinned at the real corners (rebuilt, or kinks) of a mixed
outline (straight edges and curved stretches) and at none of a smooth curve; tangent joins of
a straight edge and an arc are no corners. When no smoothing spline fits, a spline through the
simplified vertices with corners where it would stray from the traced points
(:func:`.simplify.spline_corners`).

- **mask** (``mono8``): 0 is background, larger values object; read as coverage (value / 255,
  or / 1 for a 0/1 mask) with the edge at half coverage, so an anti-aliased mask gives edges
  to a small fraction of a pixel and a binary one to about half a pixel. The mask is the
  object's top face at ``object_height_m`` above the plane.
- **depth** (``16UC1`` mm, 0 invalid; ``32FC1`` m, NaN, inf, 0 or negative invalid): the
  support plane is fitted and checked (:mod:`.support`); object pixels stand more than
  ``min_height_m`` above it; the edge is at half the object's median height (a mixed pixel's
  height is its coverage times the top height) and is met with the plane of the top face.

Views that would give a wrong outline are refused with :class:`InvalidInputError` naming the
reason: wrong image size or type, no object, an object touching the border, two blobs of
similar size, invalid depth pixels touching the object, a tilted, shifted or non-planar support.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from squeeze_grasp_ros.mechanics.elastic.shapes import Outline, signed_area, validate_polyline
from squeeze_grasp_ros.mechanics.errors import InvalidInputError
from squeeze_grasp_ros.mechanics.vocabulary import ImageEncoding, ShapeType
from squeeze_grasp_ros.perception.blobs import Blob, BlobChoice, choose_object
from squeeze_grasp_ros.perception.camera import CameraModel, CameraPose
from squeeze_grasp_ros.perception.primitives import Primitive, recognise, sampled, scene_shape
from squeeze_grasp_ros.perception.simplify import (
    KINK_TURN_DEG,
    centred_vertices,
    joined_curve,
    kept_vertices,
    segment_distances,
    sharpen_corners,
    smoothed_curve,
    spline_corners,
    vertex_turns,
)
from squeeze_grasp_ros.perception.support import SupportPlane, fit_support, floor_grids

__all__ = ["DEFAULT_TOLERANCE_PX", "MIN_AREA_PX", "PRIMITIVE_TOLERANCE_PX", "ObjectOutline",
           "extract_outline"]

DEFAULT_TOLERANCE_PX = 0.15
"""Default simplification tolerance, in pixel footprints at the object."""

CORNER_RADIUS_PX = 2.0
"""Traced points closer than this (pixel footprints) to a corner are not used to rebuild it."""

CORNER_SPAN_PX = 8.0
"""Length (pixel footprints) of the straight stretches fitted on each side of a corner."""

CORNER_CUT_PX = 0.6
"""Largest cut (pixel footprints) of a right-angle corner by the traced curve that is rebuilt
(:func:`~.simplify.sharpen_corners` scales it by 1 / sin(alpha / 2) for a corner of angle
alpha): the 0.5 iso-contour of an anti-aliased corner cuts it by about 0.3 px."""

CORNER_STRAIGHT_PX = 0.12
"""How straight (pixel footprints) both stretches must be. Traced straight edges stray up to
0.09 px (marching squares on slanted edges); an arc strays span^2 / (16 R) from its best line,
so only arcs of radius R >= 33 px pass, and those turn far less than 30 degrees between the
two stretches (12 px apart): smooth bends are never made corners."""

STRAIGHT_PX = 1.0
"""An outline with rebuilt corners whose other vertices all lie within this (pixel footprints)
of the segment joining the two corners around them (rebuilt, or kinks turning more than
:data:`~.simplify.KINK_TURN_DEG`: a corner noise kept from being rebuilt) is a polygon
(straight edges: noisy depth strays up to about 1 px); otherwise it has curved stretches and is
a spline with declared corners (a mixed outline: an arc of radius R px between corners strays
R (1 - cos(a / 2)) from its chord, 3.5 px for a quarter circle of 12 px)."""

CENTRE_WINDOW_PX = 2.0
"""Half-length (pixel footprints) of the stretch of traced points a smooth outline's vertex is
the mean of (:func:`~.simplify.centred_vertices`)."""

TRACE_NOISE_PX = 0.05
"""RMS wobble (pixel footprints) of a traced edge the smoothing spline may leave unfitted
(:func:`~.simplify.smoothed_curve`)."""

JOIN_SPACING_PX = 1.0
"""Spacing (pixel footprints) of the samples of a mixed outline's piecewise spline
(:func:`~.simplify.joined_curve`)."""

PRIMITIVE_TOLERANCE_PX = 0.3
"""Largest distance (pixel footprints) of a traced point from a fitted circle or ellipse for
the curve to be recognised as one (:mod:`.primitives`). Anti-aliased masks trace edges within
about 0.1 px; a binary mask's staircase strays about 0.5 px, so its circles stay smooth curves
(``spline``) rather than primitives."""

MIN_AREA_PX = 9
"""Default smallest blob and hole that counts, px (``extract_outline``'s ``min_area_px``)."""

IMAGE_TYPES: dict[ImageEncoding, tuple[type, ...]] = {
    ImageEncoding.MONO8: (np.uint8, np.bool_),
    ImageEncoding.DEPTH_16UC1: (np.uint16,),
    ImageEncoding.DEPTH_32FC1: (np.float32, np.float64),
}
"""Array types accepted for each encoding."""


@dataclass(frozen=True)
class ObjectOutline:
    """The outline of the object seen in one image.

    Attributes
    ----------
    outline : Outline
        Outer curve (counter-clockwise) and holes, plane frame, m.
    frame_id : str
        Name of the plane frame the outline is in.
    encoding : ImageEncoding
        The image it came from.
    plane_height : float
        Height of the top face the contour was met with, m.
    level : float
        Iso-level of the contour: mask value (127.5 for 0-255, 0.5 for 0/1 masks) or height
        above the support, m (depth).
    tolerance_m : float
        Douglas-Peucker tolerance of the simplification, m: every traced contour point lies
        within it of a polygon outline; of a spline outline, within the larger of it and
        :data:`PRIMITIVE_TOLERANCE_PX` pixel footprints (outside :data:`CORNER_RADIUS_PX` of its
        rebuilt corners).
    pixel_size_m : float
        Footprint of one pixel at the object's centroid on its top face, m.
    contour_points : int
        Traced contour points before simplification (all curves).
    blob : Blob
        The object's blob.
    others : tuple of Blob
        Other blobs in view, largest first.
    specks : int
        Blobs too small to count (below ``min_area_px``).
    small_holes : int
        Holes smaller than ``min_area_px`` that were filled.
    undistort_residual_px : float
        Largest reprojection residual of the undistorted contour points, px.
    support : SupportPlane or None
        The fitted support plane (depth images).
    shape : ShapeType
        What the outline was recognised as: ``disk``, ``ellipse`` or ``annulus`` (a primitive
        fitted within :data:`PRIMITIVE_TOLERANCE_PX`; the outline is then the fitted curve), else
        ``polygon`` when rebuilt corners join straight edges or a hole has a rebuilt corner
        (every vertex is kept as a corner) or ``spline`` for curves, its corners (straight
        edges meeting arcs) in ``outline.corners``.
    primitive : Primitive or None
        The fitted primitive (centre, parameters, residual), when one was recognised.
    """

    outline: Outline
    frame_id: str
    encoding: ImageEncoding
    plane_height: float
    level: float
    tolerance_m: float
    pixel_size_m: float
    contour_points: int
    blob: Blob
    others: tuple[Blob, ...]
    specks: int
    small_holes: int
    undistort_residual_px: float
    support: SupportPlane | None = None
    shape: ShapeType = ShapeType.POLYGON
    primitive: Primitive | None = None

    @property
    def smooth(self) -> bool:
        """Whether the outline is no polygon: its vertices sample smooth curves, between its
        declared corners (``outline.corners``, a mixed outline) if it has any.
        """
        return self.shape != ShapeType.POLYGON

    def to_scene_shape(self) -> dict:
        """The outline as a scene's ``object.shape``: the named ``disk``, ``ellipse`` or
        ``annulus`` when a primitive was recognised at the frame's origin (centre within
        :data:`PRIMITIVE_TOLERANCE_PX`, axes along x and y), else ``{"type": "polygon",
        "points": [[x, y], ...]}`` (``"spline"`` when it is :attr:`smooth`), plus ``"holes":
        [[[x, y], ...], ...]`` when it has holes (m).
        """
        if self.primitive is not None:
            named = scene_shape(self.primitive, PRIMITIVE_TOLERANCE_PX * self.pixel_size_m)
            if named is not None:
                return named
        kind = ShapeType.SPLINE if self.smooth else ShapeType.POLYGON
        shape = {"type": kind.value, "points": self.outline.points.tolist()}
        if self.smooth and len(self.outline.corners):
            shape["corners"] = self.outline.corners.tolist()
        if self.outline.holes:
            shape["holes"] = [h.tolist() for h in self.outline.holes]
        return shape

    def to_json(self) -> dict:
        """Every attribute as JSON values, the outline under ``"shape"`` (scene form)."""
        return {"frame_id": self.frame_id, "encoding": str(self.encoding),
                "shape": self.to_scene_shape(), "area_m2": self.outline.area,
                "vertices": len(self.outline.points), "holes": len(self.outline.holes),
                "plane_height": self.plane_height, "level": self.level,
                "tolerance_m": self.tolerance_m, "pixel_size_m": self.pixel_size_m,
                "contour_points": self.contour_points, "blob": self.blob.to_json(),
                "others": [b.to_json() for b in self.others], "specks": self.specks,
                "small_holes": self.small_holes,
                "undistort_residual_px": self.undistort_residual_px,
                "support": None if self.support is None else self.support.to_json(),
                "recognised": self.shape.value,
                "primitive": None if self.primitive is None else self.primitive.to_json()}


def _check_image(image: np.ndarray, encoding: ImageEncoding, camera: CameraModel) -> np.ndarray:
    image = np.asarray(image)
    if image.ndim != 2 or image.shape != camera.shape:
        raise InvalidInputError(f"{encoding} image has shape {image.shape}, the camera's "
                                f"images are {camera.height} x {camera.width} (height x width)")
    if not any(image.dtype == t for t in IMAGE_TYPES[encoding]):
        allowed = "/".join(np.dtype(t).name for t in IMAGE_TYPES[encoding])
        raise InvalidInputError(f"{encoding} image must hold {allowed}, got {image.dtype}")
    return image


def _mask_level(mask: np.ndarray) -> float:
    """The edge's value in a mask: half of full coverage (255 for mono8, 1 for 0/1 masks)."""
    return 0.5 if mask.dtype == np.bool_ or mask.max() <= 1 else 127.5


def _check_mask_values(mask: np.ndarray, level: float) -> None:
    """Refuse a mask whose values never reach the edge ``level`` though some are not 0 (a label
    image such as 0/1/2, or a dim mask): it would read as empty.
    """
    top = int(mask.max())
    if 0 < top < level:
        raise InvalidInputError(
            f"mask: its largest value is {top}, below the edge level {level:g} (half of 255): a "
            "mask holds 0/1 or 0-255 coverage of one object; a label image (0/1/2...), a dim "
            "mask or an object blurred away reads as empty")


def _check_ones(mask: np.ndarray, level: float, object_px: int) -> None:
    """Refuse a 0-255 mask in which pixels of value 1 form a region at least as large as the
    object (``object_px`` px at or above ``level``): a 0/1 mask mixed with 255s (a void label
    around the object, a speck), whose object would be the 255s. An anti-aliased or noisy
    0-255 mask has value 1 only on thin edge bands or scattered pixels.
    """
    from scipy import ndimage

    ones = mask == 1
    if level <= 1 or np.count_nonzero(ones) < object_px:  # one pass; labels only if needed
        return
    labels, count = ndimage.label(ones)
    largest = int(np.bincount(labels.ravel())[1:].max()) if count else 0
    if largest >= object_px:
        raise InvalidInputError(
            f"mask: {largest} px of value 1 form one region, as large as the object would be "
            f"({object_px} px of values >= {level:g}): the mask mixes 0/1 with 255 (a void "
            "label, a speck) and its object would be the 255s; give 0/1 or 0-255 values only")


def _depth_metres(depth: np.ndarray, encoding: ImageEncoding) -> np.ndarray:
    if encoding == ImageEncoding.DEPTH_16UC1:
        metres = depth.astype(np.float32) * np.float32(1e-3)
        metres[depth == 0] = np.nan
        return metres
    return depth.astype(np.float32, copy=False)


def _trace(field: np.ndarray, level: float, choice: BlobChoice, min_area_px: int):
    """Closed sub-pixel contours (u, v in px) of the chosen blob: outer curve first, then the
    holes of at least ``min_area_px``; and the number of smaller holes.
    """
    from skimage.measure import find_contours

    rows, cols = choice.box
    r0, c0 = rows.start - 1, cols.start - 1
    window = (slice(r0, rows.stop + 1), slice(c0, cols.stop + 1))
    crop = np.array(field[window], dtype=float)
    labels = choice.labels[window]
    crop[(labels != 0) & (labels != choice.label)] = 0.0
    crop[~np.isfinite(crop)] = 0.0
    loops = [c[:-1, ::-1] + (c0, r0) for c in find_contours(crop, level) if len(c) > 3]
    if not loops:
        raise InvalidInputError(f"the object's blob ({choice.blob.area_px} px) is too small to "
                                "trace an outline")
    areas = np.array([signed_area(loop) for loop in loops])
    outer = int(np.argmax(np.abs(areas)))
    holes = [k for k in range(len(loops)) if k != outer and abs(areas[k]) >= min_area_px]
    return [loops[outer]] + [loops[k] for k in holes], len(loops) - 1 - len(holes)


def _simplify(points: np.ndarray, tolerance: float, pixel: float, name: str):
    """The simplified vertices of a traced curve (m, counter-clockwise) and which of them are
    rebuilt corners (bool each).
    """
    kept = kept_vertices(points, tolerance)
    vertices, corners = sharpen_corners(
        points, kept, radius=CORNER_RADIUS_PX * pixel, span=CORNER_SPAN_PX * pixel,
        tolerance=CORNER_STRAIGHT_PX * pixel, max_cut=CORNER_CUT_PX * pixel)
    try:
        out = validate_polyline(vertices, name)
    except InvalidInputError as exc:
        raise InvalidInputError(f"{exc}; the simplified {name} is not a simple curve: lower "
                                f"tolerance_m (now {tolerance:g} m)") from None
    if len(out) != len(corners):  # repeated vertices dropped: keep every vertex a corner
        return out, np.ones(len(out), bool)
    return out, (corners[::-1] if signed_area(vertices) < 0 else corners)


def _straight(vertices: np.ndarray, corners: np.ndarray, reach: float) -> bool:
    """Whether the vertices between each two consecutive rebuilt corners lie within ``reach``
    (m) of the segment joining them (straight edges with extra vertices: a polygon).
    """
    start = np.flatnonzero(corners)
    n = len(vertices)
    for a, b in zip(start, np.roll(start, -1)):
        run = vertices[np.arange(a + 1, b + (n if b <= a else 0)) % n]
        ends = np.broadcast_to(vertices[a], run.shape), np.broadcast_to(vertices[b], run.shape)
        if len(run) and segment_distances(run, *ends).max() > reach:
            return False
    return True


def _outline(loops: list[np.ndarray], camera: CameraModel, pose: CameraPose,
             plane_height: float, tolerance_m: float | None, centroid_px: tuple[float, float]):
    """Back-project the traced loops and recognise a primitive in them, or simplify them;
    returns (Outline, shape type, primitive or None, tolerance, pixel size, undistortion
    residual).
    """
    centre = camera.back_project(pose, np.array([centroid_px]), plane_height).points[0]
    pixel = camera.ground_pixel_size(pose, np.array([*centre, plane_height]))
    tolerance = DEFAULT_TOLERANCE_PX * pixel if tolerance_m is None else tolerance_m
    if not (np.isfinite(tolerance) and tolerance > 0):
        raise InvalidInputError(f"tolerance_m must be a positive length in m, got {tolerance_m!r}")
    sizes = [len(loop) for loop in loops]
    plane = camera.back_project(pose, np.concatenate(loops), plane_height)
    metric = np.split(plane.points, np.cumsum(sizes)[:-1])
    primitive = recognise(metric[0], metric[1:], PRIMITIVE_TOLERANCE_PX * pixel)
    if primitive is not None:
        outer, holes = sampled(primitive, tolerance)
        return (Outline(outer, holes), primitive.shape, primitive, tolerance, pixel,
                plane.undistort_residual_px)
    outer, cornered = _simplify(metric[0], tolerance, pixel, "extracted outline")
    simplified = [_simplify(h, tolerance, pixel, f"extracted hole {k + 1}")
                  for k, h in enumerate(metric[1:])]
    holes = tuple(h for h, _ in simplified)
    from matplotlib.path import Path as MplPath  # 0.1-0.2 s to import: only when extracting

    boundary = MplPath(outer)
    for k, hole in enumerate(holes):
        if not np.all(boundary.contains_points(hole)):
            raise InvalidInputError(f"extracted hole {k + 1} crosses the simplified outer curve: "
                                    f"lower tolerance_m (now {tolerance:g} m)")
    kinks = cornered | (np.abs(vertex_turns(outer)) > KINK_TURN_DEG)  # a rounded corner too
    straight = cornered.any() and _straight(outer, kinks, STRAIGHT_PX * pixel)
    if straight or any(c.any() for _, c in simplified):
        return (Outline(outer, holes), ShapeType.POLYGON, None, tolerance, pixel,
                plane.undistort_residual_px)
    reach = max(tolerance, PRIMITIVE_TOLERANCE_PX * pixel)
    smoothed = smoothed_curve(metric[0], outer, kinks, tolerance=reach,
                              spacing=JOIN_SPACING_PX * pixel,
                              clearance=CORNER_RADIUS_PX * pixel, noise=TRACE_NOISE_PX * pixel)
    if smoothed is not None:
        fitted_holes = [smoothed_curve(t, h, np.zeros(len(h), bool), tolerance=reach,
                                       spacing=JOIN_SPACING_PX * pixel, clearance=0.0,
                                       noise=TRACE_NOISE_PX * pixel)
                        for t, h in zip(metric[1:], holes)]
        holes = tuple(h if f is None else f[0] for h, f in zip(holes, fitted_holes))
        return (Outline(smoothed[0], holes, smoothed[1]), ShapeType.SPLINE, None, tolerance,
                pixel, plane.undistort_residual_px)
    window = CENTRE_WINDOW_PX * pixel
    outer = centred_vertices(metric[0], outer, cornered, window=window)
    holes = tuple(centred_vertices(t, h, np.zeros(len(h), bool), window=window)
                  for t, h in zip(metric[1:], holes))
    corners = spline_corners(metric[0], outer, cornered,
                             tolerance=max(tolerance, PRIMITIVE_TOLERANCE_PX * pixel),
                             radius=CORNER_RADIUS_PX * pixel)
    if corners.all():
        return (Outline(outer, holes, np.arange(len(outer))), ShapeType.POLYGON, None,
                tolerance, pixel, plane.undistort_residual_px)
    if corners.any():
        outer, at = joined_curve(outer, corners, spacing=JOIN_SPACING_PX * pixel)
    else:
        at = np.zeros(0, int)
    return (Outline(outer, holes, at), ShapeType.SPLINE, None, tolerance, pixel,
            plane.undistort_residual_px)


def _positive(**values: float) -> None:
    for name, value in values.items():
        if not (np.isfinite(value) and value > 0):
            raise InvalidInputError(f"{name} must be finite and positive, got {value!r}")


def extract_outline(image: np.ndarray, encoding: ImageEncoding | str, camera: CameraModel,
                    pose: CameraPose, *, tolerance_m: float | None = None,
                    object_height_m: float = 0.0, min_height_m: float = 0.004,
                    plane_tolerance_m: float = 0.002, max_tilt_deg: float = 2.0,
                    min_area_px: int = MIN_AREA_PX, ambiguous_ratio: float = 0.8,
                    frame_id: str = "plane") -> ObjectOutline:
    """The object's outline from a top-down mask or depth image.

    Parameters
    ----------
    image : (H, W) ndarray
        ``mono8`` mask (uint8 or bool), ``16UC1`` depth (uint16, mm) or ``32FC1`` depth
        (float32, m), of the camera's size.
    encoding : ImageEncoding or str
        Its ``sensor_msgs/Image`` encoding.
    camera, pose : CameraModel, CameraPose
        Intrinsics and the camera's pose in the plane frame.
    tolerance_m : float, optional
        Douglas-Peucker tolerance of the simplification, m (default:
        :data:`DEFAULT_TOLERANCE_PX` of the pixel footprint at the object).
    object_height_m : float
        Mask only: height of the object's top face above the plane (its thickness), m.
    min_height_m : float
        Depth only: a pixel higher than this above the support belongs to an object, m.
    plane_tolerance_m : float
        Depth only: largest offset and unevenness of the support against the declared plane, m.
    max_tilt_deg : float
        Depth only: largest tilt of the support against the declared plane, deg.
    min_area_px : int
        Blobs and holes smaller than this (px) are ignored (counted in ``specks`` and
        ``small_holes``).
    ambiguous_ratio : float
        Refuse the view when another blob has at least this fraction of the object's area.
    frame_id : str
        Name of the plane frame (reported with the outline).

    Raises
    ------
    InvalidInputError
        For a bad view or option (the message says which and why).
    """
    try:
        encoding = ImageEncoding(encoding)
    except ValueError:
        raise InvalidInputError(f"encoding must be one of {list(ImageEncoding.values())}, got "
                                f"{encoding!r}") from None
    _positive(min_height_m=min_height_m, plane_tolerance_m=plane_tolerance_m,
              max_tilt_deg=max_tilt_deg, min_area_px=min_area_px)
    if not 0 < ambiguous_ratio <= 1:
        raise InvalidInputError(f"ambiguous_ratio must be in (0, 1], got {ambiguous_ratio!r}")
    if not (np.isfinite(object_height_m) and 0 <= object_height_m < pose.position[2]):
        raise InvalidInputError(f"object_height_m must be >= 0 and below the camera "
                                f"({pose.position[2]:g} m), got {object_height_m!r}")
    image = _check_image(image, encoding, camera)
    what = "mask" if encoding == ImageEncoding.MONO8 else "depth image"
    support = None
    if encoding == ImageEncoding.MONO8:
        field, level, plane_height = image, _mask_level(image), object_height_m
        _check_mask_values(image, level)
        choice = choose_object(field >= level, min_area_px=min_area_px,
                               ambiguous_ratio=ambiguous_ratio, what=what)
        _check_ones(image, level, choice.blob.area_px)
    else:
        depth = _depth_metres(image, encoding)
        valid = np.isfinite(depth) & (depth > 0)
        gz, fx, fy = floor_grids(camera, pose)
        heights = pose.position[2] + depth * gz
        support = fit_support(heights, valid, camera, pose, tolerance_m=plane_tolerance_m,
                              min_height_m=min_height_m, max_tilt_deg=max_tilt_deg)
        field = heights - support.height_at(fx, fy)
        choice = choose_object(valid & (field > min_height_m), min_area_px=min_area_px,
                               ambiguous_ratio=ambiguous_ratio, what=what)
        _check_invalid_near(valid, choice)
        top = _top_height(field, choice)
        level = max(min_height_m, 0.5 * top)
        u, v = choice.blob.centroid_px
        under = support.height_at(fx[int(round(v)), int(round(u))], fy[int(round(v)),
                                                                         int(round(u))])
        plane_height = float(under) + top
    loops, small = _trace(field, level, choice, min_area_px)
    outline, shape, primitive, tolerance, pixel, residual = _outline(
        loops, camera, pose, plane_height, tolerance_m, choice.blob.centroid_px)
    return ObjectOutline(outline, frame_id, encoding, plane_height, level, tolerance, pixel,
                         sum(map(len, loops)), choice.blob, choice.others, choice.specks, small,
                         residual, support, shape, primitive)


def _top_height(field: np.ndarray, choice: BlobChoice) -> float:
    """The object's top height above the support, m: the median over its pixels one pixel
    inside the edge (the edge's mixed pixels would pull a thin wall's median down), or over all
    its pixels when it is too thin to keep ten.
    """
    from scipy import ndimage

    blob = choice.labels[choice.box] == choice.label
    inner = ndimage.binary_erosion(blob)
    heights = field[choice.box][inner if inner.sum() >= 10 else blob]
    return float(np.median(heights))


def _check_invalid_near(valid: np.ndarray, choice: BlobChoice) -> None:
    """Refuse invalid depth pixels inside or next to the object (its outline is unknown
    there).
    """
    from scipy import ndimage

    rows, cols = choice.box
    window = (slice(rows.start - 1, rows.stop + 1), slice(cols.start - 1, cols.stop + 1))
    near = ndimage.binary_dilation(choice.labels[window] == choice.label, iterations=2)
    bad = near & ~valid[window]
    if bad.any():
        r, c = np.argwhere(bad)[0]
        raise InvalidInputError(
            f"depth image: {int(bad.sum())} invalid pixels (NaN, inf, 0 or negative) inside or "
            f"next to the object (first at row {r + window[0].start}, column "
            f"{c + window[1].start}): its outline there is unknown")
