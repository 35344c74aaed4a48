# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The contact model of a large-deformation solid: the event-driven squeeze, unchanged, on a
corotational or neo-Hookean object.

The stepper asks a contact model for the response F(delta) of a contact set and its tangent,
for boundary displacements (gaps of Event A, in the deformed geometry), for the strain of the
limit and for the strain energy. :class:`ContactModel` answers with the linear reduced
stiffness; :class:`NonlinearContactModel` solves the finite-deformation equilibrium of the
whole object with the contact displacements prescribed
(:class:`~squeeze_grasp_ros.mechanics.elastic.contact_response.ContactResponse`), so contact
normals, gaps and sliding are those of the current configuration. The strain limit uses the
model's own measure (:attr:`~squeeze_grasp_ros.mechanics.vocabulary.MaterialModel.strain_measure`:
Biot for corotational, log for neo-Hookean). The neo-Hookean law is assembled by its compiled
kernel (:mod:`~squeeze_grasp_ros.mechanics.elastic.hyperelastic_numba`) when
``SQUEEZE_GRASP_KERNEL=numba`` asks for the compiled route (:mod:`.fixed_set_kernel`), and, with
the variable unset, on objects of at least :data:`COMPILED_ASSEMBLY_NODES` nodes when numba is
installed (:func:`compiled_assembly`). What depends on the mesh alone (the assembly geometry,
the factor's pattern layout) is kept on the object for all of its contact models.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from squeeze_grasp_ros.extras import installed
from squeeze_grasp_ros.mechanics.elastic.compliance import ElasticObject, node_dofs
from squeeze_grasp_ros.mechanics.elastic.contact_response import (
    NEWTON_TOL,
    ContactResponse,
    Evaluation,
    ResponseFailure,
)
from squeeze_grasp_ros.mechanics.elastic.hyperelastic import MeshGeometry, mesh_geometry
from squeeze_grasp_ros.mechanics.elastic.interior import (
    PatternLayout,
    TangentFactor,
    default_factorizer,
)
from squeeze_grasp_ros.mechanics.elastic.material import require_poisson_ratio
from squeeze_grasp_ros.mechanics.elastic.strain_measures import max_principal_strain
from squeeze_grasp_ros.mechanics.errors import InvalidInputError
from squeeze_grasp_ros.mechanics.squeeze.contact_model import (
    ContactModel,
    Response,
    SetData,
    Solution,
    SolveFailure,
)
from squeeze_grasp_ros.mechanics.squeeze.fixed_set_kernel import Kernel, chosen
from squeeze_grasp_ros.mechanics.vocabulary import MaterialModel, StrainCriterion
from squeeze_grasp_ros.threads import one_blas_thread

__all__ = ["COMPILED_ASSEMBLY_NODES", "NonlinearContactModel", "RESPONSE_ACCURACY",
           "compiled_assembly", "contact_model", "object_geometry"]

RESPONSE_ACCURACY = 100 * NEWTON_TOL
"""Relative accuracy of the contact forces of an interior solve converged to NEWTON_TOL; the
Newton on the sliding angles cannot resolve the cone better than this."""
STALL_HALVINGS = 10
"""Halvings of a step of the Newton on the sliding angles before it gives up (the linear
model's line search takes 30, each trial a matrix product; here each trial is an equilibrium
solve of the whole object). An exact Newton step that must be cut below 2^-10 of itself to
lower the cone residual is stalling at a minimum of the residual that is no solution of the
modes: in a neo-Hookean foam square it went on to 27 halvings a step over 14 iterations, 26 s
of evaluations, before the squeeze failed. No converged solve of 1,598 random hard squeezes
took more than 6 halvings but one, whose squeeze ended in a slip either way."""


COMPILED_ASSEMBLY_NODES = 6000
"""Objects of at least this many nodes assemble the neo-Hookean law compiled when numba is
installed and SQUEEZE_GRASP_KERNEL is unset: there one squeeze saves more CPU than numba's
import and cached-code load cost the process (0.30 s measured; the compiled assembly saved
0.06 / 0.15 / 0.46 s of a 12 % foam-square squeeze at 2,054 / 4,045 / 8,038 nodes, load 11)."""


def compiled_assembly(nodes: int) -> bool:
    """Whether the neo-Hookean law of an object of ``nodes`` nodes is assembled by the compiled
    kernel (:mod:`~squeeze_grasp_ros.mechanics.elastic.hyperelastic_numba`): as
    SQUEEZE_GRASP_KERNEL says when it is set (``numba``: yes, ``numpy``: no), else when the
    object has at least :data:`COMPILED_ASSEMBLY_NODES` nodes and numba is installed. The
    linear model's fixed-set route is :func:`~.fixed_set_kernel.selected`'s either way; the two
    assembly routes agree to about 1e-15 relative.

    >>> import os; os.environ["SQUEEZE_GRASP_KERNEL"] = "numpy"; compiled_assembly(20000)
    False
    >>> del os.environ["SQUEEZE_GRASP_KERNEL"]; compiled_assembly(500)
    False
    """
    route = chosen()
    if route is not None:
        return route == Kernel.NUMBA
    return nodes >= COMPILED_ASSEMBLY_NODES and installed("numba")


def object_geometry(obj: ElasticObject, length: float, *, compiled: bool) -> MeshGeometry:
    """The :func:`~squeeze_grasp_ros.mechanics.elastic.hyperelastic.mesh_geometry` of ``obj``'s
    mesh with coordinates / ``length``, kept on ``obj`` (its arrays read-only) for all of its
    contact models: a planner or a sweep squeezes one object many times, and on an 8,000-node
    mesh the geometry takes about 50 ms to build. ``compiled``: for the compiled neo-Hookean
    assembly (:mod:`~squeeze_grasp_ros.mechanics.elastic.hyperelastic_numba`).
    """
    kept = obj._shared.setdefault("mesh_geometry", {})
    key = (float(length), bool(compiled))
    if key not in kept:
        geometry = mesh_geometry(obj.mesh.nodes / length, obj.mesh.triangles, compiled=compiled)
        for array in (geometry.area, geometry.weighted_outer, geometry.slots, geometry.indices,
                      geometry.indptr, geometry.transpose, geometry.shape_gradients,
                      geometry.dofs, geometry.upper_slots, geometry.lower, geometry.gram,
                      geometry.gradient.data, geometry.force_operator.data):
            array.flags.writeable = False
        kept[key] = geometry
    return kept[key]


@dataclass(frozen=True)
class NonlinearContactModel(ContactModel):
    """A :class:`ContactModel` whose object follows a finite-deformation material law.

    Parameters
    ----------
    material_model : MaterialModel
        ``corotational`` or ``neo_hookean`` (``linear`` through this class is the linear law
        solved by Newton, used to cross-check the two routes).
    """

    material_model: MaterialModel = MaterialModel.COROTATIONAL

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.reference:
            raise InvalidInputError("the reference (paper-literal) route is linear only; use "
                                    "material.model: linear with --reference")
        if self.limits.criterion == StrainCriterion.COMPONENTWISE:
            raise InvalidInputError("strain_limit.criterion componentwise is defined for small "
                                    "strains only; use principal with a nonlinear model")

    @property
    def constitutive_model(self) -> MaterialModel:
        """The finite-deformation law of the object."""
        return MaterialModel(self.material_model)

    @property
    def adaptive_steps(self) -> bool:
        """True unless ``options`` switch it off: every evaluation is a nonlinear solve of the
        whole object, so the stepper adapts its substeps between events to the curvature of
        the force path.
        """
        return self.options.adaptive_substeps

    @property
    def dear_evaluations(self) -> bool:
        """True: every evaluation is a nonlinear solve of the whole object (event location
        skips those whose outcome the known values and slopes make sure).
        """
        return True

    # ------------------------------------------------------------------ the response
    def _response_of(self, sd: SetData) -> ContactResponse:
        responses = self._cache.setdefault("responses", {})
        key = tuple(sd.nodes.tolist())
        if key not in responses:
            mesh = self.obj.mesh
            if "geometry" not in self._cache:
                self._cache["geometry"] = object_geometry(
                    self.obj, self.length, compiled=compiled_assembly(len(mesh.nodes)))
            if "factorization" not in self._cache:
                layout = self.obj._shared.setdefault("pattern_layout", PatternLayout())
                self._cache["factorization"] = TangentFactor(layout=layout)
            shared = self._cache["factorization"]
            responses[key] = ContactResponse(MaterialModel(self.material_model),
                                             mesh.nodes / self.length, mesh.triangles,
                                             sd.nodes, self.obj.material.nu,
                                             geometry=self._cache["geometry"],
                                             factorization=shared,
                                             reuse=self.options.reuse_factorizations)
            last = self._cache.get("last")
            if last is not None:
                responses[key].continue_from(last)
        return responses[key]

    def set_data(self, nodes: tuple[int, ...]) -> SetData:
        """The set's nodes (its response is solved on demand and cached per set)."""
        key = tuple(int(k) for k in nodes)
        if len(key) < 2:
            raise InvalidInputError(f"the object lost contact: {len(key)} contact node(s) "
                                    "left; at least 2 are needed to hold it (Lemma 2)")
        idx = np.array(key)
        m = len(idx)
        return SetData(idx, np.zeros((2 * m, 2 * m)), np.zeros((2 * m, 3)), None, None, 1.0)

    def _evaluate(self, sd: SetData, delta: np.ndarray) -> Evaluation | ResponseFailure:
        response = self._response_of(sd)
        with one_blas_thread():  # numpy's BLAS threads spin between the factorisations
            out = response.evaluate(delta)
        if isinstance(out, Evaluation):
            last = self._cache.get("last")
            if last is not None and last is not response:
                last.forget()
            self._cache["last"] = response
            stats = self._cache.setdefault("nonlinear", {"evaluations": 0, "iterations": 0})
            stats["evaluations"] += 1
            stats["iterations"] += out.iterations
        return out

    def response(self, sd: SetData) -> Response:
        """F(delta) and dF/d delta from the finite-deformation equilibrium."""
        def nonlinear(delta: np.ndarray):
            out = self._evaluate(sd, delta)
            if isinstance(out, ResponseFailure):
                return SolveFailure(out.reason, out.residual, inverted=out.inverted,
                                    measure="interior")
            return out.F, out.C
        nonlinear.tolerance = RESPONSE_ACCURACY
        nonlinear.stall_halvings = STALL_HALVINGS
        return nonlinear

    def _field(self, sd: SetData, delta: np.ndarray) -> np.ndarray:
        response = self._response_of(sd)
        if not response.at(delta):
            out = self._evaluate(sd, delta)
            if isinstance(out, ResponseFailure):
                raise SolveFailure(out.reason, out.residual, measure="interior").error()
        return response.state_u()

    # ------------------------------------------------------------------ fields
    def full_displacement(self, sd: SetData, delta: np.ndarray, F: np.ndarray) -> np.ndarray:
        """Dimensionless displacement of every node (2n,) at contact displacements ``delta``."""
        return self._field(sd, delta)

    def boundary_displacement(self, sd: SetData, delta: np.ndarray, F: np.ndarray,
                              rows: np.ndarray | None = None) -> np.ndarray:
        """Dimensionless displacement (k, 2) of boundary loop positions ``rows`` (all if None)."""
        b = self.boundary_nodes
        rows = np.arange(len(b)) if rows is None else np.asarray(rows, int)
        return self._field(sd, delta)[node_dofs(b[rows])].reshape(-1, 2)

    def boundary_rate(self, sd: SetData, sol: Solution, rows: np.ndarray) -> np.ndarray:
        """d/ds of the boundary displacement at ``sol`` (interior follows the tangent)."""
        self._field(sd, sol.delta)
        b = self.boundary_nodes
        du = self._response_of(sd).rate(sol.ddelta)
        return du[node_dofs(b[np.asarray(rows, int)])].reshape(-1, 2)

    def strain_energy(self, sd: SetData, delta: np.ndarray, F: np.ndarray) -> float:
        """Dimensionless strain energy of the finite-deformation state."""
        self._field(sd, delta)
        return self._response_of(sd).state_energy()

    def field_strain(self, u_hat: np.ndarray) -> tuple[float, int]:
        """(largest absolute principal strain in :attr:`strain_measure`, element)."""
        return max_principal_strain(self.field_deformation(u_hat), self.strain_measure)

    def _max_strain(self, sd: SetData, delta: np.ndarray, F: np.ndarray) -> tuple[float, int]:
        """(largest strain in :attr:`strain_measure`, element) of the configuration."""
        return self.field_strain(self._field(sd, delta))

    def area_ratio(self, sd: SetData, delta: np.ndarray, F: np.ndarray) -> tuple[float, int]:
        """(smallest det F, element) of the finite-deformation state (no extra solve)."""
        return self.field_area_ratio(self._field(sd, delta))

    def diagnostics(self) -> dict:
        """The assembly route (``assembly``: numpy or numba, :func:`compiled_assembly`),
        Newton evaluations, iterations and factorisations of the interior solves, the
        contact sets that solved with the factorisation of the set they grew from, bordered,
        instead of one of their own (``bordered``), the evaluations answered by a kept state
        (look-ups), the factoriser, its orderings and
        symbolic analyses (one per object: every contact set shares them) and the tangents its
        Cholesky factorisation refused (LDL^T instead).
        """
        responses = self._cache.get("responses", {}).values()
        shared = self._cache.get("factorization")
        geometry = self._cache.get("geometry")
        compiled = (geometry.compiled if geometry is not None
                    else compiled_assembly(len(self.obj.mesh.nodes)))
        return {"material_model": str(self.material_model),
                "assembly": (Kernel.NUMBA if compiled else Kernel.NUMPY).value,
                "factorizer": str(shared.method if shared else default_factorizer()),
                "ldlt_fallbacks": shared.fallbacks if shared else 0,
                "analyses": shared.analyses if shared else 0,
                "evaluations": sum(r.stats["evaluations"] for r in responses),
                "newton_iterations": sum(r.stats["iterations"] for r in responses),
                "factorizations": sum(r.stats["factorizations"] for r in responses),
                "bordered": shared.bordered if shared else 0,
                "look_ups": sum(r.stats["look_ups"] for r in responses),
                "load_substeps": sum(r.stats["substeps"] for r in responses)}


def contact_model(material_model: MaterialModel | str, obj: ElasticObject, *args,
                  **kwargs) -> ContactModel:
    """The contact model of ``material_model`` for ``obj``: the linear one (reduced stiffness)
    or the finite-deformation one; arguments as :class:`ContactModel`.

    Raises
    ------
    InvalidInputError
        For an unknown model, or a Poisson's ratio of ``obj`` outside the model's
        :data:`~squeeze_grasp_ros.mechanics.elastic.material.POISSON_RANGES` (a scene is
        checked when it loads; this is the check of every other caller).
    """
    if material_model not in MaterialModel.values():
        choices = ", ".join(MaterialModel.values())
        raise InvalidInputError(f"material_model must be one of {choices}, got "
                                f"{material_model!r}")
    model = MaterialModel(material_model)
    require_poisson_ratio(obj.material.nu, model)
    if model == MaterialModel.LINEAR:
        return ContactModel(obj, *args, **kwargs)
    return NonlinearContactModel(obj, *args, material_model=model, **kwargs)
