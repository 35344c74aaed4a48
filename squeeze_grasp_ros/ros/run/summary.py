# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The JSON summary of a finished run: ground truth, what the monitor measured, the plan."""
from __future__ import annotations

from collections import Counter
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from squeeze_grasp_interfaces.action import ExecuteGrasp
from squeeze_grasp_interfaces.msg import ContactEvent, SimState
from squeeze_grasp_ros.mechanics.vocabulary import EventType, Termination
from squeeze_grasp_ros.ros import messages
from squeeze_grasp_ros.ros.run.planning import Plan

__all__ = ["GRASP_HELD", "Observed", "event_list", "outcome", "run_summary"]

GRASP_HELD: tuple[str, ...] = ("none", Termination.PICKED_UP)
"""World terminations after which the grasp holds ("none": the world never ended)."""


@dataclass(frozen=True)
class Observed:
    """What the run's client received while the goal ran.

    Attributes
    ----------
    state : SimState
        The last ground-truth state.
    sim_events : sequence of ContactEvent
        Ground-truth events of the simulated world.
    world_end : dict or None
        ``{"termination", "depth", "stamp_ns"}`` once the world ended, else None (None again
        after a release).
    monitor_events : sequence of ContactEvent
        The monitor's events, from the sensors.
    alarms : Counter
        Alarm counts by type; ``first_alarm`` the first alarm of each type.
    world_releases : sequence of dict
        ``{"stamp_ns", "after"}`` of every release of the object by an ended world (after: the
        ``world_end`` it follows).
    """

    state: SimState
    sim_events: Sequence[ContactEvent]
    world_end: Mapping[str, Any] | None
    monitor_events: Sequence[ContactEvent]
    alarms: Counter
    first_alarm: Mapping[str, dict]
    world_releases: Sequence[Mapping[str, Any]] = ()


def event_list(events: Sequence[ContactEvent]) -> list[dict]:
    """JSON records of contact events."""
    return [messages.event_record(e) for e in events]


def outcome(observed: Observed, result: ExecuteGrasp.Result) -> str:
    """One sentence: did the grasp hold in the simulated world, and if not, why."""
    world = observed.state.termination or "none"
    if world in GRASP_HELD and result.success:
        return "grasp held" if world == "none" else "object picked up"
    if world not in GRASP_HELD:
        depth = observed.world_end["depth"] if observed.world_end else float("nan")
        stopped = ("the executor was stopped" if result.termination == "canceled" else
                   f"the executor ended {result.termination}")
        return f"grasp failed in the world: {world} at depth {depth * 1e3:.4f} mm; {stopped}"
    return f"executor did not finish: {result.termination} ({result.message})"


def run_summary(*, scene: str, mode: str, plan: Plan, observed: Observed,
                result: ExecuteGrasp.Result, recording: str | None,
                timing: Mapping[str, float]) -> dict[str, Any]:
    """JSON-able summary of a finished goal (ground truth and measured); SI units."""
    state = observed.state
    fingers = list(state.fingers)
    gt_events = list(observed.sim_events)
    return {
        "scene": scene,
        "mode": mode,
        "plan_source": plan.source,
        "termination": result.termination,
        "success": bool(result.success) and (state.termination or "none") in GRASP_HELD,
        "executor_success": bool(result.success),
        "outcome": outcome(observed, result),
        "message": result.message,
        "world_termination": state.termination or "none",
        "depth": float(state.contacts.depth),
        "relative_depth": float(state.contacts.relative_depth),
        "target_depth": float(plan.goal.depth),
        "measured_depth": float(result.depth),
        "ticks": int(result.ticks),
        "sim_time": float(result.duration),
        "hold_ticks": int(result.hold_ticks),
        "redirected": bool(result.redirected),
        "attempts": int(result.attempts),
        "resqueezed": bool(result.resqueezed),
        "planned_depth": float(result.planned_depth),
        "world_releases": list(observed.world_releases),
        "events": event_list(gt_events),
        "event_counts": {t: sum(1 for e in gt_events if e.type == t) for t in EventType.values()},
        "world_end": observed.world_end,
        "monitor_events": event_list(observed.monitor_events),
        "monitor_event_counts": dict(Counter(e.type for e in observed.monitor_events)),
        "alarms": dict(observed.alarms),
        "first_alarms": dict(observed.first_alarm),
        "prediction": {
            "termination": plan.prediction.termination,
            "depth": float(plan.prediction.depth),
            "events": event_list(plan.prediction.events),
        },
        "forces": {f: [v.x, v.y] for f, v in zip(fingers, state.forces)},
        "work": dict(zip(fingers, (float(w) for w in state.work))),
        "measured_forces": {f: [v.x, v.y] for f, v in zip(result.fingers, result.forces)},
        "measured_work": dict(zip(result.fingers, (float(w) for w in result.work))),
        "contacts": messages.contact_records(state.contacts),
        "recording": recording,
        "timing": dict(timing),
    }
