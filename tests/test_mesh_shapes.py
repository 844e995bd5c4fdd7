"""Mesh primitives: closed where they should be, facing outward, the volume and extent of the shape
they stand for (converging as the tessellation refines), and clear errors for bad sizes."""
import math

import numpy as np
import pytest

from atmos.plugins.mesh.geometry import capsule, cone, cylinder, plane, revolve, sphere, torus


def volume(mesh) -> float:
    c = mesh.positions[mesh.indices.astype(int)]
    return float(np.einsum("ij,ij->i", c[:, 0], np.cross(c[:, 1], c[:, 2])).sum() / 6)


def faces_outward(mesh) -> bool:
    c = mesh.positions[mesh.indices.astype(int)]
    face = np.cross(c[:, 1] - c[:, 0], c[:, 2] - c[:, 0])
    return bool((np.einsum("ij,ij->i", face, mesh.normals[mesh.indices.astype(int)].sum(1)) > 0).all())


SHAPES = {   # name: (make(fine: bool), exact volume, exact (min, max) corners)
    "sphere": (lambda f: sphere(0.7, 128 if f else 32, 64 if f else 16), 4 / 3 * math.pi * 0.7 ** 3,
               ((-0.7, -0.7, -0.7), (0.7, 0.7, 0.7))),
    "cylinder": (lambda f: cylinder(0.4, 2.0, 256 if f else 32), math.pi * 0.16 * 2.0, ((-0.4, -1, -0.4), (0.4, 1, 0.4))),
    "cone": (lambda f: cone(0.5, 1.5, 256 if f else 32), math.pi * 0.25 * 1.5 / 3, ((-0.5, -0.75, -0.5), (0.5, 0.75, 0.5))),
    "capsule": (lambda f: capsule(0.3, 1.6, 128 if f else 32, 32 if f else 8),
                math.pi * 0.09 * 1.0 + 4 / 3 * math.pi * 0.027, ((-0.3, -0.8, -0.3), (0.3, 0.8, 0.3))),
    "torus": (lambda f: torus(1.2, 0.3, 192 if f else 48, 64 if f else 16), 2 * math.pi ** 2 * 1.2 * 0.09,
              ((-1.5, -0.3, -1.5), (1.5, 0.3, 1.5))),
}


@pytest.mark.parametrize("name", sorted(SHAPES))
def test_primitives_are_the_shapes_they_name(name):
    make, exact, (lo, hi) = SHAPES[name]
    coarse, fine = make(False), make(True)
    for mesh in (coarse, fine):
        assert faces_outward(mesh), "every triangle counter-clockwise seen from outside"
        np.testing.assert_allclose(np.linalg.norm(mesh.normals, axis=1), 1.0, atol=1e-12)
        np.testing.assert_allclose(mesh.positions.min(0), lo, atol=1e-9)
        np.testing.assert_allclose(mesh.positions.max(0), hi, atol=1e-9)
    err_coarse, err_fine = abs(volume(coarse) - exact) / exact, abs(volume(fine) - exact) / exact
    assert err_coarse < 0.03 and err_fine < err_coarse / 4 + 1e-12, (err_coarse, err_fine)   # converges (h²)


def test_a_plane_is_one_quad_facing_up():
    mesh = plane((4.0, 2.0))
    assert len(mesh.indices) == 2 and faces_outward(mesh)
    np.testing.assert_allclose(mesh.positions.min(0), (-2, 0, -1))
    np.testing.assert_allclose(mesh.normals, np.tile([0.0, 1.0, 0.0], (4, 1)))


@pytest.mark.parametrize("make, message", [
    (lambda: sphere(0.0), "sphere radius must be a finite number > 0"),
    (lambda: sphere(1.0, segments=2), "segments must be a whole number 3..1024"),
    (lambda: cylinder(1.0, float("nan")), "cylinder height must be a finite number > 0"),
    (lambda: cone(-1.0), "cone radius"),
    (lambda: capsule(0.5, 0.8), "capsule height must be at least 2 × radius"),
    (lambda: torus(1.0, 1.0), "torus tube must be smaller than its radius"),
    (lambda: torus(1.0, 0.2, sides=True), "sides must be a whole number"),
    (lambda: plane((1.0, 0.0)), "plane size must be two positive numbers"),
    (lambda: revolve([(0, 0, 0, 1)]), "revolve profile must be"),
])
def test_bad_sizes_are_named(make, message):
    with pytest.raises(ValueError, match=message):
        make()


def test_a_child_moves_with_its_parent_and_bad_families_are_named():
    from atmos.plugins.mesh import MeshInstance, collect_instances, raycast_instances
    from atmos.transform import Parent, Transform, world_matrix
    from atmos.world import World
    world = World()
    balloon = world.create_entity(Transform(position=(10.0, 50.0, 0.0), yaw=math.pi / 2, scale=2.0),
                                  MeshInstance(sphere(3.0)))
    basket = world.create_entity(Transform(position=(0.0, -5.0, 0.0)), MeshInstance(cylinder(1.0, 1.0)),
                                 Parent(balloon))
    m = world_matrix(world, basket)
    np.testing.assert_allclose(m[:3, 3], (10.0, 40.0, 0.0), atol=1e-12)        # 5 m below, doubled by the scale
    parent_m = world.component_for_entity(balloon, Transform).pose().matrix(2.0)
    child_m = world.component_for_entity(basket, Transform).pose().matrix(1.0)
    np.testing.assert_allclose(m, parent_m @ child_m, atol=1e-12)
    rows = collect_instances(world, 1.0)
    drawn = {mesh: data for mesh, data in rows.items()}
    basket_mesh = world.component_for_entity(basket, MeshInstance).mesh
    np.testing.assert_allclose(drawn[basket_mesh][0, :16].reshape(4, 4).T, m, atol=1e-5)   # what the pass draws
    found = raycast_instances(world, (10.0, 40.0, 30.0), (0.0, 0.0, -1.0), ignore=balloon)
    assert found is not None and found[0] == basket and found[1].distance == pytest.approx(28.0, abs=1e-6)
    world.component_for_entity(balloon, Transform).position = np.array([0.0, 0.0, 0.0])
    np.testing.assert_allclose(world_matrix(world, basket)[:3, 3], (0.0, -10.0, 0.0), atol=1e-12)
    world.add_component(balloon, Parent(basket))                                   # a loop
    with pytest.raises(ValueError, match=r"form a cycle"):
        world_matrix(world, basket)
    world.remove_component(balloon, Parent)
    orphan = world.create_entity(Transform(), Parent(10_000))
    with pytest.raises(ValueError, match=r"its parent entity 10000 does not exist"):
        world_matrix(world, orphan)
    with pytest.raises(ValueError, match="Parent.entity must be an entity id"):
        Parent(-1)
    world.close()
