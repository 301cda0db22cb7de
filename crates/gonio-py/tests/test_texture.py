"""gonio.texture_uv: one-chart UVs of star-shaped meshes from numpy arrays (docs/TEXTURE.md)."""

import numpy as np
import pytest

import gonio


def octahedron_sphere(levels: int = 3):
    """A unit sphere: the octahedron, each face split into 4 `levels` times, outward faces."""
    v = [np.array(p, float) for p in
         [(1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1)]]
    f = [(0, 2, 4), (2, 1, 4), (1, 3, 4), (3, 0, 4), (2, 0, 5), (1, 2, 5), (3, 1, 5), (0, 3, 5)]
    for _ in range(levels):
        mid = {}

        def m(a, b):
            key = (min(a, b), max(a, b))
            if key not in mid:
                p = v[a] + v[b]
                v.append(p / np.linalg.norm(p))
                mid[key] = len(v) - 1
            return mid[key]

        f = [t for a, b, c in f for t in
             [(a, m(a, b), m(c, a)), (b, m(b, c), m(a, b)), (c, m(c, a), m(b, c)),
              (m(a, b), m(b, c), m(c, a))]]
    return np.array(v), np.array(f)


def test_uvs_are_in_the_square_and_counter_clockwise():
    v, f = octahedron_sphere()
    v = v * np.array([1.0, 0.7, 0.5])  # an ellipsoid
    r = gonio.texture_uv(v, f)
    uv, faces, fuv = r["uvs"], r["faces"], r["face_uvs"]
    assert uv.shape[1] == 2 and np.all((uv >= 0) & (uv <= 1))
    assert faces.shape == fuv.shape and faces.shape[0] >= f.shape[0]
    a, b, c = uv[fuv[:, 0]], uv[fuv[:, 1]], uv[fuv[:, 2]]
    area = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (c[:, 0] - a[:, 0]) * (b[:, 1] - a[:, 1])
    assert np.all(area > 0)
    assert 0.3 < r["seam"] < 0.7
    assert np.allclose(r["positions"][: len(v)], v)
    for layout in ["latlong", "cube", "octahedral"]:
        assert gonio.texture_uv(v, f, layout=layout)["seam"] is None


def test_bad_input_is_refused():
    v, f = octahedron_sphere(1)
    with pytest.raises(gonio.InputError, match="not closed"):
        gonio.texture_uv(v, f[:-1])
    with pytest.raises(gonio.InputError, match="not a vertex index"):
        gonio.texture_uv(v, f + 100)
    with pytest.raises(gonio.InputError, match="not star-shaped"):
        gonio.texture_uv(v, f, center=(5.0, 0.0, 0.0))
    with pytest.raises(gonio.InputError, match="density"):
        gonio.texture_uv(v, f, density="nope")
    with pytest.raises(gonio.InputError):
        gonio.texture_uv(v, f, weights=np.zeros(len(v)))
