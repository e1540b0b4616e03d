"""Conversions into NED, FRD, specific force and heave down."""
import numpy as np
import pytest

from marinefmu.frames import attitude_kinematics
from marinefmu.sea.recording.convert import (
    angles_to_ned_frd, body_to_frd, euler_matrix, gravity_to_specific_force, matrix_euler, world_to_ned,
)

RNG = np.random.default_rng(3)
ANG = RNG.uniform([-0.5, -0.4, -3.0], [0.5, 0.4, 3.0], (50, 3))


def test_euler_matrix_is_the_project_rotation_and_round_trips():
    for r, p, y in ANG[:5]:
        rot = attitude_kinematics([r, p, y], [0, 0, 0], [0, 0, 0])[0]
        np.testing.assert_allclose(euler_matrix(np.array([r]), np.array([p]), np.array([y]))[0], rot, atol=1e-14)
    back = np.column_stack(matrix_euler(euler_matrix(*ANG.T)))
    np.testing.assert_allclose(back, ANG, atol=1e-12)


def test_enu_and_flu_vectors():
    np.testing.assert_array_equal(world_to_ned(np.array([[1.0, 2.0, 3.0]]), "enu"), [[2.0, 1.0, -3.0]])
    np.testing.assert_array_equal(body_to_frd(np.array([[1.0, 2.0, 3.0]]), "flu"), [[1.0, -2.0, -3.0]])


def test_enu_flu_angles_closed_form_equals_the_matrix_route():
    r, p, y = ANG.T
    closed = np.column_stack(angles_to_ned_frd(r, p, y, "enu", "flu"))
    a = np.array([[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]])
    b = np.diag([1.0, -1.0, -1.0])
    via = np.column_stack(matrix_euler(a @ euler_matrix(r, p, y) @ b))
    d = closed - via
    d[:, 2] = np.angle(np.exp(1j * d[:, 2]))
    np.testing.assert_allclose(d, 0.0, atol=1e-12)


def test_a_vector_keeps_its_world_direction_through_the_conversion():
    """f_n = R f_b holds in both conventions: the converted attitude rotates the converted vector
    onto the converted world vector."""
    r, p, y = ANG.T
    v_rec = RNG.normal(size=(50, 3))
    w_rec = np.einsum("kij,kj->ki", euler_matrix(r, p, y), v_rec)
    for world, body in (("enu", "flu"), ("ned", "flu"), ("enu", "frd")):
        rn, pn, yn = angles_to_ned_frd(r, p, y, world, body)
        w = np.einsum("kij,kj->ki", euler_matrix(rn, pn, yn), body_to_frd(v_rec, body))
        np.testing.assert_allclose(w, world_to_ned(w_rec, world), atol=1e-12)


def test_gravity_removed_becomes_specific_force():
    r, p = np.array([0.1, -0.3]), np.array([0.2, 0.05])
    a = np.array([[0.5, 0.0, -0.2], [0.0, 1.0, 0.3]])
    f = gravity_to_specific_force(a, r, p)
    rot = euler_matrix(r, p, np.zeros(2))
    expected = a - np.einsum("kji,j->ki", rot, np.array([0.0, 0.0, 9.80665]))
    np.testing.assert_allclose(f, expected, atol=1e-12)
    level = gravity_to_specific_force(np.zeros((1, 3)), np.zeros(1), np.zeros(1))
    np.testing.assert_allclose(level, [[0.0, 0.0, -9.80665]])   # a level sensor at rest reads −g
