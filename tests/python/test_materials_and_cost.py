"""csgrt.painted (per-operand materials) and the cost of every structure from Python, judged
against geometry worked out here and against exact counts."""

import numpy as np
import pytest

import csgrt
from conftest import INVALID_ID, icosphere

STONE = (0.5, 0.5, 0.5)
GOLD = (0.8, 0.6, 0.2)


def bitten_box():
    """The box [-1, 1]^3 (the object's material, stone) minus a ball of radius 1 at its corner
    (1, 1, 1) painted gold; returns the scene and the two material indices."""
    scene = csgrt.Scene()
    stone = scene.add_material("stone", STONE)
    gold = scene.add_material("gold", GOLD)
    ball = csgrt.painted(csgrt.sphere(center=[1, 1, 1], radius=1), gold)
    assert ball.kind == "painted" and ball.is_solid
    scene.add_object(csgrt.difference(csgrt.box(lower=[-1, -1, -1], upper=[1, 1, 1]), ball),
                     material="stone")
    scene.commit()
    return scene, stone, gold


def test_a_painted_operand_gives_its_material_to_the_cut_it_makes():
    scene, stone, gold = bitten_box()
    # Rays straight down -z from z = 5 at (x, y) in the box's top face. Where (x, y, 1) is
    # inside the ball, r^2 = (x-1)^2 + (y-1)^2 < 1, the top face is gone and the ray first
    # meets the ball's lower surface, the cut, at z = 1 - sqrt(1 - r^2): material gold.
    # Elsewhere it meets the top face at z = 1: the object's stone.
    rng = np.random.default_rng(17)
    xy = rng.uniform(-0.99, 0.99, size=(4000, 2))
    r2 = ((xy - 1) ** 2).sum(axis=1)
    keep = np.abs(r2 - 1) > 1e-6  # away from the rim, where a ray grazes both surfaces
    xy, r2 = xy[keep], r2[keep]
    rays = np.hstack([xy, np.full((len(xy), 1), 5.0), np.tile([0.0, 0, -1], (len(xy), 1))])
    hits = scene.cast_rays(rays, outputs=["t_hit", "material_ids", "geometry_ids"])
    in_cut = r2 < 1
    assert 500 < in_cut.sum() < len(xy) - 500  # both kinds of ray are there
    np.testing.assert_array_equal(hits["material_ids"], np.where(in_cut, gold, stone))
    expected_t = np.where(in_cut, 4 + np.sqrt(np.maximum(1 - r2, 0)), 4.0)
    # Sphere roots in double near t ~ 5: a few ulps, far inside 1e-12.
    np.testing.assert_allclose(hits["t_hit"], expected_t, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(hits["geometry_ids"], 0)
    # Misses have no material; the default outputs stay Open3D's five.
    miss = scene.cast_rays(np.array([[3.0, 3, 5, 0, 0, -1]]), outputs=["material_ids"])
    assert miss["material_ids"][0] == INVALID_ID
    assert "material_ids" not in scene.cast_rays(rays[:1])


def test_the_render_shades_each_surface_with_its_material():
    scene, _, _ = bitten_box()
    # Without lights the renderer lights from the eye: radiance = albedo |n . v|
    # (docs/rendering.md). Looking straight down -z, the top face (n = +z) is stone exactly
    # and the cut is gold scaled by |n_z|: every fully covered pixel's colour is parallel to
    # one of the two albedos, and both appear.
    scene.set_camera(position=[0, 0, 5], look_at=[0, 0, 0], up=[0, 1, 0],
                     projection="orthographic", height=1.9)
    scene.commit()  # render() sees the camera of the last commit
    image = scene.render(40, 40, nthreads=2)
    covered = image["color"][..., 3] == 1
    rgb = image["color"][..., :3][covered].astype(np.float64)
    stone_like = np.abs(rgb / STONE - (rgb / STONE)[:, :1]).max(axis=1) < 1e-2
    gold_like = np.abs(rgb / GOLD - (rgb / GOLD)[:, :1]).max(axis=1) < 1e-2
    assert (stone_like | gold_like).all()
    assert stone_like.sum() > 100 and gold_like.sum() > 100
    # The flat face is the albedo itself, up to the colour's float32 and half-free arrays.
    np.testing.assert_allclose(rgb[stone_like & ~gold_like], np.tile(STONE, (
        (stone_like & ~gold_like).sum(), 1)), atol=1e-6)


def test_painted_materials_must_be_the_scenes():
    scene = csgrt.Scene()
    scene.add_object(csgrt.painted(csgrt.sphere(radius=1), 4))
    with pytest.raises(ValueError, match="object 0: a painted shape names material 4"):
        scene.commit()
    with pytest.raises(ValueError, match="material"):
        csgrt.painted(csgrt.sphere(radius=1), 70000)
    with pytest.raises(ValueError, match="unknown output 'material_ids'"):
        csgrt.RaycastingScene().cast_rays(np.zeros((1, 6)), outputs=["material_ids"])


def one_mesh_scene(accelerator=""):
    vertices, triangles = icosphere(2)  # 320 triangles
    scene = csgrt.Scene()
    scene.add_object(csgrt.mesh(vertices, triangles, accelerator=accelerator))
    scene.set_camera(position=[0, 0, 4], look_at=[0, 0, 0], fov=40)
    scene.commit(accelerator or "auto")
    return scene, len(triangles)


def test_cost_layers_count_brute_force_exactly_and_match_scenes_built_with_each_structure():
    scene, triangles = one_mesh_scene()
    names = csgrt.accelerator_names()
    assert "brute" in names and "bvh" in names
    layers = scene.cost_layers(12, 8, nthreads=1)
    assert list(layers) == names
    for name, layer in layers.items():
        assert layer["total"].shape == (8, 12) and layer["total"].dtype == np.float32
        np.testing.assert_array_equal(
            layer["total"], layer["nodes"] + layer["primitives"] + layer["solves"])
        assert layer["build_milliseconds"] >= 0
        np.testing.assert_array_equal(layer["solves"], 0)  # triangles are tested, not solved
    # Brute force at both levels tests the one object, then every triangle, on every pixel.
    brute = layers["brute"]
    np.testing.assert_array_equal(brute["primitives"], triangles + 1)
    np.testing.assert_array_equal(brute["nodes"], 0)
    # Each layer is what a scene built by hand with that structure at both levels costs. Ray
    # classification splits its cells as rays arrive, so its counts depend on which rays came
    # first: render() traces the same centre rays but in its own order, and it is left out.
    for name in names:
        if name == "rayclass":
            continue
        built, _ = one_mesh_scene(name)
        image = built.render(12, 8, nthreads=1)
        np.testing.assert_array_equal(image["cost"], layers[name]["total"], err_msg=name)
        np.testing.assert_array_equal(image["cost_nodes"], layers[name]["nodes"], err_msg=name)
        np.testing.assert_array_equal(image["cost_primitives"], layers[name]["primitives"],
                                      err_msg=name)
        if name != "brute":
            assert layers[name]["total"].sum() < brute["total"].sum(), name


def test_the_cost_of_a_sphere_is_one_test_and_one_solve_per_pixel():
    scene = csgrt.Scene()
    scene.add_object(csgrt.sphere(radius=1))
    scene.set_camera(position=[0, 0, 4], look_at=[0, 0, 0], fov=40)
    scene.commit()
    brute = scene.cost_layers(6, 5, structures=["brute"])["brute"]
    np.testing.assert_array_equal(brute["nodes"], 0)
    np.testing.assert_array_equal(brute["primitives"], 1)
    np.testing.assert_array_equal(brute["solves"], 1)
    with pytest.raises(ValueError, match="unknown structure 'kdtree'"):
        scene.cost_layers(6, 5, structures=["kdtree"])


def test_render_with_cost_all_returns_and_writes_every_layer(tmp_path):
    scene, _ = one_mesh_scene()
    path = tmp_path / "mesh.exr"
    image = scene.render(10, 6, nthreads=1, exr_path=str(path), cost_all=True)
    assert list(image["cost_layers"]) == csgrt.accelerator_names()
    alone = scene.cost_layers(10, 6, structures=["brute", "bvh"], nthreads=1)
    for name in ("brute", "bvh"):
        np.testing.assert_array_equal(image["cost_layers"][name]["total"], alone[name]["total"])
    np.testing.assert_array_equal(
        image["cost"], image["cost_nodes"] + image["cost_primitives"] + image["cost_solves"])
    assert path.stat().st_size > 0
    assert (tmp_path / "mesh.cost-all.png").stat().st_size > 0
