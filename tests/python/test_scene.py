"""csgrt.Scene: analytic shapes and CSG against closed forms, scene files, render()."""

import concurrent.futures

import numpy as np
import pytest

import csgrt
from conftest import INVALID_ID, SOURCE_DIR, box_mesh, icosphere


def sphere_scene():
    scene = csgrt.Scene()
    scene.add_object(csgrt.sphere(center=[1, 2, 3], radius=2), name="ball")
    scene.commit()
    return scene


def test_sphere_hits_against_the_closed_form():
    scene = sphere_scene()
    rng = np.random.default_rng(10)
    centre = np.array([1.0, 2, 3])
    # Rays from a shell of radius 6 toward random points within 1.5 of the centre: they all
    # hit, at t = d.(c - o) - sqrt(r^2 - |(c - o) x d|^2) for unit d.
    origins = rng.normal(size=(500, 3))
    origins = centre + 6 * origins / np.linalg.norm(origins, axis=1, keepdims=True)
    targets = centre + rng.uniform(-0.8, 0.8, size=(500, 3))
    d = targets - origins
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    rays = np.hstack([origins, d])
    result = scene.cast_rays(rays, outputs=["t_hit", "geometry_ids", "primitive_normals",
                                            "shading_normals"])
    oc = centre - origins
    along = np.einsum("ij,ij->i", oc, d)
    expected = along - np.sqrt(4 - (np.einsum("ij,ij->i", oc, oc) - along**2))
    # The library solves the quadratic without cancellation in double: a few ulps of t ~ 5.
    np.testing.assert_allclose(result["t_hit"], expected, rtol=0, atol=1e-13)
    np.testing.assert_array_equal(result["geometry_ids"], 0)
    points = origins + expected[:, None] * d
    np.testing.assert_allclose(result["primitive_normals"], (points - centre) / 2, atol=1e-12)
    np.testing.assert_array_equal(result["shading_normals"], result["primitive_normals"])
    # Two crossings each, entering then leaving; occupancy of the segment's midpoint.
    np.testing.assert_array_equal(scene.count_intersections(rays), 2)
    listed = scene.list_intersections(rays)
    np.testing.assert_array_equal(listed["entering"], np.tile([True, False], 500))
    far = listed["t_hit"][1::2]
    np.testing.assert_allclose(far, 2 * along - expected, atol=1e-12)
    middle = origins + along[:, None] * d
    np.testing.assert_array_equal(scene.compute_occupancy(middle), 1.0)


def test_complement_in_an_intersection_is_the_difference():
    # box ∩ not(sphere) holds exactly the points of the box outside the sphere.
    scene = csgrt.Scene()
    cut = csgrt.intersection(csgrt.box(lower=[-1, -1, -1], upper=[1, 1, 1]),
                             csgrt.complement(csgrt.sphere(center=[1, 1, 1], radius=1)))
    assert cut.is_solid
    scene.add_object(cut)
    scene.commit()
    rng = np.random.default_rng(12)
    points = rng.uniform(-1.5, 1.5, size=(4000, 3))
    expected = np.all(np.abs(points) < 1, axis=1) & (np.linalg.norm(points - 1, axis=1) > 1)
    np.testing.assert_array_equal(scene.compute_occupancy(points), expected.astype(np.float32))
    assert not hasattr(csgrt, "array")
    with pytest.raises((TypeError, ValueError)):
        csgrt.complement(42)


def test_csg_difference_and_instances_against_membership():
    scene = csgrt.Scene()
    bitten = csgrt.difference(csgrt.box(lower=[-1, -1, -1], upper=[1, 1, 1]),
                              csgrt.sphere(center=[1, 1, 1], radius=1))
    assert bitten.is_solid and bitten.kind == "difference"
    scene.add_object(bitten)
    # A unit sphere moved to (5, 0, 0) and scaled by 2 along x: an ellipsoid.
    matrix = np.array([[2.0, 0, 0, 5], [0, 1, 0, 0], [0, 0, 1, 0]])
    scene.add_object(csgrt.instance(csgrt.sphere(radius=1), matrix))
    scene.commit()
    rng = np.random.default_rng(11)
    points = rng.uniform([-2, -2, -2], [8, 2, 2], size=(5000, 3))
    in_box = np.all(np.abs(points) < 1, axis=1) & (np.linalg.norm(points - 1, axis=1) > 1)
    scaled = (points - [5, 0, 0]) / [2, 1, 1]
    in_ellipsoid = np.linalg.norm(scaled, axis=1) < 1
    occupancy = scene.compute_occupancy(points, nthreads=2)
    np.testing.assert_array_equal(occupancy, (in_box | in_ellipsoid).astype(np.float32))
    # Along the x axis from x = 10: the ellipsoid from x = 7 to 3, then the box's face x = 1 is
    # bitten away near (1, 1, 1) but not at y = z = 0: crossings at t = 3, 7, 9, 11.
    rays = np.array([[10.0, 0, 0, -1, 0, 0]])
    listed = scene.list_intersections(rays)
    np.testing.assert_allclose(listed["t_hit"], [3, 7, 9, 11], atol=1e-12)
    np.testing.assert_array_equal(listed["geometry_ids"], [1, 1, 0, 0])
    # Through the bite: the ray along the diagonal enters the box where the sphere ends.
    diagonal = np.array([[3.0, 3, 3, -1, -1, -1]]) / [1, 1, 1, 3**0.5, 3**0.5, 3**0.5]
    t = scene.cast_rays(diagonal)["t_hit"][0]
    np.testing.assert_allclose(diagonal[0, :3] + t * diagonal[0, 3:], [0.42264973] * 3,
                               atol=1e-8)  # 1 - 1/sqrt(3), the sphere's near point


def test_meshes_from_arrays_agree_with_the_raycasting_scene():
    vertices, triangles = icosphere(2)
    scene = csgrt.Scene()
    mesh = csgrt.mesh(vertices, triangles)
    assert mesh.is_solid
    scene.add_object(mesh)
    scene.commit()
    reference = csgrt.RaycastingScene()
    reference.add_triangles(vertices, triangles)
    rng = np.random.default_rng(12)
    rays = np.hstack([rng.normal(size=(300, 3)) * 3, rng.normal(size=(300, 3))])
    # The same float32 triangles and the same watertight test: the same t, bit for bit.
    np.testing.assert_array_equal(scene.cast_rays(rays)["t_hit"],
                                  reference.cast_rays(rays)["t_hit"])
    points = rng.uniform(-1.2, 1.2, size=(1000, 3))
    np.testing.assert_array_equal(scene.compute_occupancy(points),
                                  reference.compute_occupancy(points))


def test_render_returns_the_aovs_and_writes_the_exr(tmp_path):
    scene = csgrt.Scene()
    red = scene.add_material("red", [0.8, 0.1, 0.1])
    scene.add_object(csgrt.sphere(radius=1), material="red", name="ball")
    assert red == 1
    scene.add_point_light([2, 4, 6], 50)
    scene.set_camera(position=[0, 0, 5], look_at=[0, 0, 0], fov=40)
    scene.commit()
    # Odd sizes: the middle pixel's centre ray is the view axis, which meets the unit sphere
    # at distance 4 with normal +z.
    image = scene.render(49, 33, spp=1, nthreads=2)
    assert image["color"].shape == (33, 49, 4) and image["color"].dtype == np.float32
    assert image["depth"].shape == (33, 49) and image["normal"].shape == (33, 49, 3)
    assert image["object_id"].dtype == np.uint32
    np.testing.assert_allclose(image["depth"][16, 24], 4.0, rtol=1e-6)  # float32 channel
    np.testing.assert_allclose(image["normal"][16, 24], [0, 0, 1], atol=1e-6)
    background = image["object_id"] == INVALID_ID
    assert background[0, 0] and not background[16, 24]
    assert np.isinf(image["depth"][background]).all()
    assert np.isfinite(image["depth"][~background]).all()
    assert (image["object_id"][~background] == 0).all()
    assert image["color"][16, 24, 0] > image["color"][16, 24, 2] > 0  # red, lit
    assert image["stats"]["primary_rays"] == 49 * 33
    # The image does not depend on the thread count.
    again = scene.render(49, 33, nthreads=1)
    np.testing.assert_array_equal(again["color"], image["color"])
    path = tmp_path / "frame.exr"
    scene.render(16, 16, exr_path=str(path))
    assert path.stat().st_size > 0 and (tmp_path / "frame.png").exists()


def test_scene_files_load_and_answer():
    scene = csgrt.load_scene(str(SOURCE_DIR / "data/scenes/showcase.json"))
    assert scene.object_count > 5 and scene.accelerator
    lower, upper = scene.bounds
    rng = np.random.default_rng(14)
    origins = rng.uniform(lower, upper, size=(500, 3))
    rays = np.hstack([origins, rng.normal(size=(500, 3))])
    hits = scene.cast_rays(rays)
    hit = np.isfinite(hits["t_hit"])
    assert hit.mean() > 0.5
    assert (hits["geometry_ids"][hit] < scene.object_count).all()
    np.testing.assert_array_equal(scene.test_occlusions(rays), hit)
    # The first crossing listed is the nearest hit.
    listed = scene.list_intersections(rays)
    first = listed["ray_splits"][:-1][hit]
    np.testing.assert_array_equal(listed["t_hit"][first], hits["t_hit"][hit])


def test_bad_shapes_files_and_uncommitted_scenes():
    with pytest.raises(ValueError, match=r"radius must be > 0"):
        csgrt.sphere(radius=-1)
    with pytest.raises(ValueError, match=r"centre"):
        csgrt.shape("sphere", centre=[0, 0, 0], radius=1)  # an unknown key
    with pytest.raises(ValueError, match=r"operands\[1\]: expected a csgrt.Shape, got int"):
        csgrt.union(csgrt.sphere(radius=1), 3)
    with pytest.raises(ValueError, match=r"matrix: expected an array of shape \(4, 4\) or \(3, 4\), got \(3, 3\)"):
        csgrt.instance(csgrt.sphere(radius=1), np.eye(3))
    with pytest.raises(csgrt.SceneError, match=r"missing.json"):
        csgrt.load_scene("/nonexistent/missing.json")
    with pytest.raises(csgrt.MeshError):
        csgrt.load_mesh("/nonexistent/missing.off")
    assert issubclass(csgrt.SceneError, ValueError)
    scene = csgrt.Scene()
    scene.add_object(csgrt.sphere(radius=1))
    with pytest.raises(ValueError, match=r"scene: not committed"):
        scene.cast_rays(np.zeros((1, 6)))
    with pytest.raises(ValueError, match=r"rays: expected an array of shape \(\.\.\., 6\), got \(2, 3\)"):
        scene.commit()
        scene.cast_rays(np.zeros((2, 3)))


def test_objects_added_after_commit_appear_at_the_next_commit():
    scene = sphere_scene()
    ray = np.array([[-10.0, 2, 3, 1, 0, 0]])
    assert scene.cast_rays(ray)["t_hit"][0] == 9.0
    scene.add_object(csgrt.box(lower=[-6, 1, 2], upper=[-5, 3, 4]))
    assert scene.cast_rays(ray)["t_hit"][0] == 9.0
    scene.commit()
    assert scene.cast_rays(ray)["t_hit"][0] == 4.0
    assert scene.cast_rays(ray)["geometry_ids"][0] == 1


def test_thread_pool_on_one_scene():
    scene = csgrt.load_scene(str(SOURCE_DIR / "data/scenes/part_objects.json"))
    assert scene.object_count > 0
    rng = np.random.default_rng(13)
    rays = np.hstack([rng.uniform(-5, 5, size=(3000, 3)), rng.normal(size=(3000, 3))])
    expected = scene.cast_rays(rays, nthreads=1)
    with concurrent.futures.ThreadPoolExecutor(max_workers=4) as pool:
        results = list(pool.map(lambda _: scene.cast_rays(rays, nthreads=2), range(8)))
    for result in results:
        for key in expected:
            np.testing.assert_array_equal(result[key], expected[key])


def test_help_reads_well():
    assert "rays: array of shape (..., 6)" in csgrt.RaycastingScene.cast_rays.__doc__
    assert "t_hit" in csgrt.Scene.cast_rays.__doc__
    for name in ["sphere", "box", "torus", "part_sphere", "union", "difference", "instance",
                 "mesh", "load_mesh", "load_scene", "shape"]:
        assert getattr(csgrt, name).__doc__, name
