"""SensorRecording FMU: a recorded file (CSV or Parquet) played back with VesselMotion's sensor
names, and its reference signals as ref.*.

A thin adapter: reading, conversion and interpolation are in ``marinefmu.sea.recording``. A bad
record or mapping is refused at initialisation (logged, naming the file, the column and the
line), and the FMU then discards every step (see ``marinefmu.fmu.slave``). A self-contained FMU
(``marinefmu build-recording``) carries its record in ``resources/recording/``: empty ``file``
and ``mapping`` parameters then mean that one.
"""
from pythonfmu import Fmi2Slave
from pythonfmu.enums import Fmi2Status

from marinefmu import __version__
from marinefmu.fmu.slave import SlaveIO
from marinefmu.fmu.tables import (
    SENSOR_RECORDING_BOOLEANS, SENSOR_RECORDING_OUTPUTS, SENSOR_RECORDING_PARAMETERS, sensor_recording_params,
)
from marinefmu.sea.recording.player import SensorRecording as Model
from marinefmu.sea.recording.player import bundled_paths


if "SensorRecording" in globals():  # pythonfmu runs this file again for each instance: see SlaveIO.rerun
    SensorRecording = SlaveIO.rerun(globals(), "SensorRecording")
else:
    class SensorRecording(Fmi2Slave):
        author = "marinefmu developers"
        description = "A recorded IMU/GNSS file played back as VesselMotion-named outputs, reference signals as ref.*"
        version = __version__
        license = "MIT"

        def __init__(self, **kwargs):
            super().__init__(**kwargs)
            self.io = SlaveIO(self, SENSOR_RECORDING_PARAMETERS, SENSOR_RECORDING_OUTPUTS, SENSOR_RECORDING_BOOLEANS)
            self.model = None

        def setup_experiment(self, start_time, stop_time, tolerance):
            self.io.start_time = start_time

        def exit_initialization_mode(self):
            self.model = self.io.build(self._make)
            if self.model is not None:
                self.io.set_outputs(self.model.peek(), self.model.boolean_outputs())
                self._log()

        def _make(self, values):
            values["file"], values["mapping"] = bundled_paths(values["file"], values["mapping"], self.resources)
            return Model(sensor_recording_params(values), self.io.start_time)

        def do_step(self, current_time, step_size):
            return self.io.step(self._step, current_time, step_size)

        def _step(self, t, dt):
            self.io.set_outputs(self.model.step(t, dt), self.model.boolean_outputs())
            if self.model.messages:
                self._log()

        def _log(self):
            for text in self.model.messages:
                self.log(f"{self.instance_name}: {text}", Fmi2Status.warning)

        def _get_fmu_state(self):
            return self.io.get_state(self.model)

        def _set_fmu_state(self, state):
            self.io.set_state(self.model, state)
