"""A Python host with nothing but the standard library: one FMU through its FMI 2.0 C API with
ctypes (no FMPy, so that a run under valgrind stays short), STEPS steps, free, normal exit.
Prints the set of fmi2DoStep statuses. Used by test_exit.py.

Usage::

    python ctypes_host.py FMU STEPS
"""
from __future__ import annotations

import ctypes
import sys
import tempfile
import xml.etree.ElementTree as ET
import zipfile
from pathlib import Path


class Callbacks(ctypes.Structure):
    """fmi2CallbackFunctions: no logger, the C library's calloc and free."""
    _fields_ = [("logger", ctypes.c_void_p), ("allocateMemory", ctypes.c_void_p), ("freeMemory", ctypes.c_void_p),
                ("stepFinished", ctypes.c_void_p), ("componentEnvironment", ctypes.c_void_p)]


def main(fmu: Path, steps: int) -> None:
    unzip = Path(tempfile.mkdtemp())
    with zipfile.ZipFile(fmu) as z:
        z.extractall(unzip)
    md = ET.parse(unzip / "modelDescription.xml").getroot()
    lib = ctypes.CDLL(str(unzip / "binaries" / "linux64" / f"{md.find('CoSimulation').get('modelIdentifier')}.so"))
    libc = ctypes.CDLL(None)
    callbacks = Callbacks(None, ctypes.cast(libc.calloc, ctypes.c_void_p), ctypes.cast(libc.free, ctypes.c_void_p))
    lib.fmi2Instantiate.restype = ctypes.c_void_p
    lib.fmi2Instantiate.argtypes = [ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p, ctypes.c_char_p, ctypes.c_void_p,
                                    ctypes.c_int, ctypes.c_int]
    c = ctypes.c_void_p(lib.fmi2Instantiate(b"one", 1, md.get("guid").encode(), (unzip / "resources").as_uri().encode(),
                                            ctypes.byref(callbacks), 0, 0))
    if not c:
        raise SystemExit("fmi2Instantiate failed")
    d = ctypes.c_double
    lib.fmi2SetupExperiment(c, 0, d(0.0), d(0.0), 0, d(0.0))
    lib.fmi2EnterInitializationMode(c)
    lib.fmi2ExitInitializationMode(c)
    statuses = {lib.fmi2DoStep(c, d(k * 0.05), d(0.05), 1) for k in range(steps)}
    lib.fmi2Terminate(c)
    lib.fmi2FreeInstance(c)
    print("statuses", sorted(statuses), flush=True)


if __name__ == "__main__":
    main(Path(sys.argv[1]), int(sys.argv[2]))
