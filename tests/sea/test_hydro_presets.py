"""The shipped BEM presets and ``marinefmu hydro``: tables VesselMotion reads, the command line."""
import math

import numpy as np
import pytest

from marinefmu.cli import main
from marinefmu.errors import ParameterError
from marinefmu.sea.hydro import presets
from marinefmu.sea.hydro.hulls import check_closed
from marinefmu.sea.motion_model import VesselMotionParams, simulate_record
from marinefmu.sea.vessel import BEM_PRESETS, PRESET_NAMES, PRESETS, bem_preset_path, load_rao_csv, preset_raos
from marinefmu.sea.waves import SeaState


def test_vessel_and_hydro_agree_on_the_preset_names():
    assert BEM_PRESETS == tuple(presets.BEM_PRESETS)
    assert PRESET_NAMES == (*PRESETS, *BEM_PRESETS)
    for p in presets.BEM_PRESETS.values():
        assert p.counterpart is None or p.counterpart in PRESETS


@pytest.mark.parametrize("name", BEM_PRESETS)
def test_shipped_tables_are_current_and_follow_the_surface_in_long_waves(name):
    path = bem_preset_path(name)
    text = path.read_text()
    assert "regenerate: marinefmu hydro --preset all --out src/marinefmu/data/hydro --plots docs" in text
    assert "irregular" in text and "natural periods heave" in text
    t = preset_raos(name)
    assert t.name == name
    np.testing.assert_array_equal(t.rao, load_rao_csv(path).rao)
    head, beam = int(np.argmin(np.abs(t.heading - math.pi))), int(np.argmin(np.abs(t.heading - math.pi / 2)))
    assert t.omega[0] == pytest.approx(0.1)
    # heave → −η: no one-DOF amplification as in the closed form, since in long waves the
    # excitation carries the water's inertia too (the semi-submersible, ω/ω_n = 0.3: −1.0006 + 0.03i)
    assert t.rao[2, 0, head] == pytest.approx(-1.0, abs=0.04)
    assert t.rao[2, 0, beam] == pytest.approx(-1.0, abs=0.04)
    assert t.rao[0, 0, head] == pytest.approx(1j, abs=0.03)
    p = presets.preset(name)
    assert t.omega[-1] >= p.omega_max - 1e-9


@pytest.mark.parametrize("name", BEM_PRESETS)
def test_vessel_motion_runs_on_the_shipped_table(name):
    rec = simulate_record(VesselMotionParams(sea=SeaState(hs=3.0, tp=10.0), rao_file=str(bem_preset_path(name))), 30.0, 0.1)
    assert np.all(np.isfinite(rec["truth.cog.d"])) and np.std(rec["truth.cog.d"]) > 0.05


@pytest.mark.parametrize("name", BEM_PRESETS)
def test_coarse_preset_hulls_are_closed_with_the_cog_inside(name):
    pytest.importorskip("capytaine")
    p = presets.preset(name)
    hull = p.hull(coarse=True)
    assert check_closed(hull) > 0
    mp = presets.mass_properties(p, hull)
    assert hull.contains(np.array(mp.cog))


def test_gm_places_the_cog_of_the_box_by_its_hydrostatics():
    pytest.importorskip("capytaine")
    from marinefmu.sea.hydro import bem, hulls

    hull = hulls.box_barge(100.0, 20.0, 5.0, 1.0)
    kb, bm = 2.5, 20.0**2 / (12 * 5.0)
    # z down from the waterline; Capytaine integrates y² at panel centres: BM low by (Δy/B)² = 0.25 %
    assert bem.cog_for_gm(hull, 4.0) == pytest.approx(5.0 - (kb + bm - 4.0), abs=0.02)


def test_unknown_preset_lists_the_bem_presets_too():
    with pytest.raises(ParameterError, match="box_barge"):
        preset_raos("tanker")


def test_hydro_command_writes_table_plot_and_summary(tmp_path, capsys):
    pytest.importorskip("capytaine")
    out = tmp_path / "hydro"
    code = main(["hydro", "--hull", "box", "--length", "10", "--beam", "4", "--draft", "2", "--cog", "0", "0", "1.0", "--panel", "1",
                 "--radii", "1.4", "2.5", "2.6", "--roll-damping", "0.05", "--omega-max", "1.0", "--omega-step", "0.3",
                 "--name", "tiny", "--out", str(out), "--json", "--no-progress"])
    assert code == 0
    table = load_rao_csv(out / "tiny.csv")
    assert table.omega[0] == pytest.approx(0.1) and table.heading.size == 24
    assert (out / "hydro_tiny.png").stat().st_size > 10_000 and (out / "tiny.json").exists()
    assert "natural periods heave" in capsys.readouterr().out


@pytest.mark.parametrize(("argv", "message"), [
    (["hydro", "--hull", "box", "--beam", "4", "--draft", "2"], "needs --length"),
    (["hydro", "--hull", "box", "--length", "10", "--beam", "4", "--draft", "2", "--cog", "0", "0", "0"], "needs --radii"),
    (["hydro", "--mesh", "missing.gdf", "--cog", "0", "0", "0", "--radii", "1", "1", "1"], "does not exist"),
    (["hydro", "--hull", "box", "--length", "10", "--beam", "4", "--draft", "2", "--cog", "0", "9", "0",
      "--radii", "1", "1", "1", "--omega-max", "1"], "outside the hull"),
])
def test_hydro_command_refuses_bad_input_naming_it(argv, message, capsys):
    pytest.importorskip("capytaine")
    assert main(argv + ["--no-progress"]) == 2
    assert message in capsys.readouterr().err
