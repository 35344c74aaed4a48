# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Writing output files (plots, CSV, sweep parts and manifests, reports).

Every failure becomes one error naming the file, the cause and its errno, of the kind that says
who must act: a path the user can change (a read-only folder, no permission, a missing folder,
``/proc``) is an :class:`~squeeze_grasp_ros.mechanics.errors.InvalidInputError` (exit 2); the
machine failing (a full disk, a quota, a file-size limit, an I/O error) an
:class:`~squeeze_grasp_ros.mechanics.errors.InternalError` (exit 4). Folders are probed before a
computation starts (:func:`probe_folder`), so a bad path costs no work, and files are replaced
atomically (:func:`write_atomically`), so a failed write leaves neither a half file nor a
temporary one behind.

>>> import errno
>>> str(output_error(OSError(errno.EROFS, "Read-only file system"), "/mnt/ro/x.csv", "CSV"))
'cannot write CSV /mnt/ro/x.csv: Read-only file system (EROFS)'
>>> type(output_error(OSError(errno.ENOSPC, "No space left on device"), "x", "a part")).__name__
'InternalError'
"""
from __future__ import annotations

import errno
import os
import tempfile
from collections.abc import Callable
from pathlib import Path

from squeeze_grasp_ros.mechanics.errors import InternalError, InvalidInputError

__all__ = ["MACHINE_ERRNOS", "output_error", "probe_folder", "write_atomically"]

MACHINE_ERRNOS = frozenset({errno.ENOSPC, errno.EDQUOT, errno.EFBIG, errno.EIO})
"""Write failures of the machine, not of the path the user gave (exit 4, INTERNAL)."""


def _error(exc: OSError, message: str) -> InvalidInputError | InternalError:
    name = errno.errorcode.get(exc.errno or 0)
    reason = (exc.strerror or str(exc)) + (f" ({name})" if name else "")
    if exc.errno in MACHINE_ERRNOS:
        return InternalError(f"{message}: {reason}")
    return InvalidInputError(f"{message}: {reason}")


def output_error(exc: OSError, path: str | Path, what: str) -> InvalidInputError | InternalError:
    """The one-line error of a failed write of ``what`` to ``path``."""
    return _error(exc, f"cannot write {what} {path}")


def probe_folder(folder: str | Path, what: str) -> None:
    """Refuse (as :func:`output_error` does) a ``folder`` in which no file can be created: a
    probe file is made and removed again, so read-only mounts, missing permissions and pseudo
    file systems fail here, before any computation, also for root. ``what`` names the output
    ("--plot").
    """
    try:
        fd, name = tempfile.mkstemp(prefix=".squeeze-grasp-probe-", dir=folder)
        os.close(fd)
        os.unlink(name)
    except OSError as exc:
        raise _error(exc, f"{what}: cannot create files in {folder}") from None


def write_atomically(path: str | Path, write: Callable[[Path], None], what: str) -> None:
    """Write ``path`` through ``write(temporary path)`` next to it, fsync and rename: the file
    is complete or unchanged whatever happens. On failure the temporary file is removed and
    :func:`output_error` raised.
    """
    path = Path(path)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    try:
        write(tmp)
        with open(tmp, "rb") as fh:
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except OSError as exc:
        try:
            tmp.unlink(missing_ok=True)
        except OSError:
            pass
        raise output_error(exc, path, what) from None
