"""The closedness test that decides back-face culling (alight.core.mesh.is_closed) gives the
verdict of the row-wise version it replaced, on closed, open, non-manifold and badly wound
meshes; that version is kept here as the reference."""

import numpy as np
import pytest

from alight.core import mesh as mesh_module
from alight.core.mesh import closed_edges, cube, is_closed, plane, sphere


def reference_is_closed(positions, indices) -> bool:
    """The former implementation: np.unique over rounded position rows, then directed edges
    keyed a * n + b, each unique and each reverse present (np.isin)."""
    if len(indices) == 0:
        return False
    _, weld = np.unique(np.round(np.asarray(positions, np.float64), 6), axis=0, return_inverse=True)
    tri = weld.reshape(-1)[np.asarray(indices, np.int64)]
    tri = tri[(tri[:, 0] != tri[:, 1]) & (tri[:, 1] != tri[:, 2]) & (tri[:, 2] != tri[:, 0])]
    if len(tri) == 0:
        return False
    edges = np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]])
    n = int(weld.max()) + 1
    forward = edges[:, 0] * n + edges[:, 1]
    backward = edges[:, 1] * n + edges[:, 0]
    uniq, counts = np.unique(forward, return_counts=True)
    if (counts != 1).any():
        return False
    return bool(np.isin(backward, uniq, assume_unique=False).all())


def _tetrahedron(offset=(0.0, 0.0, 0.0)):
    p = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float) + offset
    f = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    return p, f


def _cases():
    s = sphere(16, 8).parts[0]
    c = cube().parts[0]
    pl = plane().parts[0]
    tp, tf = _tetrahedron()
    # Two tetrahedra sharing the edge (0, 1): that edge is used four times (non-manifold).
    p2, f2 = _tetrahedron()
    q = p2.copy()
    q[2:] = [[0.3, -1.0, 0.2], [0.4, -0.2, -1.0]]
    shared = (np.concatenate([tp, q]), np.concatenate([tf, f2 + 4]))
    # Two tetrahedra glued at the vertex 0 only: closed and consistently wound, though not a manifold.
    r = -tp
    glued = (np.concatenate([tp, r]), np.concatenate([tf, tf[:, ::-1] + 4]))
    # -0.0 and 0.0 are one position.
    signed = tp.copy()
    signed[0] = [-0.0, -0.0, -0.0]
    return {
        "sphere (seam and poles welded)": (s.positions, s.indices, True),
        "cube (24 corners welded to 8)": (c.positions, c.indices, True),
        "plane (open)": (pl.positions, pl.indices, False),
        "cube without a face": (c.positions, c.indices[2:], False),
        "tetrahedron": (tp, tf, True),
        "one face flipped": (tp, np.concatenate([tf[:3], tf[3:, ::-1]]), False),
        "all faces flipped (inside out, still consistent)": (tp, tf[:, ::-1], True),
        "a face twice": (tp, np.concatenate([tf, tf[:1]]), False),
        "a face twice, once each way": (tp, np.concatenate([tf, tf[:1], tf[:1, ::-1]]), False),
        "a degenerate face added": (tp, np.concatenate([tf, [[0, 1, 1]]]), True),
        "only degenerate faces": (tp, np.array([[0, 0, 1], [2, 2, 2]]), False),
        "no faces": (tp, np.zeros((0, 3), np.int64), False),
        "two tetrahedra on one edge (non-manifold)": (*shared, False),
        "two tetrahedra on one vertex": (*glued, True),
        "a minus-zero corner": (signed, tf, True),
        "a corner 1e-8 away welded": (np.concatenate([tp, tp[:1] + 1e-8]),
                                       np.concatenate([[[4, 2, 1]], tf[1:]]), True),
    }


@pytest.mark.parametrize("name", list(_cases()))
def test_verdict_matches_the_former_test(name):
    positions, indices, expected = _cases()[name]
    assert reference_is_closed(positions, indices) == expected
    assert is_closed(positions, indices) == expected
    # The shadow test's variant, which keeps the edge pairing: the same verdict, packed or not.
    assert (closed_edges(positions, indices) is not None) == expected
    assert (closed_edges(positions, indices, pack=False) is not None) == expected


def test_random_edits_of_a_closed_mesh_agree():
    """Faces dropped, flipped or duplicated at random from a closed sphere: the two tests agree
    on every variant, and both verdicts occur."""
    rng = np.random.default_rng(7)
    s = sphere(24, 12).parts[0]
    verdicts = set()
    for _ in range(60):
        faces = s.indices.astype(np.int64).copy()
        edit = rng.integers(0, 4)
        pick = rng.integers(0, len(faces), size=rng.integers(1, 4))
        if edit == 0:
            faces = np.delete(faces, pick, axis=0)
        elif edit == 1:
            faces[pick] = faces[pick][:, ::-1]
        elif edit == 2:
            faces = np.concatenate([faces, faces[pick]])
        rng.shuffle(faces)
        expected = reference_is_closed(s.positions, faces)
        assert is_closed(s.positions, faces) == expected
        assert (closed_edges(s.positions, faces) is not None) == expected
        verdicts.add(expected)
    assert verdicts == {True, False}


def test_hashed_weld_groups_as_the_column_weld_and_survives_collisions(monkeypatch):
    """_weld hashes rounded positions; its groups are _weld_by_columns' (ids may differ, the
    partition may not), and where every position hashes alike the exact check sends it to
    _weld_by_columns, so the verdicts stay right."""
    s = sphere(32, 16).parts[0]       # seams and poles: many positions at equal coordinates
    rng = np.random.default_rng(3)
    for positions in (s.positions, s.positions * -1.0, rng.integers(-3, 3, (500, 3)) * 0.5,
                      np.concatenate([s.positions, s.positions + 1e-8])):
        a, b = mesh_module._weld(positions), mesh_module._weld_by_columns(positions)
        pairs = np.unique(np.stack([a, b], axis=1), axis=0)
        assert len(pairs) == len(np.unique(a)) == len(np.unique(b))
    monkeypatch.setattr(mesh_module, "_mix64", lambda v: v * np.uint64(0))
    a = mesh_module._weld(s.positions)
    assert np.array_equal(a, mesh_module._weld_by_columns(s.positions))
    assert is_closed(s.positions, s.indices)
    assert not is_closed(s.positions, s.indices[1:])


@pytest.mark.parametrize("pack", [True, False])
def test_closed_edges_pairs_the_two_faces_of_each_edge(pack):
    """Per edge, ``face`` holds the edge and ``across`` is the other face's third corner: after
    the weld, the face and across's face share exactly the edge's two corners, and across is
    not one of the face's corners; no face is named for more than its 3 edges."""
    s = sphere(24, 12).parts[0]
    weld = mesh_module._weld(s.positions)
    e = closed_edges(s.positions, s.indices, pack=pack)
    assert e is not None
    welded = weld[e.faces]
    assert len(e.face) == 3 * len(e.faces) // 2
    near = welded[e.face]
    across = weld[e.across]
    assert not (near == across[:, None]).any()
    count = np.bincount(e.face, minlength=len(e.faces))
    assert count.max() <= 3
    # The other face: one of the faces holding `across` shares two corners with the edge's face.
    for i in range(0, len(e.face), 7):
        f = welded[e.face[i]]
        holders = np.where((welded == across[i]).any(axis=1))[0]
        assert any(len(set(f) & set(welded[h])) == 2 for h in holders)
