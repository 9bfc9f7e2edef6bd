"""`simulate_garment`: real Newton simulations of tiny garments (a few hundred vertices, a
few dozen frames), and its retries with more substeps.

The first simulation of a process compiles Newton's kernels: ~45 s with an empty Warp
cache (a fresh CI machine), under a second once cached in the home directory.
"""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from data_prep.simulate import SimulationFailed, SimulationSettings, simulate_garment
from data_prep.simulate.inside import signed_distance
from tests.data_prep.simulate.scenes import FPS, sphere, square
from tests.meshes import tube

GRAVITY = 9.81


def _capsule(radius: float = 0.12, height: float = 0.5) -> tuple[np.ndarray, np.ndarray]:
    capsule = trimesh.creation.capsule(height=height, radius=radius, count=[16, 16])
    assert capsule.is_watertight and capsule.volume > 0  # closed, outward winding
    return np.asarray(capsule.vertices), np.asarray(capsule.faces)


@pytest.fixture(scope="module")
def skirt_on_moving_capsule() -> dict:
    """A 280-vertex skirt tube, waist ring pinned, around a capsule that sways ±8 cm
    sideways and bobs 2 cm; 5 settle frames + 16 animated frames."""
    body_rest, body_faces = _capsule()
    pos, faces = tube(rings=10, sections=28, radius=0.16, height=0.3)
    pos = pos - np.array([0.0, 0.0, 0.25])  # waist ring at z = 0.05, hem at −0.25
    ring = np.flatnonzero(np.isclose(pos[:, 2], 0.05))
    t = np.arange(16) / FPS
    shift = np.column_stack([0.08 * np.sin(2 * np.pi * t / 0.5),
                             np.zeros_like(t), 0.02 * np.sin(2 * np.pi * t / 0.25)])
    body = body_rest[None] + shift[:, None]
    targets = pos[ring][None] + shift[:, None]
    settings = SimulationSettings(settle_frames=5)
    calls: list[tuple[int, int]] = []
    result = simulate_garment(pos, faces, body, body_faces, FPS, "cotton", pinned=ring,
                              pin_targets=targets, settings=settings,
                              progress=lambda done, total: calls.append((done, total)))
    return dict(result=result, pos=pos, faces=faces, ring=ring, targets=targets, body=body,
                body_faces=body_faces, shift=shift, settings=settings, calls=calls)


def test_skirt_on_moving_capsule_passes_the_quality_gates(skirt_on_moving_capsule) -> None:
    run = skirt_on_moving_capsule
    result, settings = run["result"], run["settings"]
    assert result.positions.shape == (16, len(run["pos"]), 3)
    assert result.positions.dtype == np.float32
    assert np.isfinite(result.positions).all()
    quality = result.quality
    assert quality.ok and quality.frames_simulated == 16 and quality.finite.all()
    assert (quality.max_stretch < settings.max_edge_stretch).all()
    assert (quality.inside_fraction < settings.max_inside_fraction).all()
    assert result.substeps == settings.substeps and result.attempts == 1
    assert result.seconds_per_frame > 0 and result.setup_seconds > 0
    # Progress: every settle and animation frame of the (single) attempt, in order.
    assert run["calls"] == [(k, 5 + 15) for k in range(1, 21)]


def test_skirt_stays_outside_the_body_by_an_independent_measure(skirt_on_moving_capsule) -> None:
    run = skirt_on_moving_capsule
    free = np.setdiff1d(np.arange(len(run["pos"])), run["ring"])
    for frame in range(0, 16, 3):
        depth = signed_distance(run["result"].positions[frame][free], run["body"][frame],
                                run["body_faces"])
        assert np.mean(depth < 0) < 0.02


def test_pinned_vertices_follow_their_targets_exactly(skirt_on_moving_capsule) -> None:
    run = skirt_on_moving_capsule
    np.testing.assert_allclose(run["result"].positions[:, run["ring"]], run["targets"],
                               atol=1e-6)


def test_skirt_hangs_and_moves_with_the_body(skirt_on_moving_capsule) -> None:
    run = skirt_on_moving_capsule
    positions, ring = run["result"].positions, run["ring"]
    free = np.setdiff1d(np.arange(len(run["pos"])), ring)
    # Hanging under gravity: in every frame nothing rises above the pinned waist.
    assert (positions[:, free, 2].max(axis=1) <= positions[:, ring, 2].min(axis=1) + 5e-3).all()
    # The skirt's sideways motion follows the capsule's (it lags, but correlates).
    sway = positions[:, free, 0].mean(axis=1)
    assert np.corrcoef(sway, run["shift"][:, 0])[0, 1] > 0.5


def test_free_cloth_falls_like_a_stone_before_contact() -> None:
    pos, faces = square(cells=6, size=0.3, height=1.0)
    far_body = np.stack([sphere(0.1, centre=(5.0, 0.0, 0.0), subdivisions=1)[0]] * 7)
    body_faces = sphere(0.1, subdivisions=1)[1]
    result = simulate_garment(pos, faces, far_body, body_faces, FPS, "silk",
                              settings=SimulationSettings(settle_frames=0))
    t = np.arange(7) / FPS
    drop = pos[:, 2].mean() - result.positions[:, :, 2].mean(axis=1)
    np.testing.assert_allclose(drop[0], 0.0, atol=1e-6)
    # g t²/2 up to implicit Euler's O(dt) bias (n substeps fall g dt² n(n+1)/2).
    np.testing.assert_allclose(drop[2:], 0.5 * GRAVITY * t[2:] ** 2, rtol=0.06)
    # A free fall is a rigid translation: no stretch, no sideways drift.
    assert result.quality.max_stretch.max() < 1.01
    np.testing.assert_allclose(result.positions[-1][:, :2], pos[:, :2], atol=1e-4)


def test_sphere_keeps_a_draped_cloth_outside() -> None:
    radius = 0.15
    body_rest, body_faces = sphere(radius)
    pos, faces = square(cells=12, size=0.5, height=radius + 0.05)
    body = np.stack([body_rest] * 20)
    result = simulate_garment(pos, faces, body, body_faces, FPS, "cotton",
                              settings=SimulationSettings(settle_frames=0))
    assert (result.quality.inside_fraction < 0.02).all()
    final = result.positions[-1]
    depth = signed_distance(final, body_rest, body_faces)
    assert np.mean(depth < 0) < 0.02 and depth.min() > -0.01
    # Draped: the centre rests on top of the sphere, the corners hang below it.
    centre = np.argmin(np.linalg.norm(pos[:, :2], axis=1))
    assert final[centre, 2] == pytest.approx(radius, abs=0.015)
    corners = np.argsort(-np.linalg.norm(pos[:, :2], axis=1))[:4]
    assert (final[corners, 2] < final[centre, 2] - 0.05).all()


def test_failing_sequence_is_retried_with_more_substeps_then_raises() -> None:
    pos, faces = square(cells=4, size=0.2, height=0.5)
    body_rest, body_faces = sphere(0.1, centre=(5.0, 0.0, 0.0), subdivisions=1)
    corner = np.array([0])  # pinned: the cloth swings and stretches a little
    settings = SimulationSettings(substeps=2, settle_frames=0, max_retries=2,
                                  retry_substep_factor=2, max_edge_stretch=1.0001,
                                  retry_only_if_progress=False)
    with pytest.raises(SimulationFailed, match="max edge stretch") as caught:
        simulate_garment(pos, faces, np.stack([body_rest] * 6), body_faces, FPS, "silk",
                         pinned=corner, settings=settings)
    reports = caught.value.reports
    assert [r.substeps for r in reports] == [2, 4, 8]
    assert caught.value.report is reports[-1]
    for report in reports:
        assert not report.ok
        # Each attempt stops at its first failing frame (frame 0 is the rest shape).
        assert report.frames_simulated == 2 and "frame 1" in report.failure


def test_retries_stop_when_more_substeps_get_no_further() -> None:
    pos, faces = square(cells=4, size=0.2, height=0.5)
    body_rest, body_faces = sphere(0.1, centre=(5.0, 0.0, 0.0), subdivisions=1)
    settings = SimulationSettings(substeps=2, settle_frames=0, max_retries=3,
                                  retry_substep_factor=2, max_edge_stretch=1.0001)
    assert settings.retry_only_if_progress  # the default
    with pytest.raises(SimulationFailed) as caught:
        simulate_garment(pos, faces, np.stack([body_rest] * 6), body_faces, FPS, "silk",
                         pinned=np.array([0]), settings=settings)
    # Both attempts fail at frame 1: the third and fourth would be wasted work.
    assert [r.substeps for r in caught.value.reports] == [2, 4]


def test_self_contact_option_runs() -> None:
    body_rest, body_faces = sphere(0.1)
    pos, faces = square(cells=8, size=0.4, height=0.15)
    result = simulate_garment(pos, faces, np.stack([body_rest] * 8), body_faces, FPS, "silk",
                              settings=SimulationSettings(settle_frames=0, self_contact=True))
    assert result.quality.ok and np.isfinite(result.positions).all()
