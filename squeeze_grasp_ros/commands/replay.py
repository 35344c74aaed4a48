# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""``squeeze-grasp replay DIR``: a recording's sensor topics into a fresh monitor."""
from __future__ import annotations

import argparse

HELP = ("replay a recording's sensor topics on its sim time into a fresh monitor and check that "
        "it reproduces the recorded event sequence")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """DIR and monitor parameter overrides for recordings made by other tools."""
    parser.add_argument("bag", metavar="DIR", help="rosbag2 folder (MCAP or SQLite3) or .mcap file")
    parser.add_argument("--mu", type=float,
                        help="friction coefficient for the monitor (default: the recording's)")
    parser.add_argument("--load-threshold", type=float,
                        help="taxel load threshold, N (default: the recording's)")


def run(args: argparse.Namespace) -> dict | int:
    """Replay; exit code 1 when the recorded event sequence is not reproduced."""
    from ..recording.replay import replay

    overrides = {k: v for k, v in (("mu", args.mu), ("load_threshold", args.load_threshold))
                 if v is not None}
    result = replay(args.bag, overrides)
    if result["reproduced"] is False and not args.json:
        print(summary(result))
        return 1
    return result


def summary(result: dict) -> str:
    """Human-readable report of a replay."""
    lines = [f"{result['bag']}: {result['ticks']} ticks replayed into a fresh monitor in "
             f"{result['seconds']:.2f} s; {len(result['events'])} events, {result['alarms']} "
             "alarm reports"]
    for e in result["events"]:
        lines.append(f"  t={e['stamp_ns'] * 1e-9:9.4f} s  {e['type']:>9} {e['finger'] or '-':>2}  "
                     f"depth {e['depth'] * 1e3:.4f} mm")
    if result["reproduced"] is None:
        lines.append("the recording has no monitor/events to compare with")
    else:
        lines.append("recorded event sequence reproduced exactly" if result["reproduced"] else
                     f"DIFFERENT from the {len(result['recorded_events'])} recorded events")
    return "\n".join(lines)
