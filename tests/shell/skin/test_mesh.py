"""The icosphere: counts per subdivision, orientation, hinges, volume and masses against closed forms."""

import numpy as np
import pytest

from ballenv.shell.skin.gas import volume
from ballenv.shell.skin.mesh import counts, icosphere, lumped_masses, triangle_areas, winding_numbers


@pytest.mark.parametrize("k", [0, 1, 2, 3, 4])
def test_counts_of_each_subdivision(k):
    mesh = icosphere(k, 0.12)
    n = 4**k
    assert counts(k) == {"vertices": 10 * n + 2, "edges": 30 * n, "triangles": 20 * n, "hinges": 30 * n}
    assert (len(mesh.vertices), len(mesh.edges), len(mesh.triangles), len(mesh.hinges)) == (
        10 * n + 2, 30 * n, 20 * n, 30 * n,
    )  # fmt: skip
    assert len(mesh.vertices) - len(mesh.edges) + len(mesh.triangles) == 2  # a sphere's Euler characteristic
    assert np.allclose(np.linalg.norm(mesh.vertices, axis=1), 0.12)
    assert np.allclose(mesh.vertices[0], (0, 0, 0.12)) and np.allclose(mesh.vertices[1], (0, 0, -0.12))


def test_triangles_point_outwards_and_hinges_join_their_two_triangles():
    mesh = icosphere(2)
    x, t = mesh.vertices, mesh.triangles
    normals = np.cross(x[t[:, 1]] - x[t[:, 0]], x[t[:, 2]] - x[t[:, 0]])
    assert np.all(np.einsum("ij,ij->i", normals, x[t].mean(axis=1)) > 0)
    cyclic = {tuple(np.roll(tri, -m)) for tri in t.tolist() for m in range(3)}
    for i, j, k, m in mesh.hinges.tolist():
        assert (i, j, k) in cyclic and (j, i, m) in cyclic and i < j
    assert np.array_equal(np.sort(mesh.edges, axis=1), mesh.edges)
    assert len({tuple(e) for e in mesh.edges.tolist()}) == len(mesh.edges)


def test_volume_converges_to_the_ball_with_subdivision():
    errors = [
        1 - volume(icosphere(k, 0.12).vertices, icosphere(k).triangles) / (4 / 3 * np.pi * 0.12**3)
        for k in range(5)
    ]
    assert all(e > 0 for e in errors)  # inscribed
    ratios = [errors[k] / errors[k + 1] for k in range(1, 4)]  # measured: 3.74, 3.93, 3.98
    assert all(3.7 < r < 4.0 for r in ratios) and ratios == sorted(ratios)  # second order in the edge length
    assert errors[4] < 2.2e-3


def test_lumped_masses_share_the_skin_mass():
    mesh = icosphere(3, 0.12)
    masses = lumped_masses(mesh, 1100.0, 3e-3)
    area = triangle_areas(mesh.vertices, mesh.triangles).sum()
    assert masses.sum() == pytest.approx(1100.0 * 3e-3 * area, rel=1e-12)
    assert area == pytest.approx(4 * np.pi * 0.12**2, rel=6e-3)
    assert masses.min() > 0.5 * masses.mean()


def test_the_winding_number_is_one_inside_and_zero_outside():
    mesh = icosphere(2, 0.5)
    rng = np.random.default_rng(1)
    inside = 0.45 * rng.uniform(-1, 1, (50, 3)) / np.sqrt(3)
    outside = inside / np.linalg.norm(inside, axis=1)[:, None] * 0.6
    np.testing.assert_allclose(
        winding_numbers(inside, mesh.vertices, mesh.triangles, chunk=7), 1.0, atol=1e-12
    )
    np.testing.assert_allclose(winding_numbers(outside, mesh.vertices, mesh.triangles), 0.0, atol=1e-12)
