"""csgrt.RaycastingScene against brute force, closed forms and its own other queries."""

import concurrent.futures

import numpy as np
import pytest

import csgrt
from conftest import INVALID_ID, box_mesh, brute_force_hits, icosphere, random_rays

# The triangles are stored in float32 and the watertight test shears their corners relative to
# the ray's origin in float32 (for float64 rays too), so t carries a few float32 ulps of the
# origin-to-corner distance (at most 4.2 for these rays): 32 ulps of 4.2, far below the ~1e-2
# between neighbouring triangles' t. Moeller-Trumbore in float64 on the same corners is exact
# by comparison.
FLOAT_TRIANGLE_T_TOLERANCE = 32 * np.finfo(np.float32).eps * 4.2


def test_open3d_unit_box_example():
    # Open3D's documented example: a unit box, rays from outside toward it and one away.
    vertices, triangles = box_mesh()
    scene = csgrt.RaycastingScene()
    assert scene.add_triangles(vertices.astype(np.float32), triangles) == 0
    rays = np.array([[0.5, 0.5, 10, 0, 0, -1], [-1, 0.5, 0.5, 1, 0, 0], [0.5, 0.5, 10, 0, 0, 1]],
                    dtype=np.float32)
    result = scene.cast_rays(rays)
    np.testing.assert_array_equal(result["t_hit"], [9, 1, np.inf])
    assert result["t_hit"].dtype == np.float32
    np.testing.assert_array_equal(result["geometry_ids"], [0, 0, INVALID_ID])
    assert result["primitive_ids"][2] == INVALID_ID
    assert csgrt.RaycastingScene.INVALID_ID == INVALID_ID
    # The face hit first: z = 1 (triangles 2, 3) and x = 0 (triangles 8, 9).
    assert result["primitive_ids"][0] in (2, 3) and result["primitive_ids"][1] in (8, 9)
    np.testing.assert_array_equal(result["primitive_normals"][0], [0, 0, 1])
    np.testing.assert_array_equal(result["primitive_normals"][1], [-1, 0, 0])
    np.testing.assert_array_equal(result["primitive_normals"][2], [0, 0, 0])


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_cast_rays_against_brute_force(sphere_scene, dtype):
    scene, vertices, triangles = sphere_scene
    rays = random_rays(600, seed=1).astype(dtype)
    result = scene.cast_rays(rays, outputs=["t_hit", "geometry_ids", "primitive_ids",
                                            "primitive_uvs", "primitive_normals"])
    assert result["t_hit"].dtype == dtype
    t_all, ids_all = brute_force_hits(vertices, triangles, rays)
    corners = vertices.astype(np.float32).astype(np.float64)[triangles]
    hits = 0
    for i, (t, ids) in enumerate(zip(t_all, ids_all)):
        if len(t) == 0:
            assert result["t_hit"][i] == np.inf and result["primitive_ids"][i] == INVALID_ID
            continue
        hits += 1
        assert abs(result["t_hit"][i] - t[0]) <= FLOAT_TRIANGLE_T_TOLERANCE, i
        assert result["primitive_ids"][i] == ids[0]
        a, b, c = corners[ids[0]]
        u, v = result["primitive_uvs"][i].astype(np.float64)
        point = rays[i, :3].astype(np.float64) + t[0] * rays[i, 3:].astype(np.float64)
        # The barycentrics rebuild the hit point (float32 uvs: 2**-24 of the unit triangle).
        assert np.linalg.norm(a + u * (b - a) + v * (c - a) - point) < 1e-6
        n = np.cross(b - a, c - a)
        np.testing.assert_allclose(result["primitive_normals"][i], n / np.linalg.norm(n),
                                   atol=max(4 * np.finfo(dtype).eps, 1e-12))
    assert hits > 300


def test_leading_shape_layouts_and_threads(sphere_scene):
    scene, _, _ = sphere_scene
    rays = random_rays(120, seed=2).astype(np.float32)
    flat = scene.cast_rays(rays, nthreads=1)
    shaped = scene.cast_rays(rays.reshape(4, 5, 6, 6), nthreads=3)
    assert shaped["t_hit"].shape == (4, 5, 6) and shaped["primitive_uvs"].shape == (4, 5, 6, 2)
    for key in flat:
        np.testing.assert_array_equal(shaped[key].reshape(flat[key].shape), flat[key])
    # Non-contiguous and integer-free conversions give the same answers.
    wide = np.zeros((120, 12), dtype=np.float32)
    wide[:, ::2] = rays
    strided = scene.cast_rays(wide[:, ::2])
    np.testing.assert_array_equal(strided["t_hit"], flat["t_hit"])
    double = scene.cast_rays(rays.astype(np.float64))
    np.testing.assert_array_equal(double["primitive_ids"], flat["primitive_ids"])
    only_t = scene.cast_rays(rays, outputs=["t_hit"])
    assert list(only_t) == ["t_hit"]
    np.testing.assert_array_equal(only_t["t_hit"], flat["t_hit"])


def test_occlusions_counts_and_lists_agree_with_brute_force(sphere_scene):
    scene, vertices, triangles = sphere_scene
    rays = random_rays(400, seed=3)
    t_all, ids_all = brute_force_hits(vertices, triangles, rays)
    nearest = np.array([t[0] if len(t) else np.inf for t in t_all])
    occluded = scene.test_occlusions(rays)
    assert occluded.dtype == bool
    np.testing.assert_array_equal(occluded, np.isfinite(nearest))
    # A short interval: occluded only where the first hit lies inside it.
    short = scene.test_occlusions(rays, tnear=0.0, tfar=2.5)
    np.testing.assert_array_equal(short, nearest <= 2.5)

    counts = scene.count_intersections(rays)
    assert counts.dtype == np.int32
    np.testing.assert_array_equal(counts, [len(t) for t in t_all])
    listed = scene.list_intersections(rays)
    splits = listed["ray_splits"]
    assert splits[-1] == counts.sum()
    for i, (t, ids) in enumerate(zip(t_all, ids_all)):
        rows = slice(splits[i], splits[i + 1])
        np.testing.assert_allclose(listed["t_hit"][rows], t, rtol=0,
                                   atol=FLOAT_TRIANGLE_T_TOLERANCE)
        np.testing.assert_array_equal(listed["primitive_ids"][rows], ids)
        assert (listed["ray_ids"][rows] == i).all()
        # Along a ray through a closed outward sphere crossings alternate: in, out.
        np.testing.assert_array_equal(listed["entering"][rows], [k % 2 == 0 for k in range(len(t))])


def test_occupancy_distance_and_closest_points_on_a_box():
    vertices, triangles = box_mesh((-1, -2, -3), (1, 2, 3))
    scene = csgrt.RaycastingScene()
    scene.add_triangles(vertices, triangles)
    rng = np.random.default_rng(4)
    points = rng.uniform(-4, 4, size=(3000, 3))
    lower, upper = np.array([-1, -2, -3.0]), np.array([1, 2, 3.0])
    inside = np.all((points > lower) & (points < upper), axis=1)
    # The box's distance in closed form: outside, the norm of the excess over the faces;
    # inside, the nearest face.
    excess = np.maximum(lower - points, 0) + np.maximum(points - upper, 0)
    expected = np.where(inside, np.minimum(points - lower, upper - points).min(axis=1),
                        np.linalg.norm(excess, axis=1))
    occupancy = scene.compute_occupancy(points)
    assert occupancy.dtype == np.float32
    np.testing.assert_array_equal(occupancy, inside.astype(np.float32))
    distance = scene.compute_distance(points)
    # Ericson's projection in double on coordinates below 8: a few ulps.
    np.testing.assert_allclose(distance, expected, rtol=0, atol=1e-14)
    signed = scene.compute_signed_distance(points)
    np.testing.assert_array_equal(signed, np.where(inside, -distance, distance))
    closest = scene.compute_closest_points(points)
    np.testing.assert_allclose(np.linalg.norm(closest["points"] - points, axis=1), distance,
                               atol=1e-14)
    assert (closest["geometry_ids"] == 0).all()
    # The nearest triangle's normal points from the surface toward outside points.
    away = ~inside & (distance > 1e-3)
    direction = points[away] - closest["points"][away]
    assert (np.einsum("ij,ij->i", direction, closest["primitive_normals"][away]) > 0).all()


def test_occupancy_of_a_sphere_mesh_against_membership(sphere_scene):
    scene, vertices, triangles = sphere_scene
    rng = np.random.default_rng(5)
    points = rng.uniform(-1.5, 1.5, size=(4000, 3))
    radius = np.linalg.norm(points, axis=1)
    # The mesh lies between the inscribed radius of its flattest triangle and 1.
    corners = vertices[triangles]
    normals = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    inner = np.einsum("ij,ij->i", normals, corners[:, 0]).min()
    occupancy = scene.compute_occupancy(points)
    sure = (radius < inner - 1e-6) | (radius > 1 + 1e-6)
    np.testing.assert_array_equal(occupancy[sure], (radius[sure] < 1).astype(np.float32))
    assert 0.8 < inner < 1


def test_several_geometries_have_their_own_ids():
    box_v, box_t = box_mesh((2, -0.5, -0.5), (3, 0.5, 0.5))
    sphere_v, sphere_t = icosphere(1)
    scene = csgrt.RaycastingScene()
    assert scene.add_triangles(sphere_v, sphere_t) == 0
    assert scene.add_triangles(box_v, box_t) == 1
    assert scene.geometry_count == 2 and scene.triangle_count == len(box_t) + len(sphere_t)
    rays = np.array([[5, 0.1, 0.2, -1, 0, 0], [0.1, 0.2, 5, 0, 0, -1]])
    result = scene.cast_rays(rays)
    np.testing.assert_array_equal(result["geometry_ids"], [1, 0])
    assert result["t_hit"][0] == 2.0 and result["primitive_ids"][0] < len(box_t)
    np.testing.assert_array_equal(scene.count_intersections(rays), [4, 2])
    closest = scene.compute_closest_points(np.array([[2.5, 0, 0.9], [0, 0, 0]]))
    np.testing.assert_array_equal(closest["geometry_ids"], [1, 0])


def test_empty_scene_answers_misses():
    scene = csgrt.RaycastingScene()
    rays = np.array([[0, 0, 0, 1, 0, 0]], dtype=np.float32)
    assert scene.cast_rays(rays)["t_hit"][0] == np.inf
    assert not scene.test_occlusions(rays)[0]
    assert scene.compute_distance(np.zeros((1, 3)))[0] == np.inf
    assert scene.compute_closest_points(np.zeros((1, 3)))["geometry_ids"][0] == INVALID_ID


def test_invalid_rays_get_a_miss_in_their_slot(sphere_scene):
    scene, _, _ = sphere_scene
    # Off the axis: (0, 0, 1) is a vertex of the icosphere.
    rays = np.array([[0.1, 0.05, 5, 0, 0, -1], [np.nan, 0, 5, 0, 0, -1], [0.1, 0.05, 5, 0, 0, 0],
                     [0.1, 0.05, 5, 0, 0, np.inf], [0.1, 0.05, 5, 0, 0, -1]], dtype=np.float32)
    t = scene.cast_rays(rays)["t_hit"]
    assert np.isfinite(t[0]) and t[4] == t[0]
    assert (t[1:4] == np.inf).all()
    np.testing.assert_array_equal(scene.count_intersections(rays), [2, 0, 0, 0, 2])


def test_bad_inputs_name_the_argument_shape_and_dtype():
    scene = csgrt.RaycastingScene()
    with pytest.raises(ValueError, match=r"^rays: expected an array of shape \(\.\.\., 6\), got \(10, 5\)$"):
        scene.cast_rays(np.zeros((10, 5), dtype=np.float32))
    with pytest.raises(ValueError, match=r"rays: expected a float32 or float64 array, got dtype <U1"):
        scene.cast_rays(np.array([["a"] * 6]))
    with pytest.raises(ValueError, match=r"query_points: expected an array of shape \(\.\.\., 3\), got \(4,\)"):
        scene.compute_distance(np.zeros(4))
    with pytest.raises(ValueError, match=r"triangles: row 0 refers to vertex 3, but there are 3"):
        scene.add_triangles(np.eye(3), np.array([[0, 1, 3]]))
    with pytest.raises(ValueError, match=r"triangles: expected an integer array"):
        scene.add_triangles(np.eye(3), np.array([[0.0, 1.0, 2.0]]))
    with pytest.raises(ValueError, match=r"vertices: row 1 is not finite"):
        scene.add_triangles(np.array([[0, 0, 0], [np.nan, 0, 0], [0, 1, 0]]), np.array([[0, 1, 2]]))
    with pytest.raises(ValueError, match=r"nthreads: expected 0 \(every core\) or a positive count, got -2"):
        scene.cast_rays(np.zeros((1, 6)), nthreads=-2)
    with pytest.raises(ValueError, match=r"outputs: unknown output 'depth'"):
        scene.cast_rays(np.zeros((1, 6)), outputs=["depth"])
    with pytest.raises(ValueError, match=r"tnear, tfar: expected tnear <= tfar"):
        scene.test_occlusions(np.zeros((1, 6)), tnear=2.0, tfar=1.0)
    with pytest.raises(ValueError, match=r"nsamples"):
        scene.compute_occupancy(np.zeros((1, 3)), nsamples=3)
    assert scene.geometry_count == 0  # nothing was added by the refused calls


def test_thread_pool_on_one_scene_while_another_thread_adds(sphere_scene):
    scene, _, _ = sphere_scene
    rays = random_rays(2000, seed=6).astype(np.float32)
    expected = scene.cast_rays(rays, nthreads=1)["t_hit"]
    far_v, far_t = box_mesh((50, 50, 50), (51, 51, 51))  # added meanwhile, hit by no ray

    def query(_):
        return scene.cast_rays(rays, nthreads=2)["t_hit"]

    with concurrent.futures.ThreadPoolExecutor(max_workers=4) as pool:
        futures = [pool.submit(query, k) for k in range(12)]
        pool.submit(scene.add_triangles, far_v, far_t).result()
        for future in futures:
            np.testing.assert_array_equal(future.result(), expected)
    assert scene.geometry_count == 2


def test_pinhole_rays():
    rays = csgrt.RaycastingScene.create_rays_pinhole(90.0, [0, 0, 0], [0, 0, 5], [0, 1, 0], 4, 2)
    assert rays.shape == (2, 4, 6) and rays.dtype == np.float32
    np.testing.assert_array_equal(rays[..., :3], np.broadcast_to([0, 0, 5], (2, 4, 3)))
    np.testing.assert_allclose(np.linalg.norm(rays[..., 3:], axis=-1), 1, atol=1e-6)
    # Pixel (0, 0) is top-left: looking down -z with +y up, it points to -x and +y.
    assert rays[0, 0, 3] < 0 and rays[0, 0, 4] > 0
    # The horizontal field of view of 90 degrees: the image's edges are at 45 degrees.
    half_width = np.tan(np.radians(45))
    x_centre = (0.5 * 2 * half_width / 4) - half_width
    np.testing.assert_allclose(rays[0, 0, 3] / -rays[0, 0, 5], x_centre, rtol=1e-6)


def test_results_in_reused_memory_hold_nothing_of_the_last_call():
    # Result arrays of 1 MiB and more reuse the memory of dead ones (python/src/arrays.h), so
    # a query must write every element: 300,000 rays that all hit a large square, then the
    # same number that all miss it, each output read against what a miss is.
    vertices = np.array([[-10, -10, 0], [10, -10, 0], [10, 10, 0], [-10, 10, 0]], np.float32)
    scene = csgrt.RaycastingScene()
    scene.add_triangles(vertices, np.array([[0, 1, 2], [0, 2, 3]], np.uint32))
    count = 300_000
    rng = np.random.default_rng(5)
    hitting = np.zeros((count, 6), np.float32)
    hitting[:, :2] = rng.uniform(-5, 5, (count, 2))
    hitting[:, 2] = 1
    hitting[:, 5] = -1
    missing = hitting.copy()
    missing[:, 5] = 1  # away from the square
    first = scene.cast_rays(hitting)
    assert np.all(first["t_hit"] == 1) and np.all(first["geometry_ids"] == 0)
    assert np.all(scene.count_intersections(hitting) == 1)
    del first
    kept = csgrt._kept_result_memory()
    assert kept >= 5 * 2**20  # t, ids, uvs and normals of 300,000 rays came back
    second = scene.cast_rays(missing)
    assert csgrt._kept_result_memory() < kept  # their memory was taken again
    np.testing.assert_array_equal(second["t_hit"], np.inf)
    np.testing.assert_array_equal(second["geometry_ids"], INVALID_ID)
    np.testing.assert_array_equal(second["primitive_ids"], INVALID_ID)
    np.testing.assert_array_equal(second["primitive_uvs"], 0)
    np.testing.assert_array_equal(second["primitive_normals"], 0)
    np.testing.assert_array_equal(scene.count_intersections(missing), 0)
    # What is kept stays bounded however many results die at once: 40 x 10 MB here.
    results = [scene.cast_rays(hitting) for _ in range(40)]
    del results
    assert 200 * 2**20 < csgrt._kept_result_memory() <= 256 * 2**20
