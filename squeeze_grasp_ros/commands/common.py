# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Argument and loading helpers shared by the verbs."""
from __future__ import annotations

import argparse
import re
import sys
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from squeeze_grasp_ros.exit_codes import ExitCode, error_json
from squeeze_grasp_ros.mechanics.elastic.compliance import ROUTES
from squeeze_grasp_ros.mechanics.errors import SqueezeGraspError
from squeeze_grasp_ros.outputs import output_error, probe_folder
from squeeze_grasp_ros.scene import GraspSetup, load_scene

FIELD = re.compile(r"^([A-Za-z_][\w.\[\]]*) (?:must|is|needs|has)\b")
"""A message that starts with the name of the offending field ("object.shape.side must ...")."""


def fail(args: argparse.Namespace, message: str, code: ExitCode, *,
         details: Mapping[str, Any] | None = None) -> int:
    """Report an error: one line on stderr, and with ``--json`` a JSON object on stdout (with
    ``details``, :func:`~squeeze_grasp_ros.exit_codes.error_json`).
    """
    print(f"squeeze-grasp {args.verb}: error: {message}", file=sys.stderr)
    if getattr(args, "json", False):
        match = FIELD.match(message)
        print(error_json(message, match.group(1) if match else None, code, details))
    return code


def add_scene_argument(parser: argparse.ArgumentParser) -> None:
    """The positional SCENE argument (a YAML file, see `squeeze-grasp scene-help`)."""
    parser.add_argument("scene", metavar="SCENE", help="scene YAML file (e.g. "
                                                       "config/scenes/disk.yaml)")


def add_solver_argument(parser: argparse.ArgumentParser) -> None:
    """``--solver``: the K+ route (factorized default, spectral = the paper's dense reference)."""
    parser.add_argument("--solver", choices=ROUTES, default="factorized",
                        help="contact-compliance route (default: factorized; spectral is the "
                             "paper's O(n^3) eigendecomposition, for cross-checks)")


def int_in(lo: int, hi: int):
    """Argparse type of an integer in [lo, hi]; the error names the range."""

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"must be an integer in [{lo}, {hi}], got "
                                             f"{text[:40]!r}") from None
        if not lo <= value <= hi:
            raise argparse.ArgumentTypeError(f"must be in [{lo}, {hi}], got {value}")
        return value

    parse.__name__ = "integer"
    return parse


def output_file(text: str) -> str:
    """Argparse type of an output file: a path whose folder exists and takes new files (probed
    before any computation), and that is not a folder.
    """
    path = Path(text)
    if not text:
        raise argparse.ArgumentTypeError("needs a file name")
    if path.is_dir():
        raise argparse.ArgumentTypeError(f"{text} is a folder; give a file name in it")
    if not path.resolve().parent.is_dir():
        raise argparse.ArgumentTypeError(f"the folder of {text} does not exist")
    try:
        probe_folder(path.resolve().parent, text)
    except SqueezeGraspError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None
    return text


def output_folder(text: str) -> str:
    """Argparse type of an output folder (a report, plots): a folder, or one that can be made
    (its nearest existing parent a folder in which files can be created: probed, before any
    computation); not a file. It is made by :func:`make_output_folder` when the command runs,
    not while the command line is parsed (an error in a later argument left it behind).
    """
    path = Path(text)
    if not text.strip():
        raise argparse.ArgumentTypeError("needs a folder name")
    if path.exists() and not path.is_dir():
        raise argparse.ArgumentTypeError(f"{text} exists and is not a folder; give a folder")
    parent = next(p for p in (path, *path.absolute().parents) if p.exists())
    if not parent.is_dir():
        raise argparse.ArgumentTypeError(f"{text}: {parent} is not a folder")
    try:
        probe_folder(parent, text)
    except SqueezeGraspError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None
    return text


def make_output_folder(text: str) -> Path:
    """Make the output folder ``text`` of :func:`output_folder` (with its parents).

    Raises
    ------
    InvalidInputError, InternalError
        If it cannot be made (:func:`~squeeze_grasp_ros.outputs.output_error`).
    """
    path = Path(text)
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise output_error(exc, text, "the folder") from None
    return path


def new_folder(text: str) -> str:
    """Argparse type of a folder to create (a recording): not empty, not a file, not a folder
    that already holds something.
    """
    path = Path(text)
    if not text.strip():
        raise argparse.ArgumentTypeError("needs a folder name")
    if path.is_file():
        raise argparse.ArgumentTypeError(f"{text} is a file; give a new folder")
    if path.is_dir() and any(path.iterdir()):
        raise argparse.ArgumentTypeError(f"{text} exists and is not empty")
    return text


def add_plot_argument(parser: argparse.ArgumentParser) -> None:
    """``--plot FILE.png``."""
    parser.add_argument("--plot", metavar="FILE.png", type=output_file,
                        help="write a figure to this PNG file")


def load_setup(path: str, solver: str = "factorized") -> GraspSetup:
    """The scene of file ``path`` made mechanics (:class:`GraspSetup`), a solid meshed for the
    ``solver`` route.
    """
    return GraspSetup.build(load_scene(path), route=solver)
