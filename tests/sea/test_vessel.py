"""RAO tables: presets, long-wave limits, CSV round trip and malformed files."""
import math

import numpy as np
import pytest

from marinefmu.errors import ParameterError, RaoFileError
from marinefmu.sea.vessel import CSV_COLUMNS, PRESETS, load_rao_csv, preset_raos, save_rao_csv


@pytest.mark.parametrize("name", sorted(PRESETS))
def test_presets_follow_the_surface_in_long_waves(name):
    hull, w = PRESETS[name], 0.05
    t = preset_raos(name)
    r = t.interpolate(np.array([w, w]), np.array([math.pi, math.pi / 2]))

    def amp(period, zeta):  # one-DOF dynamic amplification, still a few % at 0.05 rad/s for the semi-sub
        q = w * period / (2 * math.pi)
        return 1 / (1 - q**2 + 2j * zeta * q)

    # heave → −η (positive down), pitch → ∂η/∂x = −i k cos β, roll → −∂η/∂y = i k sin β (β = π/2);
    # the remaining difference is the hull attenuation at k·L/2 ≤ 0.01 and e^{−kT} ≥ 0.99
    k = w**2 / 9.80665
    assert r[2, 0] == pytest.approx(-amp(hull.t_heave, hull.zeta_heave), rel=0.01)
    assert r[4, 0] == pytest.approx(-1j * k * math.cos(math.pi) * amp(hull.t_pitch, hull.zeta_pitch), rel=0.01)
    assert r[3, 1] == pytest.approx(1j * k * amp(hull.t_roll, hull.zeta_roll), rel=0.01)
    assert np.all(np.isfinite(t.rao))


@pytest.mark.parametrize("name", sorted(PRESETS))
def test_preset_roll_resonates_at_its_natural_period(name):
    hull = PRESETS[name]
    t = preset_raos(name)
    w = np.linspace(0.1, 2.0, 2000)
    roll = np.abs(t.interpolate(w, np.full(w.size, math.pi / 2))[3])
    # the peak sits near the natural frequency (the k factor and attenuation shift it slightly)
    assert w[np.argmax(roll)] == pytest.approx(2 * math.pi / hull.t_roll, rel=0.15)


def test_interpolation_is_exact_on_grid_points_and_periodic_in_heading():
    t = preset_raos("research36")
    i, j = 17, 5
    np.testing.assert_allclose(t.interpolate(t.omega[[i]], t.heading[[j]])[:, 0], t.rao[:, i, j], atol=1e-15)
    np.testing.assert_allclose(t.interpolate(t.omega[[i]], t.heading[[j]] + 2 * math.pi)[:, 0], t.rao[:, i, j], atol=1e-14)
    assert np.all(t.interpolate(np.array([t.omega[-1] + 1.0]), np.array([0.0])) == 0)


def test_csv_round_trip(tmp_path):
    t = preset_raos("semisub")
    save_rao_csv(t, tmp_path / "r.csv")
    back = load_rao_csv(tmp_path / "r.csv")
    np.testing.assert_allclose(back.rao, t.rao, atol=1e-15)
    np.testing.assert_array_equal(back.omega, t.omega)


def test_unknown_preset_names_the_choices():
    with pytest.raises(ParameterError, match=r"vessel\.preset = 'tanker' is not allowed: must be one of"):
        preset_raos("tanker")


def _write(tmp_path, text):
    p = tmp_path / "bad.csv"
    p.write_text(text)
    return p


def test_unreadable_rao_file(tmp_path):
    with pytest.raises(RaoFileError, match=r"vessel\.rao_file = '.*missing\.csv' cannot be read"):
        load_rao_csv(tmp_path / "missing.csv")


def test_rao_file_missing_column(tmp_path):
    with pytest.raises(RaoFileError, match="missing column.*yaw_phase"):
        load_rao_csv(_write(tmp_path, ",".join(CSV_COLUMNS[:-1]) + "\n"))


def test_rao_file_non_number(tmp_path):
    row = ["0.5", "0.0"] + ["1.0"] * 12
    row[4] = "abc"
    with pytest.raises(RaoFileError, match=r"data row 1, column 'sway_amp': not a number"):
        load_rao_csv(_write(tmp_path, ",".join(CSV_COLUMNS) + "\n" + ",".join(row) + "\n"))


def test_rao_file_incomplete_grid(tmp_path):
    rows = [["0.5", "0.0"], ["0.6", "0.0"], ["0.5", "1.0"]]
    text = ",".join(CSV_COLUMNS) + "\n" + "".join(",".join(r + ["1.0"] * 12) + "\n" for r in rows)
    with pytest.raises(RaoFileError, match="do not form a complete grid"):
        load_rao_csv(_write(tmp_path, text))


def test_rao_file_negative_amplitude(tmp_path):
    rows = [["0.5", "0.0"], ["0.6", "0.0"]]
    text = ",".join(CSV_COLUMNS) + "\n" + "".join(",".join(r + ["-1.0"] * 12) + "\n" for r in rows)
    with pytest.raises(RaoFileError, match="amplitudes must be >= 0"):
        load_rao_csv(_write(tmp_path, text))
