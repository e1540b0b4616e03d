"""Hull meshes for the BEM solve: closed surfaces, analytic volumes, refused defects, mesh files."""
import math

import numpy as np
import pytest

from marinefmu.errors import ParameterError
from marinefmu.sea.hydro import hulls
from marinefmu.sea.hydro.hulls import HullMesh, check_closed


@pytest.mark.parametrize(("hull", "volume", "rel"), [
    (hulls.box_barge(100.0, 20.0, 5.0, 3.0), 100 * 20 * 5, 1e-12),
    (hulls.semisubmersible(82.0, 71.2, 36.0, 18.0, 18.0, 11.6, 3.0), 2 * 82 * 18 * 11.6 + 4 * 18 * 18 * (36 - 11.6), 1e-12),
    # Wigley hull: C_B = 4/9; the flat panels cut the convex sections by ~1 %
    (hulls.ship_hull(3.0, 0.3, 0.1875, 0.03), 4 / 9 * 3.0 * 0.3 * 0.1875, 0.015),
    (hulls.ship_hull(134.2, 22.0, 7.65, 1.5, p=3.0, q=4.0), 0.75 * 0.8 * 134.2 * 22.0 * 7.65, 0.015),
    (hulls.hemisphere(1.0, 0.1), 2 / 3 * math.pi, 0.01),
])
def test_parametric_hulls_are_closed_with_the_analytic_volume(hull, volume, rel):
    assert check_closed(hull) == pytest.approx(volume, rel=rel)
    v, f = hull.full()
    assert v[:, 2].max() <= 1e-9 and np.all(np.abs(v[:, 1]).max() > 0)


def test_quarter_mirrors_into_a_symmetric_hull():
    v, f = hulls.box_barge(10.0, 4.0, 2.0, 1.0).full()
    for axis in (0, 1):
        m = v.copy()
        m[:, axis] *= -1
        assert {tuple(p) for p in np.round(m, 9)} == {tuple(p) for p in np.round(v, 9)}


def _box():
    return hulls.box_barge(10.0, 4.0, 2.0, 1.0)


def _modified(h: HullMesh, faces: np.ndarray) -> HullMesh:
    return HullMesh(h.name, h.vertices, faces, h.quarter, h.freeboard, h.description, h.inside)


def test_a_hole_below_the_waterline_is_refused():
    h = _box()
    bottom = int(np.argmin(h.vertices[h.faces].mean(axis=1)[:, 2]))
    with pytest.raises(ParameterError, match=r"not closed: \d+ open edge\(s\) below the waterline"):
        check_closed(_modified(h, np.delete(h.faces, bottom, axis=0)))


def test_a_hole_at_the_waterline_is_refused():
    h = _box()
    top = int(np.argmax(h.vertices[h.faces].mean(axis=1)[:, 2]))   # a side panel touching z = 0
    with pytest.raises(ParameterError, match="not closed"):
        check_closed(_modified(h, np.delete(h.faces, top, axis=0)))


def test_inward_normals_are_refused():
    h = _box()
    with pytest.raises(ParameterError, match="normals point into the hull"):
        check_closed(_modified(h, h.faces[:, ::-1]))


def test_one_flipped_panel_is_refused():
    h = _box()
    f = h.faces.copy()
    f[3] = f[3, ::-1]
    with pytest.raises(ParameterError, match="inconsistent panel orientation"):
        check_closed(_modified(h, f))


def test_a_submerged_closed_body_is_not_a_hull():
    v, f = hulls.box_barge(10.0, 4.0, 2.0, 1.0).full()
    low = v - [0.0, 0.0, 3.0]               # the open box lowered to −5 … −3
    top = low.copy()
    top[:, 2] = -6.0 - low[:, 2]            # and its mirror about z = −3 close it under water
    closed = np.vstack([low, top])
    faces = np.vstack([f, f[:, ::-1] + v.shape[0]])
    with pytest.raises(ParameterError, match="no waterline"):
        check_closed(HullMesh("sub", closed, faces, False, 1.0, "submerged"))


def test_cog_inside_the_hull():
    box = _box()
    assert box.contains([0.0, 0.0, 1.0]) and box.contains([4.9, -1.9, -1.9])
    assert not box.contains([0.0, 2.5, 0.0]) and not box.contains([0.0, 0.0, 2.5])
    ship = hulls.ship_hull(100.0, 20.0, 6.0, 2.0)
    assert ship.contains([0.0, 9.0, -3.0]) and not ship.contains([45.0, 9.0, 0.0])


def test_gdf_file_round_trip(tmp_path):
    pytest.importorskip("capytaine")
    h = hulls.box_barge(10.0, 4.0, 2.0, 1.0)
    back = hulls.load_mesh_file(hulls.write_gdf(h, tmp_path / "box.gdf"))
    assert not back.quarter and back.name == "box"
    assert check_closed(back) == pytest.approx(80.0, rel=1e-9)
    assert back.contains([0.0, 0.0, -1.5])    # deck: the draft by default for an immersed-only file


def test_mesh_file_above_the_waterline_is_clipped(tmp_path):
    pytest.importorskip("capytaine")
    v, f = hulls.box_barge(10.0, 4.0, 2.0, 1.0).full()
    v = v + [0.0, 0.0, 1.0]                   # a 1 m freeboard above z = 0: draft 1 m
    h = HullMesh("raised", v, f, False, 1.0, "")
    back = hulls.load_mesh_file(hulls.write_gdf(h, tmp_path / "raised.gdf"))
    # the hull's top (the open waterplane at z = 1) becomes the deck; the waterline cut at z = 0
    assert check_closed(back) == pytest.approx(40.0, rel=1e-9)
    assert back.freeboard == pytest.approx(1.0)


def test_bad_mesh_files_are_refused(tmp_path):
    pytest.importorskip("capytaine")
    with pytest.raises(ParameterError, match="does not exist"):
        hulls.load_mesh_file(tmp_path / "none.gdf")
    bad = tmp_path / "bad.gdf"
    bad.write_text("title\n1 9.81\n0 0\n3\n0 0 0\n")
    with pytest.raises(ParameterError, match="cannot be read"):
        hulls.load_mesh_file(bad)


@pytest.mark.parametrize(("call", "match"), [
    (lambda: hulls.box_barge(-1.0, 4.0, 2.0, 1.0), "hull.length"),
    (lambda: hulls.box_barge(10.0, 4.0, 2.0, 0.0), "hull.panel"),
    (lambda: hulls.semisubmersible(80.0, 70.0, 30.0, 18.0, 18.0, 40.0, 3.0), "do not fit"),
    (lambda: hulls.ship_hull(100.0, 20.0, 6.0, 2.0, p=0.5), "hull.p"),
])
def test_bad_hull_parameters_are_named(call, match):
    with pytest.raises(ParameterError, match=match):
        call()
