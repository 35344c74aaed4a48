# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The planner examples of a page (docs/ros.md), run against a real planner process.

A page's ``python`` snippets (each optionally followed by a ``text`` block with what it
prints) and its ``ros2 service call``, ``ros2 param get``/``set`` and ``ros2 action list``
transcripts run in document order in one client process, against one planner started as the
page says (``planner --ros-args --params-file config/planner.yaml``). The ``ros2`` commands
run as their rclpy equivalents, printing what ros2cli prints: ``ros2 service call`` the
request's and the response's ``repr`` (ros2service's own format), ``ros2 param get``
``<Type> value is: <value>``, ``ros2 param set`` ros2param's ``Set parameter successful`` or
``Setting parameter failed: <reason>``, ``ros2 action list -t`` ``name [type]``.
"""
from __future__ import annotations

import os
import shlex
import signal
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

from doc_transcripts import Block, blocks, parse
from executables import script

SEPARATOR = "\x1e"

HELPERS = '''
import time as _time
import yaml as _yaml
from importlib import import_module as _import

import rclpy as _rclpy
from rclpy.context import Context as _Context
from rclpy.executors import SingleThreadedExecutor as _Executor
from squeeze_grasp_ros.ros.nodes.planner_client import PlannerClient as _PlannerClient

_context = _Context()
_rclpy.init(context=_context)
_node = _rclpy.create_node("ros2cli_equivalent", context=_context)
_executor = _Executor(context=_context)
_executor.add_node(_node)
_planner = _PlannerClient(_node, _executor)


def _fill(message, fields):
    for key, value in fields.items():
        current = getattr(message, key)
        if isinstance(value, dict):
            _fill(current, value)
        else:
            setattr(message, key, type(current)(value) if isinstance(current, (int, float, str,
                                                                            bool)) else value)
    return message


def _service_call(name, type_name, values):
    package, _, kind = type_name.split("/")
    srv = getattr(_import(f"{package}.srv"), kind)
    request = _fill(srv.Request(), _yaml.safe_load(values) or {})
    print(f"requester: making request: {request!r}\\n")
    response = _planner.call(srv, name.rsplit("/", 1)[1], request, attempts=3)
    print(f"response:\\n{response!r}\\n")


def _param_get(node_name, name):
    from rcl_interfaces.srv import GetParameters
    from rcl_interfaces.msg import ParameterType
    client = _node.create_client(GetParameters, f"{node_name}/get_parameters")
    client.wait_for_service(timeout_sec=30.0)
    future = client.call_async(GetParameters.Request(names=[name]))
    _planner.spin_until(future.done)
    value = future.result().values[0]
    kinds = {ParameterType.PARAMETER_INTEGER: ("Integer", value.integer_value),
             ParameterType.PARAMETER_STRING: ("String", value.string_value),
             ParameterType.PARAMETER_DOUBLE: ("Double", value.double_value),
             ParameterType.PARAMETER_BOOL: ("Boolean", value.bool_value)}
    kind, shown = kinds[value.type]
    print(f"{kind} value is: {shown}")


def _param_set(node_name, name, text):
    from rcl_interfaces.srv import SetParameters
    from rclpy.parameter import Parameter
    client = _node.create_client(SetParameters, f"{node_name}/set_parameters")
    client.wait_for_service(timeout_sec=30.0)
    value = _yaml.safe_load(text)  # ros2param reads the value as YAML too
    future = client.call_async(SetParameters.Request(
        parameters=[Parameter(name, value=value).to_parameter_msg()]))
    _planner.spin_until(future.done)
    result = future.result().results[0]
    said = "Set parameter successful" if result.successful else "Setting parameter failed"
    print(said + (f": {result.reason}" if result.reason else ""))


def _action_list():
    from rclpy.action import get_action_names_and_types
    deadline = _time.monotonic() + 30.0
    while _time.monotonic() < deadline:
        found = [(n, t) for n, t in get_action_names_and_types(_node) if n.startswith("/planner")]
        if len(found) >= 2:
            break
        _executor.spin_once(timeout_sec=0.1)
    for name, types in sorted(found):
        print(f"{name} [{types[0]}]")
'''


@dataclass(frozen=True)
class Step:
    """One thing the client process does: run a snippet or a ``ros2`` command."""

    block: Block
    source: str
    expected: tuple[str, ...] | None
    """What it prints (None: not compared, a snippet without a ``text`` block)."""


def _command_source(text: str) -> str:
    from squeeze_grasp_ros.resources import share_dir

    # $SHARE is `ros2 pkg prefix --share squeeze_grasp_ros`: the package's share folder
    words = shlex.split(text.replace("$SHARE", str(share_dir())), comments=True)
    if words[:3] == ["ros2", "service", "call"]:
        return f"_service_call({words[3]!r}, {words[4]!r}, {words[5]!r})"
    if words[:3] == ["ros2", "param", "get"]:
        return f"_param_get({words[3]!r}, {words[4]!r})"
    if words[:3] == ["ros2", "param", "set"]:
        return f"_param_set({words[3]!r}, {words[4]!r}, {words[5]!r})"
    if words[:3] == ["ros2", "action", "list"]:
        return "_action_list()"
    raise AssertionError(f"the planner session cannot run {text!r}")


def steps(page: Path, start: str) -> list[Step]:
    """The page's snippets and ``ros2`` transcripts from the heading ``start`` on."""
    text = page.read_text(encoding="utf-8")
    first = text[:text.index(start)].count("\n") + 1
    found = [b for b in blocks(page) if b.line > first]
    result = []
    for k, block in enumerate(found):
        if block.language == "python":
            follows = found[k + 1] if k + 1 < len(found) else None
            expected = follows.lines if follows and follows.language == "text" else None
            result.append(Step(block, "\n".join(block.lines), expected))
        elif block.language == "console":
            transcript = parse(block)
            if transcript.untested is not None:
                continue
            for command in transcript.commands:
                if command.text.startswith(("ros2 service", "ros2 param", "ros2 action")):
                    result.append(Step(block, _command_source(command.text), command.output))
    return result


def run(page: Path, start: str, folder: Path,
        timeout: float = 600.0) -> list[tuple[Step, list[str]]]:
    """Run the steps of ``page`` against a planner started in ``folder``; each step's output."""
    plan = steps(page, start)
    client = HELPERS + "\n".join(f"print({SEPARATOR!r}, flush=True)\n{s.source}" for s in plan)
    planner = subprocess.Popen(
        [script("planner"), "--ros-args", "--params-file", "config/planner.yaml"],
        cwd=folder, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
        start_new_session=True)
    try:
        done = subprocess.run([sys.executable, "-c", client], cwd=folder, capture_output=True,
                              text=True, timeout=timeout, stdin=subprocess.DEVNULL,
                              env={**os.environ, "PYTHONUNBUFFERED": "1"})
    finally:
        os.killpg(planner.pid, signal.SIGINT)
        planner.communicate(timeout=30)
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
    outputs = done.stdout.split(SEPARATOR + "\n")[1:]
    assert len(outputs) == len(plan), done.stdout[-3000:]
    return [(step, out.splitlines()) for step, out in zip(plan, outputs)]
