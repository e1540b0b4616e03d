"""Recorded sensor files played back into a co-simulation (the SensorRecording FMU's model).

- :mod:`.schema`: the signals a record can hold and the FMU's fixed outputs;
- :mod:`.mapping`: the TOML sidecar saying which column is which signal, in which unit and frame;
- :mod:`.convert`: the conversion into NED, FRD, specific force, heave down, SI;
- :mod:`.reader`: the streaming CSV/Parquet reader and its checks of bad input;
- :mod:`.player`: :class:`~.player.SensorRecording`, the model the FMU runs.

Like the rest of ``sea/`` it imports only the shared modules, numpy and the standard library.
"""
from .mapping import Mapping, RecordingError, load_mapping, parse_mapping
from .player import SensorRecording, SensorRecordingParams
from .reader import Record

__all__ = ["Mapping", "Record", "RecordingError", "SensorRecording", "SensorRecordingParams", "load_mapping",
           "parse_mapping"]
