"""MotionReferenceUnit FMU: roll, pitch, yaw and real-time and delayed surge, sway and heave at
the IMU and at up to four monitoring points, from one strapdown IMU (papers 000 and 003 in one
process). Thin adapter over ``marinefmu.estimators.mru.unit``; never raises (see
``marinefmu.fmu.slave``)."""
from pythonfmu import Fmi2Slave

from marinefmu import __version__
from marinefmu.fmu.tables import MRU_BOOLEANS, MRU_INPUTS, MRU_OUTPUTS, MRU_PARAMETERS, mru_params
from marinefmu.fmu.slave import SlaveIO
from marinefmu.estimators.mru.params import MAX_POINTS
from marinefmu.estimators.mru.unit import MotionReferenceUnit as Estimator


if "MotionReferenceUnit" in globals():  # pythonfmu runs this file again for each instance: see SlaveIO.rerun
    MotionReferenceUnit = SlaveIO.rerun(globals(), "MotionReferenceUnit")
else:
    class MotionReferenceUnit(Fmi2Slave):
        author = "marinefmu developers"
        description = "Virtual motion reference unit: attitude and three-axis motion at the IMU and monitoring points"
        version = __version__
        license = "MIT"

        def __init__(self, **kwargs):
            super().__init__(**kwargs)
            self.io = SlaveIO(self, MRU_PARAMETERS, MRU_OUTPUTS, MRU_BOOLEANS, MRU_INPUTS)
            self.model = None
            self.rows = []

        def setup_experiment(self, start_time, stop_time, tolerance):
            self.io.start_time = start_time

        def exit_initialization_mode(self):
            self.model = self.io.build(lambda values: Estimator(mru_params(values)))
            # output block of each location: the IMU, then every monitoring point (10 reals each)
            enabled = [i for i in range(1, MAX_POINTS + 1) if self.io.params[f"mp{i}.enabled"]]
            self.rows = [0, *enabled]

        def do_step(self, current_time, step_size):
            return self.io.step(self._step, current_time, step_size)

        def _step(self, t, dt):
            i = self.io.inputs
            r = self.model.step((i["gyro.x"], i["gyro.y"], i["gyro.z"]), (i["acc.x"], i["acc.y"], i["acc.z"]), dt,
                                i["heading"], i["heading.valid"])
            self.io.warn(r.warning, t, r.valid and r.motion_valid)
            reals = [0.0] * (3 + 10 * (MAX_POINTS + 1))
            reals[0:3] = (r.roll, r.pitch, r.yaw)
            for row, place in enumerate(self.rows):
                at = 3 + 10 * place
                reals[at:at + 10] = (*r.position[row], *r.velocity[row], r.heave_acc[row], *r.delayed_position[row])
            self.io.set_outputs([*reals, r.delay, r.wave_period],
                                [r.valid, r.motion_valid, r.delayed_valid, r.heading_used, r.joint])

        def _get_fmu_state(self):
            return self.io.get_state(self.model)

        def _set_fmu_state(self, state):
            self.io.set_state(self.model, state)
