"""DisplacementReconstructor FMU: COG displacement from acceleration without integration
(paper 000) on a sliding window, at its centre (``delay`` s late). Thin adapter over
``marinefmu.estimators.reconstruction.sliding``; never raises (see ``marinefmu.fmu.slave``)."""
from pythonfmu import Fmi2Slave

from marinefmu import __version__
from marinefmu.fmu.tables import (
    RECONSTRUCTOR_BOOLEANS, RECONSTRUCTOR_INPUTS, RECONSTRUCTOR_OUTPUTS, RECONSTRUCTOR_PARAMETERS, sliding_params,
)
from marinefmu.fmu.slave import SlaveIO
from marinefmu.estimators.reconstruction.sliding import DisplacementReconstructor as Estimator


def _build(values):
    params = sliding_params(values)
    params.validate(1e-3)  # refuse what is invalid at any rate now; checked against the real step later
    return Estimator(params)


if "DisplacementReconstructor" in globals():  # pythonfmu runs this file again for each instance: see SlaveIO.rerun
    DisplacementReconstructor = SlaveIO.rerun(globals(), "DisplacementReconstructor")
else:
    class DisplacementReconstructor(Fmi2Slave):
        author = "marinefmu developers"
        description = "Non-integral displacement reconstruction from acceleration on a sliding window (paper 000)"
        version = __version__
        license = "MIT"

        def __init__(self, **kwargs):
            super().__init__(**kwargs)
            self.io = SlaveIO(self, RECONSTRUCTOR_PARAMETERS, RECONSTRUCTOR_OUTPUTS, RECONSTRUCTOR_BOOLEANS, RECONSTRUCTOR_INPUTS)
            self.model = None

        def setup_experiment(self, start_time, stop_time, tolerance):
            self.io.start_time = start_time

        def exit_initialization_mode(self):
            self.model = self.io.build(_build)

        def do_step(self, current_time, step_size):
            return self.io.step(self._step, current_time, step_size)

        def _step(self, t, dt):
            i = self.io.inputs
            r = self.model.step((i["acc.x"], i["acc.y"], i["acc.z"]), (i["roll"], i["pitch"], i["yaw"]), dt)
            self.io.warn(r.warning, t, r.valid)
            self.io.set_outputs([*r.disp, *r.vel, r.delay], [r.valid])

        def _get_fmu_state(self):
            return self.io.get_state(self.model)

        def _set_fmu_state(self, state):
            self.io.set_state(self.model, state)
