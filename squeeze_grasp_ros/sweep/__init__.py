# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Grasp datasets at scale: ``squeeze-grasp sweep`` (see docs/sweep.md).

``spec`` parses and validates the sweep YAML, ``families`` draws the seeded random shapes,
``plan`` expands a spec into Dask tasks grouped by (object, mesh, material), ``evaluate`` runs a
task on a worker (mesh and factorise once, then every evaluation), ``store`` writes the
Parquet parts and the manifest, ``engine`` drives Dask, ``report`` summarises a dataset.
Only ``engine`` and ``store`` import Dask / pyarrow.
"""
