"""The ``ahc_mru`` scenario: the heave-compensation loop fed by the MotionReferenceUnit at the
crane tip beside the same loop fed by today's AttitudeEstimator + HeaveObserver chain."""
import pytest

from marinefmu.analysis.scoring import ahc_scores
from marinefmu.cosim.scenarios import load_scenario


@pytest.mark.fmu
def test_the_mru_fed_loop_compensates_the_tip_heave(fmu_dir):
    """600 s (the loops engaged from about 150 s, scored from 60 s after; the joint filter not
    yet taught): the MRU-fed winch leaves 0.96 % of the tip's heave against the chain's 0.90 %
    (1.06 ×). The goal of no worse than the chain is not met here; over the scenario's 21
    scored minutes 1.06 % against 0.91 % (docs/decisions/mru-design.md says where the rest
    lies). Tolerances: 1.0 % and 1.1 × the chain's."""
    from marinefmu.cosim.system import SystemRunner

    sc = load_scenario("ahc_mru")
    result = SystemRunner(sc.system, fmu_dir).run(600.0, record=list(sc.record), progress=False)
    scores = ahc_scores(result, sc.system)
    mru, chain, none = scores["winch_mru"], scores["winch_observer"], scores["winch_none"]
    assert none["residual_pct"] > 99.0                           # the tip's own heave, uncompensated
    assert mru["residual_pct"] <= 1.0, mru
    assert mru["vs_observer"] <= 1.1, mru
    assert mru["limited_pct"] == 0.0
