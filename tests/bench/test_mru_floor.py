"""The MotionReferenceUnit's cost floor replays the unit's own filter work: a fresh filter group
fed what the unit fed its own returns what the unit's returned, designs included."""
import numpy as np

from marinefmu.bench.cases import CASES, case_record
from marinefmu.bench.mru import filter_feed, replay_filters
from marinefmu.estimators.mru.goals import POINTS
from marinefmu.estimators.mru.params import MotionReferenceUnitParams
from marinefmu.sea.motion_model import stack


def test_the_replayed_filters_repeat_the_units_outputs_step_by_step():
    rec = case_record(*CASES[0][:4], duration=240.0)
    gyro, acc = stack(rec, "imu.gyro"), stack(rec, "imu.acc")
    for params in (MotionReferenceUnitParams(), MotionReferenceUnitParams(points=POINTS[:1])):
        fed, got, sizing = filter_feed(gyro, acc, params)
        assert len(fed) == len(acc) and len(fed[0]) == (4 if params.points else 3)
        designed = [k for k, out in enumerate(got) if out is not None]
        assert designed and designed[0] < len(acc) - 5000      # the filters ran designed for a minute or more
        again = replay_filters(fed, params, sizing)
        assert sizing                                           # the unit sized its surge and sway filters
        for k in range(len(got)):
            if got[k] is None:
                assert again[k] is None, k
            else:
                np.testing.assert_array_equal(again[k], got[k])
