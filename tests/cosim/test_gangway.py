"""The ``gangway`` scenario: the MotionReferenceUnit at its defaults, given the tip of a 25 m
gangway on the polar supply vessel as its monitoring point, gives the tip's three-axis motion
within the project's goals, the report draws it, and OSP libcosim repeats the FMPy runner."""
import numpy as np
import pytest
from tests.conftest import LibcosimBeside

from marinefmu.cosim.scenarios import load_scenario

RECORD_LIBCOSIM = ["mru.roll", "mru.pitch", "mru.mp1.surge", "mru.mp1.sway", "mru.mp1.heave", "mru.mp1.surge_rate",
                   "mru.mp1.delayed.heave", "mru.motion.valid", "vessel.truth.point.n"]


@pytest.mark.fmu
@pytest.mark.libcosim
@pytest.mark.isolated(timeout=900)
def test_the_gangway_tip_motion_meets_its_goals_and_libcosim_repeats_it(fmu_dir, tmp_path):
    """The whole scenario (900 s) under the FMPy runner, scored against the vessel's truth; the
    first 200 s (the unit valid from 131 s) under libcosim, in a second process at the same
    time, equal to rounding (relative 1e-9, sampled every second: libcosim's time is integer
    nanoseconds)."""
    from marinefmu.analysis.html_report import write_report
    from marinefmu.analysis.scoring import mru_point, score
    from marinefmu.cosim.system import SystemRunner

    sc = load_scenario("gangway")
    assert mru_point(sc.system, "mru", "vessel") == "mp1."      # the unit's point 1 is the vessel's point
    short, sample = 200.0, 1.0
    with LibcosimBeside("gangway", fmu_dir, tmp_path, short, RECORD_LIBCOSIM, sample) as libcosim:
        result = SystemRunner(sc.system, fmu_dir).run(sc.duration, record=sc.record, progress=False)
        lib = libcosim.result(timeout=600)
    every = int(round(sample / sc.step))
    fmpy = result[every:int(round(short / sc.step)) + 1:every]
    assert fmpy["mru.motion.valid"][-1] and len(lib) == len(fmpy)
    for f in RECORD_LIBCOSIM:
        np.testing.assert_allclose(lib[f].astype(float), fmpy[f].astype(float), rtol=1e-9, atol=1e-12, err_msg=f)

    s = score(result, sc.system, "vessel")["mru"]
    assert s["point_distance_m"] == pytest.approx(34.21, abs=0.01) and s["scored_s"] > 600
    # The project goals at the tip: surge and sway <= max(2 cm, 5 % of std), heave <= max(2 cm,
    # 2.5 % of std); here the tip moves 21-22 cm (std) per axis, so each goal is 2 cm: the goal
    # is the bound asserted (one seeded run, no tolerance to add; the MotionReferenceUnit page
    # has the measured errors).
    for axis, pct in (("surge", 5.0), ("sway", 5.0), ("heave", 2.5)):
        goal = max(2.0, pct / 100 * s[f"point_{axis}_std_cm"])
        assert s[f"point_{axis}_cm"] <= goal, (axis, s[f"point_{axis}_cm"], goal)
        assert 15.0 < s[f"point_{axis}_std_cm"] < 30.0          # the tip does move: the goal is not vacuous
        # the delayed output is better than the real-time one on every axis (the half is
        # met for sway only, see the MotionReferenceUnit page)
        assert s[f"point_delayed_{axis}_cm"] < s[f"point_{axis}_cm"], axis
    # the 3-D error <= the length of the three 2 cm goals together (2·√3 = 3.46 cm)
    assert s["point_3d_cm"] <= 2.0 * np.sqrt(3.0)

    page = write_report(result, sc.system, {"mru": s}, "vessel", tmp_path, "gangway", sc.description).read_text()
    assert "three-axis motion of monitoring point mp1 (34.2 m from the IMU)" in page
    assert "point position (3-D), RMS length of the error [cm]" in page
