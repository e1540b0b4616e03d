"""AttitudeEstimator FMU: roll, pitch, yaw and quaternion from gyro and accelerometer samples
(paper 000 quaternion integration; mode 1 adds the aided drift correction). Thin adapter over
``marinefmu.estimators.attitude.estimator``; never raises (see ``marinefmu.fmu.slave``)."""
from pythonfmu import Fmi2Slave

from marinefmu import __version__
from marinefmu.fmu.tables import (
    ATTITUDE_BOOLEANS, ATTITUDE_INPUTS, ATTITUDE_OUTPUTS, ATTITUDE_PARAMETERS, attitude_params,
)
from marinefmu.fmu.slave import SlaveIO
from marinefmu.estimators.attitude.estimator import AttitudeEstimator as Estimator


if "AttitudeEstimator" in globals():  # pythonfmu runs this file again for each instance: see SlaveIO.rerun
    AttitudeEstimator = SlaveIO.rerun(globals(), "AttitudeEstimator")
else:
    class AttitudeEstimator(Fmi2Slave):
        author = "marinefmu developers"
        description = "Attitude from gyros by quaternion integration (paper 000) with optional aided drift correction"
        version = __version__
        license = "MIT"

        def __init__(self, **kwargs):
            super().__init__(**kwargs)
            self.io = SlaveIO(self, ATTITUDE_PARAMETERS, ATTITUDE_OUTPUTS, ATTITUDE_BOOLEANS, ATTITUDE_INPUTS)
            self.model = None

        def setup_experiment(self, start_time, stop_time, tolerance):
            self.io.start_time = start_time

        def exit_initialization_mode(self):
            self.model = self.io.build(lambda values: Estimator(attitude_params(values)))

        def do_step(self, current_time, step_size):
            return self.io.step(self._step, current_time, step_size)

        def _step(self, t, dt):
            i = self.io.inputs
            r = self.model.step((i["gyro.x"], i["gyro.y"], i["gyro.z"]), (i["acc.x"], i["acc.y"], i["acc.z"]), dt)
            self.io.warn(r.warning, t, r.valid)
            self.io.set_outputs([r.roll, r.pitch, r.yaw, *r.q, *r.gyro_bias], [r.valid])

        def _get_fmu_state(self):
            return self.io.get_state(self.model)

        def _set_fmu_state(self, state):
            self.io.set_state(self.model, state)
