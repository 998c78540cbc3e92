"""SphereCollision: rows against closed-form clearances on pinocchio sphere centres, and which terms are kept."""

from __future__ import annotations

import copy
import dataclasses

import casadi as ca
import numpy as np
import pytest
from helpers import REPO

import ocpkit
from ocpkit.constraints import Context, PointValues
from ocpkit.constraints.collision import MAX_MARGIN, SOFTMIN_SHARPNESS, SphereCollision, active_terms
from ocpkit.dynamics import make_dynamics
from ocpkit.geometry.clearances import clearances, sphere_centers
from ocpkit.geometry.distance import box_distance, cylinder_distance
from ocpkit.geometry.quaternion import quaternion_matrix
from ocpkit.geometry.scene import Boxes, Cylinders, Scene, Workspace

PROBLEM = ocpkit.load_scenario(REPO / "scenarios/paper/case2.yaml")
ROBOT = PROBLEM.robot
N = ROBOT.n
RADIUS = ROBOT.sphere_radius


def with_scene(**changes) -> ocpkit.Problem:
    return dataclasses.replace(PROBLEM, scene=dataclasses.replace(PROBLEM.scene, **changes))


def evaluate(constraint: SphereCollision, problem: ocpkit.Problem, q: np.ndarray, margin: float
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(g, lower, upper) at configuration q with the problem's own parameter values, via a ca.Function."""
    n = problem.robot.n
    point = PointValues(*(ca.SX.sym(k, n) for k in ("q", "qd", "qdd", "tau", "dtau_ds")), ca.SX.sym("dt_ds"))
    shapes = constraint.parameter_shapes()
    symbols = {name: ca.SX.sym(name, *shape) for name, shape in shapes.items()}
    margin_sx = ca.SX.sym("margin")
    rows = constraint.evaluate(point, Context(make_dynamics("casadi", problem.robot), margin_sx, ca.SX.sym("s"),
                                              symbols))
    function = ca.Function("rows", [point.q, margin_sx, *symbols.values()], [rows.g])
    values = constraint.parameter_values(problem)
    g = function(q, margin, *(np.reshape(values[name], shapes[name]) for name in symbols))
    return np.asarray(g).ravel(), rows.lower, rows.upper


def expected_rows(constraint: SphereCollision, problem: ocpkit.Problem, q: np.ndarray, margin: float) -> np.ndarray:
    """Closed forms on pinocchio centres: ‖c_a − c_b‖² − (r_a + r_b + m)² for self pairs and obstacle spheres,
    max(d, 0)² − (r + m)² with d the exact (coal-tested) distance to a box or cylinder (in mask order), then one
    workspace row per (sphere, axis) with a reachable face; m = min(margin, the row's cap)."""
    c, scene = sphere_centers(ROBOT, q), problem.scene
    margins = iter(np.minimum(margin, constraint.margin_caps(problem)))
    rows = [np.sum((c[a] - c[b]) ** 2) - (RADIUS[a] + RADIUS[b] + next(margins)) ** 2 for a, b in constraint.pairs]
    outside = np.maximum(np.hstack([box_distance(c, scene.boxes), cylinder_distance(c, scene.cylinders)]), 0.0)
    spheres = len(scene.obstacle_radii)
    for m in range(len(RADIUS)):
        for s in range(scene.n_obstacles):
            if constraint.obstacle_mask[m, s] and s < spheres:
                rows.append(np.sum((c[m] - scene.obstacle_centers[s]) ** 2)
                            - (RADIUS[m] + scene.obstacle_radii[s] + next(margins)) ** 2)
            elif constraint.obstacle_mask[m, s]:
                rows.append(outside[m, s - spheres] ** 2 - (RADIUS[m] + next(margins)) ** 2)
    faces = constraint.face_mask
    for m in range(len(RADIUS)):
        for axis in range(3):
            if not (faces[m, axis] or faces[m, axis + 3]):
                continue
            inset = RADIUS[m] + next(margins)
            low, high = scene.workspace.lower[axis] + inset, scene.workspace.upper[axis] - inset
            if faces[m, axis] and faces[m, axis + 3]:
                rows.append((c[m, axis] - low) / (high - low))
            elif faces[m, axis]:
                rows.append(c[m, axis] - low)
            else:
                rows.append(high - c[m, axis])
    assert next(margins, None) is None  # one cap per row
    return np.array(rows)


def test_each_rows_margin_cap_is_half_its_clearance_at_the_nearer_end():
    constraint = SphereCollision(PRIMITIVES)
    caps = constraint.margin_caps(PRIMITIVES)
    ends = [sphere_centers(ROBOT, q) for q in (PRIMITIVES.start, PRIMITIVES.goal)]
    scene = PRIMITIVES.scene
    pairs = [min(np.linalg.norm(c[a] - c[b]) - RADIUS[a] - RADIUS[b] for c in ends) for a, b in constraint.pairs]
    np.testing.assert_allclose(caps[:len(pairs)], np.maximum(0.5 * np.array(pairs), 0.0), atol=1e-12)
    m, s = np.nonzero(constraint.obstacle_mask)
    spheres = len(scene.obstacle_radii)
    distance = [np.hstack([np.linalg.norm(c[:, None] - scene.obstacle_centers, axis=-1) - scene.obstacle_radii,
                           box_distance(c, scene.boxes), cylinder_distance(c, scene.cylinders)])[m, s] - RADIUS[m]
                for c in ends]
    obstacle_caps = caps[len(pairs):len(pairs) + len(m)]
    np.testing.assert_allclose(obstacle_caps, np.maximum(0.5 * np.minimum(*distance), 0.0), atol=1e-12)
    assert (obstacle_caps[s >= spheres] < 0.01).any() and (obstacle_caps > 0.05).any()  # some bind, some not
    assert len(caps) == constraint.term_count


def test_rows_match_closed_form_clearances_at_random_configurations():
    constraint = SphereCollision(PROBLEM)
    rng = np.random.default_rng(3)
    for q in rng.uniform(ROBOT.q_lower, ROBOT.q_upper, (3, N)):
        g, lower, upper = evaluate(constraint, PROBLEM, q, margin=0.02)
        np.testing.assert_allclose(g, expected_rows(constraint, PROBLEM, q, 0.02), rtol=1e-9, atol=1e-12)
        assert lower.shape == upper.shape == g.shape and np.all(lower == 0)


TILTED = quaternion_matrix([0.2, -0.3, 0.4, 0.8])
PRIMITIVES = with_scene(boxes=Boxes(np.array([[1.0, 0.2, 0.9], [0.0, -0.9, 0.5]]), np.array([[0.3, 0.6, 0.2],
                                                                                         [1.0, 0.2, 1.0]]),
                                    np.stack([TILTED, np.eye(3)])),
                        cylinders=Cylinders(np.array([[0.9, -0.4, 1.2]]), np.array([0.15]), np.array([0.8]),
                                            TILTED[None]))


def test_box_and_cylinder_rows_match_the_exact_outside_distance():
    """At random configurations, many spheres inside (row −(r + margin)²) and outside the primitives."""
    constraint = SphereCollision(PRIMITIVES)
    assert constraint.obstacle_mask[:, 1:].sum() > 10  # boxes and cylinder give rows
    rng = np.random.default_rng(4)
    for q in rng.uniform(ROBOT.q_lower, ROBOT.q_upper, (4, N)):
        g, _, _ = evaluate(constraint, PRIMITIVES, q, margin=0.02)
        np.testing.assert_allclose(g, expected_rows(constraint, PRIMITIVES, q, 0.02), rtol=1e-9, atol=1e-12)


def test_box_and_cylinder_rows_have_finite_gradients_everywhere():
    """On a cylinder's axis and on the planes of a box's faces the smooth rows still differentiate."""
    constraint = SphereCollision(PRIMITIVES)
    assert constraint.obstacle_mask[-1, -1]  # the last sphere has a row for the cylinder
    point = PointValues(*(ca.SX.sym(k, N) for k in ("q", "qd", "qdd", "tau", "dtau_ds")), ca.SX.sym("dt_ds"))
    shapes = constraint.parameter_shapes()
    symbols = {name: ca.SX.sym(name, *shape) for name, shape in shapes.items()}
    rows = constraint.evaluate(point, Context(make_dynamics("casadi", ROBOT), 0.0, ca.SX.sym("s"), symbols))
    jacobian = ca.Function("j", [point.q, *symbols.values()], [ca.jacobian(rows.g, point.q)])
    values = constraint.parameter_values(PRIMITIVES)
    c = sphere_centers(ROBOT, PROBLEM.start)
    on_axis = dataclasses.replace(PRIMITIVES.scene.cylinders, centers=c[-1][None] + TILTED[:, 2] * 0.1)
    values["cylinder_center"] = on_axis.centers
    J = np.asarray(jacobian(PROBLEM.start, *(np.reshape(values[name], shapes[name]) for name in symbols)))
    assert np.all(np.isfinite(J))


def test_obstacle_row_is_zero_when_the_sphere_touches_the_obstacle_with_margin():
    q, m, margin = 0.5 * (PROBLEM.start + PROBLEM.goal), 13, 0.03  # midway: the obstacle is far from both ends
    centre = sphere_centers(ROBOT, q)[m]
    direction = np.array([0.6, 0.0, 0.8])
    touching = with_scene(obstacle_centers=(centre + (RADIUS[m] + 0.1 + margin) * direction)[None],
                          obstacle_radii=np.array([0.1]))
    constraint = SphereCollision(touching)
    g, _, _ = evaluate(constraint, touching, q, margin)
    row = len(constraint.pairs) + int(np.flatnonzero(constraint.obstacle_mask[:, 0]).tolist().index(m))
    assert constraint.margin_caps(touching)[row] > margin  # so the row takes the whole margin
    assert g[row] == pytest.approx(0.0, abs=1e-12)


def test_self_pair_rows_cover_every_pair_with_a_moving_sphere():
    constraint = SphereCollision(PROBLEM)
    assert np.all(ROBOT.sphere_joint[constraint.pairs].max(axis=1) > 0)
    assert len(constraint.pairs) == len(ROBOT.self_collision)  # industrial6: every listed pair has one


def test_workspace_rows_are_within_unit_interval_inside_the_box():
    constraint = SphereCollision(PROBLEM)
    g, _, upper = evaluate(constraint, PROBLEM, PROBLEM.start, margin=0.01)
    both = constraint.face_mask[:, :3] & constraint.face_mask[:, 3:]
    assert both.any()
    n_workspace = int((constraint.face_mask[:, :3] | constraint.face_mask[:, 3:]).sum())
    workspace, bounds = g[-n_workspace:], upper[-n_workspace:]
    two_sided = bounds == 1.0
    assert two_sided.sum() == both.sum()
    assert np.all((workspace[two_sided] >= 0) & (workspace[two_sided] <= 1))
    assert np.all(workspace[~two_sided] >= 0) and np.all(np.isinf(bounds[~two_sided]))


def test_parameters_are_the_obstacles_and_the_box_by_name():
    constraint = SphereCollision(PROBLEM)
    assert constraint.parameter_shapes() == {
        "obstacle_center": (1, 3), "obstacle_radius": (1, 1), "box_center": (0, 3), "box_half_size": (0, 3),
        "box_rotation": (0, 9), "cylinder_center": (0, 3), "cylinder_half_size": (0, 2), "cylinder_rotation": (0, 9),
        "workspace": (6, 1), "margin_cap": (constraint.term_count, 1)}
    values = constraint.parameter_values(PROBLEM)
    np.testing.assert_array_equal(values["obstacle_center"], PROBLEM.scene.obstacle_centers)
    np.testing.assert_array_equal(values["obstacle_radius"], PROBLEM.scene.obstacle_radii)
    np.testing.assert_array_equal(values["workspace"], np.concatenate([PROBLEM.scene.workspace.lower,
                                                                       PROBLEM.scene.workspace.upper]))


def test_without_a_workspace_there_are_no_workspace_rows_or_parameters():
    free = with_scene(workspace=None)
    constraint = SphereCollision(free)
    assert constraint.face_mask.shape == (len(RADIUS), 0)
    assert constraint.parameter_shapes()["workspace"] == (0, 1)
    g, _, _ = evaluate(constraint, free, PROBLEM.start, margin=0.0)
    assert len(g) == len(constraint.pairs) + int(constraint.obstacle_mask.sum())


def test_a_sphere_that_cannot_reach_an_obstacle_gets_no_row():
    far = with_scene(obstacle_centers=np.array([[10.0, 0.0, 0.5]]), obstacle_radii=np.array([0.2]))
    obstacles, _ = active_terms(far)
    assert not obstacles.any()
    g, _, _ = evaluate(SphereCollision(far), far, PROBLEM.start, margin=0.0)
    none = with_scene(obstacle_centers=np.zeros((0, 3)), obstacle_radii=np.zeros(0))
    assert len(g) == len(evaluate(SphereCollision(none), none, PROBLEM.start, margin=0.0)[0])
    near = SphereCollision(PROBLEM)
    assert len(evaluate(near, PROBLEM, PROBLEM.start, margin=0.0)[0]) == len(g) + int(near.obstacle_mask.sum())


def test_spheres_on_the_base_never_get_an_obstacle_row():
    at_base = with_scene(obstacle_centers=np.array([[0.0, 0.0, 0.12]]), obstacle_radii=np.array([0.3]))
    obstacles, _ = active_terms(at_base)
    assert not obstacles[ROBOT.sphere_joint == 0].any()
    assert obstacles[ROBOT.sphere_joint > 0].any()


def test_moving_an_obstacle_within_reach_changes_the_shape():
    far = SphereCollision(with_scene(obstacle_centers=np.array([[10.0, 0.0, 0.5]])))
    near = SphereCollision(with_scene(obstacle_centers=np.array([[1.0, 0.0, 0.5]])))
    nudged = SphereCollision(with_scene(obstacle_centers=PROBLEM.scene.obstacle_centers + [0.0, 0.02, 0.0]))
    assert far.shape() != near.shape()
    assert nudged.shape() == SphereCollision(PROBLEM).shape()
    assert hash(near.shape()) is not None


def test_kept_terms_cover_every_contact_the_robot_can_reach():
    """Soundness of the reach bound: any configuration's clearance below MAX_MARGIN is a kept term."""
    problem = with_scene(obstacle_centers=np.array([[1.2, 0.1, 1.05], [0.0, 0.9, 0.4], [-0.6, -0.6, 1.6]]),
                         obstacle_radii=np.array([0.25, 0.3, 0.2]),
                         workspace=Workspace(np.array([-0.8, -1.2, -0.3]), np.array([1.4, 1.2, 1.8])))
    obstacles, faces = active_terms(problem)
    rng = np.random.default_rng(11)
    c = clearances(ROBOT, problem.scene, sphere_centers(ROBOT, rng.uniform(ROBOT.q_lower, ROBOT.q_upper, (400, N))))
    moving = ROBOT.sphere_joint > 0
    close_obstacles = (c.obstacles < MAX_MARGIN).any(axis=0) & moving[:, None]
    close_faces = (c.workspace < MAX_MARGIN).any(axis=0) & moving[:, None]
    assert close_obstacles.any() and close_faces.any()  # the sample does reach the terms
    assert np.all(obstacles[close_obstacles]) and np.all(faces[close_faces])


def test_empty_scene_without_self_pairs_gives_an_empty_column():
    scene = Scene()
    problem = dataclasses.replace(PROBLEM, scene=scene)
    constraint = SphereCollision(problem)
    constraint.pair_mask[:] = False
    g, lower, upper = evaluate(constraint, problem, PROBLEM.start, margin=0.0)
    assert g.shape == lower.shape == upper.shape == (0,)


def test_a_spherized_arm_gets_one_row_per_group_never_above_its_smallest_term():
    """MBM's Panda: one row per (joint, obstacle) and per joint pair, each within log(terms) / β below the smallest
    of its terms; the paper robot keeps a row per term."""
    problem = ocpkit.load_scenario(REPO / "scenarios/mbm/panda/box/0001.yaml")
    grouped = SphereCollision(problem)
    assert grouped.grouped and not SphereCollision(PROBLEM).grouped
    each = copy.copy(grouped)
    each.grouped = False
    joint = problem.robot.sphere_joint
    keys = [("self", joint[a], joint[b]) for a, b in grouped.pairs]
    keys += [("obstacle", joint[m], s) for m, s in zip(*np.nonzero(grouped.obstacle_mask))]
    groups = list(dict.fromkeys(keys))
    robot = problem.robot
    for q in np.random.default_rng(8).uniform(robot.q_lower, robot.q_upper, (3, robot.n)):
        rows = evaluate(grouped, problem, q, 0.01)[0]
        terms = evaluate(each, problem, q, 0.01)[0]
        smallest = np.array([min(t for k, t in zip(keys, terms) if k == g) for g in groups])
        count = np.array([keys.count(g) for g in groups])
        assert np.all(rows[:len(groups)] <= smallest + 1e-12)
        assert np.all(rows[:len(groups)] >= smallest - np.log(count) / SOFTMIN_SHARPNESS - 1e-12)
        np.testing.assert_array_equal(rows[len(groups):], terms[len(keys):])  # workspace rows as they were
    assert len(groups) < len(keys) / 5
