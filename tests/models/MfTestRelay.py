"""Test-only FMU: y = gain · u (real) and counts its steps; used to test wiring and rates."""
from pythonfmu import Fmi2Slave

from marinefmu.fmu.slave import SlaveIO
from marinefmu.variables import Variable, real

PARAMETERS = [real("gain", 2.0, "", "Gain")]
INPUTS = [real("u", 0.0, "m", "Input signal")]
OUTPUTS = [real("y", 0.0, "m", "gain * u at the end of the step"), real("steps", 0.0, "", "Number of steps taken"),
           real("time", 0.0, "s", "Time at the end of the last step")]


class MfTestRelay(Fmi2Slave):
    description = "marinefmu test relay"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.io = SlaveIO(self, PARAMETERS, OUTPUTS, inputs=INPUTS)
        self.model = None

    def do_step(self, current_time, step_size):
        steps = self.io.real_out[1] + 1.0
        self.io.set_outputs([self.io.params["gain"] * self.io.inputs["u"], steps, current_time + step_size])
        return True
