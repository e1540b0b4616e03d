"""HeaveObserver FMU: heave at the IMU and at a remote point from a strapdown IMU by an adaptive
bank of oscillator modes (paper 003). Thin adapter over ``marinefmu.estimators.heave.observer``; never
raises (see ``marinefmu.fmu.slave``)."""
from pythonfmu import Fmi2Slave

from marinefmu import __version__
from marinefmu.fmu.tables import HEAVE_DISCRETE, HEAVE_INPUTS, HEAVE_OUTPUTS, HEAVE_PARAMETERS, heave_params
from marinefmu.fmu.slave import SlaveIO
from marinefmu.estimators.heave.observer import HeaveObserver as Estimator


if "HeaveObserver" in globals():  # pythonfmu runs this file again for each instance: see SlaveIO.rerun
    HeaveObserver = SlaveIO.rerun(globals(), "HeaveObserver")
else:
    class HeaveObserver(Fmi2Slave):
        author = "marinefmu developers"
        description = "Adaptive heave observer with transfer to a remote point (paper 003); model = highpass: the classical baseline"
        version = __version__
        license = "MIT"

        def __init__(self, **kwargs):
            super().__init__(**kwargs)
            self.io = SlaveIO(self, HEAVE_PARAMETERS, HEAVE_OUTPUTS, HEAVE_DISCRETE, HEAVE_INPUTS)
            self.model = None

        def setup_experiment(self, start_time, stop_time, tolerance):
            self.io.start_time = start_time

        def exit_initialization_mode(self):
            self.model = self.io.build(lambda values: Estimator(heave_params(values)))

        def do_step(self, current_time, step_size):
            return self.io.step(self._step, current_time, step_size)

        def _step(self, t, dt):
            i = self.io.inputs
            r = self.model.step((i["acc.x"], i["acc.y"], i["acc.z"]), i["roll"], i["pitch"], dt)
            self.io.warn(r.warning, t, r.valid)
            self.io.set_outputs([r.heave, r.heave_rate, r.point_heave, r.point_heave_rate, r.delayed_heave,
                                 r.delayed_heave_rate, r.delayed_point_heave, r.delay, r.offset, r.peak_period],
                                [r.modes, r.valid, r.delayed_valid])

        def _get_fmu_state(self):
            return self.io.get_state(self.model)

        def _set_fmu_state(self, state):
            self.io.set_state(self.model, state)
