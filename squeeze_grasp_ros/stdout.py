# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Standard output carries results only (``squeeze-grasp ... --json | jq`` always parses).

Libraries below Python write diagnostics to file descriptor 1: Fast DDS's default log consumer
prints its errors to stdout, for instance ``[RTPS_TRANSPORT_SHM Error] Failed init_port
fastrtps_port7413: open_and_lock_file failed`` when the lock of a shared-memory port times out
on a loaded machine (the transport then falls back to UDP and the run is fine), and that line
broke the JSON of ``run --json``. :func:`reserve_stdout` points descriptor 1 at stderr for the
rest of the process, so whatever the middleware (or a node process started later, which
inherits it) writes there goes to stderr, and gives Python's ``sys.stdout`` a descriptor of its
own on the original output, where only the program's results go.
"""
from __future__ import annotations

import io
import os
import sys

__all__ = ["reserve_stdout"]


def reserve_stdout() -> bool:
    """Send descriptor 1 to stderr and keep the original stdout for ``sys.stdout`` alone.

    Returns True if it did; False if ``sys.stdout`` is not descriptor 1 (replaced, e.g. by a
    test's capture, or already reserved): nothing below Python can write into it then.
    """
    try:
        if sys.stdout.fileno() != 1:
            return False
    except (AttributeError, OSError, io.UnsupportedOperation):
        return False
    old = sys.stdout
    old.flush()
    own = os.dup(1)
    os.dup2(2, 1)
    sys.stdout = io.TextIOWrapper(io.FileIO(own, "w"), encoding=old.encoding, errors=old.errors,
                                  line_buffering=old.line_buffering)
    return True
