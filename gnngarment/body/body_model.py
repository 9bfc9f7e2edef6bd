"""The interface every body model implements (:class:`BodyModel`)."""

from __future__ import annotations

import abc
import dataclasses
from typing import Any

import numpy as np
import torch

from gnngarment.body.features import joint_vertex_distances, vertex_velocities
from gnngarment.body.motion import Motion
from gnngarment.body.sampling import farthest_point_sampling


@dataclasses.dataclass(frozen=True)
class RestBody:
    """A body in the canonical rest pose (T-pose, Z up, metres).

    Attributes:
        vertices: ``(N_b, 3)`` float32 rest vertices.
        faces: ``(F_b, 3)`` int64 triangles (outward winding).
        joints: ``(24, 3)`` float32 rest joint positions, SMPL order.
    """

    vertices: torch.Tensor
    faces: np.ndarray
    joints: torch.Tensor


@dataclasses.dataclass(frozen=True)
class PosedBody:
    """A body posed by a motion.

    Attributes:
        vertices: ``(T, N_b, 3)`` float32 posed vertices (world, metres).
        joint_transforms: ``(T, 24, 4, 4)`` float32 skinning transforms ``G_j`` mapping
            rest world coordinates to posed world coordinates (SMPL's ``A``).
        joints: ``(T, 24, 3)`` float32 posed joint positions.
    """

    vertices: torch.Tensor
    joint_transforms: torch.Tensor
    joints: torch.Tensor


class BodyModel(abc.ABC):
    """A parametric body seen through the canonical 24-joint skeleton.

    Subclasses implement :meth:`rest`, :meth:`pose`, :meth:`default_shape` and
    :meth:`parse_shape`; the feature helpers are shared.
    """

    name: str = "body"

    @abc.abstractmethod
    def default_shape(self) -> Any:
        """The shape used when none is given."""

    @abc.abstractmethod
    def parse_shape(self, spec: str) -> Any:
        """A shape from a command-line spec (a preset name or a file)."""

    @abc.abstractmethod
    def rest(self, shape: Any = None) -> RestBody:
        """The rest body of ``shape`` (default shape if ``None``)."""

    @abc.abstractmethod
    def pose(self, motion: Motion, shape: Any = None) -> PosedBody:
        """Pose ``shape`` by every frame of ``motion`` (at the motion's own fps)."""

    def skinning_weights(self) -> np.ndarray:
        """``(N_b, 24)`` the body's own linear-blend-skinning weights per canonical joint
        (rows sum to 1); used by the body-skinning baseline."""
        raise NotImplementedError(f"{type(self).__name__} does not expose skinning weights")

    # ---- shared helpers ------------------------------------------------------------
    def feature_vertex_indices(self, count: int = 512) -> np.ndarray:
        """The fixed body-vertex subset: ``count`` indices ``(count,)`` into the rest
        vertices, by farthest-point sampling (seed vertex 0) on the default shape's rest
        mesh. Same topology ⇒ same indices for every shape."""
        cache: dict[int, np.ndarray] = self.__dict__.setdefault("_fps_cache", {})
        if count not in cache:
            vertices = self.rest(self.default_shape()).vertices.detach().cpu().numpy()
            cache[count] = farthest_point_sampling(vertices, count, start=0)
        return cache[count]

    def shape_features(self, shape: Any = None, count: int = 512) -> torch.Tensor:
        """Body-shape feature D: distances from the subset's rest vertices to the 24 rest
        joints, ``(count, 24)`` metres."""
        rest = self.rest(shape)
        index = torch.as_tensor(self.feature_vertex_indices(count))
        return joint_vertex_distances(rest.vertices[index], rest.joints)

    def subset_velocities(self, posed: PosedBody, fps: float, count: int = 512) -> torch.Tensor:
        """Body-vertex velocities on the subset, ``(T, count, 3)`` m/s (zero at frame 0)."""
        index = torch.as_tensor(self.feature_vertex_indices(count))
        return vertex_velocities(posed.vertices[:, index], fps)
