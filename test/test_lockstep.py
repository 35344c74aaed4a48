# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The lockstep bookkeeping the executor and the monitor share (ros/nodes/pipeline.TickAnswer)."""
from __future__ import annotations

from squeeze_grasp_ros.ros.nodes.pipeline import TickAnswer


class Recorder:
    def __init__(self) -> None:
        self.sent: list = []

    def publish(self, msg) -> None:
        self.sent.append(msg)


def test_each_tick_is_answered_once_and_a_resent_tick_gets_the_same_answer():
    pub = Recorder()
    ticks = TickAnswer()
    assert ticks.is_new(0) and pub.sent == []
    ticks.answer(0, [(pub, "status 0")])
    assert pub.sent == ["status 0"]
    assert not ticks.is_new(0) and pub.sent == ["status 0", "status 0"]  # re-sent tick 0
    assert ticks.is_new(1_000_000)
    ticks.answer(1_000_000, [(pub, "status 1")])
    assert not ticks.is_new(0) and pub.sent[-1] == "status 1"  # an old tick: nothing new
    assert ticks.stamp_ns == 1_000_000
