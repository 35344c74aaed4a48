# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Images from file bytes, and their ``sensor_msgs/Image`` encoding.

========================================  ==========================  ===========================
file                                      array                       encoding
========================================  ==========================  ===========================
PNG 8-bit grey (mode L) or 1-bit          uint8 / bool                ``mono8`` mask
PNG 16-bit grey (mode I;16)               uint16, mm                  ``16UC1`` depth
NPY uint8 / bool                          as stored                   ``mono8`` mask
NPY uint16                                mm                          ``16UC1`` depth
NPY float32 / float64                     m                           ``32FC1`` depth
========================================  ==========================  ===========================

Colour PNGs, other array types and pickled NPY files are refused.

>>> import io
>>> buffer = io.BytesIO()
>>> np.save(buffer, np.zeros((4, 5), np.uint16))
>>> image, encoding = decode_image(buffer.getvalue(), ".npy")
>>> image.shape, str(encoding)
((4, 5), '16UC1')
"""
from __future__ import annotations

import io

import numpy as np

from squeeze_grasp_ros.mechanics.errors import InvalidInputError
from squeeze_grasp_ros.mechanics.vocabulary import ImageEncoding

__all__ = ["decode_image", "encode_png"]

ENCODINGS: dict[str, ImageEncoding] = {
    "bool": ImageEncoding.MONO8, "uint8": ImageEncoding.MONO8,
    "uint16": ImageEncoding.DEPTH_16UC1, "float32": ImageEncoding.DEPTH_32FC1,
    "float64": ImageEncoding.DEPTH_32FC1,
}
"""Array type -> encoding it is read as."""

PNG_MODES: dict[str, str] = {"1": "bool", "L": "uint8", "I;16": "uint16"}
"""Pillow mode of a single-channel PNG -> array type."""


def decode_image(data: bytes, suffix: str) -> tuple[np.ndarray, ImageEncoding]:
    """The 2-D array in PNG or NPY ``data`` and the encoding its type implies.

    Raises
    ------
    InvalidInputError
        Not a PNG or NPY file, a colour or multi-channel image, or an unsupported type.
    """
    suffix = suffix.lower()
    if suffix == ".npy":
        # without the NPY header np.load would open a .npz or call the file pickled
        if not data.startswith(np.lib.format.MAGIC_PREFIX):
            raise InvalidInputError("image: not an NPY array file (no NPY header; an .npz archive "
                                    "or another format named .npy?); save it with numpy.save")
        try:
            image = np.load(io.BytesIO(data), allow_pickle=False)
        except (ValueError, OSError, EOFError) as exc:
            raise InvalidInputError(f"image: not a readable NPY array ({exc})") from None
    elif suffix == ".png":
        from PIL import Image, UnidentifiedImageError

        try:
            with Image.open(io.BytesIO(data)) as png:
                if png.mode not in PNG_MODES:
                    raise InvalidInputError(f"image: a PNG of mode {png.mode} (colour or "
                                            "multi-channel); give a single-channel 8-bit mask "
                                            "or 16-bit depth PNG")
                image = np.asarray(png).astype(PNG_MODES[png.mode])
        except (UnidentifiedImageError, OSError) as exc:
            raise InvalidInputError(f"image: not a readable PNG ({exc})") from None
    else:
        raise InvalidInputError(f"image must be a .png or .npy file, got {suffix or 'no suffix'}")
    if image.ndim != 2 or image.dtype.name not in ENCODINGS:
        raise InvalidInputError(f"image must be a 2-D array of {sorted(ENCODINGS)}, got "
                                f"{image.dtype.name} of shape {image.shape}")
    return image, ENCODINGS[image.dtype.name]


def encode_png(image: np.ndarray) -> bytes:
    """PNG bytes of a uint8 mask (mode L) or uint16 depth image in mm (mode I;16)."""
    from PIL import Image

    mode = {"uint8": "L", "uint16": "I;16"}.get(np.asarray(image).dtype.name)
    if mode is None:
        raise InvalidInputError("encode_png takes uint8 masks or uint16 depth (mm)")
    buffer = io.BytesIO()
    Image.fromarray(np.ascontiguousarray(image)).save(buffer, format="PNG")
    return buffer.getvalue()
