"""`animate_outfit`: garments that do not overlap come out as alone; layered ones stay
layered; chunked and one-pass agree; the outfit glb holds one mesh per garment."""

from __future__ import annotations

import numpy as np
import pytest

from gnngarment.geometry.garment_layers import LayerSettings, outward_faces
from gnngarment.inference.animate import animate
from gnngarment.inference.outfit import OutfitGarment, animate_outfit
from tests.inference.test_animate import scene  # noqa: F401 (the fixture)


def garments(scene, outer_radius: float, outer_low: float):  # noqa: F811
    pos, faces = scene["pos"].copy(), scene["faces"]
    pos[:, :2] *= 0.16 / 0.13                        # inner: just outside the 0.14 body
    outer = pos.copy()
    outer[:, :2] *= outer_radius / 0.16
    outer[:, 2] = outer_low + (outer[:, 2] - pos[:, 2].min())
    return [OutfitGarment("skirt", pos, faces), OutfitGarment("coat", outer, faces)]


def test_garments_apart_come_out_exactly_as_alone(scene) -> None:  # noqa: F811
    outfit = garments(scene, 0.2, 1.2)               # the "coat" hangs above the skirt
    result = animate_outfit(scene["model"], outfit, scene["body"], scene["frames"])
    assert result.relations == []
    for garment, animation in zip(outfit, result.animations, strict=True):
        alone = animate(scene["model"], garment.pos, garment.faces, scene["body"],
                        scene["frames"])
        np.testing.assert_array_equal(animation.posed, alone.posed)
        np.testing.assert_array_equal(animation.rest_pos, alone.rest_pos)


def test_layered_garments_stay_layered_and_chunks_agree(scene) -> None:  # noqa: F811
    outfit = garments(scene, 0.17, 0.55)             # the coat 1 cm outside the skirt
    body = scene["body"]
    one = animate_outfit(scene["model"], outfit, body, scene["frames"])
    assert one.order == [0, 1]
    chunked = animate_outfit(scene["model"], outfit, body, scene["frames"], chunk=1)
    for a, b in zip(one.animations, chunked.animations, strict=True):
        np.testing.assert_allclose(a.posed, b.posed, atol=1e-5)
    assert one.penetration[1].max() == 0.0
    # The resolved coat keeps the clearance over the skirt in every frame.
    from gnngarment.geometry.garment_layers import LayerCollider

    inner = one.animations[0].posed
    collider = LayerCollider(inner[0], outward_faces(one.animations[0].rest_pos,
                                                     outfit[0].faces, body.rest_vertices,
                                                     body.faces))
    settings = LayerSettings()
    for t in range(len(inner)):
        collider.move(inner[t])
        height, _ = collider.heights(one.animations[1].posed[t], settings)
        assert height.min() >= settings.clearance * 0.99


def test_the_order_given_is_the_order_used_and_must_name_everyone(scene) -> None:  # noqa: F811
    from gnngarment.geometry.garment_layers import LayerOrderError

    outfit = garments(scene, 0.17, 0.55)
    result = animate_outfit(scene["model"], outfit, scene["body"], scene["frames"],
                            layers=["coat", "skirt"])
    assert result.order == [1, 0]
    with pytest.raises(LayerOrderError, match="every garment"):
        animate_outfit(scene["model"], outfit, scene["body"], scene["frames"],
                       layers=["coat"])


def test_the_outfit_glb_has_one_mesh_per_garment_on_one_skeleton(scene, tmp_path) -> None:  # noqa: F811
    from gnngarment.inference.export.gltf_reader import evaluate_mesh_node, read_glb
    from gnngarment.inference.export.outfit_export import export_outfit

    result = animate_outfit(scene["model"], garments(scene, 0.17, 0.55), scene["body"],
                            scene["frames"])
    paths = export_outfit(result, tmp_path, formats=["glb", "pc2"])
    glb = read_glb(paths["glb"])
    assert [mesh["name"] for mesh in glb.document["meshes"]] == ["skirt", "coat", "body"]
    assert len(glb.document["skins"]) == 1
    coat = evaluate_mesh_node(glb, "coat")
    posed = result.animations[1].posed @ np.array([[1, 0, 0], [0, 0, 1], [0, -1, 0]]).T
    assert np.abs(coat - posed).max() < 1e-4
    assert (tmp_path / "coat.pc2").is_file() and (tmp_path / "skirt_body.pc2").is_file()
