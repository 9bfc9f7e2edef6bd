import numpy as np
import pytest
import torch

from gnngarment.body.anny_model import (
    ANNY_PRESETS,
    ANNY_SHAPE_RANGES,
    AnnyShape,
    sample_anny_shapes,
)
from gnngarment.body.motion import Motion
from gnngarment.body.procedural import make_motion
from gnngarment.body.rotations import axis_angle_to_matrix
from gnngarment.body.skeleton import JOINT_INDEX
from gnngarment.body.skinning import skin


def _single_joint_motion(joint, rotvec, frames=1, translation=(0.0, 0.0, 0.0)):
    rotations = np.zeros((frames, 24, 3))
    rotations[:, JOINT_INDEX[joint]] = rotvec
    return Motion(rotations, np.tile(translation, (frames, 1)), 30.0)


def test_rest_mesh_is_the_closed_body_component(anny_body, anny_rest):
    faces = anny_rest.faces
    assert anny_rest.vertices.shape == (13348, 3) and faces.max() == 13347
    edges = np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]), axis=1)
    _, counts = np.unique(edges, axis=0, return_counts=True)
    assert np.all(counts == 2)  # closed, manifold
    height = anny_rest.vertices[:, 2].max() - anny_rest.vertices[:, 2].min()
    assert 1.5 < height < 1.75


def test_tpose_joints(anny_rest):
    joints = anny_rest.joints
    for side, sign in (("L", 1), ("R", -1)):
        arm = joints[JOINT_INDEX[f"{side}_hand"]] - joints[JOINT_INDEX[f"{side}_shoulder"]]
        assert sign * arm[0] > 0.5 and abs(arm[1]) < 1e-5 and abs(arm[2]) < 1e-5
    assert joints[JOINT_INDEX["head"], 2] > joints[JOINT_INDEX["neck"], 2] > joints[0, 2]
    assert joints[JOINT_INDEX["L_ankle"], 2] < joints[JOINT_INDEX["L_knee"], 2] < joints[0, 2]
    assert joints[JOINT_INDEX["L_hip"], 0] > 0  # left is +X


def test_zero_motion_reproduces_rest(anny_body, anny_rest):
    posed = anny_body.pose(Motion.rest(2))
    assert torch.allclose(posed.vertices[1], anny_rest.vertices, atol=1e-5)
    assert torch.allclose(posed.joint_transforms, torch.eye(4).expand(2, 24, 4, 4), atol=1e-6)


def test_pelvis_rotation_is_rigid_about_the_pelvis(anny_body, anny_rest):
    rotvec = np.array([0.2, -0.4, 0.9])
    posed = anny_body.pose(_single_joint_motion("pelvis", rotvec, translation=(0.1, -0.2, 0.3)))
    R = axis_angle_to_matrix(torch.tensor(rotvec, dtype=torch.float32))
    pelvis = anny_rest.joints[0]
    expected = (anny_rest.vertices - pelvis) @ R.T + pelvis + torch.tensor([0.1, -0.2, 0.3])
    assert (posed.vertices[0] - expected).abs().max() < 1e-5
    assert torch.allclose(posed.joints[0, 0], pelvis + torch.tensor([0.1, -0.2, 0.3]), atol=1e-6)


def test_matches_annys_own_skinning(anny_body):
    """Our per-joint decomposition equals Anny's own forward pass (its skinning code) when
    each bone is given the pose G_j(bone) · T-pose correction · rest pose ('world'
    parameterization). Anny's identity 'local-ref' deltas give its *reference* pose,
    which differs from the rest mesh by up to ~1.4 cm, so we drive it in world poses."""
    rng = np.random.default_rng(0)
    rotations = 0.4 * rng.standard_normal((2, 24, 3))
    translation = rng.standard_normal((2, 3)) * 0.1
    posed = anny_body.pose(Motion(rotations, translation, 30.0))

    model = anny_body.anny
    with torch.no_grad():
        rest = model()
        heads = rest["rest_bone_heads"][0]
        correction = anny_body._rest_correction(heads)
        G = posed.joint_transforms.double()[:, torch.as_tensor(anny_body.bone_joint)]
        world = G @ correction @ rest["rest_bone_poses"]
        reference = model(pose_parameters=world, pose_parameterization="world")["vertices"]
    reference = reference[:, anny_body.body_vertex_indices].float()
    assert (posed.vertices - reference).abs().max() < 1e-4


@pytest.mark.parametrize("joint", ["L_elbow", "R_knee", "L_ankle", "head", "L_shoulder", "L_hand"])
def test_attached_point_follows_the_body(anny_body, anny_rest, joint):
    """A garment point 1 cm off a body vertex that Anny skins entirely to ``joint``,
    skinned with weight 1 on that joint, stays 1 cm from that vertex in a random pose."""
    weights = anny_body._weights.numpy()
    bone_joint = anny_body.bone_joint[anny_body._indices.numpy()]
    on_joint = np.where(weights > 1e-6, bone_joint == JOINT_INDEX[joint], True).all(axis=1)
    candidates = np.flatnonzero(on_joint)
    assert len(candidates) > 5
    vertex = int(candidates[len(candidates) // 2])
    rng = np.random.default_rng(1)
    motion = Motion(0.5 * rng.standard_normal((3, 24, 3)), rng.standard_normal((3, 3)), 30.0)
    posed = anny_body.pose(motion)
    point = anny_rest.vertices[vertex] + torch.tensor([0.0, 0.0, 0.01])
    w = torch.zeros(1, 24)
    w[0, JOINT_INDEX[joint]] = 1.0
    moved = skin(point[None], None, w, posed.joint_transforms)[:, 0]  # (T, 3)
    distance = (moved - posed.vertices[:, vertex]).norm(dim=-1)
    assert torch.allclose(distance, torch.full((3,), 0.01), atol=1e-4)


def test_garment_lbs_with_body_weights_tracks_walking_body(anny_body, anny_rest):
    """Summed per-joint Anny weights as garment weights: body vertices re-skinned by the 24
    transforms match the posed body exactly where Anny's bones of one vertex share one
    A→T-pose correction (most of the body); around the shoulders, where corrected upper-arm
    bones blend with uncorrected spine/clavicle bones, they differ by up to ~2 cm."""
    walk = make_motion("walk", duration=2.0)
    posed = anny_body.pose(walk)
    bone_joint = torch.as_tensor(anny_body.bone_joint)[anny_body._indices]
    weights = torch.zeros(len(anny_rest.vertices), 24, dtype=torch.float64)
    weights.scatter_add_(1, bone_joint, anny_body._weights.double())
    skinned = skin(anny_rest.vertices, None, weights.float(), posed.joint_transforms)
    error = (skinned - posed.vertices).norm(dim=-1).max(0).values  # worst frame per vertex
    assert error.median() < 1e-4
    assert torch.quantile(error, 0.99) < 0.015 and error.max() < 0.03


def test_shapes_presets_and_sampler(anny_body):
    tall = anny_body.rest(ANNY_PRESETS["tall_male"]).vertices
    petite = anny_body.rest(ANNY_PRESETS["petite_female"]).vertices
    assert np.ptp(tall[:, 2].numpy()) > np.ptp(petite[:, 2].numpy()) + 0.15
    shapes = sample_anny_shapes(4, seed=7)
    assert shapes == sample_anny_shapes(4, seed=7) and shapes != sample_anny_shapes(4, seed=8)
    for shape in shapes:
        for name, (low, high) in ANNY_SHAPE_RANGES.items():
            assert low <= getattr(shape, name) <= high
    assert anny_body.parse_shape("male") == ANNY_PRESETS["male"]
    with pytest.raises(ValueError, match="must be in"):
        AnnyShape(height=1.5)
    with pytest.raises(ValueError, match="unknown Anny shape"):
        anny_body.parse_shape("giant")


def test_shape_file(anny_body, tmp_path):
    (tmp_path / "s.yaml").write_text("gender: 1.0\nheight: 0.7\n")
    assert anny_body.parse_shape(str(tmp_path / "s.yaml")) == AnnyShape(gender=1.0, height=0.7)
    (tmp_path / "bad.json").write_text('{"gendr": 1.0}')
    with pytest.raises(ValueError, match="bad.json.*gendr"):
        anny_body.parse_shape(str(tmp_path / "bad.json"))


def test_feature_subset_and_body_features(anny_body):
    index = anny_body.feature_vertex_indices(512)
    assert index.shape == (512,) and len(np.unique(index)) == 512 and index[0] == 0
    assert np.array_equal(index, anny_body.feature_vertex_indices(512))
    D = anny_body.shape_features(ANNY_PRESETS["heavy_male"], 512)
    assert D.shape == (512, 24) and (D > 0).all() and D.max() < 2.0
    walk = make_motion("walk", duration=1.0)
    velocities = anny_body.subset_velocities(anny_body.pose(walk), walk.fps, 512)
    assert velocities.shape == (walk.num_frames, 512, 3)
    assert velocities[0].abs().max() == 0 and velocities[-1].norm(dim=-1).max() < 10.0


def test_a_four_second_walk_poses_every_frame(anny_body):
    walk = make_motion("walk", duration=4.0)
    anny_body.rest(ANNY_PRESETS["female"])
    posed = anny_body.pose(walk, ANNY_PRESETS["female"])
    assert posed.vertices.shape == (121, 13348, 3)
    assert torch.isfinite(posed.vertices).all()


def test_skinning_weights_follow_the_posed_body(anny_body) -> None:
    """The body's own weights summed per joint reproduce the posed body (the baseline's
    premise): skinning the rest body with them lands within ~2 cm almost everywhere."""
    import numpy as np
    import torch

    from gnngarment.body import make_motion, skin

    weights = anny_body.skinning_weights()
    assert weights.shape == (anny_body.rest().vertices.shape[0], 24)
    np.testing.assert_allclose(weights.sum(1), 1.0, atol=1e-5)
    motion = make_motion("walk", duration=0.5)
    posed = anny_body.pose(motion)
    skinned = skin(anny_body.rest().vertices, None, torch.from_numpy(weights),
                   posed.joint_transforms)
    error = (skinned - posed.vertices).norm(dim=-1)
    assert float(torch.quantile(error.flatten(), 0.95)) < 0.02
