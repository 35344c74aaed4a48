# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The simulated world: devices follow setpoints, the stepper moves the contact, sensors read it.

One :meth:`SimWorld.step` is one lockstep tick of ``scene.sim.dt`` seconds:

1. every device moves its fingertip toward its setpoint (:func:`.devices.follow`);
2. the per-tick translations of the fingertips in contact go to the incremental stepper
   (:func:`..mechanics.stepper.advance`), which locates the contact events on the way
   (ground truth); a tick that crosses no event on a linear object with every contact sticking
   is answered without the stepper's event loop, with the same result
   (:class:`..mechanics.squeeze.stepper.QuietSteps`);
3. the declared sensors read the new contact state (:mod:`.sensors`).

Only declared effects are composed (``scene.effects``): ``friction`` sets mu (else 0),
``strain_limit`` and ``pickup`` set the stepper's termination limits, ``adversary`` adds the
third fingertip and its pusher, ``force_sensing``/``tactile_sensing`` render wrenches/taxels,
``sensor_noise``/``sensor_dropout`` draw random numbers, ``actuator_lag`` lags the devices,
``camera`` renders the deformed object at its frame rate (:meth:`SimWorld.camera_frame`). Every
piece of optional work increments a counter of :attr:`SimWorld.work`; the wall and CPU time spent
in the stepper are :attr:`SimWorld.stepper_seconds` and ``stepper_cpu_seconds``, those of whole
ticks (devices, stepper, sensors) ``step_seconds`` and ``step_cpu_seconds`` (benchmarks subtract
them to measure what the nodes and their messages cost).

When the stepper reports a termination (a finger slips, the strain limit, pickup, a lost
contact) the object's motion can no longer be simulated: the world *ends*, the contact state
freezes (the sensors keep reading it) and the devices still follow their setpoints.

**The lift of a gripper scene** (effect ``pickup`` and a ``controller:`` section). A lab lifts
the object once its gripper has closed, so the squeeze is not ended by the stepper's pickup
criterion; instead, once every squeezing tip has squeezed (a positive depth) and stood still
in contact for ``pickup.lift_after`` s, the simulated arm lifts, and the world judges the lift
with the stepper's own criterion (:func:`~..mechanics.squeeze.stepper.functions.pickup_margin`:
each finger's sticking nodes supply sum sqrt(mu^2 f_n^2 - f_t^2) of vertical friction, against
its share of ``pickup.weight``, the true weight) on the contact state at that tick:

- it holds: the world ends ``picked_up`` (the object hangs in the jaws, the state frozen);
- it does not: the object slips out of the grip under its weight and stays behind on the
  plane: the world ends ``weight_slip`` with no contact (the tips hold no force), and
  releases the object as after any end once the tips are clear of it (below), so a re-squeeze
  starts from rest. The slip itself (the pads sliding along the object's height) is not
  followed: the jaws lose the object at the lift's tick.

**Release and a fresh squeeze.** An ended world whose fingertips have all left the object
(every tip of the frozen state clear of the object's outline *at rest*: a positive gap to every
outer boundary node, :meth:`~..mechanics.squeeze.tip_shapes.TipGeometry.gaps`) *releases* it at
that tick: the elastic object, quasi-static, relaxes to its rest configuration (no contacts,
zero forces, zero displacement; :attr:`TickOutput.released`) and the world runs again
(termination None). What happened to the object during the slip is not modelled: it is assumed
back at its rest pose in the object frame (the rigid shift of a real slip, the object's turn in
the jaws, is not simulated). While released, the tips move freely. When every released tip
touches the rest outline again (a gap <= 0), a fresh squeeze starts from the rest state at the
scene's placements (:func:`~..mechanics.squeeze.contact_state.initial_state`: a new mechanics
state on the same cached object and contact model), advanced at once by each tip's translation
past its placement. The world assumes the tips come back through their first-contact positions
(the executor's re-squeeze does); a tip that comes back elsewhere is still placed at its
first-contact node. A scene with an adversary that has touched the object does not release.

The adversary's pusher waits at its home (its fingertip touching the undeformed object at its
placement) until its setpoint first moves; then a guarded move places its fingertip on the
*deformed* boundary (:func:`..mechanics.resistance_friction.add_adversary`). The pusher's
position readings and setpoints stay in its own frame (its encoder counts from home), so
commands and measurements stay consistent; the ground truth (:class:`TickOutput` ``state``) has
the true tip centre.
"""

from __future__ import annotations

import time
from collections import Counter
from collections.abc import Mapping
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from squeeze_grasp_ros.mechanics.resistance.frictional import add_adversary
from squeeze_grasp_ros.mechanics.squeeze.contact_state import (
    ContactState,
    Event,
    FingerState,
    initial_state,
)
from squeeze_grasp_ros.mechanics.squeeze.stepper import QuietSteps
from squeeze_grasp_ros.mechanics.squeeze.stepper.functions import pickup_margin
from squeeze_grasp_ros.mechanics.squeeze.tip_shapes import TipGeometry
from squeeze_grasp_ros.mechanics.vocabulary import ContactMode, Effect, Finger, Termination
from squeeze_grasp_ros.perception.shape_match import deformed_outline
from squeeze_grasp_ros.scene import GraspSetup, SensorsSpec, finger_devices
from squeeze_grasp_ros.sim.camera import CameraFrame, SimCamera
from squeeze_grasp_ros.sim.devices import DeviceModel, device_model, follow
from squeeze_grasp_ros.sim.sensors import (
    FingerSensors,
    SensorRandomness,
    TactileLayout,
    tactile_layout,
)

RELEASED = "released"
"""The ``sim/events`` termination field at the tick an ended world released the object."""

TERMINATE_ON: tuple[str, ...] = (
    Termination.STRAIN_LIMIT,
    Termination.FINGER_SLIP,
    Termination.PICKED_UP,
)
"""Stepper terminations that end the simulated world (as in Algorithm 1)."""


class FingerReading(NamedTuple):
    """What one fingertip's devices and sensors report at a tick (SI, fingertip frame; a named
    tuple: one is built per finger and tick).

    Attributes
    ----------
    finger : str
    device : str
    position : (2,) ndarray
        Measured fingertip centre, m, object frame (the pusher's from its home, see the module).
    force, torque : (3,) ndarray or None
        Wrench the object applies to the fingertip (N, N m); None without force sensing or
        when the message was dropped.
    normal, tangential : (n,) ndarray or None
        Taxel forces, N; None without tactile sensing or when the message was dropped.
    """

    finger: str
    device: str
    position: np.ndarray
    force: np.ndarray | None = None
    torque: np.ndarray | None = None
    normal: np.ndarray | None = None
    tangential: np.ndarray | None = None


@dataclass(frozen=True)
class TickOutput:
    """Everything the world reports for one tick.

    Attributes
    ----------
    index : int
        Tick number (0 = the initial state).
    stamp_ns : int
        Sim time of the tick, ns (index * dt).
    readings : tuple of FingerReading
        One per finger, in finger order.
    events : tuple of Event
        Ground-truth events located during the motion into this tick, in processing order.
    termination : str or None
        Set from the tick at which the world ended on (None again once it released the object).
    state : ContactState
        Ground-truth contact state.
    released : bool
        True at the tick the ended world released the object (see the module).
    """

    index: int
    stamp_ns: int
    readings: tuple[FingerReading, ...]
    events: tuple[Event, ...]
    termination: str | None
    state: ContactState
    released: bool = False


@dataclass(frozen=True)
class WorldView:
    """Geometry for visualisation (object frame, m, N).

    Attributes
    ----------
    outline : (b, 2) ndarray
        Deformed outer boundary, counter-clockwise.
    tips : tuple of (str, (2,) ndarray, float)
        (finger, centre, radius) of every fingertip.
    contacts : tuple of (str, (2,) ndarray, str, (2,) ndarray)
        (finger, deformed node position, mode, force on the object) of every contact node.
    """

    outline: np.ndarray
    tips: tuple
    contacts: tuple


class SimWorld:
    """The simulated hardware's world for one scene (ROS-free, deterministic).

    Parameters
    ----------
    setup : GraspSetup
        A solid-model scene with rounded fingertips, made mechanics (precomputed here).
    quiet : bool
        Answer the ticks that cross no event without the stepper's event loop
        (:class:`~..mechanics.squeeze.stepper.QuietSteps`: the same results); False sends every
        tick through :func:`~..mechanics.squeeze.stepper.advance` (to compare the two).
    """

    def __init__(self, setup: GraspSetup, *, quiet: bool = True) -> None:
        scene = setup.scene
        self.setup = setup.precompute()
        self.scene = scene
        self._work: Counter = Counter()
        self.obj = setup.solid
        self.model = setup.contact_model()
        self.contacts = setup.contacts
        tips = setup.fingertips()
        motion = setup.motion
        self.directions, self.relative_per_depth = motion.directions, motion.relative_per_depth
        self.state = initial_state(tips, self.relative_per_depth)
        self.placements = tuple(tips)
        """The squeezing tips at their placements: where a fresh squeeze starts from rest."""
        self.rest_outline = self.obj.mesh.nodes[self.obj.mesh.boundary]
        """The outer boundary at rest (b, 2), m: what a released tip must clear and touch."""
        self.released = False
        """True while the object is released (at rest, no contacts; see the module)."""
        self.adversary = None
        if scene.has(Effect.ADVERSARY):
            self.adversary = setup.adversary_tip()
            tips.append(self.adversary)
        lag = scene.actuators.time_constant if scene.has(Effect.ACTUATOR_LAG) else 0.0
        devices = finger_devices(scene)
        self.fingers: tuple[str, ...] = tuple(t.name for t in tips)
        self.devices: dict[str, DeviceModel] = {
            t.name: device_model(devices[t.name], lag) for t in tips
        }
        self.radii = {t.name: t.radius for t in tips}
        self.tips = {t.name: TipGeometry(np.array([t.radius]), np.array([t.flat]),
                                         np.array([t.facing])) for t in tips}
        self.positions = {t.name: np.asarray(t.center, float) for t in tips}
        self.offsets = {t.name: np.zeros(2) for t in tips}
        sensors = scene.sensors
        self.layouts: dict[str, TactileLayout] = {}
        if scene.has(Effect.TACTILE_SENSING):
            layout = sensors if sensors is not None else SensorsSpec()
            taxels, span = layout.taxels, np.radians(layout.taxel_span_deg)
            # a pad's array covers its whole face: the flat and both rounded edges
            self.layouts = {t.name: tactile_layout(t.theta, taxels, span) if t.flat == 0.0
                            else tactile_layout(t.facing, taxels, 2 * t.flat / t.radius + np.pi,
                                                periodic=False)
                            for t in tips}
        self.force_sensing = scene.has(Effect.FORCE_SENSING)
        """Whether the fingers have wrench sensors (the scene's force_sensing effect)."""
        self.sensors = {t.name: FingerSensors(self.tips[t.name], self.layouts.get(t.name))
                        for t in tips}
        """Each finger's wrench sensor and tactile array (:class:`.sensors.FingerSensors`)."""
        self.randomness = SensorRandomness(
            sensors.seed if sensors is not None and sensors.seed is not None else 0,
            sensors.noise_std if scene.has(Effect.SENSOR_NOISE) else None,
            sensors.dropout if scene.has(Effect.SENSOR_DROPOUT) else None,
            self._work,
        )
        self.dt = scene.sim.dt
        self.dt_ns = int(round(scene.sim.dt * 1e9))
        self.index = 0
        self.termination: str | None = None
        self.stepper_seconds = 0.0
        self.stepper_cpu_seconds = 0.0
        self.step_seconds = 0.0
        self.step_cpu_seconds = 0.0
        self.step_size = scene.squeeze.step
        self.event_tol = scene.squeeze.event_tol
        self.lift_weight = (scene.pickup.weight if scene.has(Effect.PICKUP)
                            and scene.controller is not None else None)
        """The true weight a gripper scene's lift meets, N (None: no lift; see the module)."""
        self.lift_ticks = (max(1, int(round(scene.pickup.lift_after / scene.sim.dt)))
                           if self.lift_weight is not None else 0)
        self.still_ticks = 0
        """Ticks the squeezing tips have stood still in contact (the lift's count)."""
        self.lift_margin: float | None = None
        """The pickup margin at the lift, N (<= 0: held); None before a lift."""
        terminate_on = tuple(t for t in TERMINATE_ON if self.lift_weight is None
                             or t != Termination.PICKED_UP)
        self.stepper = QuietSteps(self.model, self.step_size, self.event_tol, terminate_on,
                                  quiet=quiet)
        self.camera = (SimCamera(scene.camera, scene.object.material.thickness, self.dt)
                       if scene.has(Effect.CAMERA) else None)

    @property
    def work(self) -> Counter:
        """Counted optional work: one counter per kind (sensor renderings, noise draws, lag
        updates, stepper calls, strain evaluations of the strain limit, ...); a kind never
        done has no entry.
        """
        work = Counter(self._work)
        if self.model.strain_evaluations:
            work["strain_evaluations"] = self.model.strain_evaluations
        return work

    # ----------------------------------------------------------------- ticks
    def start(self) -> TickOutput:
        """The readings of tick 0 (initial placement, no motion)."""
        return self._output(())

    def step(self, setpoints: Mapping[str, np.ndarray]) -> TickOutput:
        """Advance one tick toward ``setpoints`` (finger -> tip centre (2,), m, object frame).

        Fingers without a setpoint hold their position.
        """
        started, cpu = time.perf_counter(), time.thread_time()
        out = self._step(setpoints)
        self.step_seconds += time.perf_counter() - started
        self.step_cpu_seconds += time.thread_time() - cpu
        return out

    def _step(self, setpoints: Mapping[str, np.ndarray]) -> TickOutput:
        moves: dict[str, np.ndarray] = {}
        for name in self.fingers:
            if name not in setpoints:
                continue
            target = np.asarray(setpoints[name], float) + self.offsets[name]
            waiting = name == Finger.A and not self._adversary_touching()
            if waiting and np.any(target != self.positions[name]):
                target = self._touch_adversary(target)
            device = self.devices[name]
            if device.lagged:
                self._work["lag_updates"] += 1
            new = follow(device, self.positions[name], target, self.dt)
            moves[name] = new - self.positions[name]
            self.positions[name] = new
        self.index += 1
        events: tuple[Event, ...] = ()
        if self.termination is not None and self._tips_clear():
            self._release()
            return self._output(events, released=True)
        if self.released:
            if not self._tips_touch():
                self._release()
                return self._output(events)
            self._work["fresh_squeezes"] += 1
            self.state, self.released = initial_state(list(self.placements),
                                                      self.relative_per_depth), False
            moves = {t.name: self.positions[t.name] - np.asarray(t.center, float)
                     for t in self.placements}
        touching = {f.name for f in self.state.fingers}
        translations = {
            k: tuple(v) for k, v in moves.items() if k in touching and np.any(v != 0.0)
        }
        if translations and self.termination is None:
            self._work["stepper_calls"] += 1
            started, cpu = time.perf_counter(), time.thread_time()
            result = self.stepper.advance(self.state, translations)
            self.stepper_seconds += time.perf_counter() - started
            self.stepper_cpu_seconds += time.thread_time() - cpu
            self.state, events = result.state, result.events
            self.termination = result.termination
        if self.lift_weight is not None and self.termination is None:
            self._watch_lift(moves)
        return self._output(events)

    def _watch_lift(self, moves: Mapping[str, np.ndarray]) -> None:
        """Count the ticks the squeezing tips stood still in contact, once they have squeezed
        (a positive depth: not at the placements before the goal); lift after enough.
        """
        names = [t.name for t in self.placements]
        touching = {c.finger for c in self.state.contacts}
        still = all(not np.any(moves.get(n, 0.0)) for n in names)
        squeezed = touching >= set(names) and self.state.depth > 0.0
        self.still_ticks = self.still_ticks + 1 if still and squeezed else 0
        if self.still_ticks < self.lift_ticks:
            return
        self._work["lifts"] += 1
        contacts = self.state.contacts
        order = {n: k for k, n in enumerate(names)}
        self.lift_margin = pickup_margin(
            self.model.mu, np.array([c.normal_force() for c in contacts]),
            np.array([c.tangential_force() for c in contacts]),
            np.array([c.mode == ContactMode.STICK for c in contacts]),
            np.array([order[c.finger] for c in contacts]), list(range(len(names))),
            self.lift_weight)
        self.still_ticks = 0
        if self.lift_margin <= 0.0:
            self.termination = Termination.PICKED_UP
            return
        self.termination = Termination.WEIGHT_SLIP
        self.state = self._free_state(self.state.depth)

    def _adversary_touching(self) -> bool:
        return any(f.name == Finger.A for f in self.state.fingers)

    def _rest_gaps(self, names) -> np.ndarray:
        """Smallest gap (m) of each of the tips ``names`` at its position to the rest outline."""
        return np.array([self.tips[n].gaps(self.rest_outline, self.positions[n][None]).min()
                         for n in names])

    def _tips_clear(self) -> bool:
        """Every tip of the ended state is clear of the object at rest (no adversary)."""
        names = [f.name for f in self.state.fingers]
        return Finger.A not in names and bool(np.all(self._rest_gaps(names) > 0.0))

    def _tips_touch(self) -> bool:
        """Every squeezing tip touches (or enters) the object at rest."""
        return bool(np.all(self._rest_gaps([t.name for t in self.placements]) <= 0.0))

    def _release(self) -> None:
        """The object at rest and free: no contacts, the tips where the devices hold them."""
        if not self.released:
            self._work["releases"] += 1
        self.released, self.termination = True, None
        self.state = self._free_state()

    def _free_state(self, depth: float = 0.0) -> ContactState:
        """No contacts, the tips where the devices hold them (``depth``: the state's, m)."""
        return ContactState(
            tuple(FingerState(t.name, self.positions[t.name].copy(), t.radius, np.zeros(2),
                              flat=t.flat, facing=t.facing) for t in self.placements),
            (), depth, self.relative_per_depth)

    def _touch_adversary(self, target: np.ndarray) -> np.ndarray:
        """Place A on the deformed boundary; return its setpoint shifted by the same offset."""
        self._work["adversary_placements"] += 1
        field_ = self.displacement_field()
        self.state = add_adversary(
            self.state, self.model, field_, self.adversary.node, self.adversary.radius
        )
        touched = np.asarray(self.state.finger(Finger.A).center, float)
        offset = touched - self.positions[Finger.A]
        self.offsets[Finger.A] = self.offsets[Finger.A] + offset
        self.positions[Finger.A] = touched
        return target + offset

    def _output(self, events: tuple[Event, ...], *, released: bool = False) -> TickOutput:
        readings = tuple(map(self._read, self.fingers))
        return TickOutput(
            self.index, self.index * self.dt_ns, readings, events, self.termination, self.state,
            released,
        )

    def _read(self, name: str) -> FingerReading:
        """Sensor readings of finger ``name`` (dropout decided before noise is drawn)."""
        rnd, sensors = self.randomness, self.sensors[name]
        force = torque = normal = tangential = sensed = None
        if self.force_sensing and not rnd.dropped():
            self._work["wrench_evaluations"] += 1
            forces, geometry = sensed = self._sense(name)
            force, torque = sensors.wrench(forces, geometry)
            force, torque = rnd.perturb(force), rnd.perturb(torque, self.radii[name])
        if name in self.layouts and not rnd.dropped():
            self._work["tactile_renderings"] += 1
            forces, geometry = sensed or self._sense(name)
            normal, tangential = sensors.tactile(forces, geometry)
            normal, tangential = rnd.perturb(normal), rnd.perturb(tangential)
        return FingerReading(name, self.devices[name].name,
                             self.positions[name] - self.offsets[name], force, torque, normal,
                             tangential)

    def _sense(self, name: str) -> tuple:
        """Finger ``name``'s sensors reading its contact nodes (:meth:`.sensors.FingerSensors.
        read_arrays` of the state's :attr:`~.contact_state.ContactState.arrays`): (forces on
        the object (k, 2), N; their geometry).
        """
        arrays = self.state.arrays
        rows = arrays.rows(name)
        return self.sensors[name].read_arrays(arrays.thetas[rows], arrays.forces[rows],
                                              arrays.normal_angles[rows])

    # ----------------------------------------------------------------- geometry
    def _contact_solution(self) -> tuple:
        """(set data, dimensionless displacements, dimensionless forces) of the current
        contacts.
        """
        contacts = self.state.contacts
        sd = self.model.set_data(tuple(c.node for c in contacts))
        delta = np.array([c.displacement for c in contacts]) / self.model.length
        forces = np.array([c.force for c in contacts]) / self.model.force_unit
        return sd, delta, forces

    def displacement_field(self) -> np.ndarray:
        """Displacement (n, 2) of every mesh node, m (one sparse solve; counted)."""
        self._work["displacement_fields"] += 1
        if not self.state.contacts:  # released: the object at rest
            return np.zeros_like(self.obj.mesh.nodes)
        sd, delta, forces = self._contact_solution()
        return self.model.full_displacement(sd, delta, forces).reshape(-1, 2) * self.model.length

    def deformed_outline(self):
        """The deformed outline (outer boundary and holes), object frame, m (one sparse solve)."""
        return deformed_outline(self.obj.mesh, self.displacement_field())

    def camera_frame(self, index: int, stamp_ns: int) -> CameraFrame | None:
        """The camera's frame of tick ``index`` (sim time ``stamp_ns``) when the scene declares
        a camera and the tick takes one (its rate in sim time), else None (counted as
        ``camera_frames``).
        """
        if self.camera is None or not self.camera.due(index):
            return None
        self._work["camera_frames"] += 1
        return self.camera.render(self.deformed_outline(), stamp_ns)

    def view(self) -> WorldView:
        """Deformed outline, fingertips and contacts for display (counted as ``views``)."""
        self._work["views"] += 1
        mesh = self.obj.mesh
        outline = self.rest_outline
        if self.state.contacts:
            sd, delta, forces = self._contact_solution()
            outline = outline + (self.model.boundary_displacement(sd, delta, forces)
                                 * self.model.length)
        tips = tuple(
            (f.name, np.asarray(f.center, float), float(f.radius)) for f in self.state.fingers
        )
        contacts = tuple(
            (c.finger, mesh.nodes[c.node] + c.displacement, c.mode, c.force)
            for c in self.state.contacts
        )
        return WorldView(outline, tips, contacts)
