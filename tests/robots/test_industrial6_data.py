"""Consistency checks of the built-in industrial6 robot data (robot.urdf + spec.yaml)."""

import xml.etree.ElementTree as ET

import numpy as np
import pinocchio as pin
import pytest
import yaml
from helpers import REPO

DATA = REPO / "ocpkit/robots/data/industrial6"
URDF = DATA / "robot.urdf"

# Paper Table I, in the paper's units (deg, deg/s, Nm, Nm/s).
TABLE_I = {
    "q_min": [-160, -90, -120, -180, -120, -180],
    "q_max": [170, 90, 230, 180, 100, 180],
    "qd": [165, 165, 175, 350, 340, 520],
    "tau": [1397, 1402, 383, 45.2, 44.6, 32.5],
    "tau_rate": [20948, 21035, 5741, 678, 669, 488],
}
HOME = np.deg2rad([0, 0, 0, 0, -90, 0])


@pytest.fixture(scope="module")
def spec():
    return yaml.safe_load((DATA / "spec.yaml").read_text())


@pytest.fixture(scope="module")
def model():
    return pin.buildModelFromUrdf(str(URDF))


def link_joint(model, link):
    """Index of the pinocchio joint that moves `link` (0 = fixed base)."""
    return model.frames[model.getFrameId(link)].parentJoint


def sphere_centres(model, spec, q):
    data = model.createData()
    pin.framesForwardKinematics(model, data, q)
    return np.array([data.oMf[model.getFrameId(s["link"])].act(np.array(s["center"], float))
                     for s in spec["spheres"]])


def pair_gaps(model, spec, q):
    """Distance between sphere surfaces for every self-collision pair (negative = contact)."""
    c = sphere_centres(model, spec, q)
    r = np.array([s["radius"] for s in spec["spheres"]])
    return np.array([np.linalg.norm(c[a] - c[b]) - r[a] - r[b] for a, b in spec["self_collision"]])


def sample_shape(shape, n, rng):
    """Points on the surface and inside a URDF <box> or <cylinder>, in the shape's own frame."""
    if shape.tag == "box":
        half = np.array(shape.get("size").split(), float) / 2
        p = rng.uniform(-1, 1, (2 * n, 3))
        face = rng.integers(0, 3, n)
        p[np.arange(n), face] = rng.choice([-1.0, 1.0], n)  # first n points pushed onto faces
        return p * half
    r, half_len = float(shape.get("radius")), float(shape.get("length")) / 2
    phi = rng.uniform(0, 2 * np.pi, 3 * n)
    rho = r * np.sqrt(rng.uniform(0, 1, 3 * n))
    rho[:n] = r  # mantle
    z = rng.uniform(-half_len, half_len, 3 * n)
    z[n:2 * n] = rng.choice([-half_len, half_len], n)  # end caps
    return np.column_stack([rho * np.cos(phi), rho * np.sin(phi), z])


def collision_points(link, n=2000, seed=0):
    """Points sampled on every <collision> shape of `link`, expressed in the link frame."""
    rng = np.random.default_rng(seed)
    node = ET.parse(URDF).getroot().find(f"link[@name='{link}']")
    chunks = []
    for col in node.findall("collision"):
        origin = col.find("origin")
        xyz = np.array(origin.get("xyz", "0 0 0").split(), float)
        rot = pin.rpy.rpyToMatrix(np.array(origin.get("rpy", "0 0 0").split(), float))
        chunks.append(sample_shape(col.find("geometry")[0], n, rng) @ rot.T + xyz)
    return np.vstack(chunks)


def test_urdf_loads_with_spec_joint_order(model, spec):
    assert spec["name"] == "industrial6"
    assert list(model.names)[1:] == spec["joints"]
    assert all(model.frames[model.getFrameId(name)].type == pin.FrameType.JOINT
               for name in spec["joints"])
    assert model.existFrame("flange")


def test_total_mass_is_about_220kg(model):
    # pinocchio lumps the fixed base_link into the universe body, inertias[0]
    total = sum(inertia.mass for inertia in model.inertias)
    assert model.inertias[0].mass > 0
    assert 200.0 <= total <= 240.0


def test_flange_at_zero_pose(model):
    data = model.createData()
    pin.framesForwardKinematics(model, data, np.zeros(model.nq))
    flange = data.oMf[model.getFrameId("flange")]
    expected = [0.15 + 0.18425 + 0.55575 + 0.1, 0.0, 0.245 + 0.28 + 0.77 + 0.1]
    np.testing.assert_allclose(flange.translation, expected, atol=1e-12)
    np.testing.assert_allclose(flange.rotation, np.eye(3), atol=1e-12)


def test_worst_static_gravity_torque_below_80_percent(model, spec):
    data = model.createData()
    q = np.random.default_rng(42).uniform(model.lowerPositionLimit, model.upperPositionLimit,
                                          (3000, model.nq))
    worst = np.max([np.abs(pin.computeGeneralizedGravity(model, data, qi)) for qi in q], axis=0)
    assert np.all(worst < 0.8 * np.array(spec["limits"]["torque"]))


def test_spec_limits_are_table_i(spec):
    lim = spec["limits"]
    np.testing.assert_allclose(lim["position"]["lower"], np.deg2rad(TABLE_I["q_min"]), rtol=1e-10)
    np.testing.assert_allclose(lim["position"]["upper"], np.deg2rad(TABLE_I["q_max"]), rtol=1e-10)
    np.testing.assert_allclose(lim["velocity"], np.deg2rad(TABLE_I["qd"]), rtol=1e-10)
    np.testing.assert_allclose(lim["torque"], TABLE_I["tau"], rtol=1e-12)
    np.testing.assert_allclose(lim["torque_rate"], TABLE_I["tau_rate"], rtol=1e-12)


def test_urdf_limits_equal_spec_limits(model, spec):
    lim = spec["limits"]
    np.testing.assert_allclose(model.lowerPositionLimit, lim["position"]["lower"], rtol=1e-10)
    np.testing.assert_allclose(model.upperPositionLimit, lim["position"]["upper"], rtol=1e-10)
    np.testing.assert_allclose(model.velocityLimit, lim["velocity"], rtol=1e-10)
    np.testing.assert_allclose(model.effortLimit, lim["torque"], rtol=1e-10)


def test_estimates_have_the_documented_shape(spec):
    n = len(spec["joints"])
    assert len(spec["gear_ratios"]) == n and all(g > 0 for g in spec["gear_ratios"])
    friction = spec["friction"]
    assert len(friction["viscous"]) == n and len(friction["coulomb"]) == n
    assert min(friction["viscous"] + friction["coulomb"]) > 0
    assert friction["smoothing"] == 0.05


def test_sphere_links_exist(model, spec):
    assert 12 <= len(spec["spheres"]) <= 18
    for s in spec["spheres"]:
        assert model.existBodyName(s["link"]), s["link"]
        assert len(s["center"]) == 3 and s["radius"] > 0


def test_self_collision_pairs_skip_same_and_adjacent_links(model, spec):
    assert spec["self_collision"]
    for a, b in spec["self_collision"]:
        ja, jb = (link_joint(model, spec["spheres"][i]["link"]) for i in (a, b))
        assert ja != jb, (a, b)
        assert model.parents[ja] != jb and model.parents[jb] != ja, (a, b)


@pytest.mark.parametrize("q", [np.zeros(6), HOME], ids=["zero", "home"])
def test_pose_is_free_of_self_collision(model, spec, q):
    assert np.all(pair_gaps(model, spec, q) > 0)


@pytest.mark.parametrize("link", ["base_link"] + [f"link_{i}" for i in range(1, 7)])
def test_spheres_cover_link_collision_geometry(spec, link):
    points = collision_points(link)
    own = [s for s in spec["spheres"] if s["link"] == link]
    assert own, f"{link} has no spheres"
    centres = np.array([s["center"] for s in own], float)
    radii = np.array([s["radius"] for s in own])
    dist = np.linalg.norm(points[:, None, :] - centres[None], axis=2)
    uncovered = points[np.all(dist > radii, axis=1)]
    assert len(uncovered) == 0, f"{len(uncovered)} points of {link} outside its spheres, e.g. {uncovered[:3]}"
