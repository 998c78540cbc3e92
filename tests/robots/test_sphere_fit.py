"""Sphere fitting and its quality measures against independent counts and closed forms."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from ocpkit.cli.main import main
from ocpkit.robots.link_geometry import link_meshes
from ocpkit.robots.sphere_fit import fit_spheres, inside_mesh, quality
from ocpkit.robots.urdf import example_robot_data_dir

SIZE = np.array([0.4, 0.1, 0.06])  # box edges, m


def box_surface_points(size: np.ndarray, count: int, rng: np.random.Generator) -> np.ndarray:
    """Uniform points on a centred box's surface, drawn face by face in proportion to face area (no trimesh)."""
    areas = np.array([size[1] * size[2], size[0] * size[2], size[0] * size[1]]).repeat(2)
    face = rng.choice(6, size=count, p=areas / areas.sum())
    points = rng.uniform(-size / 2, size / 2, (count, 3))
    axis, sign = face // 2, np.where(face % 2, 1.0, -1.0)
    points[np.arange(count), axis] = sign * size[axis] / 2
    return points


def covered(points: np.ndarray, centers: np.ndarray, radii: np.ndarray) -> float:
    return float((np.linalg.norm(points[:, None] - centers[None], axis=-1) <= radii).any(axis=1).mean())


def test_fitted_box_spheres_cover_an_independent_sample():
    mesh = trimesh.creation.box(extents=SIZE)
    fit = fit_spheres(mesh, budget=6, coverage=0.99)
    independent = covered(box_surface_points(SIZE, 20000, np.random.default_rng(5)), fit.centers, fit.radii)
    assert independent >= 0.99 and len(fit.radii) <= 6
    assert abs(independent - fit.quality.coverage) < 0.01  # the reported coverage is the independent one's


def test_coverage_and_protrusion_of_one_sphere_on_a_cube_are_the_closed_forms():
    a = 0.2
    mesh = trimesh.creation.box(extents=[a, a, a])
    circumscribed = quality(mesh, np.zeros((1, 3)), np.array([a * np.sqrt(3) / 2]))
    assert circumscribed.coverage == 1.0
    # farthest outside point of the circumscribed sphere: on a face normal, r - a/2
    assert circumscribed.protrusion == pytest.approx(a * (np.sqrt(3) - 1) / 2, rel=5e-3)  # sampled: from below
    inscribed = quality(mesh, np.zeros((1, 3)), np.array([a / 2]))
    assert inscribed.protrusion == pytest.approx(0.0, abs=1e-9)
    # a cube-surface point lies in the sphere of radius a/sqrt(2) iff it is within a/2 of its face centre
    half = quality(mesh, np.zeros((1, 3)), np.array([a / np.sqrt(2)]))
    assert half.coverage == pytest.approx(np.pi / 4, abs=0.02)


def test_fit_is_deterministic_and_cylinders_are_read_from_urdfs(tmp_path):
    (tmp_path / "c.urdf").write_text('<robot name="c"><link name="rod"><collision><origin xyz="0 0 0.2" rpy="0 0 0"/>'
                                     '<geometry><cylinder radius="0.05" length="0.4"/></geometry></collision></link>'
                                     '</robot>')
    mesh = link_meshes(tmp_path / "c.urdf")["rod"]
    np.testing.assert_allclose(mesh.bounds, [[-0.05, -0.05, 0.0], [0.05, 0.05, 0.4]], atol=1e-12)
    one, two = fit_spheres(mesh), fit_spheres(mesh)
    np.testing.assert_array_equal(one.centers, two.centers)
    assert one.quality.coverage >= 0.99


def test_inside_is_the_box_itself():
    mesh = trimesh.creation.box(extents=SIZE)
    points = np.random.default_rng(2).uniform(-0.6 * SIZE, 0.6 * SIZE, (3000, 3))
    np.testing.assert_array_equal(inside_mesh(mesh, points), np.all(np.abs(points) < SIZE / 2, axis=1))


def test_panda_links_from_example_robot_data_meshes_reach_99_percent_the_same_each_time():
    meshes = link_meshes(example_robot_data_dir() / "robots/panda_description/urdf/panda.urdf")
    for link in ("panda_link3", "panda_leftfinger"):  # the finger's meshes made trimesh's ray test cast random rays
        first, again = fit_spheres(meshes[link]), fit_spheres(meshes[link])
        assert first.quality.coverage >= 0.99, link
        np.testing.assert_array_equal(first.radii, again.radii)


def test_spheres_command_prints_the_side_by_side_table(tmp_path, capsys):
    (tmp_path / "b.urdf").write_text('<robot name="b"><link name="block"><collision><geometry>'
                                     '<box size="0.4 0.1 0.06"/></geometry></collision></link></robot>')
    (tmp_path / "s.urdf").write_text('<robot name="b"><link name="block"><collision><geometry><sphere radius="0.25"/>'
                                     '</geometry></collision></link></robot>')
    assert main(["robot", "spheres", str(tmp_path / "b.urdf"), "--compare", str(tmp_path / "s.urdf")]) == 0
    row = next(line for line in capsys.readouterr().out.splitlines() if line.startswith("block"))
    fit, other = row.split("|")[1:]
    assert other.split()[:2] == ["1", "100.00"]  # one sphere of radius 0.25 holds the whole box
    assert float(fit.split()[1]) >= 99.0
