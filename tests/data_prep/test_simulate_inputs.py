"""Settings, fabric presets and input validation of the reference simulation (no Newton
run: these fail before any kernel is compiled)."""

from __future__ import annotations

import dataclasses
import itertools
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from data_prep.simulate import (
    FABRICS,
    FabricPreset,
    SimulationSettings,
    load_simulation_settings,
    resolve_fabric,
    simulate_garment,
)
from data_prep.simulate.quality import gate_failure, max_edge_stretch, unique_edges
from data_prep.simulate.scene import bending_stiffness_per_edge
from gnngarment.config import ConfigError
from gnngarment.paths import default_config
from tests.meshes import grid


def test_shipped_yaml_equals_the_dataclass_defaults() -> None:
    loaded = load_simulation_settings(default_config("simulation.yaml"))
    assert dataclasses.asdict(loaded) == dataclasses.asdict(SimulationSettings())


@pytest.mark.parametrize("text,message", [
    ("substep: 3\n", "substep"),                   # typo: an error, not a new key
    ("substeps: many\n", "substeps"),              # wrong type
    ("substeps: 0\n", "substeps must be >= 1"),    # out of range
    ("max_inside_fraction: 2.0\n", "max_inside_fraction"),
])
def test_bad_settings_files_name_file_and_key(tmp_path: Path, text: str, message: str) -> None:
    path = tmp_path / "sim.yaml"
    path.write_text(text)
    with pytest.raises(ConfigError, match=rf"sim\.yaml.*{message}"):
        load_simulation_settings(path)


def test_presets_are_named_like_cloth3d_and_ordered_by_stiffness() -> None:
    assert set(FABRICS) == {"cotton", "silk", "denim", "leather"}
    order = [FABRICS[name] for name in ("silk", "cotton", "denim", "leather")]
    for lighter, stiffer in itertools.pairwise(order):
        assert lighter.stretch_stiffness < stiffer.stretch_stiffness
        assert lighter.bend_stiffness < stiffer.bend_stiffness
    assert resolve_fabric(" Denim ") is FABRICS["denim"]
    assert resolve_fabric(FABRICS["silk"]) is FABRICS["silk"]


def test_unknown_or_invalid_fabric_is_rejected() -> None:
    with pytest.raises(ValueError, match="unknown fabric 'tweed'.*cotton"):
        resolve_fabric("tweed")
    with pytest.raises(ValueError, match="density"):
        dataclasses.replace(FABRICS["cotton"], density=-1.0)
    with pytest.raises(ValueError, match="friction"):
        FabricPreset("x", 0.2, 1e4, 1e4, 1e-5, 0.0, float("nan"))


def test_bending_stiffness_of_a_rhombus_edge() -> None:
    # Two equilateral triangles of side L sharing edge (0, 1): k = 3·B·L / A_e, A_e = √3/2·L².
    side, bend = 0.02, 4e-5
    pos = np.array([[0, 0, 0], [side, 0, 0], [side / 2, side * np.sqrt(3) / 2, 0],
                    [side / 2, -side * np.sqrt(3) / 2, 0]])
    edges = np.array([[2, 3, 0, 1], [-1, 3, 0, 2]])  # interior edge, then a boundary edge
    stiffness = bending_stiffness_per_edge(pos, edges, bend)
    np.testing.assert_allclose(stiffness, [3 * bend * side / (np.sqrt(3) / 2 * side**2), 0.0])


def test_edge_stretch_and_gates() -> None:
    pos, faces = grid(3, 3, spacing=0.1)
    edges = unique_edges(faces)
    assert len(edges) == 16
    rest = np.linalg.norm(pos[edges[:, 0]] - pos[edges[:, 1]], axis=1)
    assert max_edge_stretch(pos, edges, rest) == pytest.approx(1.0)
    assert max_edge_stretch(pos * [1.3, 1, 1], edges, rest) == pytest.approx(1.3)
    assert gate_failure(4, True, 1.2, 0.01, 1.5, 0.02) == ""
    assert "non-finite" in gate_failure(4, False, np.nan, np.nan, 1.5, 0.02)
    assert "frame 4: max edge stretch 1.600" in gate_failure(4, True, 1.6, 0.0, 1.5, 0.02)
    assert "3.00% of vertices inside" in gate_failure(4, True, 1.0, 0.03, 1.5, 0.02)


def _valid_inputs() -> dict:
    pos, faces = grid(4, 4, spacing=0.05)
    body = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.0]]) - 3.0
    body_faces = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    return dict(garment_rest=pos, garment_faces=faces, body_vertices=np.stack([body] * 3),
                body_faces=body_faces, fps=30.0)


def _with(**changes: object) -> dict:
    inputs = _valid_inputs()
    inputs.update(changes)
    return inputs


def _nan_rest() -> np.ndarray:
    pos = _valid_inputs()["garment_rest"].copy()
    pos[3, 1] = np.nan
    return pos


def _degenerate_rest() -> np.ndarray:
    pos = _valid_inputs()["garment_rest"].copy()
    pos[1] = pos[0]
    return pos


@pytest.mark.parametrize("changes,message", [
    (dict(garment_rest=np.zeros((16, 2))), r"garment_rest must have shape \(N, 3\)"),
    (dict(garment_rest=_nan_rest()), "garment_rest contains NaN"),
    (dict(garment_faces=np.zeros((5, 4), dtype=int)), r"garment_faces must have shape"),
    (dict(garment_faces=np.array([[0, 1, 16]])), r"garment_faces indices must lie in \[0, 16\)"),
    (dict(garment_faces=np.array([[0.0, 1.0, 2.0]])), "garment_faces must hold integer"),
    (dict(garment_rest=_degenerate_rest()), "degenerate face"),
    (dict(body_vertices=np.zeros((4, 3))), r"body_vertices must have shape \(T, N_b, 3\)"),
    (dict(body_vertices=np.full((2, 4, 3), np.inf)), "body_vertices contains NaN or inf"),
    (dict(body_faces=np.array([[0, 1, 9]] * 4)), r"body_faces indices must lie in \[0, 4\)"),
    (dict(fps=0.0), "fps must be a positive finite number"),
    (dict(fps=float("nan")), "fps must be a positive finite number"),
    (dict(pinned=np.array([0, 0])), "pinned contains repeated"),
    (dict(pinned=np.array([99])), r"pinned indices must lie in \[0, 16\)"),
    (dict(pin_targets=np.zeros((3, 1, 3))), "pin_targets given without pinned"),
    (dict(pinned=np.array([0, 1]), pin_targets=np.zeros((2, 2, 3))),
     r"pin_targets must have shape \(T, P, 3\) = \(3, 2, 3\)"),
    (dict(fabric="tweed"), "unknown fabric"),
])
def test_bad_inputs_raise_value_errors_naming_the_problem(changes: dict, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        simulate_garment(**_with(**changes))


def test_importing_the_package_loads_neither_warp_nor_newton() -> None:
    code = ("import sys, data_prep.simulate; "
            "print(sorted(m for m in ('warp', 'newton') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True)
    assert out.stdout.strip() == "[]"
