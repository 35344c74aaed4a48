# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Two-finger squeeze grasps of deformable planar objects (Jia, Guo, Lin, IJRR 2014).

The mechanics solve many tiny dense systems (m x m, m ~ 2-50); multithreaded BLAS only adds
overhead there and, on an oversubscribed machine (several ROS node processes on 2 cores), its
spinning threads made them up to 1000x slower in our measurements. Unless the user chose
otherwise, BLAS is therefore single-threaded in processes that import this package before numpy
(the CLI, the nodes): set OPENBLAS_NUM_THREADS / OMP_NUM_THREADS yourself to override.
"""
import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

__version__ = "0.1.0"
