"""The vessel plots and summary draw what a run recorded: a scenario that records only part of
VesselMotion's outputs (as ``gangway`` does) gets the plots and statistics of that part."""
import numpy as np

from marinefmu.analysis.vessel_plots import plot_vessel, vessel_summary


def test_a_partial_record_gets_the_plots_and_statistics_of_what_it_holds(tmp_path):
    n = 500
    fields = ["vessel.truth.wave", "vessel.truth.imu.d", "vessel.truth.roll"]
    r = np.zeros(n, dtype=[("time", "f8")] + [(f, "f8") for f in fields])
    r["time"] = np.arange(n) * 0.1
    r["vessel.truth.wave"] = 0.5 * np.sin(0.7 * r["time"])
    r["vessel.truth.roll"] = 0.01 * np.sin(0.7 * r["time"])
    summary = vessel_summary(r, "vessel")
    assert set(summary) == {"hs_realised_m", "roll_std_deg"}
    assert summary["hs_realised_m"] == 4.0 * np.std(r["vessel.truth.wave"])
    paths = plot_vessel(r, "vessel", tmp_path)
    assert [p.name for p in paths] == ["vessel_motion.png"] and paths[0].stat().st_size > 10_000
