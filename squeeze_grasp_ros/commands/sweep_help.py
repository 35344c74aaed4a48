# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""``squeeze-grasp sweep-help``: every sweep-spec key with its unit, allowed range and default."""
from __future__ import annotations

import argparse

from squeeze_grasp_ros.sweep.spec import sweep_help


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """No options."""


def run(args: argparse.Namespace) -> dict:
    """The reference text (``{"text": ...}``)."""
    return {"text": sweep_help()}


def summary(result: dict) -> str:
    """The reference text."""
    return result["text"]
