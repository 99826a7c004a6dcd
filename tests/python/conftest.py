"""Shared fixtures of the csgrt module's tests: small meshes made in NumPy and a brute-force
ray-triangle test to judge the module against. ctest runs this suite with the interpreter the
module was built for and PYTHONPATH pointing at the build's python/ folder."""

import os
import pathlib

import numpy as np
import pytest

import csgrt

SOURCE_DIR = pathlib.Path(os.environ.get("CSGRT_SOURCE_DIR", pathlib.Path(__file__).parents[2]))
INVALID_ID = 2**32 - 1


def box_mesh(lower=(0.0, 0.0, 0.0), upper=(1.0, 1.0, 1.0)):
    """The 12 outward-wound triangles of an axis-aligned box."""
    lo, hi = np.asarray(lower, float), np.asarray(upper, float)
    corners = np.array([[(hi if (i >> k) & 1 else lo)[k] for k in range(3)] for i in range(8)])
    faces = [
        (0, 2, 3, 1), (4, 5, 7, 6),  # z = lo, z = hi
        (0, 1, 5, 4), (2, 6, 7, 3),  # y = lo, y = hi
        (0, 4, 6, 2), (1, 3, 7, 5),  # x = lo, x = hi
    ]
    # Corner index bits are (x, y, z); the quads above wind counter-clockwise seen from outside.
    triangles = []
    for a, b, c, d in faces:
        triangles += [(a, b, c), (a, c, d)]
    return corners, np.array(triangles, dtype=np.uint32)


def icosphere(levels=2):
    """A unit sphere from a subdivided icosahedron: closed, outward, 20 * 4**levels triangles."""
    t = (1 + 5**0.5) / 2
    v = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t), (0, -1, -t),
         (0, 1, -t), (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    f = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4),
         (11, 10, 2), (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8),
         (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    vertices = [np.array(p, float) / np.linalg.norm(p) for p in v]
    for _ in range(levels):
        cache, finer = {}, []

        def mid(a, b):
            key = (min(a, b), max(a, b))
            if key not in cache:
                m = vertices[a] + vertices[b]
                vertices.append(m / np.linalg.norm(m))
                cache[key] = len(vertices) - 1
            return cache[key]

        for a, b, c in f:
            ab, bc, ca = mid(a, b), mid(b, c), mid(c, a)
            finer += [(a, ab, ca), (ab, b, bc), (ca, bc, c), (ab, bc, ca)]
        f = finer
    return np.array(vertices), np.array(f, dtype=np.uint32)


def brute_force_hits(vertices, triangles, rays):
    """Every (t, triangle) hit of every ray with t >= 0, by Moeller-Trumbore in float64 on the
    float32-rounded corners the module stores: a list of sorted arrays of t and of ids."""
    corners = vertices.astype(np.float32).astype(np.float64)[triangles]  # (M, 3, 3)
    a, b, c = corners[:, 0], corners[:, 1], corners[:, 2]
    e1, e2 = b - a, c - a
    out_t, out_id = [], []
    for o, d in zip(rays[:, :3].astype(np.float64), rays[:, 3:].astype(np.float64)):
        p = np.cross(d, e2)
        det = np.einsum("ij,ij->i", e1, p)
        with np.errstate(divide="ignore", invalid="ignore"):
            inv = 1.0 / det
            s = o - a
            u = np.einsum("ij,ij->i", s, p) * inv
            q = np.cross(s, e1)
            v = (q @ d) * inv
            t = np.einsum("ij,ij->i", e2, q) * inv
        hit = (det != 0) & (u >= 0) & (v >= 0) & (u + v <= 1) & (t >= 0)
        order = np.argsort(t[hit], kind="stable")
        out_t.append(t[hit][order])
        out_id.append(np.nonzero(hit)[0][order])
    return out_t, out_id


def random_rays(count, seed, center=(0, 0, 0), spread=3.0):
    """Rays from a shell around `center` toward random points near it, unit directions."""
    rng = np.random.default_rng(seed)
    origins = rng.normal(size=(count, 3))
    origins = origins / np.linalg.norm(origins, axis=1, keepdims=True) * spread + center
    targets = rng.uniform(-1.2, 1.2, size=(count, 3)) + center
    directions = targets - origins
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    return np.hstack([origins, directions])


@pytest.fixture
def sphere_scene():
    vertices, triangles = icosphere(2)
    scene = csgrt.RaycastingScene()
    scene.add_triangles(vertices.astype(np.float32), triangles)
    return scene, vertices, triangles
