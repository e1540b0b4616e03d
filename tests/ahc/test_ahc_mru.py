"""The ``ahc_mru`` scenario: the heave-compensation loop fed by the MotionReferenceUnit at the
crane tip beside the same loop fed by today's AttitudeEstimator + HeaveObserver chain."""
import pytest

from marinefmu.analysis.scoring import ahc_scores
from marinefmu.cosim.scenarios import load_scenario


@pytest.mark.fmu
def test_the_mru_fed_loop_compensates_the_tip_heave_as_well_as_the_chain(fmu_dir):
    """The scenario's 1500 s (the loops engaged from about 150 s, scored from 60 s after; the
    joint filter from about 850 s): the MRU-fed winch, its gains designed for the unit
    (``marinefmu design-ahc ahc_mru --controller ctrl_mru --identify 1500``), leaves 0.90 % of the tip's heave
    against the chain's 0.91 % (0.99 ×): no worse, the goal. The margin is small and the loop
    is sensitive to the estimate's in-band error (docs/decisions/mru-design.md): with the
    attitude's aid reference on (the unit's default) 1.06 %. Tolerances: the chain's residual
    and 0.95 %."""
    from marinefmu.cosim.system import SystemRunner

    sc = load_scenario("ahc_mru")
    result = SystemRunner(sc.system, fmu_dir).run(sc.duration, record=list(sc.record), progress=False)
    scores = ahc_scores(result, sc.system)
    mru, chain, none = scores["winch_mru"], scores["winch_observer"], scores["winch_none"]
    assert none["residual_pct"] > 99.0                           # the tip's own heave, uncompensated
    assert mru["residual_pct"] <= 0.95, mru
    assert mru["vs_observer"] <= 1.0, mru
    assert mru["limited_pct"] == 0.0
