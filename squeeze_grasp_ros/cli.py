# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""``squeeze-grasp``: the mechanics without ROS, plus running and replaying scenes on ROS 2."""
from __future__ import annotations

import argparse
import importlib
import json
import math
import os
import re
import sys
from typing import Any

from squeeze_grasp_ros.commands import VERBS
from squeeze_grasp_ros.exit_codes import ExitCode, error_json

EPILOG = ("exit status: 0 done; 1 negative outcome (grasp failed in the world, replay differs); "
          "2 invalid input; 3 a solver failed (the message carries its residuals); 4 pipeline or "
          "environment failure (e.g. ROS not installed); 130 interrupted (Ctrl-C); 143 "
          "terminated (SIGTERM)")


class _Parser(argparse.ArgumentParser):
    """An argument parser whose usage errors, with ``--json`` on the command line, are also one
    JSON object on stdout (:func:`.exit_codes.error_json`), as the errors of a running verb are
    (:func:`.commands.common.fail`): a script reading stdout got nothing for ``plan --json
    --depth abc``.
    """

    def __init__(self, *args: Any, json_errors: bool = False, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.json_errors = json_errors

    def error(self, message: str):
        if self.json_errors:
            named = ARGUMENT.match(message)
            print(error_json(message, named.group(1).lstrip("-") if named else None,
                             ExitCode.USAGE))
        super().error(message)


ARGUMENT = re.compile(r"^argument ([\w-]+)")
"""The option or positional an argparse error names ("argument --depth: invalid float ...")."""


class _Verbs(argparse._SubParsersAction):
    """The verb sub-parsers, each filled by its module only when that verb is chosen, so that
    ``--help`` and every verb import only what they use (argparse calls this action once, with
    the verb and its arguments, before it parses them).
    """

    def __call__(self, parser, namespace, values, option_string=None):
        add_verb_arguments(self._name_parser_map[values[0]])
        super().__call__(parser, namespace, values, option_string)


def add_verb_arguments(parser: argparse.ArgumentParser) -> argparse.ArgumentParser:
    """Import the module of ``parser``'s verb and let it add its arguments (once), plus
    ``--json`` if it has none; returns ``parser``.
    """
    name = parser.get_default("_verb")
    if parser.get_default("_module") is None:
        module = importlib.import_module(f".commands.{name}", __package__)
        module.add_arguments(parser)
        if not any(a.dest == "json" for a in parser._actions):
            parser.add_argument("--json", action="store_true", help="print machine-readable JSON")
        parser.set_defaults(_module=module)
    return parser


def build_parser(*, json_errors: bool = False) -> argparse.ArgumentParser:
    """The argument parser with one sub-command per verb (:data:`.commands.VERBS`); a verb's
    arguments are added when it is chosen (:func:`add_verb_arguments`). ``json_errors``: usage
    errors are also printed as a JSON object on stdout (``--json`` was given).
    """
    parser = _Parser(
        json_errors=json_errors,
        prog="squeeze-grasp",
        description="Squeeze grasps of deformable planar objects (Jia, Guo, Lin, IJRR 2014). "
                    "SI units throughout. Scene format: `squeeze-grasp scene-help`.",
        epilog=EPILOG)
    sub = parser.add_subparsers(action=_Verbs, dest="verb", metavar="VERB", required=True)
    for name, help_ in VERBS.items():
        verb = sub.add_parser(name.replace("_", "-"), help=help_, description=help_,
                              json_errors=json_errors)
        verb.set_defaults(_verb=name, _module=None)
    return parser


def finite_json(value: Any, path: str = "", bad: list[str] | None = None) -> Any:
    """``value`` with every non-finite float replaced by None; their paths appended to ``bad``."""
    if isinstance(value, float) and not math.isfinite(value):
        if bad is not None:
            bad.append(path or "(result)")
        return None
    if isinstance(value, dict):
        return {k: finite_json(v, f"{path}.{k}" if path else str(k), bad)
                for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [finite_json(v, f"{path}[{k}]", bad) for k, v in enumerate(value)]
    return value


def exit_code(error: Exception) -> ExitCode:
    """The exit code of an error of the package (:mod:`.mechanics.errors`, by who must act):
    2 for invalid input, 1 for a physical "no", 3 for a failed solver, 4 otherwise.
    """
    from squeeze_grasp_ros.mechanics.errors import (
        InfeasibleError,
        InvalidInputError,
        NumericalError,
    )

    codes = ((InvalidInputError, ExitCode.USAGE), (InfeasibleError, ExitCode.OUTCOME),
             (NumericalError, ExitCode.NUMERICAL))
    return next((code for kind, code in codes if isinstance(error, kind)), ExitCode.INTERNAL)


def error_details(error: Exception) -> dict[str, Any]:
    """What an error's JSON object adds to its message: for a solver failure
    (:class:`~.mechanics.errors.NumericalError`) its ``residuals`` by name, and ``depth`` (m)
    and ``relative_depth`` of a squeeze's failure (None where it was not a squeeze's); numbers
    that are not finite become None (a residual never computed is inf).

    >>> from squeeze_grasp_ros.mechanics.errors import NumericalError
    >>> error_details(NumericalError("stalled", residuals={"cone": 2e-6}).located(0.0177, 0.24))
    {'residuals': {'cone': 2e-06}, 'depth': 0.0177, 'relative_depth': 0.24}
    """
    from squeeze_grasp_ros.mechanics.errors import NumericalError

    if not isinstance(error, NumericalError):
        return {}

    def finite(value: float | None) -> float | None:
        return value if value is not None and math.isfinite(value) else None
    return {"residuals": {k: finite(v) for k, v in error.residuals.items()},
            "depth": finite(error.depth), "relative_depth": finite(error.relative_depth)}


def main(argv: list[str] | None = None) -> int:
    """Entry point; returns the process exit code (:class:`~.exit_codes.ExitCode`).

    With ``--json`` a result is printed as one JSON object (non-finite numbers become null and
    are listed under ``non_finite``), and an error as ``{"error", "field", "code",
    "code_name"}``, a usage error too, a solver failure with its :func:`error_details`.
    """
    argv = sys.argv[1:] if argv is None else argv
    args = build_parser(json_errors="--json" in argv).parse_args(argv)
    from squeeze_grasp_ros import plots
    from squeeze_grasp_ros.commands.common import fail
    from squeeze_grasp_ros.extras import install_hint
    from squeeze_grasp_ros.mechanics.errors import SqueezeGraspError

    written = len(plots.WRITTEN)
    try:
        result = args._module.run(args)
    except SqueezeGraspError as exc:
        return fail(args, str(exc), exit_code(exc), details=error_details(exc))
    except ModuleNotFoundError as exc:
        hint = install_hint(exc.name or "")
        if hint is None:
            raise
        return fail(args, f"needs {exc.name.split('.')[0]}, which is not installed: {hint}",
                    ExitCode.INTERNAL)
    if isinstance(result, int):
        return result
    try:
        if args.json:
            bad: list[str] = []
            clean = finite_json(result, "", bad)
            if bad:
                clean["non_finite"] = bad
            sys.stdout.write(json.dumps(clean, allow_nan=False) + "\n")
        else:
            text = args._module.summary(result)
            pictures = [f"plot: {p}" for p in plots.WRITTEN[written:] if p not in text]
            print("\n".join([text, *pictures]) if text else "\n".join(pictures))
        sys.stdout.flush()
    except BrokenPipeError:  # the reader (e.g. `| head`) closed the pipe: not an error
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
    return ExitCode.OK


if __name__ == "__main__":
    from squeeze_grasp_ros.entry import cli_process

    sys.exit(cli_process())  # as the console script: signals while starting end with one line
