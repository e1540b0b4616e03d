"""AhcWinch FMU: an active-heave-compensation winch at a crane tip with a load on an elastic
wire. Thin adapter over ``marinefmu.ahc.winch``; never raises (see
``marinefmu.fmu.slave``). The load starts at rest below the crane tip of the first step."""
from pythonfmu import Fmi2Slave

from marinefmu import __version__
from marinefmu.ahc.winch import AhcWinch as Model
from marinefmu.fmu.tables import WINCH_BOOLEANS, WINCH_INPUTS, WINCH_OUTPUTS, WINCH_PARAMETERS, winch_params
from marinefmu.fmu.slave import SlaveIO


if "AhcWinch" in globals():  # pythonfmu runs this file again for each instance: see SlaveIO.rerun
    AhcWinch = SlaveIO.rerun(globals(), "AhcWinch")
else:
    class AhcWinch(Fmi2Slave):
        author = "marinefmu developers"
        description = "Active-heave-compensation winch with a load on an elastic wire"
        version = __version__
        license = "MIT"

        def __init__(self, **kwargs):
            super().__init__(**kwargs)
            self.io = SlaveIO(self, WINCH_PARAMETERS, WINCH_OUTPUTS, WINCH_BOOLEANS, WINCH_INPUTS)
            self.model = None
            self.started = False

        def setup_experiment(self, start_time, stop_time, tolerance):
            self.io.start_time = start_time

        def exit_initialization_mode(self):
            self.model = self.io.build(lambda values: Model(winch_params(values)))
            self.started = False

        def do_step(self, current_time, step_size):
            return self.io.step(self._step, current_time, step_size)

        def _step(self, t, dt):
            i = self.io.inputs
            if not self.started:   # at rest below the first tip position the host gives
                self.model.reset(i["tip.d"] if abs(i["tip.d"]) < 1e4 else 0.0)
                self.started = True
            r = self.model.step(i["command"], i["tip.d"], i["tip_vel.d"], dt, (i["tip.n"], i["tip.e"]))
            self.io.warn(r.warning, t, r.valid)
            self.io.set_outputs([r.length, r.speed, r.acc, r.load_n, r.load_e, r.load, r.load_vel, r.tension],
                                [r.speed_limited, r.acc_limited, r.stroke_limited, r.slack, r.valid])

        def _get_fmu_state(self):
            state = self.io.get_state(self.model)
            state["started"] = self.started
            return state

        def _set_fmu_state(self, state):
            self.io.set_state(self.model, state)
            self.started = state["started"]
