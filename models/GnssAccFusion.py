"""GnssAccFusion FMU: four-antenna GNSS attitude (or, with attitude = input, the roll/pitch/yaw
inputs and one receiver) corrects the accelerometer, and a multirate Kalman filter fuses it with
the GNSS position (paper 001). Thin adapter over ``marinefmu.estimators.gnss_fusion.filter``;
never raises (see ``marinefmu.fmu.slave``)."""
import numpy as np
from pythonfmu import Fmi2Slave

from marinefmu import __version__
from marinefmu.fmu.tables import (
    FUSION_BOOLEANS, FUSION_INPUTS, FUSION_OUTPUTS, FUSION_PARAMETERS, fusion_params,
)
from marinefmu.fmu.slave import SlaveIO
from marinefmu.estimators.gnss_fusion.filter import GnssAccFusion as Estimator

ANT_NAMES = [f"gnss.ant{i}.{a}" for i in range(1, 5) for a in "ned"]


if "GnssAccFusion" in globals():  # pythonfmu runs this file again for each instance: see SlaveIO.rerun
    GnssAccFusion = SlaveIO.rerun(globals(), "GnssAccFusion")
else:
    class GnssAccFusion(Fmi2Slave):
        author = "marinefmu developers"
        description = "Multi-antenna GNSS + accelerometer Kalman fusion with attitude correction (paper 001)"
        version = __version__
        license = "MIT"

        def __init__(self, **kwargs):
            super().__init__(**kwargs)
            self.io = SlaveIO(self, FUSION_PARAMETERS, FUSION_OUTPUTS, FUSION_BOOLEANS, FUSION_INPUTS)
            self.model = None
            self.ant_names = ANT_NAMES
            self.last_fix = None
            self.new_connected = False  # gnss.new has been seen true: rely on it, not on changes

        def setup_experiment(self, start_time, stop_time, tolerance):
            self.io.start_time = start_time

        def exit_initialization_mode(self):
            self.model = self.io.build(lambda values: Estimator(fusion_params(values)))
            self.ant_names = ANT_NAMES if self.io.params["attitude"] != "input" else ANT_NAMES[:3]  # one receiver

        def do_step(self, current_time, step_size):
            return self.io.step(self._step, current_time, step_size)

        def _step(self, t, dt):
            i = self.io.inputs
            ant = [i[n] for n in self.ant_names]
            self.new_connected = self.new_connected or i["gnss.new"]
            # unconnected gnss.new: a change of the positions is a new fix (a held NaN is no change)
            new = i["gnss.valid"] and (i["gnss.new"] if self.new_connected
                                        else not np.array_equal(ant, self.last_fix, equal_nan=True))
            if new:
                self.last_fix = ant
            r = self.model.step((i["acc.x"], i["acc.y"], i["acc.z"]), np.array(ant) if new else None, dt,
                                (i["gyro.x"], i["gyro.y"], i["gyro.z"]), (i["roll"], i["pitch"], i["yaw"]))
            self.io.warn(r.warning, t, r.valid)
            self.io.set_outputs([*r.pos, *r.vel, *r.pos_std, *r.euler, *r.acc_n, *r.acc_bias, r.residual],
                                [r.valid, r.fix == "accepted"])

        def _get_fmu_state(self):
            state = self.io.get_state(self.model)
            state["last_fix"], state["new_connected"] = self.last_fix, self.new_connected
            return state

        def _set_fmu_state(self, state):
            self.last_fix, self.new_connected = state.get("last_fix"), state.get("new_connected", False)
            self.io.set_state(self.model, state)
