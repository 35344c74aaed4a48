# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Decode a recording with Foxglove's own TypeScript libraries, run under node.

``test/js/`` holds the decoder script and a ``package.json`` pinning the libraries; both are
copied into a cache folder outside the repository, where ``npm install`` fetches the libraries
once (the npm registry must be reachable the first time; offline, the check skips and says so).
"""
from __future__ import annotations

import json
import os
import shutil
import subprocess
from pathlib import Path

import pytest

JS_DIR = Path(__file__).parent / "js"
CACHE = Path(os.environ.get("SQUEEZE_GRASP_JS_CACHE",
                            Path.home() / ".cache" / "squeeze_grasp_ros" / "foxglove-js"))


def foxglove_decoder() -> Path:
    """The decoder script in the cache, its libraries installed; skips visibly without node."""
    node, npm = shutil.which("node"), shutil.which("npm")
    if node is None or npm is None:
        pytest.skip("node/npm not installed: the Foxglove decoding check (Foxglove's TypeScript "
                    "libraries) cannot run on this machine")
    CACHE.mkdir(parents=True, exist_ok=True)
    manifest = (JS_DIR / "package.json").read_text()
    installed = CACHE / ".installed-package.json"  # the manifest of the last good install
    if not installed.is_file() or installed.read_text() != manifest \
            or not (CACHE / "node_modules").is_dir():
        (CACHE / "package.json").write_text(manifest)
        done = subprocess.run([npm, "install", "--no-audit", "--no-fund", "--loglevel=error"],
                              cwd=CACHE, capture_output=True, text=True, timeout=300)
        if done.returncode != 0:
            errors = [line for line in done.stderr.splitlines() if "error" in line]
            pytest.skip(f"npm install of Foxglove's MCAP libraries into {CACHE} failed (the npm "
                        f"registry must be reachable once): {' | '.join(errors[:3])}")
        installed.write_text(manifest)
    script = CACHE / "decode_mcap.mjs"
    shutil.copyfile(JS_DIR / "decode_mcap.mjs", script)
    return script


def foxglove_decode(mcap_file: Path) -> dict[str, dict]:
    """Per topic: schema, messages, decoded, error (first) and frame_ids (first message)."""
    done = subprocess.run(["node", str(foxglove_decoder()), str(mcap_file)], capture_output=True,
                          text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout)


def resolve(message, path: str):
    """The value of a Foxglove message path below the topic ('forces[0].x') in a message."""
    value = message
    for part in path.split("."):
        name, _, index = part.partition("[")
        value = getattr(value, name)
        if index:
            value = value[int(index.rstrip("]"))]
    return value


def first_messages(bag: Path) -> dict:
    """The first message of every topic of a recording (rosbags' reader)."""
    from rosbags.highlevel import AnyReader

    out = {}
    with AnyReader([bag]) as reader:
        for connection, _, raw in reader.messages():
            if connection.topic not in out:
                out[connection.topic] = reader.deserialize(raw, connection.msgtype)
    return out


def layout_paths(panels: dict) -> list[str]:
    """Every plotted message path ('/topic.field[0].x') of a Foxglove layout's panels."""
    paths = [p["value"] for c in panels.values() for p in c.get("paths", [])]
    return paths + [c["xAxisPath"]["value"] for c in panels.values() if "xAxisPath" in c]
