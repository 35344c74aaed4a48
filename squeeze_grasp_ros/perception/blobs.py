# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Which connected region of an image is the object: the largest blob, the others reported.

Blobs are 4-connected (two pixels that touch only at a corner are apart), as the marching
squares of :mod:`skimage.measure` separate them at the iso-level. A view is refused, with the
reason, when the object is cut by the image border or when another blob is nearly as large.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from squeeze_grasp_ros.mechanics.errors import InvalidInputError

__all__ = ["Blob", "BlobChoice", "choose_object"]


@dataclass(frozen=True)
class Blob:
    """A connected region of object pixels.

    Attributes
    ----------
    area_px : int
        Pixels at or above the iso-level.
    centroid_px : tuple of float
        (u, v) of its pixels' mean, px.
    """

    area_px: int
    centroid_px: tuple[float, float]

    def to_json(self) -> dict:
        """``{"area_px", "centroid_px"}``."""
        return {"area_px": self.area_px, "centroid_px": list(self.centroid_px)}


@dataclass(frozen=True)
class BlobChoice:
    """The object's blob in an image.

    Attributes
    ----------
    blob : Blob
    others : tuple of Blob
        The other blobs of at least ``min_area_px`` pixels, largest first.
    specks : int
        Blobs smaller than ``min_area_px`` (ignored).
    labels : (H, W) ndarray of int
        Label image (0 background).
    label : int
        The object's label in ``labels``.
    box : tuple of slice
        Rows and columns of the object's bounding box.
    """

    blob: Blob
    others: tuple[Blob, ...]
    specks: int
    labels: np.ndarray
    label: int
    box: tuple[slice, slice]


def choose_object(inside: np.ndarray, *, min_area_px: int, ambiguous_ratio: float,
                  what: str) -> BlobChoice:
    """The largest 4-connected blob of ``inside`` after the checks of a usable view.

    Parameters
    ----------
    inside : (H, W) ndarray of bool
        Pixels at or above the iso-level.
    min_area_px : int
        Blobs smaller than this are specks: ignored and counted.
    ambiguous_ratio : float
        Refuse the view when the second largest blob has at least this fraction of the largest
        one's area (in (0, 1]).
    what : str
        The image's name in error messages ("mask", "depth image").

    Raises
    ------
    InvalidInputError
        No blob (an empty view), the object touching the image border, or two blobs of similar
        size.
    """
    from scipy import ndimage

    # label only the bounding box of all pixels inside (the object and the other blobs): a
    # top-down view is mostly background, and labelling the whole frame was most of a 640 x
    # 480 mask's extraction time
    rows, cols = np.flatnonzero(inside.any(axis=1)), np.flatnonzero(inside.any(axis=0))
    labels = np.zeros(inside.shape, np.int32)
    origin = (int(rows[0]), int(cols[0])) if rows.size else (0, 0)
    crop = (slice(origin[0], int(rows[-1]) + 1 if rows.size else 0),
            slice(origin[1], int(cols[-1]) + 1 if rows.size else 0))
    count = ndimage.label(inside[crop], output=labels[crop])
    areas = np.bincount(labels[crop].ravel(), minlength=count + 1)[1:]
    order = np.argsort(-areas, kind="mergesort")
    kept = [int(k) for k in order[areas[order] >= min_area_px]]  # noisy depth: 1000s of specks
    if not kept:
        raise InvalidInputError(f"{what}: no object in view (no blob of at least {min_area_px} "
                                f"px; largest {int(areas.max()) if count else 0} px)")
    first = kept[0]
    if len(kept) > 1 and areas[kept[1]] >= ambiguous_ratio * areas[first]:
        raise InvalidInputError(
            f"{what}: {sum(areas[k] >= ambiguous_ratio * areas[first] for k in kept)} blobs of "
            f"similar size ({int(areas[first])} and {int(areas[kept[1]])} px; the second is at "
            f"least ambiguous_ratio = {ambiguous_ratio:g} of the first): which one is the object "
            "is ambiguous; show one object or mask the others")
    # the boxes of the kept blobs only (find_objects on every speck's label built a list of
    # thousands of slices)
    rank = np.zeros(count + 1, np.int32)
    rank[np.array(kept) + 1] = np.arange(1, len(kept) + 1)
    boxes = {k: (slice(r.start + origin[0], r.stop + origin[0]),
                 slice(c.start + origin[1], c.stop + origin[1]))
             for k, (r, c) in zip(kept, ndimage.find_objects(rank[labels[crop]]))}
    box = boxes[first]
    H, W = inside.shape
    if box[0].start == 0 or box[1].start == 0 or box[0].stop == H or box[1].stop == W:
        raise InvalidInputError(
            f"{what}: the object touches the image border (rows {box[0].start}-"
            f"{box[0].stop - 1}, columns {box[1].start}-{box[1].stop - 1} of {H} x {W}): it may "
            "be cut, so its outline is unknown; move the camera or the object")
    blobs = []
    for k in kept:
        rows, cols = np.nonzero(labels[boxes[k]] == k + 1)
        blobs.append(Blob(int(areas[k]), (float(cols.mean() + boxes[k][1].start),
                                          float(rows.mean() + boxes[k][0].start))))
    return BlobChoice(blobs[0], tuple(blobs[1:]), int(count - len(kept)), labels, first + 1,
                      box)
