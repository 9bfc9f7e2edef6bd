"""The default body model: Anny (PyPI ``anny``, Apache-2.0, assets in its wheel).

Anny's 104 bones are merged onto the 24 canonical joints (:data:`ANNY_JOINT_BONES`,
table in ``docs/body.md``). Each canonical rotation acts on **one** Anny bone (or, for
the feet and hands, on the group of toe/finger root bones, all about the group's mean
head); every other bone follows its nearest mapped ancestor rigidly. So each Anny bone
moves exactly with one canonical joint transform ``G_j``, and garment LBS with the 24
transforms is consistent with the posed body by construction.

The canonical rest pose is a T-pose: Anny's own A-pose is turned into it once per shape
by rotating the upper arm, forearm and hand bones (shortest arc) until each points
along ±X (``anny_rest_pose="native"`` keeps the A-pose). The rest mesh the library sees
is the **largest connected component** of Anny's mesh (the body; the tongue and eyes are
dropped), in Anny's own frame: Z up, metres, facing −Y, pelvis near the origin.
"""

from __future__ import annotations

import collections
import dataclasses
import functools
from pathlib import Path
from typing import Any

import numpy as np
import torch

from gnngarment.body.body_model import BodyModel, PosedBody, RestBody
from gnngarment.body.motion import Motion
from gnngarment.body.rotations import rotation_between
from gnngarment.body.skeleton import JOINT_NAMES, JOINT_PARENTS, NUM_JOINTS, forward_kinematics
from gnngarment.geometry.graph import largest_component

ANNY_PHENOTYPES: tuple[str, ...] = ("gender", "age", "muscle", "weight", "height", "proportions")


@dataclasses.dataclass(frozen=True)
class AnnyShape:
    """Anny phenotype parameters, each in [0, 1].

    ``gender`` 0 = male, 1 = female; ``age`` 1/3 ≈ child, 0.5 ≈ teenager (Anny's
    default), 2/3 ≈ young adult, 1 = old; ``height`` 0 → ~1.1 m, 1 → ~2.1 m at default
    age; ``muscle``, ``weight``, ``proportions`` 0.5 = average.
    """

    gender: float = 0.5
    age: float = 0.5
    muscle: float = 0.5
    weight: float = 0.5
    height: float = 0.5
    proportions: float = 0.5

    def __post_init__(self) -> None:
        for name in ANNY_PHENOTYPES:
            value = float(getattr(self, name))
            if not np.isfinite(value) or not 0.0 <= value <= 1.0:
                raise ValueError(f"Anny phenotype '{name}' must be in [0, 1], got {value}")
            object.__setattr__(self, name, value)

    def as_dict(self) -> dict[str, float]:
        return {name: getattr(self, name) for name in ANNY_PHENOTYPES}

    @classmethod
    def from_dict(cls, values: dict[str, Any], source: str = "<dict>") -> AnnyShape:
        unknown = set(values) - set(ANNY_PHENOTYPES)
        if unknown:
            raise ValueError(
                f"{source}: unknown Anny phenotype(s) {sorted(unknown)}; "
                f"expected some of {list(ANNY_PHENOTYPES)}"
            )
        try:
            return cls(**{key: float(value) for key, value in values.items()})
        except (TypeError, ValueError) as error:
            raise ValueError(f"{source}: {error}") from error

    @classmethod
    def from_file(cls, path: str | Path) -> AnnyShape:
        """Read a ``.json`` or ``.yaml`` mapping of phenotype values."""
        path = Path(path)
        if not path.is_file():
            raise ValueError(f"{path}: shape file not found")
        from gnngarment.config import MAPPING_SUFFIXES, ConfigError, parse_mapping_text

        if path.suffix.lower() not in MAPPING_SUFFIXES:
            raise ValueError(f"{path}: unknown shape file type (expected .json, .yaml or .yml)")
        text = path.read_text()
        try:
            values = parse_mapping_text(text, path.suffix, str(path))
        except ConfigError as error:  # names the file already
            raise ValueError(str(error)) from None
        except Exception as error:  # json syntax errors
            raise ValueError(f"{path}: cannot parse ({error})") from error
        if not isinstance(values, dict):
            raise ValueError(f"{path}: expected a mapping of phenotype values")
        return cls.from_dict(values, source=str(path))


# Named presets (documented in docs/body.md).
ANNY_PRESETS: dict[str, AnnyShape] = {
    "average": AnnyShape(),
    "female": AnnyShape(gender=1.0, age=2 / 3),
    "male": AnnyShape(gender=0.0, age=2 / 3),
    "petite_female": AnnyShape(gender=1.0, age=2 / 3, height=0.3, weight=0.35),
    "tall_male": AnnyShape(gender=0.0, age=2 / 3, height=0.75),
    "heavy_female": AnnyShape(gender=1.0, age=2 / 3, weight=0.95, muscle=0.4),
    "heavy_male": AnnyShape(gender=0.0, age=2 / 3, weight=0.95, muscle=0.5),
    "slim_male": AnnyShape(gender=0.0, age=2 / 3, weight=0.1, muscle=0.4),
    "muscular_male": AnnyShape(gender=0.0, age=2 / 3, muscle=1.0, weight=0.6),
    "older_female": AnnyShape(gender=1.0, age=0.95, weight=0.6),
}

# Range of the seeded sampler: adult bodies of varied build (documented in docs/body.md).
ANNY_SHAPE_RANGES: dict[str, tuple[float, float]] = {
    "gender": (0.0, 1.0),
    "age": (0.55, 0.95),
    "muscle": (0.2, 0.9),
    "weight": (0.1, 0.9),
    "height": (0.25, 0.75),
    "proportions": (0.2, 0.8),
}


def sample_anny_shapes(
    count: int, seed: int = 0, ranges: dict[str, tuple[float, float]] | None = None
) -> list[AnnyShape]:
    """``count`` shapes drawn uniformly in ``ranges`` (default :data:`ANNY_SHAPE_RANGES`)
    with ``numpy.random.default_rng(seed)``: same seed, same shapes."""
    ranges = {**ANNY_SHAPE_RANGES, **(ranges or {})}
    rng = np.random.default_rng(seed)
    shapes = []
    for _ in range(count):
        values = {name: rng.uniform(*ranges[name]) for name in ANNY_PHENOTYPES}
        shapes.append(AnnyShape(**values))
    return shapes


def _side(names: tuple[str, ...], side: str) -> tuple[str, ...]:
    return tuple(f"{name}.{side}" for name in names)


# Canonical joint → the Anny bone(s) its rotation acts on. Bones not listed follow their
# nearest listed ancestor (e.g. spine05/spine03 follow pelvis/spine1, upperleg02 follows
# the hip, lowerleg02 the knee, shoulder01 the collar, neck02/03 the neck, the thumb and
# metacarpals the wrist, the eyes the head).
ANNY_JOINT_BONES: dict[str, tuple[str, ...]] = {
    "pelvis": ("root",),
    "L_hip": ("upperleg01.L",),
    "R_hip": ("upperleg01.R",),
    "spine1": ("spine04",),
    "L_knee": ("lowerleg01.L",),
    "R_knee": ("lowerleg01.R",),
    "spine2": ("spine02",),
    "L_ankle": ("foot.L",),
    "R_ankle": ("foot.R",),
    "spine3": ("spine01",),
    "L_foot": _side(("toe1-1", "toe2-1", "toe3-1", "toe4-1", "toe5-1"), "L"),
    "R_foot": _side(("toe1-1", "toe2-1", "toe3-1", "toe4-1", "toe5-1"), "R"),
    "neck": ("neck01",),
    "L_collar": ("clavicle.L",),
    "R_collar": ("clavicle.R",),
    "head": ("head",),
    "L_shoulder": ("upperarm01.L",),
    "R_shoulder": ("upperarm01.R",),
    "L_elbow": ("lowerarm01.L",),
    "R_elbow": ("lowerarm01.R",),
    "L_wrist": ("wrist.L",),
    "R_wrist": ("wrist.R",),
    "L_hand": _side(("finger2-1", "finger3-1", "finger4-1", "finger5-1"), "L"),
    "R_hand": _side(("finger2-1", "finger3-1", "finger4-1", "finger5-1"), "R"),
}

# A-pose → T-pose: bone, the point (mean of bone heads) it should point at, target axis.
_TPOSE_ALIGNMENT: tuple[tuple[str, tuple[str, ...], tuple[float, float, float]], ...] = tuple(
    item
    for side, sign in (("L", 1.0), ("R", -1.0))
    for item in (
        (f"upperarm01.{side}", (f"lowerarm01.{side}",), (sign, 0.0, 0.0)),
        (f"lowerarm01.{side}", (f"wrist.{side}",), (sign, 0.0, 0.0)),
        (f"wrist.{side}", ANNY_JOINT_BONES[f"{side}_hand"], (sign, 0.0, 0.0)),
    )
)


@functools.lru_cache(maxsize=1)
def load_anny() -> Any:
    """The process-wide ``anny.Anny()`` instance.

    The first construction on a machine builds Anny's cache under ``~/.cache/anny``
    (about 1.5 minutes on 2 cores); later constructions take ~0.5 s. Cached here so
    a process never builds it twice.
    """
    try:
        import warp

        # Anny initialises warp on import; keep its start-up banner out of our output.
        warp.config.quiet = True
        if hasattr(warp, "LOG_ERROR"):
            warp.config.log_level = warp.LOG_ERROR
    except ImportError:  # pragma: no cover - warp is an Anny dependency
        pass
    try:
        import anny
    except ImportError as error:  # pragma: no cover - anny is a declared dependency
        raise ImportError(
            "the default body model needs the 'anny' package: pip install anny"
        ) from error
    model = anny.Anny()
    model.eval()
    return model


@dataclasses.dataclass(frozen=True)
class _AnnyRest:
    points: torch.Tensor  # (N_b, 24, 4) per-joint weighted rest points (see _rest_for)
    vertices: torch.Tensor  # (N_b, 3)
    joints: torch.Tensor  # (24, 3)


class AnnyBodyModel(BodyModel):
    """Anny behind the :class:`BodyModel` interface; shape = :class:`AnnyShape`.

    Args:
        rest_pose: ``"tpose"`` (canonical) or ``"native"`` (Anny's A-pose).
        anny_model: an ``anny.Anny`` instance to reuse; default :func:`load_anny`.
    """

    name = "anny"

    def __init__(self, rest_pose: str = "tpose", anny_model: Any = None) -> None:
        if rest_pose not in ("tpose", "native"):
            raise ValueError(f"rest_pose must be 'tpose' or 'native', got {rest_pose!r}")
        self.rest_pose = rest_pose
        self.anny = anny_model if anny_model is not None else load_anny()
        self.bone_labels: list[str] = list(self.anny.bone_labels)
        self.bone_parents: list[int] = [int(p) for p in self.anny.bone_parents]
        self._bone_index = {label: i for i, label in enumerate(self.bone_labels)}
        for i, parent in enumerate(self.bone_parents):
            if i > 0 and not 0 <= parent < i:
                raise RuntimeError("Anny bones are expected in parent-before-child order")
        self.bone_joint = self._map_bones()
        all_faces = self.anny.faces.detach().cpu().numpy().astype(np.int64)
        if all_faces.shape[1] != 3:
            raise RuntimeError(f"expected a triangle mesh from Anny, got faces {all_faces.shape}")
        num_vertices = int(self.anny.template_vertices.shape[0])
        self.body_vertex_indices, self._faces = largest_component(all_faces, num_vertices)
        self._weights = self.anny.vertex_bone_weights.detach()[self.body_vertex_indices]
        self._indices = self.anny.vertex_bone_indices.detach()[self.body_vertex_indices]
        self._cache: collections.OrderedDict[AnnyShape, _AnnyRest] = collections.OrderedDict()

    # ---- skeleton mapping -------------------------------------------------------------
    def _map_bones(self) -> np.ndarray:
        """Canonical joint followed by each Anny bone ``(104,)``; checks the tree."""
        bone_joint = -np.ones(len(self.bone_labels), dtype=np.int64)
        for j, name in enumerate(JOINT_NAMES):
            for label in ANNY_JOINT_BONES[name]:
                if label not in self._bone_index:
                    raise RuntimeError(f"Anny has no bone '{label}' (mapped to joint {name})")
                bone_joint[self._bone_index[label]] = j
        mapped = bone_joint.copy()
        for b in range(len(self.bone_labels)):
            if bone_joint[b] < 0:
                bone_joint[b] = bone_joint[self.bone_parents[b]]
        # The nearest mapped ancestor of each mapped bone must be its joint's parent.
        for b in np.flatnonzero(mapped >= 0):
            j = int(mapped[b])
            if j == 0:
                continue
            parent_joint = int(bone_joint[self.bone_parents[b]])
            if parent_joint != JOINT_PARENTS[j]:
                raise RuntimeError(
                    f"Anny bone '{self.bone_labels[b]}' ({JOINT_NAMES[j]}) hangs under "
                    f"{JOINT_NAMES[parent_joint]}, expected {JOINT_NAMES[JOINT_PARENTS[j]]}"
                )
        return bone_joint

    # ---- shapes -----------------------------------------------------------------------
    def default_shape(self) -> AnnyShape:
        return AnnyShape()

    def parse_shape(self, spec: str | AnnyShape | None) -> AnnyShape:
        """A preset name (:data:`ANNY_PRESETS`), a ``.json``/``.yaml`` file, or a shape."""
        if spec is None:
            return self.default_shape()
        if isinstance(spec, AnnyShape):
            return spec
        if spec in ANNY_PRESETS:
            return ANNY_PRESETS[spec]
        path = Path(spec)
        if path.suffix.lower() in (".json", ".yaml", ".yml") or path.exists():
            return AnnyShape.from_file(path)
        raise ValueError(
            f"unknown Anny shape '{spec}': expected a preset ({', '.join(ANNY_PRESETS)}) "
            "or a .json/.yaml file of phenotype values"
        )

    # ---- rest model -------------------------------------------------------------------
    def _rest_for(self, shape: AnnyShape) -> _AnnyRest:
        if shape in self._cache:
            self._cache.move_to_end(shape)
            return self._cache[shape]
        with torch.no_grad():
            output = self.anny(phenotype_kwargs=shape.as_dict())
        vertices = output["rest_vertices"][0].double()
        heads = output["rest_bone_heads"][0].double()
        transforms = self._rest_correction(heads)  # (104, 4, 4) Anny rest → canonical rest

        def moved(bone: int, point: torch.Tensor) -> torch.Tensor:
            return transforms[bone, :3, :3] @ point + transforms[bone, :3, 3]

        joints = torch.zeros(NUM_JOINTS, 3, dtype=torch.float64)
        for j, name in enumerate(JOINT_NAMES):
            bones = [self._bone_index[label] for label in ANNY_JOINT_BONES[name]]
            joints[j] = torch.stack([moved(b, heads[b]) for b in bones]).mean(0)
        # Per-vertex, per-joint rest points: u_vj = Σ_{b follows j} w_vb [T_b v; 1], so that
        # posed v = Σ_j G_j u_vj exactly reproduces Anny's LBS with T'_b = G_j(b) T_b.
        body = vertices[self.body_vertex_indices]  # (N_b, 3)
        bone_t = transforms[self._indices]  # (N_b, K, 4, 4)
        moved_points = (bone_t[..., :3, :3] @ body[:, None, :, None])[..., 0] + bone_t[..., :3, 3]
        weights = self._weights.double()
        homogeneous = torch.cat([moved_points, torch.ones_like(moved_points[..., :1])], -1)
        points = torch.zeros(len(body), NUM_JOINTS, 4, dtype=torch.float64)
        joint_of = torch.as_tensor(self.bone_joint)[self._indices]  # (N_b, K)
        points.scatter_add_(
            1, joint_of[..., None].expand(-1, -1, 4), weights[..., None] * homogeneous
        )
        rest = _AnnyRest(
            points=points.float(),
            vertices=points[..., :3].sum(1).float(),
            joints=joints.float(),
        )
        self._cache[shape] = rest
        if len(self._cache) > 16:
            self._cache.popitem(last=False)
        return rest

    def _rest_correction(self, heads: torch.Tensor) -> torch.Tensor:
        """Rigid transforms ``(104, 4, 4)`` that pose Anny's A-pose into the T-pose."""
        count = len(self.bone_labels)
        transforms = torch.eye(4, dtype=torch.float64).repeat(count, 1, 1)
        if self.rest_pose == "native":
            return transforms
        targets = {self._bone_index[bone]: (aim, axis) for bone, aim, axis in _TPOSE_ALIGNMENT}
        for b in range(1, count):
            parent = transforms[self.bone_parents[b]]
            transforms[b] = parent
            if b not in targets:
                continue
            aim_labels, axis = targets[b]
            aim = torch.stack([heads[self._bone_index[label]] for label in aim_labels]).mean(0)
            head = parent[:3, :3] @ heads[b] + parent[:3, 3]
            aim = parent[:3, :3] @ aim + parent[:3, 3]
            rotation = rotation_between(aim - head, torch.tensor(axis, dtype=torch.float64))
            about = torch.eye(4, dtype=torch.float64)
            about[:3, :3] = rotation
            about[:3, 3] = head - rotation @ head
            transforms[b] = about @ parent
        return transforms

    # ---- public interface -------------------------------------------------------------
    @property
    def faces(self) -> np.ndarray:
        """``(F_b, 3)`` int64 faces of the body component."""
        return self._faces

    def skinning_weights(self) -> np.ndarray:
        """Anny's per-bone vertex weights summed onto the canonical joint each bone
        follows, ``(N_b, 24)`` float32 (rows sum to 1)."""
        joint = torch.as_tensor(self.bone_joint)[self._indices.long()]
        weights = torch.zeros(self._weights.shape[0], NUM_JOINTS, dtype=torch.float64)
        weights.scatter_add_(1, joint, self._weights.double())
        weights /= weights.sum(1, keepdim=True).clamp_min(1e-12)
        return weights.numpy().astype(np.float32)

    def rest(self, shape: AnnyShape | None = None) -> RestBody:
        rest = self._rest_for(shape or self.default_shape())
        return RestBody(vertices=rest.vertices, faces=self._faces, joints=rest.joints)

    def pose(self, motion: Motion, shape: AnnyShape | None = None, chunk: int = 256) -> PosedBody:
        """Posed body ``(T, N_b, 3)`` and joint transforms ``(T, 24, 4, 4)`` (float32)."""
        rest = self._rest_for(shape or self.default_shape())
        rotations, translation = motion.to_torch(torch.float32)
        transforms, joints = forward_kinematics(rotations, rest.joints, translation)
        affine = transforms[:, :, :3, :]  # (T, 24, 3, 4)
        vertices = torch.cat(
            [
                torch.einsum("tjab,vjb->tva", affine[start : start + chunk], rest.points)
                for start in range(0, motion.num_frames, chunk)
            ]
        )
        return PosedBody(vertices=vertices, joint_transforms=transforms, joints=joints)
