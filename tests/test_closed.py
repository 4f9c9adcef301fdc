"""The closedness test that decides back-face culling (alight.core.mesh.is_closed) gives the
verdict of the row-wise version it replaced, on closed, open, non-manifold and badly wound
meshes; that version is kept here as the reference."""

import numpy as np
import pytest

from alight.core.mesh import cube, is_closed, plane, sphere


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
        verdicts.add(expected)
    assert verdicts == {True, False}
