# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""How the ``squeeze-grasp`` console script ends after a verb that used ROS
(entry._end_after_ros): at once, with the verb's exit code, its exit handlers run and its
buffered output written; a verb without ROS returns as usual (and ``entry.cli``, the function a
Python caller uses, always returns: test_recording_crafted measures replay's memory after it).
"""
from __future__ import annotations

import subprocess
import sys

SCRIPT = """
import atexit, sys
from squeeze_grasp_ros.entry import _end_after_ros
atexit.register(lambda: sys.stderr.write("handler ran\\n"))
sys.stdout.write("a result without a newline")
_end_after_ros({code})
sys.stdout.write("never reached")
"""


def test_the_exit_code_handlers_and_buffered_output_survive():
    for code in (0, 3, None):
        done = subprocess.run([sys.executable, "-c", SCRIPT.format(code=code)],
                              capture_output=True, text=True, timeout=60)
        assert done.returncode == (code or 0), done.stderr
        assert done.stdout == "a result without a newline"
        assert done.stderr == "handler ran\n"


def test_a_verb_without_ros_returns_to_the_caller():
    """The console script's function returns its verb's code (no ``os._exit``) when rclpy was
    never loaded: here ``plan``.
    """
    from squeeze_grasp_ros.resources import scene_file

    scene = str(scene_file("foam_square"))
    script = ("import sys\n"
              f"sys.argv = ['squeeze-grasp', 'plan', {scene!r}, '--json']\n"
              "from squeeze_grasp_ros.entry import cli_process\n"
              "code = cli_process()\n"
              "print('rclpy' in sys.modules, int(code), 'returned', file=sys.stderr)")
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                          timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stderr.strip().endswith("False 0 returned")
    assert done.stdout.startswith("{")
