# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The simulated camera's images: an object's top face, anti-aliased, as mask and depth.

The object is a prism standing on the support plane: its outline (outer curve and holes, in the
plane frame, m) extruded to ``top_height``. The camera sees its top face over the plane; the
side walls are not drawn (the mask is the top face, as :func:`~.extract.extract_outline` reads
it; with a camera straight above they would show only at boundary parts facing the camera's
foot point, e.g. inside holes, about f h r / z^2 px wide at distance r from it).

Anti-aliasing is exact: each pixel's value is the area fraction of its square covered by the
projected face, accumulated edge by edge (the signed-area scan used by font rasterisers), with
edges split at every pixel boundary. A depth pixel mixes the two surfaces by that fraction
(a time-of-flight "mixed pixel"), so the height above the plane is coverage x top height
exactly.

>>> from squeeze_grasp_ros.mechanics.elastic.shapes import rectangle
>>> from squeeze_grasp_ros.perception.camera import CameraModel, CameraPose
>>> camera = CameraModel(64, 48, fx=100.0, fy=100.0, cx=31.5, cy=23.5)
>>> views = render_views(rectangle(0.1, 0.08), camera, CameraPose.looking_down(0.5),
...                      top_height=0.0)
>>> print(f"{views.coverage.sum():.6f}")  # 20 x 16 px of area
320.000000
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from squeeze_grasp_ros.mechanics.elastic.mesh import vertex_normals
from squeeze_grasp_ros.mechanics.elastic.shapes import Outline, signed_area, validate_polyline
from squeeze_grasp_ros.mechanics.errors import InvalidInputError
from squeeze_grasp_ros.perception.camera import CameraModel, CameraPose

__all__ = ["CameraViews", "coverage", "render_views", "ring_band"]

MAX_EDGE_PX = 0.5
"""Longest projected edge (px) drawn straight when the camera has distortion."""
MAX_16UC1_M = 65.5355
"""Largest depth (m) that rounds to a 16UC1 pixel (65,535 mm): :meth:`CameraViews.depth_mm`
writes 0, invalid, from here on."""
MAX_NOISE = {"depth_noise_m": 0.1, "mask_noise": 1.0}
"""Largest noise :func:`render_views` draws, as a scene's ``camera`` section allows it: a
depth noise in m, a mask noise as a fraction of full scale. Beyond, the image is noise alone
(a depth noise of 1e308 m overflowed to an all-inf depth image, all 0 as a 16UC1 PNG)."""


@dataclass(frozen=True)
class CameraViews:
    """One simulated camera frame.

    Attributes
    ----------
    coverage : (H, W) ndarray of float
        Area fraction of each pixel covered by the top face, before noise (ground truth).
    mask : (H, W) ndarray of uint8
        ``mono8`` mask: round(255 x coverage), with blur and mask noise applied.
    depth : (H, W) ndarray of float32
        ``32FC1`` depth, m (the optical-axis z of the surface), with blur and depth noise.
    camera : CameraModel
    pose : CameraPose
    """

    coverage: np.ndarray
    mask: np.ndarray
    depth: np.ndarray
    camera: CameraModel
    pose: CameraPose

    def depth_mm(self) -> np.ndarray:
        """The depth as ``16UC1`` (uint16, mm, rounded; 0 where it would not fit: at
        :data:`MAX_16UC1_M` and beyond).
        """
        mm = np.rint(self.depth * 1000.0)
        return np.where((mm > 0) & (mm < 65536), mm, 0).astype(np.uint16)


def _pieces(x0: np.ndarray, y0: np.ndarray, x1: np.ndarray, y1: np.ndarray):
    """Split directed edges at every integer x and y; return the pieces' end points."""
    params = [np.zeros(len(x0)), np.ones(len(x0))]
    owners = [np.arange(len(x0)), np.arange(len(x0))]
    for a, b in ((x0, x1), (y0, y1)):
        lo, hi = np.ceil(np.minimum(a, b)), np.floor(np.maximum(a, b))
        counts = np.maximum(hi - lo + 1, 0).astype(int)
        edge = np.repeat(np.arange(len(a)), counts)
        k = lo[edge] + np.arange(counts.sum()) - np.repeat(np.cumsum(counts) - counts, counts)
        with np.errstate(divide="ignore", invalid="ignore"):
            t = (k - a[edge]) / (b[edge] - a[edge])
        keep = np.isfinite(t)
        params.append(np.clip(t[keep], 0.0, 1.0))
        owners.append(edge[keep])
    t, owner = np.concatenate(params), np.concatenate(owners)
    order = np.lexsort((t, owner))
    t, owner = t[order], owner[order]
    same = owner[1:] == owner[:-1]
    e, ta, tb = owner[:-1][same], t[:-1][same], t[1:][same]
    dx, dy = x1[e] - x0[e], y1[e] - y0[e]
    return x0[e] + ta * dx, y0[e] + ta * dy, x0[e] + tb * dx, y0[e] + tb * dy


def coverage(loops: list[np.ndarray], shape: tuple[int, int]) -> np.ndarray:
    """Exact area coverage (H, W) of the region bounded by closed pixel-coordinate ``loops``.

    Parameters
    ----------
    loops : list of (n, 2) ndarray
        Closed polylines (u, v) in px (pixel centres at integers); the outer curve and its holes
        in opposite orientations (the region is where their winding numbers sum to +-1).
    shape : (H, W)

    Returns
    -------
    (H, W) ndarray
        Covered fraction of each pixel's unit square, in [0, 1].
    """
    H, W = shape
    p = [np.asarray(loop, float) + 0.5 for loop in loops]  # pixel squares on integer grid
    start = np.concatenate(p)
    end = np.concatenate([np.roll(loop, -1, axis=0) for loop in p])
    xa, ya, xb, yb = _pieces(start[:, 0], start[:, 1], end[:, 0], end[:, 1])
    dy = yb - ya
    row = np.floor(0.5 * (ya + yb)).astype(int)
    col = np.floor(0.5 * (xa + xb)).astype(int)
    inside = (row >= 0) & (row < H) & (dy != 0)
    row, col, dy, xm = row[inside], col[inside], dy[inside], 0.5 * (xa + xb)[inside]
    here = (col >= 0) & (col < W)
    area = np.bincount(row[here] * (W + 1) + col[here], weights=dy[here] * (col[here] + 1
                                                                              - xm[here]),
                       minlength=H * (W + 1))
    right = np.clip(col + 1, 0, W)
    carry = np.bincount(row * (W + 1) + right, weights=dy, minlength=H * (W + 1))
    total = area.reshape(H, W + 1) + np.cumsum(carry.reshape(H, W + 1), axis=1)
    return np.clip(np.abs(total[:, :W]), 0.0, 1.0)


def ring_band(middle: Outline, wall: float) -> Outline:
    """The band a ring object occupies: its middle curve offset by half the in-plane ``wall``
    thickness (m) to both sides, as an outline with one hole.

    Raises
    ------
    InvalidInputError
        When the inner offset folds (the wall is thicker than the middle curve's tightest
        curvature allows).
    """
    p = np.asarray(middle.points, float)
    p = p if signed_area(p) > 0 else p[::-1]
    normals = vertex_normals(p)
    outer = _untangled(p + 0.5 * wall * normals, p, wall)
    inner = _untangled(p - 0.5 * wall * normals, p, wall)
    return Outline(outer, (inner,))


def _untangled(offset: np.ndarray, middle: np.ndarray, wall: float) -> np.ndarray:
    """``offset`` with the small loops cut out that it forms where the middle curve bends more
    tightly than half the wall (a cusp, such as a heart's): each run of edges that turned back
    against the middle curve is replaced by the crossing of the edges just around it.

    Raises
    ------
    InvalidInputError
        When a fold cannot be cut this way (the wall is too thick for the curve).
    """
    n = len(offset)
    along = np.einsum("ij,ij->i", np.roll(middle, -1, axis=0) - middle,
                      np.roll(offset, -1, axis=0) - offset)
    if np.mean(along <= 0) > 0.25:
        raise InvalidInputError(f"ring_band: wall {wall:g} m is too thick for the middle curve "
                                "(its offset turns back along a quarter of it)")
    drop = np.zeros(n, bool)
    for start in np.flatnonzero((along <= 0) & (np.roll(along, 1) > 0)):
        end = start
        while along[end % n] <= 0 and end - start < n:
            end += 1
        reach = max(8, n // 8)  # the edges around the run: all pairs, the tightest loop kept
        i = (start - 1 - np.arange(reach))[:, None] % n
        j = (end + np.arange(reach))[None, :] % n
        a0, da = offset[i], offset[(i + 1) % n] - offset[i]
        b0, db = offset[j], offset[(j + 1) % n] - offset[j]
        det = da[..., 0] * db[..., 1] - da[..., 1] * db[..., 0]
        w = b0 - a0
        with np.errstate(divide="ignore", invalid="ignore"):
            t = (w[..., 0] * db[..., 1] - w[..., 1] * db[..., 0]) / det
            u = (w[..., 0] * da[..., 1] - w[..., 1] * da[..., 0]) / det
        crossing = (t >= 0) & (t <= 1) & (u >= 0) & (u <= 1)
        if not crossing.any():
            raise InvalidInputError(f"ring_band: wall {wall:g} m is too thick for the middle "
                                    "curve (its offset folds)")
        ki, kj = np.unravel_index(np.argmin(np.where(crossing, np.add.outer(
            np.arange(reach), np.arange(reach)), 2 * reach)), crossing.shape)
        first, last = int(i[ki, 0]), int(j[0, kj])
        cut = np.arange(first + 1, last + 1 + (n if last < first else 0)) % n
        offset = offset.copy()
        offset[cut[0]] = a0[ki, 0] + t[ki, kj] * da[ki, 0]
        drop[cut[1:]] = True
    result = offset[~drop]
    try:
        return validate_polyline(result, "ring band")
    except InvalidInputError:
        raise InvalidInputError(f"ring_band: wall {wall:g} m is too thick for the middle curve "
                                "(its offset crosses itself)") from None


VIEW_MARGIN = 0.05
"""Margin of the box a loop is clipped to, as a fraction of the image's extent in normalised
coordinates (plus :data:`MAX_EDGE_PX` pixels): the box holds every pixel's square."""


def _view_box(camera: CameraModel) -> tuple[np.ndarray, np.ndarray]:
    """Lower and upper corners of a box in normalised coordinates (x/z, y/z) that holds the
    whole image with a margin (:data:`VIEW_MARGIN`).
    """
    grid = camera.pixel_grid
    lo, hi = grid.min(axis=(0, 1)), grid.max(axis=(0, 1))
    pad = VIEW_MARGIN * (hi - lo) + MAX_EDGE_PX / np.array([camera.fx, camera.fy])
    return lo - pad, hi + pad


def _clipped(loop: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """A closed loop (n, 2) clipped to the box [lo, hi] (Sutherland-Hodgman, one side at a
    time): the same region inside the box, its part outside replaced by stretches of the box's
    sides (empty when the loop lies wholly outside).
    """
    for axis, bound, sign in ((0, lo[0], 1.0), (0, hi[0], -1.0), (1, lo[1], 1.0),
                              (1, hi[1], -1.0)):
        if not len(loop):
            break
        side = sign * (loop[:, axis] - bound)  # >= 0 inside
        after = np.roll(side, -1)
        inside, cross = side >= 0, (side >= 0) != (after >= 0)
        with np.errstate(divide="ignore", invalid="ignore"):
            t = np.where(cross, side / (side - after), 0.0)
        meet = loop + t[:, None] * (np.roll(loop, -1, axis=0) - loop)
        loop = np.stack([loop, meet], axis=1)[np.stack([inside, cross], axis=1)]
    return loop


def _densify(points: np.ndarray, camera: CameraModel, pose: CameraPose,
             height: float) -> np.ndarray:
    """Pixels of a closed plane-frame loop at ``height``, its edges split so that none is
    longer than :data:`MAX_EDGE_PX` in the image when the camera distorts. A loop that reaches
    beyond the image's box (:func:`_view_box`) is first clipped to it in normalised
    coordinates, where the plane's straight edges stay straight: the image is the same, and
    far points never meet the distortion polynomial outside its calibrated field (its values
    there overflowed, or folded back into the image).
    """
    xyz = np.column_stack([points, np.full(len(points), height)])
    p = (xyz - pose.position) @ pose.matrix
    if not np.all(p[:, 2] > 0):
        raise InvalidInputError("render_views: a point of the object lies behind the camera "
                                "(the camera pose looks away from it)")
    lo, hi = _view_box(camera)
    ab = p[:, :2] / p[:, 2:3]
    if np.any((ab < lo) | (ab > hi)):
        ab = _clipped(ab, lo, hi)
        return _split(ab, camera) if len(ab) else np.zeros((0, 2))
    uv = camera.project(pose, xyz)
    if not any(camera.distortion):
        return uv
    edge, s = _subdivision(uv)
    nxt = np.roll(xyz, -1, axis=0)
    return camera.project(pose, xyz[edge] + s[:, None] * (nxt[edge] - xyz[edge]))


def _split(ab: np.ndarray, camera: CameraModel) -> np.ndarray:
    """Pixels of a closed loop of normalised coordinates (n, 2), its edges split so that none
    is longer than :data:`MAX_EDGE_PX` in the image when the camera distorts.
    """
    uv = camera.distort(ab)
    if not any(camera.distortion):
        return uv
    edge, s = _subdivision(uv)
    nxt = np.roll(ab, -1, axis=0)
    return camera.distort(ab[edge] + s[:, None] * (nxt[edge] - ab[edge]))


def _subdivision(uv: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The edge index and the parameter in [0, 1) along it of the points that split each edge
    of the closed pixel loop ``uv`` (n, 2) into pieces of at most :data:`MAX_EDGE_PX`.
    """
    length = np.linalg.norm(np.roll(uv, -1, axis=0) - uv, axis=1)
    parts = np.maximum(np.ceil(length / MAX_EDGE_PX).astype(int), 1)
    edge = np.repeat(np.arange(len(uv)), parts)
    start = np.repeat(np.cumsum(parts) - parts, parts)
    return edge, (np.arange(parts.sum()) - start) / parts[edge]


def render_views(outline: Outline, camera: CameraModel, pose: CameraPose, *,
                 top_height: float, blur_px: float = 0.0, depth_noise_m: float = 0.0,
                 mask_noise: float = 0.0, seed: int = 0) -> CameraViews:
    """Render the top face of ``outline`` (plane frame, m) at ``top_height`` into a mask and a
    depth image.

    Parameters
    ----------
    outline : Outline
        The object's outline in the plane frame (e.g. a deformed boundary), m; holes included.
    camera, pose : CameraModel, CameraPose
    top_height : float
        Height of the top face above the plane (the object's thickness), m, >= 0.
    blur_px : float
        Standard deviation of a Gaussian blur of the coverage (defocus), px, in [0, the image's
        larger side] (a wider blur flattens the whole image; its kernel would not fit memory).
    depth_noise_m : float
        Standard deviation of Gaussian noise added to each depth pixel, m, in [0, 0.1]
        (:data:`MAX_NOISE`).
    mask_noise : float
        Standard deviation of Gaussian noise added to the coverage before it is quantised into
        the mask (fraction of full scale), in [0, 1].
    seed : int
        Seed of the noise draws, an integer >= 0.

    Raises
    ------
    InvalidInputError
        For a negative option or seed, a noise above :data:`MAX_NOISE`, a blur wider than the
        image, a top face at or above the camera, or a view in which some pixel does not see the
        plane.
    """
    from scipy.ndimage import gaussian_filter

    for name, value in (("top_height", top_height), ("blur_px", blur_px),
                        ("depth_noise_m", depth_noise_m), ("mask_noise", mask_noise)):
        if not (np.isfinite(value) and value >= 0):
            raise InvalidInputError(f"render_views: {name} must be a finite number >= 0, got "
                                    f"{value!r}")
        if value > MAX_NOISE.get(name, np.inf):
            raise InvalidInputError(f"render_views: {name} must be in [0, {MAX_NOISE[name]:g}], "
                                    f"got {value:g}")
    if blur_px > max(camera.shape):
        raise InvalidInputError(f"render_views: blur_px must be at most the image's larger side "
                                f"({max(camera.shape)} px), got {blur_px!r}")
    if isinstance(seed, bool) or not isinstance(seed, int | np.integer) or seed < 0:
        raise InvalidInputError(f"render_views: seed must be an integer >= 0, got {seed!r}")
    if not top_height < pose.position[2]:
        raise InvalidInputError(f"render_views: top_height {top_height:g} m is not below the "
                                f"camera (z = {pose.position[2]:g} m)")
    loops = []
    for k, loop in enumerate((outline.points, *outline.holes)):
        loop = np.asarray(loop, float)
        ccw = signed_area(loop) > 0
        loop = loop if ccw == (k == 0) else loop[::-1]  # outer counter-clockwise, holes not
        loops.append(_densify(loop, camera, pose, top_height))
    truth = coverage(loops, camera.shape)
    seen = gaussian_filter(truth, blur_px, mode="constant") if blur_px > 0 else truth
    rng = np.random.default_rng(seed)
    noisy = seen + mask_noise * rng.standard_normal(seen.shape) if mask_noise > 0 else seen
    mask = np.rint(255.0 * np.clip(noisy, 0.0, 1.0)).astype(np.uint8)
    rays_z = camera.ray_grid(pose, 2)
    if not np.all(rays_z < 0):
        raise InvalidInputError("render_views: some pixels do not see the plane (horizon in "
                                "view); tilt the camera down")
    t_z = pose.position[2]
    depth = (-t_z + seen * top_height) / rays_z  # optical z of the mixed surface
    if depth_noise_m > 0:
        depth = depth + depth_noise_m * rng.standard_normal(depth.shape)
    return CameraViews(truth, mask, depth.astype(np.float32), camera, pose)
