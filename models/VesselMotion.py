"""VesselMotion FMU: waves → 6-DOF motion → IMU and GNSS signals, with exact truth.

A thin adapter: all numerics are in ``marinefmu.sea.motion_model``. A refused parameter is
logged at initialisation and the FMU then discards every step (see ``marinefmu.fmu.slave``).
"""
from pythonfmu import Fmi2Slave

from marinefmu import __version__
from marinefmu.fmu.slave import SlaveIO
from marinefmu.fmu.tables import VESSEL_BOOLEAN_OUTPUTS, VESSEL_PARAMETERS, VESSEL_REAL_OUTPUTS
from marinefmu.sea.motion_model import VesselMotion as Model
from marinefmu.sea.motion_model import VesselMotionParams


if "VesselMotion" in globals():  # pythonfmu runs this file again for each instance: see SlaveIO.rerun
    VesselMotion = SlaveIO.rerun(globals(), "VesselMotion")
else:
    class VesselMotion(Fmi2Slave):
        author = "marinefmu developers"
        description = "Vessel in irregular waves: 6-DOF RAO motion, IMU and 4-antenna GNSS with errors, exact truth"
        version = __version__
        license = "MIT"

        def __init__(self, **kwargs):
            super().__init__(**kwargs)
            self.io = SlaveIO(self, VESSEL_PARAMETERS, VESSEL_REAL_OUTPUTS, VESSEL_BOOLEAN_OUTPUTS)
            self.model = None

        def setup_experiment(self, start_time, stop_time, tolerance):
            self.io.start_time = start_time

        def exit_initialization_mode(self):
            self.model = self.io.build(lambda values: Model(VesselMotionParams.from_flat(values)))
            if self.model is not None:
                self.io.set_outputs(self.model.peek(self.io.start_time), self.model.boolean_outputs())

        def do_step(self, current_time, step_size):
            return self.io.step(self._step, current_time, step_size)

        def _step(self, t, dt):
            self.io.set_outputs(self.model.step(t, dt), self.model.boolean_outputs())

        def _get_fmu_state(self):
            return self.io.get_state(self.model)

        def _set_fmu_state(self, state):
            self.io.set_state(self.model, state)
