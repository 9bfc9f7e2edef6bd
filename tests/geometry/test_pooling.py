"""Algorithm 1 against a literal, brute-force transcription on networkx graphs."""

from __future__ import annotations

import networkx as nx
import numpy as np
import pytest

from gnngarment.geometry.eccentricity import connected_centre, graph_centres, hop_distance
from gnngarment.geometry.graph import adjacency_matrix, connected_components, edge_index_from_faces
from gnngarment.geometry.pooling import pool
from tests.meshes import grid, interleave, random_disk, tube, union


def to_networkx(edge_index: np.ndarray, num_vertices: int) -> nx.Graph:
    graph = nx.Graph()
    graph.add_nodes_from(range(num_vertices))
    graph.add_edges_from(edge_index.T.tolist())
    return graph


def brute_force_pool(graph: nx.Graph) -> tuple[list[int], set[tuple[int, int]], list[int]]:
    """Algorithm 1 exactly as printed, one component at a time, with all-pairs BFS."""
    distance: dict[int, int] = {}
    centres = []
    for component in sorted((sorted(c) for c in nx.connected_components(graph)),
                            key=lambda c: c[0]):
        sub = graph.subgraph(component)
        lengths = dict(nx.all_pairs_shortest_path_length(sub))
        eccentricity = {v: max(lengths[v].values()) for v in component}
        smallest = min(eccentricity.values())
        centre = min(v for v in component if eccentricity[v] == smallest)
        centres.append(centre)
        distance.update(lengths[centre])
    kept = sorted(v for v in graph if distance[v] % 2 == 0)
    edges: set[tuple[int, int]] = set()
    for i in graph:
        if distance[i] % 2 == 1:
            from_ = [j for j in graph[i] if distance[j] == distance[i] - 1]
            to = [k for k in graph[i] if distance[k] == distance[i] + 1]
            edges |= {(min(j, k), max(j, k)) for j in from_ for k in to}
    for i in kept:
        for j in graph[i]:
            if distance[j] % 2 == 0:
                edges.add((min(i, j), max(i, j)))
    return kept, edges, centres


def meshes_under_test() -> list[tuple[str, np.ndarray, np.ndarray]]:
    cases = [("grid_6x9", *grid(6, 9)), ("tube_symmetric", *tube(7, 12)),
             ("tube_long", *tube(15, 6))]
    for seed in range(12):
        cases.append((f"random_{seed}", *random_disk(40 + 13 * seed, seed)))
    for seed in range(4):  # multi-component, with ties in the tube
        cases.append((f"union_{seed}", *union(random_disk(50, 100 + seed), tube(5, 8),
                                              random_disk(30, 200 + seed))))
    for seed in range(3):
        cases.append((f"relabelled_{seed}", *interleave(*union(tube(6, 10), grid(5, 5)), seed)))
    return cases


@pytest.mark.parametrize("name,pos,faces", meshes_under_test(), ids=lambda v: v
                         if isinstance(v, str) else "")
def test_pool_matches_brute_force(name: str, pos: np.ndarray, faces: np.ndarray) -> None:
    edge_index = edge_index_from_faces(faces, len(pos))
    expected_kept, expected_edges, expected_centres = brute_force_pool(
        to_networkx(edge_index, len(pos)))

    pooled = pool(edge_index, len(pos))

    assert pooled.centres.tolist() == expected_centres
    assert pooled.kept.tolist() == expected_kept
    got = {(int(pooled.kept[a]), int(pooled.kept[b]))
           for a, b in pooled.edge_index.T if a < b}
    assert got == expected_edges


@pytest.mark.parametrize("seed", range(20))
def test_connected_centre_matches_all_pairs_bfs(seed: int) -> None:
    rng = np.random.default_rng(seed)
    if seed % 3 == 0:
        pos, faces = tube(int(rng.integers(3, 9)), int(rng.integers(4, 14)))  # many ties
    else:
        pos, faces = random_disk(int(rng.integers(20, 300)), seed)
    adjacency = adjacency_matrix(edge_index_from_faces(faces, len(pos)), len(pos))
    eccentricity = np.array([hop_distance(adjacency, v).max() for v in range(len(pos))])

    centre, radius, bfs_runs = connected_centre(adjacency)

    assert radius == eccentricity.min()
    assert centre == np.flatnonzero(eccentricity == eccentricity.min())[0]
    assert bfs_runs <= len(pos)


def test_bounding_prunes_on_an_irregular_mesh() -> None:
    pos, faces = random_disk(2000, seed=7)
    adjacency = adjacency_matrix(edge_index_from_faces(faces, len(pos)), len(pos))
    _, _, bfs_runs = connected_centre(adjacency)
    assert bfs_runs < len(pos) // 10  # far fewer than one BFS per vertex


def test_hop_distance_matches_networkx_and_marks_other_components() -> None:
    pos, faces = union(random_disk(60, 3), tube(4, 6))
    edge_index = edge_index_from_faces(faces, len(pos))
    graph = to_networkx(edge_index, len(pos))
    distance = hop_distance(adjacency_matrix(edge_index, len(pos)), 5)
    expected = nx.single_source_shortest_path_length(graph, 5)
    for v in range(len(pos)):
        assert distance[v] == expected.get(v, -1)


@pytest.mark.parametrize("name,pos,faces", meshes_under_test()[::4],
                         ids=lambda v: v if isinstance(v, str) else "")
def test_pooled_graph_keeps_every_component_connected(name: str, pos: np.ndarray,
                                                      faces: np.ndarray) -> None:
    edge_index = edge_index_from_faces(faces, len(pos))
    labels = connected_components(edge_index, len(pos))
    pooled = pool(edge_index, len(pos))
    coarse_labels = connected_components(pooled.edge_index, len(pooled.kept))
    # Same number of components, and each coarse component lies inside one fine one.
    assert coarse_labels.max() == labels.max()
    assert np.array_equal(coarse_labels, labels[pooled.kept])
    assert np.all(np.diff(pooled.kept) > 0)  # kept vertices keep their relative order


def test_isolated_vertex_is_its_own_component_and_is_kept() -> None:
    pos, faces = grid(3, 3)
    edge_index = edge_index_from_faces(faces, len(pos) + 1)  # vertex 9 is isolated
    pooled = pool(edge_index, len(pos) + 1)
    assert 9 in pooled.kept.tolist()
    assert 9 in pooled.centres.tolist()


def test_graph_centres_labels_follow_vertex_order() -> None:
    pos, faces = interleave(*union(tube(4, 6), grid(4, 4)), seed=0)
    centres, labels = graph_centres(edge_index_from_faces(faces, len(pos)), len(pos))
    assert labels[0] == 0 and len(centres) == 2
