# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""``squeeze-grasp``: the mechanics without ROS, plus running and replaying scenes on ROS 2."""
from __future__ import annotations

import argparse
import importlib
import json
import sys

from .commands import VERBS
from .exit_codes import ExitCode
from .extras import install_hint
from .mechanics.errors import MechanicsError
from .scene import SceneError


def build_parser() -> argparse.ArgumentParser:
    """The argument parser with one sub-command per verb module."""
    parser = argparse.ArgumentParser(
        prog="squeeze-grasp",
        description="Squeeze grasps of deformable planar objects (Jia, Guo, Lin, IJRR 2014). "
                    "SI units throughout. Scene format: `squeeze-grasp scene-help`.",
        epilog="exit status: 0 done; 1 negative outcome (grasp failed in the world, replay "
               "differs); 2 invalid input; 4 pipeline or environment failure (e.g. ROS not "
               "installed); 130 interrupted (Ctrl-C)")
    sub = parser.add_subparsers(dest="verb", metavar="VERB", required=True)
    for name in VERBS:
        module = importlib.import_module(f".commands.{name}", __package__)
        p = sub.add_parser(name.replace("_", "-"), help=module.HELP, description=module.HELP)
        module.add_arguments(p)
        if not any(a.dest == "json" for a in p._actions):
            p.add_argument("--json", action="store_true", help="print machine-readable JSON")
        p.set_defaults(_module=module)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Entry point; returns the process exit code (2 for invalid input)."""
    args = build_parser().parse_args(argv)
    try:
        result = args._module.run(args)
    except (SceneError, MechanicsError) as exc:
        print(f"squeeze-grasp {args.verb}: error: {exc}", file=sys.stderr)
        return ExitCode.USAGE
    except ModuleNotFoundError as exc:
        hint = install_hint(exc.name or "")
        if hint is None:
            raise
        print(f"squeeze-grasp {args.verb}: error: needs {exc.name.split('.')[0]}, which is not "
              f"installed: {hint}", file=sys.stderr)
        return ExitCode.INTERNAL
    if isinstance(result, int):
        return result
    if args.json:
        json.dump(result, sys.stdout, allow_nan=False)
        sys.stdout.write("\n")
    else:
        print(args._module.summary(result))
    return 0


if __name__ == "__main__":
    sys.exit(main())
