"""Quaternions [x, y, z, w] against pinocchio's."""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from ocpkit.geometry.quaternion import IDENTITY, quaternion_matrix, quaternion_product


def pin_matrix(q: np.ndarray) -> np.ndarray:
    return pin.Quaternion(q[3], q[0], q[1], q[2]).toRotationMatrix()


def test_matrix_and_product_match_pinocchio():
    rng = np.random.default_rng(3)
    for _ in range(20):
        a, b = (v / np.linalg.norm(v) for v in rng.normal(size=(2, 4)))
        np.testing.assert_allclose(quaternion_matrix(a), pin_matrix(a), atol=1e-12)
        np.testing.assert_allclose(quaternion_matrix(quaternion_product(a, b)), pin_matrix(a) @ pin_matrix(b),
                                   atol=1e-12)
        assert quaternion_product(a, b)[3] >= 0


def test_a_quarter_turn_about_z_maps_x_to_y_and_identity_is_neutral():
    quarter = [0, 0, np.sin(np.pi / 4), np.cos(np.pi / 4)]
    np.testing.assert_allclose(quaternion_matrix(quarter) @ [1, 0, 0], [0, 1, 0], atol=1e-12)
    np.testing.assert_allclose(quaternion_product(IDENTITY, quarter), quarter, atol=1e-15)
    np.testing.assert_allclose(quaternion_matrix([0, 0, 0, 2.0]), np.eye(3))  # normalised first
