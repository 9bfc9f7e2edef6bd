"""SMPL through smplx's loader, on a small synthetic model written in the SMPL format."""

import pickle

import numpy as np
import pytest
import torch

from gnngarment.body.motion import Motion
from gnngarment.body.skeleton import JOINT_INDEX
from gnngarment.body.skinning import skin
from gnngarment.body.smpl_model import SMPLBodyModel, SMPLModelError
from gnngarment.body.smpl_motion import SMPL_TO_CANONICAL
from tests.smpl_files import synthetic_smpl as _synthetic_smpl


@pytest.fixture(scope="module", params=["pkl", "npz"])
def smpl_file(tmp_path_factory, request):
    path = tmp_path_factory.mktemp("smpl") / f"SMPL_NEUTRAL.{request.param}"
    data = _synthetic_smpl()
    if request.param == "pkl":
        with open(path, "wb") as f:
            pickle.dump(data, f)
    else:
        np.savez(path, **data)
    return path


def test_rest_is_z_up(smpl_file):
    body = SMPLBodyModel(smpl_file)
    data = _synthetic_smpl()
    rest = body.rest()
    assert torch.allclose(
        rest.vertices.double(), torch.tensor(data["v_template"] @ SMPL_TO_CANONICAL.T), atol=1e-6
    )
    assert (
        rest.joints[JOINT_INDEX["head"], 2]
        > rest.joints[0, 2]
        > rest.joints[JOINT_INDEX["L_knee"], 2]
    )
    assert rest.faces.shape[1] == 3
    betas = body.parse_shape([1.0, -1.0])
    assert betas.shape == (10,) and not torch.allclose(body.rest(betas).vertices, rest.vertices)


def test_folder_lookup(smpl_file):
    assert SMPLBodyModel(smpl_file.parent).path.name.startswith("SMPL_NEUTRAL")


def test_pose_matches_joint_transforms(smpl_file):
    body = SMPLBodyModel(smpl_file)
    rng = np.random.default_rng(2)
    motion = Motion(0.4 * rng.standard_normal((3, 24, 3)), rng.standard_normal((3, 3)), 30.0)
    betas = body.parse_shape([0.5] * 10)
    posed = body.pose(motion, betas)
    assert torch.allclose(
        body.pose(Motion.rest(1), betas).vertices[0], body.rest(betas).vertices, atol=1e-5
    )
    # No pose correctives in the synthetic model and one-hot weights: every vertex follows its
    # joint's transform exactly, i.e. garment LBS with the transforms equals the body.
    data = _synthetic_smpl()
    weights = torch.tensor(data["weights"], dtype=torch.float32)
    skinned = skin(body.rest(betas).vertices, None, weights, posed.joint_transforms)
    assert (skinned - posed.vertices).abs().max() < 1e-5


def test_missing_file_says_where_to_get_it(tmp_path):
    with pytest.raises(SMPLModelError, match=r"smpl\.is\.tue\.mpg\.de"):
        SMPLBodyModel(tmp_path / "SMPL_MALE.pkl")
    with pytest.raises(SMPLModelError, match="SMPL_FEMALE"):
        SMPLBodyModel(tmp_path, gender="female")
    (tmp_path / "broken.pkl").write_bytes(b"not a pickle")
    with pytest.raises(SMPLModelError, match="broken.pkl"):
        SMPLBodyModel(tmp_path / "broken.pkl")


class _Payload:
    """Unpickling this creates a file: the proof that a pickle ran code."""

    def __init__(self, marker: str) -> None:
        self.marker = marker

    def __reduce__(self):
        return (open, (self.marker, "w"))


def test_npz_with_a_pickled_object_is_refused_without_running_it(tmp_path):
    """An SMPL .npz is untrusted input: an object array in it (a pickle) must not be
    unpickled - issue 15's repro ran os.system before the error."""
    marker = tmp_path / "payload_ran"
    data = _synthetic_smpl()
    data["v_template"] = np.array([_Payload(str(marker))], dtype=object)
    path = tmp_path / "SMPL_NEUTRAL.npz"
    np.savez(path, **data)
    with pytest.raises(SMPLModelError, match="pickled Python objects"):
        SMPLBodyModel(path)
    assert not marker.exists()
