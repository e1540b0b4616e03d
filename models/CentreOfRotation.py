"""CentreOfRotation FMU: offset from the sensor to the ship's centre of rotation by a Kalman
filter with lever-arm states (paper 002). Thin adapter over
``marinefmu.estimators.centre_of_rotation.filter``; never raises (see ``marinefmu.fmu.slave``)."""
from pythonfmu import Fmi2Slave

from marinefmu import __version__
from marinefmu.fmu.tables import CR_BOOLEANS, CR_INPUTS, CR_OUTPUTS, CR_PARAMETERS, cr_params
from marinefmu.fmu.slave import SlaveIO
from marinefmu.estimators.centre_of_rotation.filter import CentreOfRotation as Estimator


if "CentreOfRotation" in globals():  # pythonfmu runs this file again for each instance: see SlaveIO.rerun
    CentreOfRotation = SlaveIO.rerun(globals(), "CentreOfRotation")
else:
    class CentreOfRotation(Fmi2Slave):
        author = "marinefmu developers"
        description = "Ship centre of rotation by a Kalman filter with lever-arm states (paper 002)"
        version = __version__
        license = "MIT"

        def __init__(self, **kwargs):
            super().__init__(**kwargs)
            self.io = SlaveIO(self, CR_PARAMETERS, CR_OUTPUTS, CR_BOOLEANS, CR_INPUTS)
            self.model = None

        def setup_experiment(self, start_time, stop_time, tolerance):
            self.io.start_time = start_time

        def exit_initialization_mode(self):
            self.model = self.io.build(lambda values: Estimator(cr_params(values)))

        def do_step(self, current_time, step_size):
            return self.io.step(self._step, current_time, step_size)

        def _step(self, t, dt):
            i = self.io.inputs
            r = self.model.step((i["acc.x"], i["acc.y"], i["acc.z"]), (i["gyro.x"], i["gyro.y"], i["gyro.z"]), dt,
                                (i["roll"], i["pitch"], i["yaw"]))
            self.io.warn(r.warning, t, r.valid)
            self.io.set_outputs([*r.offset, *r.offset_std, *r.offset_mean, *r.cr, *r.acc_cr, *r.acc_cr_n, *r.euler, r.delay],
                                [r.valid, r.settled])

        def _get_fmu_state(self):
            return self.io.get_state(self.model)

        def _set_fmu_state(self, state):
            self.io.set_state(self.model, state)
