"""The shipped BEM tables against VesselMotion's spectrum grid: headings over the whole circle,
frequencies from below the longest benchmark sea's grid, and a bounded loss above the highest."""
import math

import numpy as np
import pytest

from marinefmu.bench.cases import SEAS
from marinefmu.sea.hydro.export import PEAK_HEADING_DEG
from marinefmu.sea.hydro.presets import BEM_PRESETS
from marinefmu.sea.hydro.validation import tail_bound
from marinefmu.sea.vessel import bem_preset_path, load_rao_csv
from marinefmu.sea.waves import SeaState

#: What the motion above a table's last frequency may be, at most (the RAO held at its last value,
#: an upper bound): 1 % of the motion's std, or 1 mm of heave and 0.002° of roll or pitch in that
#: sea, a fifth of an MRU-grade unit's 0.01° and a tenth of the 1 cm the heave goals resolve.
LOST_FRACTION, LOST_HEAVE_M, LOST_ANGLE_DEG = 0.01, 0.001, 0.002


@pytest.mark.parametrize("name", BEM_PRESETS)
def test_headings_cover_the_circle_and_frequencies_start_below_the_sea_grid(name):
    t = load_rao_csv(bem_preset_path(name))
    step = np.diff(np.concatenate([t.heading, [t.heading[0] + 2 * math.pi]]))
    assert t.heading[0] == 0.0 and np.degrees(step.max()) <= 15.0 + 1e-9
    longest = max(tp for _, tp in SEAS)
    assert t.omega[0] <= SeaState(tp=longest).omega_range[0]       # 0.1 ≤ 0.5 ω_p at Tp 14 s


#: The box barge (no benchmark vessel) in the Tp 5 s sea is the one case over the limits: its
#: vertical walls keep the beam-sea roll RAO at 0.077 °/m at the table's 2.2 rad/s, so the bound
#: on the roll lost is 3.6 % of the std (0.0055° per metre of Hs); docs/hydrodynamics.md, Limits.
SHORT_OF_THE_GRID = {("box_barge", 5.0): {"roll": 0.04}}


def _lost_within_limits(name, hs, tp):
    t = load_rao_csv(bem_preset_path(name))
    out = {}
    for dof, limit in (("heave", LOST_HEAVE_M), ("roll", math.radians(LOST_ANGLE_DEG)),
                       ("pitch", math.radians(LOST_ANGLE_DEG))):
        r = tail_bound(t, SeaState(hs=hs, tp=tp), math.radians(PEAK_HEADING_DEG[dof]))
        assert not r["below"]
        d = r[dof]
        assert d["kept_std"] > 0
        out[dof] = (d["lost_fraction"] <= LOST_FRACTION or d["lost_std"] <= limit, d["lost_fraction"])
    return out


@pytest.mark.parametrize("name", BEM_PRESETS)
@pytest.mark.parametrize(("hs", "tp"), SEAS)
def test_motion_above_the_table_is_bounded_in_every_benchmark_sea(name, hs, tp):
    for dof, (ok, fraction) in _lost_within_limits(name, hs, tp).items():
        allowed = SHORT_OF_THE_GRID.get((name, tp), {}).get(dof)
        if allowed is None:
            assert ok, (dof, fraction)
        else:
            assert not ok and fraction <= allowed, (dof, fraction)


def test_tail_bound_sees_a_table_that_stops_short():
    """A table cut at 0.8 rad/s loses most of a Tp 5 s sea (ω_p 1.26 rad/s): the check can fail."""
    t = load_rao_csv(bem_preset_path("box_barge"))
    from marinefmu.sea.vessel import RaoTable
    cut = RaoTable(omega=t.omega[t.omega <= 0.8], heading=t.heading, rao=t.rao[:, t.omega <= 0.8], name="cut")
    r = tail_bound(cut, SeaState(hs=1.0, tp=5.0), math.pi / 2)
    assert r["heave"]["lost_fraction"] > 0.5 and r["heave"]["lost_std"] > LOST_HEAVE_M
