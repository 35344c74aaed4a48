# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Real full and read-only file systems for the output tests (a tmpfs in a private mount
namespace), and the command line of this interpreter's ``squeeze-grasp``.
"""
from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import pytest

CLI = [sys.executable, "-m", "squeeze_grasp_ros.cli"]
"""The ``squeeze-grasp`` command of this interpreter."""


def private_mount(target: Path, options: str, command: list[str],
                  timeout: float = 300) -> subprocess.CompletedProcess:
    """Run ``command`` with a tmpfs mounted at ``target`` (``options``: "ro,size=1m",
    "size=48k") in a private mount namespace; skips where ``unshare -m`` is not allowed.
    """
    if shutil.which("unshare") is None or subprocess.run(
            ["unshare", "-m", "true"], capture_output=True).returncode != 0:
        pytest.skip("needs `unshare -m` (a private mount namespace) for a real full or "
                    "read-only file system")
    target.mkdir(exist_ok=True)
    script = (f"mount -t tmpfs -o {options} tmpfs '{target}' && exec "
              + " ".join(f"'{a}'" for a in command))
    return subprocess.run(["unshare", "-m", "sh", "-c", script], capture_output=True,
                          text=True, timeout=timeout)
