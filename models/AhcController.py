"""AhcController FMU: feedforward from the estimated crane-tip heave plus PI feedback on the
wire length. Thin adapter over ``marinefmu.ahc.controller``; never raises (see
``marinefmu.fmu.slave``)."""
from pythonfmu import Fmi2Slave

from marinefmu import __version__
from marinefmu.ahc.controller import AhcController as Controller
from marinefmu.fmu.tables import (
    CONTROLLER_BOOLEANS, CONTROLLER_INPUTS, CONTROLLER_OUTPUTS, CONTROLLER_PARAMETERS, controller_params,
)
from marinefmu.fmu.slave import SlaveIO


if "AhcController" in globals():  # pythonfmu runs this file again for each instance: see SlaveIO.rerun
    AhcController = SlaveIO.rerun(globals(), "AhcController")
else:
    class AhcController(Fmi2Slave):
        author = "marinefmu developers"
        description = "Heave-compensation controller: heave feedforward + PI on the wire length"
        version = __version__
        license = "MIT"

        def __init__(self, **kwargs):
            super().__init__(**kwargs)
            self.io = SlaveIO(self, CONTROLLER_PARAMETERS, CONTROLLER_OUTPUTS, CONTROLLER_BOOLEANS, CONTROLLER_INPUTS)
            self.model = None

        def setup_experiment(self, start_time, stop_time, tolerance):
            self.io.start_time = start_time

        def exit_initialization_mode(self):
            self.model = self.io.build(lambda values: Controller(controller_params(values)))

        def do_step(self, current_time, step_size):
            return self.io.step(self._step, current_time, step_size)

        def _step(self, t, dt):
            i = self.io.inputs
            r = self.model.step(i["heave"], i["heave_rate"], i["length"], dt, i["heave_valid"])
            self.io.warn(r.warning, t, r.valid)
            self.io.set_outputs([r.command, r.length_ref, r.engagement], [r.command_limited, r.valid])

        def _get_fmu_state(self):
            return self.io.get_state(self.model)

        def _set_fmu_state(self, state):
            self.io.set_state(self.model, state)
