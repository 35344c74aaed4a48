# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""``squeeze-grasp run SCENE``: a whole scene through the real rclpy nodes, in lockstep sim
time.
"""
from __future__ import annotations

import argparse
import errno
import json
import math
import os
import re
import signal
import sys
import tempfile
from pathlib import Path

from squeeze_grasp_ros.commands.common import add_scene_argument, fail, int_in, new_folder
from squeeze_grasp_ros.control.force_watch import FORCE_MISMATCH
from squeeze_grasp_ros.control.motion import DEFAULT_ATTEMPTS, DEFAULT_MARGIN, REACTIONS
from squeeze_grasp_ros.exit_codes import ExitCode, raise_on_signals
from squeeze_grasp_ros.perception.shape_watch import SHAPE_MISMATCH

EXECUTOR_CHOICES: tuple[str, ...] = ("events", "single")
"""``--executor`` values (equal to ``nodes.runner.EXECUTORS``; kept here so that building the CLI
parser never imports rclpy: ``squeeze-grasp ros-setup`` must run before the interfaces exist)."""


def _margin(text: str) -> float:
    """Argparse type of ``--resqueeze-margin``: a fraction in (0, 1)."""
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if not 0.0 < value < 1.0:
        raise argparse.ArgumentTypeError(f"must be a fraction in (0, 1), got {text[:40]!r}")
    return value


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """SCENE, --record DIR, --processes, --executor, --on-slip-alarm (--max-attempts,
    --resqueeze-margin), --world, --no-resist,
    --no-planner.
    """
    add_scene_argument(parser)
    parser.add_argument("--record", metavar="DIR", type=new_folder,
                        help="record every topic into this rosbag2 folder (MCAP storage); if "
                             "the disk fills up, the bag keeps every complete chunk, the run "
                             "still ends and prints its summary, and exits 4 saying so")
    parser.add_argument("--include-hidden-topics", action="store_true",
                        help="with --record: also record the executor action's hidden topics "
                             "(_action/feedback, _action/status); like rosbag2, off by default. "
                             "Foxglove and rosbags decode them; mcap_ros2 cannot (it rejects "
                             "rosidl's action message names, e.g. ExecuteGrasp_FeedbackMessage)")
    parser.add_argument("--attach", action="store_true",
                        help="use the pipeline nodes already running on this ROS domain (as "
                             "sim_pipeline.launch.py starts them): plan with their planner, send "
                             "the goal and summarise; starts and records nothing itself")
    parser.add_argument("--processes", action="store_true",
                        help="one process per node, as `ros2 launch` starts them (default: "
                             "every node on one executor in this process)")
    parser.add_argument("--executor", choices=EXECUTOR_CHOICES, default="events",
                        help="rclpy executor of the one-process mode (default: events, "
                             "rclpy.experimental.EventsExecutor; single = SingleThreadedExecutor)")
    parser.add_argument("--on-slip-alarm", choices=REACTIONS, default=REACTIONS[0],
                        help="executor reaction to an imminent-slip alarm: hold (default), "
                             "change the squeeze direction once to the pure squeeze or along the "
                             "measured contact normals, or resqueeze: open past first contact "
                             "and squeeze again short of the alarm's depth (docs/grippers.md)")
    parser.add_argument("--max-attempts", type=int_in(1, 100), default=DEFAULT_ATTEMPTS,
                        metavar="N", help="with --on-slip-alarm resqueeze: squeezes in all, the "
                                          f"first included (default {DEFAULT_ATTEMPTS})")
    parser.add_argument("--resqueeze-margin", type=_margin, default=DEFAULT_MARGIN,
                        metavar="FRACTION",
                        help="with --on-slip-alarm resqueeze: a re-squeeze goes to (1 - FRACTION) "
                             f"x the alarm's measured depth, FRACTION in (0, 1) (default "
                             f"{DEFAULT_MARGIN})")
    parser.add_argument("--world", metavar="SCENE",
                        help="scene YAML of the simulated world (default: SCENE itself): a "
                             "world the planner does not know, e.g. another E or outline, to "
                             "see the monitor's force and shape watches catch the model error")
    parser.add_argument("--no-resist", action="store_true",
                        help="skip the resistance phase of a scene with a frictional adversary")
    parser.add_argument("--no-planner", action="store_true",
                        help="plan with the mechanics API instead of the planner node")
    parser.add_argument("--quiet", action="store_true", help="no progress line")
    parser.add_argument("--namespace", metavar="NS", type=ros_namespace,
                        help="ROS namespace of the run's nodes (default: a fresh one, "
                             "/squeeze_grasp/run_<pid>_<random>, so runs on one ROS domain "
                             "never see each other); with --attach: the running nodes' "
                             "namespace (default: /)")
    parser.add_argument("--timeout", type=float, default=300.0, metavar="SECONDS",
                        help="wall-clock seconds to wait for any step of the run, finite and "
                             "> 0 (a node that hangs or dies ends the run with exit 4; default: "
                             "300)")


NAMESPACE = re.compile(r"(/[A-Za-z_][A-Za-z0-9_]*)+")
"""A fully qualified ROS namespace (``/a/b_1``)."""


def ros_namespace(text: str) -> str:
    """Argparse type of ``--namespace``: a fully qualified ROS namespace.

    >>> ros_namespace("/lab/run_1")
    '/lab/run_1'
    """
    if not NAMESPACE.fullmatch(text):
        raise argparse.ArgumentTypeError(
            f"needs a fully qualified ROS namespace such as /lab/run_1 (each part a letter or "
            f"_ then letters, digits, _), got {text[:40]!r}")
    return text


def _progress_line(update: dict) -> None:
    forces = " ".join(f"{f} {(v[0] ** 2 + v[1] ** 2) ** 0.5:6.3f} N"
                      for f, v in update["forces"].items())
    sys.stderr.write(f"\r{update['state']:>10}  depth {update['depth'] * 1e3:7.3f} mm "
                     f"({update['relative_depth'] * 100:5.2f} %)  {forces}  "
                     f"monitor events {update['events']:3d}")
    sys.stderr.flush()


def run(args: argparse.Namespace) -> dict | int:
    """Run the pipeline; the JSON summary (see :meth:`PipelineRunner.summary`), or exit code
    130 after Ctrl-C (the recording is finished first).
    """
    previous = raise_on_signals()  # a signal while rclpy and the nodes start: 128 + N, one line
    try:
        return _run(args)
    finally:
        for signum, handler in previous.items():
            signal.signal(signum, handler)


def _run(args: argparse.Namespace) -> dict | int:
    from squeeze_grasp_ros.ros.run.options import RunError, RunOptions
    from squeeze_grasp_ros.ros.run.runner import PipelineRunner

    if not (args.timeout > 0 and args.timeout < float("inf")):
        return fail(args, f"--timeout must be a finite number > 0 s, got {args.timeout}",
                    ExitCode.USAGE)
    if args.record and not args.attach:  # attach records nothing (the runner says so)
        refused = prepare_recording(args.record)
        if refused is not None:
            return fail(args, refused[0], refused[1])

    overrides = {}
    if args.world is not None:
        if not Path(args.world).is_file():
            return fail(args, f"--world must name a scene YAML file, got {args.world!r} (no "
                              "such file)", ExitCode.USAGE)
        overrides = {"sim_hardware": {"scene": str(Path(args.world).resolve())}}
    options = RunOptions(args.scene, record=args.record, overrides=overrides,
                         include_hidden_topics=args.include_hidden_topics, attach=args.attach,
                         processes=args.processes,
                         executor=args.executor, on_slip_alarm=args.on_slip_alarm,
                         max_attempts=args.max_attempts, resqueeze_margin=args.resqueeze_margin,
                         resist=not args.no_resist, planner=not args.no_planner,
                         timeout=args.timeout, namespace=args.namespace)
    show = not (args.quiet or args.json) and sys.stderr.isatty()
    try:
        result = PipelineRunner(options, _progress_line if show else None).run()
    except KeyboardInterrupt as exc:
        signum = getattr(exc, "signum", signal.SIGINT)
        print(f"\nsqueeze-grasp run: stopped by {signal.Signals(signum).name}; "
              f"{recording_state(args.record)}", file=sys.stderr)
        return 128 + signum
    except RunError as exc:
        return fail(args, str(exc), ExitCode.INTERNAL)
    finally:
        if show:
            sys.stderr.write("\n")
    stopped, lost = result.get("recording_stopped"), result.get("recording_lost")
    incompatible = result.get("recording_incompatible")
    if stopped is not None or lost or incompatible:
        print(json.dumps(result) if args.json else summary(result))
        if stopped is not None:
            print(f"squeeze-grasp run: the recording in {args.record} stopped early: "
                  f"{stopped}; it is readable up to there", file=sys.stderr)
        if lost:
            print(f"squeeze-grasp run: the recording in {args.record} is incomplete: "
                  f"{sum(lost.values())} messages never reached the recorder ("
                  + ", ".join(f"{topic} {n}" for topic, n in sorted(lost.items()))
                  + ")", file=sys.stderr)
        if incompatible:
            print(f"squeeze-grasp run: the recording in {args.record} is incomplete: nothing "
                  "was recorded from publishers whose QoS the recorder cannot take ("
                  + ", ".join(f"{topic}: {policy}" for topic, policy in
                              sorted(incompatible.items()))
                  + ")", file=sys.stderr)
        return ExitCode.INTERNAL
    if not result["success"]:
        print(json.dumps(result) if args.json else summary(result))
        return ExitCode.OUTCOME
    return result


def prepare_recording(folder: str) -> tuple[str, ExitCode] | None:
    """Create the recording folder and check that the bag's 256 kB reserve fits, before any
    node starts; (the reason, the exit code) if it cannot: 4 for a full disk or quota, else 2.

    Before, ``--record /proc/x`` and a read-only folder ended in tracebacks, and a disk with
    less than 256 kB free in a BagError traceback with a 0-byte ``.space_reserve`` left.
    """
    from squeeze_grasp_ros.ros.recording.bag import RESERVE_BYTES, SPACE_ERRORS

    path = Path(folder)
    created = not path.exists()
    try:
        path.mkdir(parents=True, exist_ok=True)
        handle, probe = tempfile.mkstemp(dir=path, prefix=".probe_")
        try:
            os.posix_fallocate(handle, 0, RESERVE_BYTES)
        finally:
            os.close(handle)
            os.unlink(probe)
    except OSError as exc:
        if created and path.is_dir():
            path.rmdir()
        name = errno.errorcode.get(exc.errno or 0, "")
        code = ExitCode.INTERNAL if exc.errno in SPACE_ERRORS else ExitCode.USAGE
        return (f"--record {folder}: cannot record there: {exc.strerror}"
                f"{f' ({name})' if name else ''}"
                + ("; a recording needs at least 256 kB free" if code == ExitCode.INTERNAL
                   else ""), code)
    return None


def recording_state(record: str | None) -> str:
    """What an interrupted run left behind, checked, not assumed."""
    if not record:
        return "nothing was recorded"
    from squeeze_grasp_ros.ros.recording.bag import BagError, read_bag

    if not (Path(record) / "metadata.yaml").is_file():
        return f"no recording was written ({record} has no bag)"
    try:
        count = len(read_bag(record).messages)
    except BagError as exc:
        return f"the recording in {record} is not readable: {exc}"
    return f"the recording in {record} is complete up to here ({count} messages)"


def _vector(v: list) -> str:
    return f"({v[0]:+.4f}, {v[1]:+.4f})"


def _resqueezes(result: dict) -> str:
    """The line of a goal that released and squeezed again after slip alarms."""
    released = "; ".join(
        f"{r['stamp_ns'] * 1e-9:.3f} s"
        + (f" after {r['after']['termination']} at {r['after']['depth'] * 1e3:.4f} mm"
           if r["after"] else "") for r in result["world_releases"]) or "never"
    return (f"re-squeezed: {result['attempts']} squeezes, the last planned to "
            f"{result['planned_depth'] * 1e3:.4f} mm; the world released the object at "
            f"{released}")


def _mirror(mirror: dict) -> str:
    """The line of the monitor's mirror tolerance derived for the object the camera saw."""
    derived = (f"(e + R dtheta / 2) / (2 h) for boundary spacing h {mirror['spacing_m'] * 1e3:.2f}"
               f" mm, outline error e {mirror['outline_error_m'] * 1e3:.3f} mm (the extraction's"
               f" tolerance), fingertip R {mirror['tip_radius_m'] * 1e3:g} mm, taxel pitch dtheta "
               f"{math.degrees(mirror['taxel_pitch_rad']):.2f} deg")
    if mirror.get("used", mirror["value"]) is None:
        return (f"monitor: mirror_tolerance {mirror['value']:.3f} derived = {derived}; not "
                "applied: the attached monitor runs with its own parameter")
    if mirror.get("used", mirror["value"]) != mirror["value"]:
        return (f"monitor: mirror_tolerance {mirror['used']:.3f} as set (derived "
                f"{mirror['value']:.3f} = {derived})")
    return f"monitor: mirror_tolerance {mirror['value']:.3f} = {derived}"


def summary(result: dict) -> str:
    """Human-readable report of a run."""
    counts = " ".join(f"{k} {v}" for k, v in result["event_counts"].items())
    monitor = " ".join(f"{k} {v}" for k, v in sorted(result["monitor_event_counts"].items()))
    alarms = ", ".join(f"{k} x{v}" for k, v in sorted(result["alarms"].items())) or "none"
    timing = result["timing"]
    lines = [
        f"{result['scene']}: {result['outcome']}",
        f"executor: {result['termination']} ({result['message']}) after "
        f"{result['ticks']} ticks = {result['sim_time']:.3f} s sim time; {result['mode']}, "
        f"plan from the {result['plan_source']}",
        f"depth {result['depth'] * 1e3:.4f} mm = {result['relative_depth'] * 100:.2f} % "
        f"(target {result['target_depth'] * 1e3:.4f} mm; measured "
        f"{result['measured_depth'] * 1e3:.4f} mm); held {result['hold_ticks']} ticks for stale "
        f"data{'; redirected on a slip alarm' if result['redirected'] else ''}",
        f"world (ground truth): termination {result['world_termination']}; events {counts}",
        f"monitor: events {monitor or 'none'}; alarms {alarms}",
        f"planner prediction: {result['prediction']['termination']} at "
        f"{result['prediction']['depth'] * 1e3:.4f} mm, {len(result['prediction']['events'])} "
        "events",
        "forces on the object [N]: "
        + "  ".join(f"{f} {_vector(v)}" for f, v in result["forces"].items()),
        "work [J]: "
        + "  ".join(
            f"{f} {w:.5f} (measured {result['measured_work'].get(f, 0.0):.5f})"
            for f, w in result["work"].items()
        ),
        f"wall time {timing['total']:.2f} s (plan {timing['plan']:.2f} s, nodes "
        f"{timing['start_nodes']:.2f} s, lockstep loop {timing['loop']:.2f} s)",
    ]
    # the watches' verdicts on the model: where the forces, then the shape, first left it
    verdicts = [f"first {kind}: {result['first_alarms'][kind]['message']}"
                for kind in (FORCE_MISMATCH, SHAPE_MISMATCH) if kind in result["first_alarms"]]
    lines[5:5] = verdicts
    if result["resqueezed"]:
        lines.insert(2, _resqueezes(result))
    seen = result.get("seen_outline")
    if seen:
        fit = seen.get("fit_residual_m")
        shape = seen["recognised"] + ("" if fit is None else f" fitted within {fit * 1e3:.3f} mm")
        lines.insert(1, f"camera: planned from the first frame's outline ({shape}, "
                        f"{seen['vertices']} vertices, {seen['holes']} holes, area "
                        f"{seen['area_m2'] * 1e4:.2f} cm^2 vs "
                        f"{seen['true_area_m2'] * 1e4:.2f} cm^2 true); seen vertices from the "
                        f"true outline: rms {seen['rms_m'] * 1e3:.3f} mm, max "
                        f"{seen['max_m'] * 1e3:.3f} mm (pixel {seen['pixel_m'] * 1e3:.3f} mm)")
        if seen.get("mirror_tolerance"):
            lines.insert(2, _mirror(seen["mirror_tolerance"]))
    if result["recording"]:
        lines.append(f"recording: {result['recording']}")
    return "\n".join(lines)
