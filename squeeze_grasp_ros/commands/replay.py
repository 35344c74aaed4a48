# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""``squeeze-grasp replay DIR``: a recording's sensor topics into a fresh monitor."""

from __future__ import annotations

import argparse
import json
import sys

from squeeze_grasp_ros.commands.common import fail
from squeeze_grasp_ros.exit_codes import ExitCode
from squeeze_grasp_ros.inputs import InputError, load_yaml


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """DIR and monitor parameter overrides for recordings made by other tools."""
    parser.add_argument(
        "bag", metavar="DIR", help="rosbag2 folder (MCAP or SQLite3) or .mcap file"
    )
    parser.add_argument(
        "--param",
        metavar="NAME=VALUE",
        action="append",
        default=[],
        help="monitor parameter for the replay (repeatable; YAML value), e.g. "
        "mu=0.4 for a recording made by another tool (default: the "
        "recording's parameters, else config/monitor.yaml)",
    )


def run(args: argparse.Namespace) -> dict | int:
    """Replay; exit code 1 (after printing the result) when the recorded event sequence is not
    reproduced, 2 for a missing or corrupt bag, 4 when the replay does not finish.
    """
    from squeeze_grasp_ros.ros.recording.bag import BagError
    from squeeze_grasp_ros.ros.recording.replay import replay

    overrides = {}
    for entry in args.param:
        name, sep, value = entry.partition("=")
        if not sep or not name:
            print(
                f"squeeze-grasp replay: --param needs NAME=VALUE, got {entry!r}", file=sys.stderr
            )
            return ExitCode.USAGE
        try:
            overrides[name] = load_yaml(value, what=f"--param {name}")
        except InputError as exc:
            return fail(args, str(exc), ExitCode.USAGE)
    try:
        result = replay(args.bag, overrides)
    except BagError as exc:
        return fail(args, str(exc), ExitCode.USAGE)
    except TimeoutError as exc:
        return fail(args, str(exc), ExitCode.INTERNAL)
    if result["reproduced"] is False:
        print(json.dumps(result) if args.json else summary(result))
        return ExitCode.OUTCOME
    return result


def summary(result: dict) -> str:
    """Human-readable report of a replay."""
    lines = [
        f"{result['bag']}: {result['ticks']} ticks replayed into a fresh monitor in "
        f"{result['seconds']:.2f} s; {len(result['events'])} events, {result['alarms']} "
        "alarm reports"
    ]
    for e in result["events"]:
        lines.append(
            f"  t={e['stamp_ns'] * 1e-9:9.4f} s  {e['type']:>9} {e['finger'] or '-':>2}  "
            f"depth {e['depth'] * 1e3:.4f} mm"
        )
    if result["reproduced"] is None:
        lines.append("the recording has no monitor/events to compare with")
    else:
        lines.append(
            "recorded event sequence reproduced exactly"
            if result["reproduced"]
            else f"DIFFERENT from the {len(result['recorded_events'])} recorded events"
        )
    return "\n".join(lines)
