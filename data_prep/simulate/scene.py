"""One garment around one deforming body mesh in NVIDIA Newton (VBD cloth solver, CPU).

The body is a static mesh shape whose Warp mesh is rewritten every substep (points and
velocities interpolated between animation frames, BVH refit, bounding box updated) —
the recipe measured in NOTES.md. The cloth is a Newton cloth mesh; pinned vertices are
made kinematic (their ACTIVE flag cleared) and written before every substep.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from data_prep.simulate._backend import import_newton, import_warp
from data_prep.simulate.fabrics import FabricPreset
from data_prep.simulate.settings import SimulationSettings


def bending_stiffness_per_edge(pos: np.ndarray, edge_indices: np.ndarray,
                               bend_stiffness: float) -> np.ndarray:
    """Newton's per-edge dihedral stiffness for a shell of bending rigidity B.

    Newton's bending energy of an interior edge e is ½·k_e·|e|·(θ − θ̄)². The
    discrete-shells energy (Grinspun et al. 2003) is ½·B·3|e|²/A_e·(θ − θ̄)² with A_e
    the area of the two adjacent triangles, so k_e = 3·B·|e|/A_e, which makes the cloth's
    stiffness independent of its resolution.

    Args:
        pos: ``(N, 3)`` rest positions [m].
        edge_indices: ``(E, 4)`` Newton edges ``(o0, o1, v0, v1)``: opposite vertices
            then the edge's vertices, ``-1`` for a missing opposite vertex (boundary).
        bend_stiffness: B [N·m].

    Returns:
        ``(E,)`` float [N·m/m]; 0 on boundary edges (they carry no bending element).
    """
    o0, o1, v0, v1 = (edge_indices[:, i] for i in range(4))
    interior = (o0 >= 0) & (o1 >= 0)
    stiffness = np.zeros(len(edge_indices))
    a, b = pos[v0[interior]], pos[v1[interior]]
    edge = b - a
    area = 0.5 * (np.linalg.norm(np.cross(edge, pos[o0[interior]] - a), axis=1)
                  + np.linalg.norm(np.cross(edge, pos[o1[interior]] - a), axis=1))
    length = np.linalg.norm(edge, axis=1)
    stiffness[interior] = 3.0 * bend_stiffness * length / np.maximum(area, 1e-12)
    return stiffness


class ClothScene:
    """Newton model, solver, collision pipeline and states of one simulation attempt.

    Args:
        garment_rest: ``(N, 3)`` [m]; garment_faces ``(F, 3)``.
        body_rest: ``(N_b, 3)`` body vertices at frame 0 [m]; body_faces ``(F_b, 3)``.
        pinned: ``(P,)`` kinematic vertex indices.
        fabric: material; settings: solver/contact settings.
        substeps: solver steps per frame for this attempt.
        fps: frames per second.
    """

    def __init__(self, garment_rest: np.ndarray, garment_faces: np.ndarray,
                 body_rest: np.ndarray, body_faces: np.ndarray, pinned: np.ndarray,
                 fabric: FabricPreset, settings: SimulationSettings, substeps: int,
                 fps: float) -> None:
        newton = import_newton()
        self.substeps = substeps
        self.dt = 1.0 / (fps * substeps)
        self.pinned = pinned
        builder = newton.ModelBuilder(gravity=(0.0, 0.0, -settings.gravity))
        self.body_mesh = self._add_body(newton, builder, body_rest, body_faces, fabric,
                                        settings)
        self._add_cloth(builder, garment_rest, garment_faces, fabric, settings)
        # VBD solves one colour (independent vertex set) at a time; bending couples the
        # two opposite vertices of an edge, so they must be coloured apart too.
        builder.color(include_bending=True)
        self.model = builder.finalize(device="cpu")
        self._set_materials(fabric, settings)
        self._pin(newton)
        # The solver specialises its kernels on the materials: build it after setting them.
        self.solver = newton.solvers.SolverVBD(
            self.model, iterations=settings.iterations,
            friction_epsilon=settings.friction_smoothing,
            particle_enable_self_contact=settings.self_contact,
            particle_self_contact_margin=settings.self_contact_distance,
            particle_self_contact_gap=0.5 * settings.self_contact_distance)
        self.pipeline = newton.CollisionPipeline(self.model,
                                                 soft_contact_gap=settings.contact_gap)
        self.contacts = self.pipeline.contacts()
        self.state, self.next_state = self.model.state(), self.model.state()
        self.control = self.model.control()

    @staticmethod
    def _add_body(newton: Any, builder: Any, body_rest: np.ndarray, body_faces: np.ndarray,
                  fabric: FabricPreset, settings: SimulationSettings) -> Any:
        """Static mesh shape (no rigid body: body=-1); its Warp mesh moves every substep."""
        mesh = newton.Mesh(body_rest.astype(np.float32), body_faces.astype(np.int32).ravel(),
                           compute_inertia=False)
        cfg = newton.ModelBuilder.ShapeConfig(
            ke=settings.contact_stiffness, kd=settings.contact_damping, mu=fabric.friction,
            margin=0.0, density=0.0)
        cfg.has_shape_collision = False  # only cloth touches it
        builder.add_shape_mesh(body=-1, mesh=mesh, cfg=cfg)
        return mesh

    @staticmethod
    def _add_cloth(builder: Any, rest: np.ndarray, faces: np.ndarray, fabric: FabricPreset,
                   settings: SimulationSettings) -> None:
        wp = import_warp()
        builder.add_cloth_mesh(
            pos=wp.vec3(0.0, 0.0, 0.0), rot=wp.quat_identity(), scale=1.0,
            vel=wp.vec3(0.0, 0.0, 0.0), vertices=rest.astype(np.float32),
            indices=faces.astype(np.int32).ravel(), density=fabric.density,
            tri_ke=fabric.stretch_stiffness, tri_ka=fabric.area_stiffness,
            tri_kd=fabric.damping * fabric.stretch_stiffness,
            edge_ke=0.0, edge_kd=0.0,  # per-edge values set in _set_materials
            particle_radius=settings.particle_radius)

    def _set_materials(self, fabric: FabricPreset, settings: SimulationSettings) -> None:
        """Per-edge bending stiffness/damping and the contact material.

        Newton uses the mean of the model's and the shape's contact coefficients, so both
        get the same value.
        """
        model = self.model
        if model.edge_count:
            stiffness = bending_stiffness_per_edge(model.particle_q.numpy(),
                                                   model.edge_indices.numpy(),
                                                   fabric.bend_stiffness)
            properties = np.column_stack([stiffness, fabric.damping * stiffness])
            model.edge_bending_properties.assign(properties.astype(np.float32))
        model.soft_contact_ke = settings.contact_stiffness
        model.soft_contact_kd = settings.contact_damping
        model.soft_contact_mu = fabric.friction

    def _pin(self, newton: Any) -> None:
        if len(self.pinned) == 0:
            return
        flags = self.model.particle_flags.numpy()
        flags[self.pinned] &= ~np.int32(int(newton.ParticleFlags.ACTIVE))
        self.model.particle_flags.assign(flags)

    # ------------------------------------------------------------------ stepping

    def positions(self) -> np.ndarray:
        """Current cloth positions ``(N, 3)`` float32 [m] (a copy)."""
        return self.state.particle_q.numpy().copy()

    def advance(self, body_start: np.ndarray, body_end: np.ndarray, pins_start: np.ndarray,
                pins_end: np.ndarray) -> None:
        """Simulate one frame while the body moves from ``body_start`` to ``body_end``.

        Args:
            body_start, body_end: ``(N_b, 3)`` body vertices at the frame's start/end [m].
            pins_start, pins_end: ``(P, 3)`` pinned vertex targets at start/end [m].
        """
        body_start = body_start.astype(np.float32)
        body_step = body_end.astype(np.float32) - body_start
        velocity = body_step / (self.substeps * self.dt)
        for k in range(1, self.substeps + 1):
            w = k / self.substeps  # the body where the cloth ends this substep
            self._move_body(body_start + w * body_step, velocity)
            if len(self.pinned):
                # On the CPU .numpy() is a view: this writes the solver's input in place.
                self.state.particle_q.numpy()[self.pinned] = (1 - w) * pins_start + w * pins_end
            self.state.clear_forces()
            self.pipeline.collide(self.state, self.contacts)
            self.solver.step(self.state, self.next_state, self.control, self.contacts,
                             self.dt)
            self.state, self.next_state = self.next_state, self.state

    def _move_body(self, points: np.ndarray, velocity: np.ndarray) -> None:
        """Write the body pose into the collider (a stale BVH or bounding box lets cloth
        through: NOTES.md measured 5–19 % penetration)."""
        mesh = self.body_mesh.mesh
        mesh.points.numpy()[:] = points
        mesh.velocities.numpy()[:] = velocity
        mesh.refit()
        self.model.shape_collision_aabb_lower.numpy()[0] = points.min(axis=0)
        self.model.shape_collision_aabb_upper.numpy()[0] = points.max(axis=0)
