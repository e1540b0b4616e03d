"""The MotionReferenceUnit in a system gives the same outputs under the FMPy runner and under
OSP libcosim."""
import numpy as np
import pytest
from tests.conftest import LibcosimBeside

from marinefmu.cosim.scenarios import load_scenario

RECORD = ["mru.roll", "mru.pitch", "mru.heave", "mru.surge", "mru.sway", "mru.mp1.heave", "mru.mp1.heave_rate",
          "mru.mp1.delayed.heave", "mru.motion.valid", "winch_mru.load.d"]


@pytest.mark.fmu
@pytest.mark.libcosim
@pytest.mark.isolated(timeout=600)
def test_the_mru_system_is_the_same_under_fmpy_and_libcosim(fmu_dir, tmp_path):
    """160 s of ``ahc_mru`` (the unit valid from about 141 s, its loop engaging): libcosim, from
    the OSP file in a second process, repeats the FMPy runner to rounding, sampled every second
    (relative 1e-9: libcosim's time is integer nanoseconds, k·h to about 1 ulp)."""
    from marinefmu.cosim.system import SystemRunner

    sc = load_scenario("ahc_mru")
    duration, sample = 160.0, 1.0
    with LibcosimBeside("ahc_mru", fmu_dir, tmp_path, duration, RECORD, sample) as libcosim:
        fmpy = SystemRunner(sc.system, fmu_dir).run(duration, record=RECORD, progress=False)
        lib = libcosim.result(timeout=500)
    assert fmpy["mru.motion.valid"][-1] and abs(fmpy["mru.mp1.heave"][-100:]).max() > 0.1
    every = int(round(sample / sc.step))
    for f in RECORD:
        np.testing.assert_allclose(lib[f].astype(float), fmpy[every::every][f].astype(float), rtol=1e-9,
                                   atol=1e-12, err_msg=f)
