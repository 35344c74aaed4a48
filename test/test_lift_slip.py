# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The lift watched on a gripper's joint feedback (docs/grippers.md, "The lift"): the monitor's
pickup verdict and weight slip against the closed form 2 mu F >= w from the joint efforts,
hostile weights, and the lift scenes end to end on real rclpy (held; heavier than planned:
slipped and held, or squeezed again deeper and held; on the action controllers where
control_msgs is built).
"""

from __future__ import annotations

import importlib.util
import math
import re
from pathlib import Path

import numpy as np
import pytest
import yaml
from pipeline_support import LogLines, write_scene
from rclpy.context import Context
from sensor_msgs.msg import JointState

from squeeze_grasp_ros.control.joint_feedback import WeightWatch
from squeeze_grasp_ros.mechanics.vocabulary import Termination
from squeeze_grasp_ros.ros.nodes import ParameterError
from squeeze_grasp_ros.ros.nodes.monitor import JointFeedback

SCENES = Path(__file__).resolve().parents[1] / "config" / "scenes"
SPONGE = SCENES / "sponge_gripper.yaml"
MU, WEIGHT, MARGIN = 0.6, 1.5, 1.25


def jaw_feedback(**extra) -> JointFeedback:
    params = {"controller_scene": str(SPONGE), "load_threshold": 0.002, "mu": MU,
              "joint_slip_window": 1e-4, "joint_slip_ratio": 0.5, "weight": WEIGHT,
              "weight_margin": MARGIN, **extra}
    return JointFeedback.of(params, [])


def test_the_pickup_verdict_is_the_closed_form_from_the_joint_efforts():
    """Joint states whose efforts stand for a jaw force rising, holding, then falling: the
    monitor's jaws report picked_up at the first state with 2 mu F >= margin w, and weight_slip
    for both jaws exactly at the states with 2 mu F < w after it (value 2 mu F / w); the
    force is read back through the device's transmission, not given to the watch.
    """
    jaws = jaw_feedback()
    gripper = jaws.controller.gripper
    poses = {"F1": np.array([0.0, -0.026]), "F2": np.array([0.0, 0.026])}
    rising = np.linspace(0.0, 2.0, 41)
    forces = np.concatenate([rising, np.full(5, 2.0), np.linspace(2.0, 0.5, 31),
                             np.linspace(0.5, 1.6, 12)])
    picked, alarmed, log = [], [], LogLines()
    for k, force in enumerate(forces):
        msg = JointState(name=list(gripper.transmission.joints),
                         position=list(gripper.joint_positions(0.045)),
                         effort=list(gripper.joint_efforts(float(force))))
        msg.header.stamp.nanosec = (k + 1) * 1_000_000
        fields = {f: {"position": p.copy()} for f, p in poses.items()}
        jaws.replace(fields, msg, log)
        picked.append(jaws.take_picked_up())
        weight = [a for a in jaws.alarms if a.type == Termination.WEIGHT_SLIP]
        alarmed.append(weight)
    carried = 2.0 * MU * forces / WEIGHT
    first = int(np.argmax(carried >= MARGIN))
    assert picked == [k == first for k in range(len(forces))]
    assert math.isclose(2.0 * MU * forces[first], MARGIN * WEIGHT, rel_tol=0.05)
    expect = [k > first and carried[k] < 1.0 for k in range(len(forces))]
    assert [bool(a) for a in alarmed] == expect and any(expect)
    for k in np.flatnonzero(expect):
        assert sorted(a.finger for a in alarmed[k]) == ["F1", "F2"]
        assert alarmed[k][0].value == pytest.approx(carried[k], rel=1e-12)
        assert "below the 1.25 N that carries the weight 1.5 N" in alarmed[k][0].message
    # recovering above w / (2 mu) clears the alarm without a second picked_up
    assert not alarmed[-1] and sum(picked) == 1
    assert any(line.startswith("picked up: jaw force") for line in log.lines)


def test_the_watch_starts_again_once_the_object_is_out_of_the_jaws():
    watch = WeightWatch(("F1", "F2"), mu=0.5, weight=1.0, margin=1.0, contact_force=0.01)
    assert watch.update(1.0) == (True, ())
    picked, alarms = watch.update(0.0)  # slipped out: the force falls to nothing
    assert not picked and [a.value for a in alarms] == [0.0, 0.0]
    assert watch.update(0.0) == (False, ()) and watch.update(1.0) == (True, ())


@pytest.mark.parametrize("weight, why", [
    (-1.0, "weight must be a finite number > 0 N (0: no pickup test), got -1.0"),
    (float("nan"), "weight must be a finite number > 0 N (0: no pickup test), got nan"),
    (float("inf"), "weight must be a finite number > 0 N (0: no pickup test), got inf"),
])
def test_a_hostile_weight_is_refused_naming_the_field_and_its_range(weight, why):
    with pytest.raises(ParameterError, match=re.escape(why)):
        jaw_feedback(weight=weight)
    with pytest.raises(ValueError, match=re.escape(why)):
        WeightWatch(("F1", "F2"), mu=MU, weight=weight)


def test_no_weight_no_pickup_test_and_a_bad_margin_or_mu_is_refused():
    assert jaw_feedback(weight=0.0).weight is None
    with pytest.raises(ParameterError, match=r"weight_margin must be a finite number >= 1, "
                                             r"got 0.9"):
        jaw_feedback(weight_margin=0.9)
    with pytest.raises(ParameterError, match=r"mu must be a finite number > 0 to carry a "
                                             r"weight by friction, got 0.0"):
        jaw_feedback(mu=0.0)


@pytest.mark.parametrize("pickup, why", [
    ({"weight": 0.0}, "pickup.weight must be > 0.0 N, got 0.0"),
    ({"weight": -1.0}, "pickup.weight must be > 0.0 N, got -1.0"),
    ({"weight": float("nan")}, "pickup.weight must be a finite number N, got nan"),
    ({"weight": 3.0, "lift_after": 0.0}, "pickup.lift_after must be > 0.0 s, got 0.0"),
    ({"weight": 3.0, "planned_weight": -2.0}, "pickup.planned_weight must be > 0.0 N, got -2.0"),
])
def test_a_hostile_scene_weight_is_refused_by_run_in_one_line(pickup, why, tmp_path):
    """``run`` of a lift scene whose pickup section is out of range: exit code 2 and one line
    naming the field and its range, no traceback.
    """
    import subprocess

    from executables import script

    data = yaml.safe_load((SCENES / "sponge_gripper_lift.yaml").read_text())
    data["pickup"] = pickup
    done = subprocess.run([script("squeeze-grasp"), "run", write_scene(tmp_path, data)],
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 2 and done.stdout == ""
    assert done.stderr == f"squeeze-grasp run: error: {why}\n"


def test_a_planned_weight_needs_a_controller():
    from squeeze_grasp_ros.scene import SceneError, parse_scene

    data = yaml.safe_load((SCENES / "sponge_gripper_lift_heavy.yaml").read_text())
    del data["controller"]
    with pytest.raises(SceneError, match=r"pickup.planned_weight needs a controller: section"):
        parse_scene(data)


@pytest.mark.parametrize("weight", [-1.0, float("nan")])
def test_the_monitor_node_refuses_a_hostile_weight_on_real_rclpy(weight, ros_context: Context):
    """Every route: the monitor's weight parameter, before any joint feedback is built."""
    from rclpy.parameter import Parameter

    from squeeze_grasp_ros.ros.nodes.monitor import MonitorNode

    with pytest.raises(ParameterError, match=r"parameter 'weight' must be a finite number >= 0 "
                                             r"N \(0: no pickup test\), got "):
        MonitorNode(context=ros_context, parameter_overrides=[Parameter("weight", value=weight)])


# --------------------------------------------------------------------------- the world's lift
def lift_world(weight: float, lift_after: float = 0.005):
    from squeeze_grasp_ros.scene import GraspSetup, parse_scene
    from squeeze_grasp_ros.sim.world import SimWorld

    data = yaml.safe_load((SCENES / "sponge_gripper_lift.yaml").read_text())
    data["pickup"] = {"weight": weight, "lift_after": lift_after}
    data["object"]["mesh"]["nodes"] = 400
    return SimWorld(GraspSetup.build(parse_scene(data)))


def jaw_setpoints(world, s: float) -> dict:
    """Both jaws of ``world`` at squeeze parameter ``s`` (m) from their placements."""
    return {t.name: np.asarray(t.center, float) + s * np.asarray(world.directions[t.name])
            for t in world.placements}


def vertical_supply(state, mu: float) -> dict:
    """Per finger, the vertical friction its sticking contact nodes can supply (N), computed
    here from the contact records: sum sqrt(mu^2 f_n^2 - f_t^2), f_n and f_t the force along
    and across each node's contact normal (Sec. 5.1's cone, out of the plane).
    """
    out = {"F1": 0.0, "F2": 0.0}
    for c in state.contacts:
        if c.mode != "stick":
            continue
        normal = np.array([np.cos(c.normal_angle), np.sin(c.normal_angle)])
        fn, ft = float(c.force @ normal), float(c.force @ np.array([-normal[1], normal[0]]))
        out[c.finger] += math.sqrt(max(mu * mu * fn * fn - ft * ft, 0.0))
    return out


@pytest.mark.parametrize("share", [0.98, 1.02])
def test_the_world_lifts_once_the_jaws_stand_still_and_judges_the_weight(share):
    """The world does not end the squeeze at the pickup criterion while the jaws close (the
    weight is carried long before 3 mm); it lifts lift_after (5 ticks) after they stop, and
    holds (picked_up, frozen) or lets the object slip out (weight_slip: no contact, no force,
    released once the jaws open clear of it) exactly as the criterion computed here from the
    contact nodes' forces says, for a weight 2 % below and above what the grip carries. The
    jaws standing at their placements before the squeeze lift nothing.
    """
    probe = lift_world(0.1)
    probe.start()
    step, steps = 1e-5, 300
    for k in range(1, steps + 1):
        out = probe.step(jaw_setpoints(probe, k * step))
        assert out.termination is None
    supply = vertical_supply(out.state, probe.model.mu)
    carried = 2.0 * min(supply.values())  # each jaw carries half the weight
    world = lift_world(share * carried)
    world.start()
    for _ in range(world.lift_ticks + 3):  # at the placements, before the squeeze: no lift
        assert world.step(jaw_setpoints(world, 0.0)).termination is None
    for k in range(1, steps + 1):
        out = world.step(jaw_setpoints(world, k * step))
    ends = []
    for _ in range(world.lift_ticks + 3):
        out = world.step(jaw_setpoints(world, steps * step))
        ends.append(out.termination)
    held = share < 1.0
    end = "picked_up" if held else "weight_slip"
    assert world.lift_ticks == 5 and ends == [None] * 4 + [end] * 4
    assert world.lift_margin == pytest.approx(share * carried / 2 - carried / 2, rel=1e-9)
    if held:
        assert len(out.state.contacts) > 0
        assert out.state.depth == pytest.approx(steps * step, rel=1e-9)
        return
    assert out.state.contacts == () and world.work["lifts"] == 1
    assert out.state.depth == pytest.approx(steps * step, rel=1e-9)
    released = []
    for k in range(steps, -300, -5):  # open past the placements: the object is released
        out = world.step(jaw_setpoints(world, k * step))
        released += [k] if out.released else []
    assert len(released) == 1 and out.termination is None


# --------------------------------------------------------------------------- on real rclpy
LIFT, HEAVY = SCENES / "sponge_gripper_lift.yaml", SCENES / "sponge_gripper_lift_heavy.yaml"


def lift_run(path, *, record: str | None = None, **options) -> dict:
    """Run a lift scene on real rclpy (planned by the mechanics): the summary, the joint states
    and the monitor's statuses.
    """
    from squeeze_grasp_interfaces.msg import MonitorStatus
    from squeeze_grasp_ros.ros.nodes import pipeline
    from squeeze_grasp_ros.ros.run.options import RunOptions
    from squeeze_grasp_ros.ros.run.runner import PipelineRunner

    runner = PipelineRunner(RunOptions(str(path), planner=False, record=record, **options))
    states, statuses = [], []
    runner.client.create_subscription(JointState, "joint_states", states.append,
                                      pipeline.loop_qos(4000))
    runner.client.create_subscription(MonitorStatus, pipeline.STATUS, statuses.append,
                                      pipeline.loop_qos(4000))
    run = runner.run()
    return {**run, "states": states, "statuses": statuses}


def jaw_forces(run: dict, path) -> np.ndarray:
    """The jaw force of every joint state (N), read back through the scene's transmission."""
    from squeeze_grasp_ros.scene import load_scene
    from squeeze_grasp_ros.scene.controller import scene_controller

    jaws = scene_controller(load_scene(path), path)
    return np.array([jaws.reading(s.name, s.position, s.effort).force for s in run["states"]])


def picked_up_stamp(run: dict) -> int:
    stamps = [s.header.stamp.sec * 10**9 + s.header.stamp.nanosec for s in run["statuses"]
              if any(e.type == "picked_up" for e in s.events)]
    assert len(stamps) >= 1
    return stamps[0]


def test_a_grip_that_carries_the_weight_is_picked_up_and_held(tmp_path):
    """sponge_gripper_lift on the JointTrajectory route, watched on joint_states alone: the
    monitor's picked_up comes at the first joint state whose effort gives 2 mu F >= 1.25 w,
    the squeeze stops there, the world lifts 5 ms later and its own criterion (the stepper's
    pickup margin, with the pads' tangential forces) holds; no alarm; replayed, the recorded
    joint states give the same verdict.
    """
    from squeeze_grasp_ros.ros.recording.replay import replay

    bag = tmp_path / "bag"
    run = lift_run(LIFT, record=str(bag))
    print(run["outcome"], run["message"], run["alarms"])
    assert run["outcome"] == "object picked up" and run["termination"] == "picked_up"
    assert run["world_termination"] == "picked_up" and run["alarms"] == {}
    forces, weight = jaw_forces(run, str(LIFT)), 3.0
    stamps = [s.header.stamp.sec * 10**9 + s.header.stamp.nanosec for s in run["states"]]
    first = stamps.index(picked_up_stamp(run))
    assert 2 * MU * forces[first] >= MARGIN * weight > 2 * MU * forces[first - 1]
    # the executor held: the jaw force after the pickup is the pickup's, above w / (2 mu)
    assert np.all(forces[first:] >= forces[first] - 1e-9)
    assert run["measured_forces"]["F1"][1] == pytest.approx(forces[first], rel=1e-9)
    replayed = replay(str(bag))
    assert replayed["alarms"] == 0


def test_an_object_heavier_than_planned_slips_and_the_executor_holds(tmp_path):
    """sponge_gripper_lift_heavy (4.2 N planned as 3 N): picked up at the planned weight, lifted,
    the world's criterion fails: the sponge slips out (world weight_slip, no contact), the jaw
    force on joint_states falls to zero, the monitor raises weight_slip (value 2 mu F / w = 0)
    and contact_lost for both jaws, and the executor ends slip_alarm holding; recorded and
    replayed, the same picked_up and the same four alarms.
    """
    from squeeze_grasp_ros.ros.recording.replay import replay

    bag = tmp_path / "bag"
    run = lift_run(HEAVY, record=str(bag))
    print(run["outcome"], run["message"], run["first_alarms"])
    assert run["world_termination"] == "weight_slip" and run["termination"] == "slip_alarm"
    assert run["message"] == "slip under the weight of F1, F2"
    assert run["alarms"].get("weight_slip") == 2 and run["alarms"].get("contact_lost") == 2
    first = run["first_alarms"]["weight_slip"]
    assert "jaw force 0 N below the 2.5 N that carries the weight 3 N" in first["message"]
    values = [a.value for s in run["statuses"] for a in s.alarms if a.type == "weight_slip"]
    assert values == [0.0, 0.0]
    forces = jaw_forces(run, str(HEAVY))
    assert forces[-1] == 0.0 and 2 * MU * forces.max() >= MARGIN * 3.0
    assert run["world_end"]["depth"] == pytest.approx(run["measured_depth"], rel=1e-9)
    # replayed into a fresh monitor, the recorded joint states give the same verdict
    replayed = replay(str(bag))
    assert replayed["alarms"] == 4 and [e["type"] for e in replayed["events"]] == ["picked_up"]


def test_the_heavy_object_is_squeezed_again_deeper_and_held(tmp_path):
    """With on_slip_alarm resqueeze: released, squeezed again to 1.25 x the depth of the alarm
    (deeper: a larger jaw force carries more), lifted again: held; the world's second squeeze
    is the mechanics API's squeeze from rest to that depth (forces within 0.1 %).
    """
    from squeeze_grasp_ros.scene import GraspSetup, load_scene

    slipped = lift_run(HEAVY)
    run = lift_run(HEAVY, on_slip_alarm="resqueeze")
    print(run["outcome"], run["message"], run["planned_depth"], run["world_releases"])
    assert run["termination"] == "picked_up" and run["world_termination"] == "picked_up"
    assert run["attempts"] == 2 and run["resqueezed"] and len(run["world_releases"]) == 1
    assert run["planned_depth"] == pytest.approx(1.25 * slipped["measured_depth"], rel=1e-9)
    assert run["depth"] == pytest.approx(run["planned_depth"], rel=1e-6)
    forces = jaw_forces(run, str(HEAVY))
    assert 2 * MU * forces[-1] >= 4.2  # the true weight, carried
    # the mechanics API's squeeze of the sponge (no pickup to end it) to the same depth
    data = yaml.safe_load(HEAVY.read_text())
    data.update(name="heavy_unlifted", effects=["friction"])
    del data["pickup"]
    direct = GraspSetup.build(load_scene(write_scene(tmp_path, data))).event_squeeze(
        depth=run["depth"])
    for name in ("F1", "F2"):
        want = direct.state.finger_force(name)
        got = np.array(run["forces"][name])
        assert np.linalg.norm(got - want) <= 1e-3 * np.linalg.norm(want)


@pytest.mark.parametrize("kind", ["parallel_gripper", "gripper_action"])
def test_the_weight_slip_under_an_action_controller(kind, tmp_path):
    """The lift scenes under a gripper action controller: at picked_up the gripper goal is
    canceled (the controller holds) and the arm lifts. The light sponge is held; the heavy one
    slips (slip_alarm), and with resqueeze the executor opens and squeezes again deeper with a
    new gripper goal, whose reached depth is lifted again: held.
    """
    if importlib.util.find_spec("control_msgs") is None:
        pytest.skip("control_msgs is not built: squeeze-grasp ros-setup --control-msgs DIR (DIR "
                    "a jazzy checkout of github.com/ros-controls/control_msgs)")
    controller = {"type": kind, "name": "gripper_controller", "device": "generic_85mm",
                  "goal_tolerance": 1e-7, "stall_timeout": 0.02}
    data = yaml.safe_load(LIFT.read_text())
    data.update(name=f"lift_{kind}", controller=controller)
    held = lift_run(write_scene(tmp_path, data))
    print(kind, held["outcome"], held["message"])
    assert held["termination"] == "picked_up" and held["world_termination"] == "picked_up"
    assert held["alarms"] == {}
    data = yaml.safe_load(HEAVY.read_text())
    data.update(name=f"heavy_{kind}", controller=controller)
    path = write_scene(tmp_path, data)
    slipped = lift_run(path)
    print(kind, slipped["outcome"], slipped["message"])
    assert slipped["world_termination"] == "weight_slip"
    assert slipped["termination"] == "slip_alarm" and slipped["alarms"].get("weight_slip") == 2
    run = lift_run(path, on_slip_alarm="resqueeze")
    print(kind, run["outcome"], run["message"], run["planned_depth"])
    assert run["termination"] == "picked_up" and run["world_termination"] == "picked_up"
    assert run["attempts"] == 2 and len(run["world_releases"]) == 1
    assert run["planned_depth"] == pytest.approx(1.25 * slipped["measured_depth"], rel=1e-9)
    assert 2 * MU * jaw_forces(run, path)[-1] >= 4.2


# --------------------------------------------------------------------------- the program
def lift_program(reaction: str = "hold", attempts: int = 2):
    from squeeze_grasp_ros.control.motion import GraspGoal, GraspProgram, MotionLimits

    goal = GraspGoal(("F1", "F2"), np.array([[0.0, 1.0], [0.0, -1.0]]) / np.sqrt(2), 0.005,
                     on_slip_alarm=reaction, max_attempts=attempts)
    return GraspProgram(goal, MotionLimits(lift_watch=0.003), ("F1", "F2"))


def observation(depth: float, alarms=(), events=()):
    from squeeze_grasp_ros.control.motion import Observation

    positions = {"F1": np.array([0.0, -0.025 + depth / np.sqrt(2)]),
                 "F2": np.array([0.0, 0.025 - depth / np.sqrt(2)])}
    return Observation(0, positions, {f: np.zeros(2) for f in positions},
                       {f: np.zeros(2) for f in positions}, tuple(alarms), tuple(events), depth)


SLIPPED = [("weight_slip", "F1"), ("weight_slip", "F2"), ("contact_lost", "F1"),
           ("contact_lost", "F2")]


@pytest.mark.parametrize("reaction", ["hold", "pure", "normals", "resqueeze"])
def test_the_program_holds_at_picked_up_and_reacts_to_a_weight_slip(reaction):
    """picked_up: hold the measured aperture and watch (state holding, no end); a weight slip
    with the jaws' contact lost at once: resqueeze releases to squeeze 25 % deeper than the
    alarm's depth, every other reaction ends slip_alarm (a redirection adds no force).
    """
    program = lift_program(reaction)
    program.step(observation(0.0), 0.001)
    command = program.step(observation(0.003, events=["picked_up"]), 0.001)
    assert command.state == "holding" and command.termination is None
    np.testing.assert_array_equal(command.setpoints["F1"], observation(0.003).positions["F1"])
    command = program.step(observation(0.003, SLIPPED), 0.001)
    if reaction == "resqueeze":
        assert command.state == "releasing" and command.termination is None
        assert program.planned_depth == pytest.approx(1.25 * 0.003, rel=1e-12)
        assert program.freed == {"F1", "F2"}  # the contact lost at the slip frees the jaws
        assert "slip under the weight at depth 3 mm" in command.message
    else:
        assert command.termination == "slip_alarm"
        assert command.message == "slip under the weight of F1, F2"


def test_the_lift_ends_picked_up_after_lift_watch_or_contact_lost_and_a_last_attempt_holds():
    program = lift_program()
    program.step(observation(0.0), 0.001)
    program.step(observation(0.003, events=["picked_up"]), 0.001)
    ends = [program.step(observation(0.003), 0.001).termination for _ in range(3)]
    assert ends == [None, None, "picked_up"]
    program = lift_program()
    program.step(observation(0.0), 0.001)
    program.step(observation(0.003, events=["picked_up"]), 0.001)
    assert program.step(observation(0.003, SLIPPED[2:]), 0.001).termination == "contact_lost"
    program = lift_program("resqueeze", attempts=1)
    program.step(observation(0.0), 0.001)
    program.step(observation(0.003, events=["picked_up"]), 0.001)
    assert program.step(observation(0.003, SLIPPED), 0.001).termination == "slip_alarm"
