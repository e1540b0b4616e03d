"""Frame helpers against scipy's Rotation and against each other."""
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from marinefmu.frames import (GRAVITY_N, attitude_kinematics, cross3, euler_rates_to_body, nav_tilt, rigid_point_operator,
                              rot_nb, specific_force)

rng = np.random.default_rng(3)
ANGLES = rng.uniform([-0.5, -0.4, -3.1], [0.5, 0.4, 3.1], size=(20, 3))


@pytest.mark.parametrize("roll,pitch,yaw", ANGLES)
def test_rot_nb_is_scipy_zyx(roll, pitch, yaw):
    expected = Rotation.from_euler("ZYX", [yaw, pitch, roll]).as_matrix()
    np.testing.assert_allclose(rot_nb(roll, pitch, yaw), expected, atol=2e-15)


def test_level_sensor_at_rest_reads_minus_g():
    np.testing.assert_allclose(specific_force(np.eye(3), np.zeros(3)), -GRAVITY_N)


def test_attitude_kinematics_agrees_with_the_separate_functions():
    e, ed, edd = ANGLES[0], rng.normal(size=3) * 0.1, rng.normal(size=3) * 0.05
    rot, w, a = attitude_kinematics(list(e), list(ed), list(edd))
    w2, a2 = euler_rates_to_body(e, ed, edd)
    np.testing.assert_allclose(rot, rot_nb(*e), atol=1e-16)
    np.testing.assert_allclose(w, w2, atol=1e-17)
    np.testing.assert_allclose(a, a2, atol=1e-17)


def test_body_rate_matches_rotation_derivative():
    # Euler angles moving linearly: Ṙ = R [ω×] with ω from euler_rates_to_body
    e0, ed = np.array([0.3, -0.2, 1.0]), np.array([0.05, -0.03, 0.02])
    h = 1e-6
    rdot = (rot_nb(*(e0 + h * ed)) - rot_nb(*(e0 - h * ed))) / (2 * h)
    w, _ = euler_rates_to_body(e0, ed, np.zeros(3))
    wx = rot_nb(*e0).T @ rdot
    np.testing.assert_allclose([wx[2, 1], wx[0, 2], wx[1, 0]], w, atol=1e-10)


def test_rigid_point_operator_is_cross_products():
    w, a, arm = rng.normal(size=3), rng.normal(size=3), rng.normal(size=3)
    body = rigid_point_operator(list(w), list(a)) @ arm
    np.testing.assert_allclose(body[:3], arm, atol=1e-15)
    np.testing.assert_allclose(body[3:6], np.cross(w, arm), atol=1e-15)
    np.testing.assert_allclose(body[6:9], np.cross(a, arm) + np.cross(w, np.cross(w, arm)), atol=1e-14)


def test_cross3_is_numpy_cross():
    """The written-out cross product equals np.cross bit for bit on seeded random vectors."""
    rng = np.random.default_rng(4)
    for a, b in rng.normal(size=(50, 2, 3)):
        assert np.array_equal(cross3(a, b), np.cross(a, b))


@pytest.mark.parametrize("roll,pitch,yaw", ANGLES)
def test_nav_tilt_is_scipys_rotation_vector_without_the_yaw(roll, pitch, yaw):
    """nav_tilt is the N / E part of scipy's rotation vector of R_nb·R_z(ψ)ᵀ, and a small
    rotation exp([ε]×) of the attitude moves it by (ε_N, ε_E) to second order: off by at most
    0.39 |ε|·|tilt| here (|tilt| = √(roll² + pitch²) up to 0.6 rad); bound 0.5 |ε|·|tilt|."""
    r = rot_nb(roll, pitch, yaw)
    expected = Rotation.from_matrix(r @ Rotation.from_euler("z", yaw).as_matrix().T).as_rotvec()[:2]
    np.testing.assert_allclose(nav_tilt(r), expected, atol=1e-15)
    eps = np.array([3e-3, -2e-3, 1e-3])
    moved = Rotation.from_rotvec(eps).as_matrix() @ r
    bound = 0.5 * np.linalg.norm(eps) * np.hypot(roll, pitch)
    assert np.max(np.abs(nav_tilt(moved) - nav_tilt(r) - eps[:2])) < bound
