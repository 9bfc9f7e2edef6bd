"""Bodies, the canonical 24-joint skeleton, garment skinning and motions.

Public API (shapes in each docstring):

* skeleton: :data:`JOINT_NAMES`, :data:`JOINT_PARENTS`, :data:`NUM_JOINTS`,
  :func:`forward_kinematics`;
* motions: :class:`Motion`, :class:`MotionError`, :func:`make_motion`,
  :func:`list_motions`, :func:`load_motion`, :func:`load_motion_for_body`,
  :func:`load_amass_motion`, :func:`load_bvh_motion`, :func:`load_cloth3d_motion`,
  :func:`motion_from_smpl`, :func:`with_lead_in`, :func:`lead_in_frames`,
  :func:`trim_reference_pose`;
* body models: :class:`BodyModel`, :class:`RestBody`, :class:`PosedBody`,
  :class:`AnnyBodyModel`, :class:`AnnyShape`, :data:`ANNY_PRESETS`,
  :func:`sample_anny_shapes`, :class:`SMPLBodyModel`, :func:`create_body_model`;
* skinning and features: :func:`skin`, :func:`farthest_point_sampling`,
  :func:`joint_vertex_distances`, :func:`motion_features`, :func:`motion_windows`,
  :func:`vertex_velocities`, :func:`velocity_windows`, :func:`sliding_windows`;
* configuration: :class:`BodyConfig`, :func:`load_body_config`.

Nothing heavy happens on import: Anny is built on first use (:func:`load_anny`).
"""

from gnngarment.body.anny_model import (
    ANNY_JOINT_BONES,
    ANNY_PRESETS,
    ANNY_SHAPE_RANGES,
    AnnyBodyModel,
    AnnyShape,
    load_anny,
    sample_anny_shapes,
)
from gnngarment.body.body_model import BodyModel, PosedBody, RestBody
from gnngarment.body.bvh_motion import load_bvh_motion
from gnngarment.body.cloth3d_motion import load_cloth3d_motion, read_cloth3d_info
from gnngarment.body.config import BodyConfig, load_body_config
from gnngarment.body.factory import create_body_model
from gnngarment.body.features import (
    joint_vertex_distances,
    motion_features,
    motion_windows,
    sliding_windows,
    velocity_windows,
    vertex_velocities,
)
from gnngarment.body.lead_in import (
    MAX_LEAD_IN_SECONDS,
    lead_in_frames,
    trim_reference_pose,
    with_lead_in,
)
from gnngarment.body.motion import Motion, MotionError
from gnngarment.body.motion_io import load_motion, load_motion_for_body
from gnngarment.body.procedural import MOTION_LIBRARY, list_motions, make_motion
from gnngarment.body.sampling import farthest_point_sampling
from gnngarment.body.skeleton import (
    JOINT_NAMES,
    JOINT_PARENTS,
    NUM_JOINTS,
    forward_kinematics,
)
from gnngarment.body.skinning import skin
from gnngarment.body.smpl_model import SMPLBodyModel, SMPLModelError
from gnngarment.body.smpl_motion import load_amass_motion, motion_from_smpl

__all__ = [
    "ANNY_JOINT_BONES",
    "ANNY_PRESETS",
    "ANNY_SHAPE_RANGES",
    "JOINT_NAMES",
    "JOINT_PARENTS",
    "MAX_LEAD_IN_SECONDS",
    "MOTION_LIBRARY",
    "NUM_JOINTS",
    "AnnyBodyModel",
    "AnnyShape",
    "BodyConfig",
    "BodyModel",
    "Motion",
    "MotionError",
    "PosedBody",
    "RestBody",
    "SMPLBodyModel",
    "SMPLModelError",
    "create_body_model",
    "farthest_point_sampling",
    "forward_kinematics",
    "joint_vertex_distances",
    "lead_in_frames",
    "list_motions",
    "load_amass_motion",
    "load_anny",
    "load_body_config",
    "load_bvh_motion",
    "load_cloth3d_motion",
    "load_motion",
    "load_motion_for_body",
    "make_motion",
    "motion_features",
    "motion_from_smpl",
    "motion_windows",
    "read_cloth3d_info",
    "sample_anny_shapes",
    "skin",
    "sliding_windows",
    "trim_reference_pose",
    "velocity_windows",
    "vertex_velocities",
    "with_lead_in",
]
