# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""How the ``squeeze-grasp`` console script ends after a verb that used ROS
(:func:`squeeze_grasp_ros.entry.end_after_ros`): at once with the verb's exit code, after the
exit handlers and the flushed streams, and only when nothing is left running; and a recorded
run ended that way leaves a complete bag and the whole JSON summary.
"""
from __future__ import annotations

import json
import subprocess
import sys
import textwrap

import pytest
from executables import script

from squeeze_grasp_ros.resources import scene_file
from squeeze_grasp_ros.ros.recording.bag import bag_info, read_bag

PROLOGUE = """
import atexit, sys, threading
import rclpy
from rclpy.context import Context
from squeeze_grasp_ros.entry import end_after_ros

atexit.register(print, "exit handler ran", file=sys.stderr)
context = Context()
rclpy.init(context=context)
node = rclpy.create_node("probe", context=context)
sys.stdout.write("result")  # buffered (no newline, a pipe): only a flush writes it
"""


def _probe(body: str) -> subprocess.CompletedProcess:
    source = PROLOGUE + textwrap.dedent(body) + "print('returned'); sys.exit(7)\n"
    return subprocess.run([sys.executable, "-c", source], capture_output=True, text=True,
                          timeout=120)


def test_a_finished_ros_verb_ends_the_process_with_its_code_after_exit_handlers():
    done = _probe("""
        node.destroy_node()
        context.try_shutdown()
        end_after_ros(3)
    """)
    assert done.returncode == 3, done.stderr[-2000:]
    assert done.stdout == "result"  # flushed, and nothing after end_after_ros ran
    assert "exit handler ran" in done.stderr


@pytest.mark.parametrize("left", ["context", "thread"])
def test_nothing_is_cut_short_a_running_context_or_thread_means_the_normal_exit(left):
    """A context still holding ROS logging, or a non-daemon thread the interpreter would wait
    for: ``end_after_ros`` returns and the program goes on to its own exit.
    """
    done = _probe(f"""
        stop = threading.Event()
        if {left == 'thread'}:
            threading.Thread(target=stop.wait, args=(60,)).start()
            node.destroy_node()
            context.try_shutdown()
        end_after_ros(3)
        stop.set()
    """)
    assert done.returncode == 7, done.stderr[-2000:]
    assert done.stdout == "resultreturned\n"
    assert "exit handler ran" in done.stderr


def test_a_recorded_run_through_the_console_script_leaves_a_complete_bag(tmp_path):
    """The console script's fast end comes after the recorder closed its bag: every chunk, the
    footer and ``metadata.yaml`` are there, and the summary on stdout is whole.
    """
    bag = tmp_path / "bag"
    done = subprocess.run([script("squeeze-grasp"), "run", str(scene_file("foam_square")),
                           "--json", "--record", str(bag)],
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    summary = json.loads(done.stdout)
    contents = read_bag(bag)  # checks every CRC; refuses a file without its footer
    ticks = sum(m.topic == "/sim/tick" for m in contents.messages)
    assert ticks == summary["ticks"] + 1  # tick 0, then one per step of the goal
    assert (bag / "metadata.yaml").is_file()
    assert bag_info(bag)["message_count"] == len(contents.messages)


SWALLOWED = """
import os, signal, sys, types
from squeeze_grasp_ros import entry

def main():
    try:  # a C extension's import that swallows the interrupt, as numpy's did under load
        os.kill(os.getpid(), signal.SIGINT)
        sum(range(10 ** 6))  # the handler runs here
    except KeyboardInterrupt:
        pass  # cleared, as C code that sets its own error clears it: nothing chains it
    raise ImportError("PyCapsule_Import could not import module 'datetime'")

sys.modules["fake_verb"] = types.SimpleNamespace(main=main)
sys.exit(entry._run("fake_verb", "squeeze-grasp"))
"""


def test_an_import_that_swallows_ctrl_c_still_ends_with_one_line_and_130():
    """An interrupt swallowed by an import and replaced by an unchained ImportError (numpy's
    datetime capsule, hit by a Ctrl-C 0.1 s into ``squeeze-grasp sweep`` on a slow machine)
    is still the interrupt: exit 130 and one line, not the ImportError's traceback.
    """
    done = subprocess.run([sys.executable, "-c", SWALLOWED], capture_output=True, text=True,
                          timeout=60, preexec_fn=lambda: __import__("signal").signal(2, 0))
    assert done.returncode == 130, done.stderr
    assert done.stderr.strip() == "squeeze-grasp: stopped by SIGINT"
