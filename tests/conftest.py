"""Shared fixtures: the built FMUs (built once per session if missing or stale)."""
from __future__ import annotations

import os
from pathlib import Path

from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave

import pytest

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="session")
def fmu_dir() -> Path:
    """fmus/ of the checkout, with every model built and validated."""
    from marinefmu.fmu.build import build_all

    build_all(verbose=False)
    return ROOT / "fmus"


@pytest.fixture(scope="session")
def relay_fmu(tmp_path_factory) -> Path:
    """A test-only FMU with inputs (tests/models/MfTestRelay.py), to exercise wiring and rates."""
    from marinefmu.fmu.build import build_all

    dest = tmp_path_factory.mktemp("relay")
    build_all(models=ROOT / "tests" / "models", dest=dest, verbose=False)
    return dest / "MfTestRelay.fmu"


def spawn_env(env: dict[str, str] | None = None) -> dict[str, str]:
    """The environment to give a child process started from a worker thread: ``env``, or a copy
    of this process's.

    Never start such a child with ``env=None``. Then ``subprocess`` vforks and the child
    execs with the C ``environ``, shared with the parent until exec. Meanwhile the main thread
    runs the next test, and pytest sets and unsets ``PYTEST_CURRENT_TEST`` at every phase:
    glibc's ``setenv`` moves the array, and the child's exec fails with ``EFAULT``
    ("[Errno 14] Bad address"). An explicit environment is copied into the child's own ``envp``
    before the fork.
    """
    return dict(os.environ) if env is None else env


DT = 0.01


class LibcosimBeside:
    """A built-in scenario run by OSP libcosim (``run_libcosim``) in a second process, while the
    test runs its own engine in this one; a context manager that kills the process on exit.

    ``result(timeout)`` waits for it, checks it ended well and returns its structured array
    (``record`` sampled every ``sample`` s from ``sample`` on)."""

    def __init__(self, scenario, fmu_dir, work, duration, record, sample):
        import subprocess
        import sys

        self.out = Path(work) / "libcosim.npy"
        code = ("import numpy as np\nfrom marinefmu.cosim.scenarios import load_scenario\n"
                "from marinefmu.cosim.libcosim import run_libcosim\n"
                f"out = run_libcosim(load_scenario({scenario!r}).system, {str(fmu_dir)!r}, {str(work)!r}, {duration}, "
                f"{list(record)!r}, {sample})\nnp.save({str(self.out)!r}, out)\n")
        self.proc = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                     text=True)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.proc.kill()

    def result(self, timeout):
        import numpy as np

        _, err = self.proc.communicate(timeout=timeout)
        assert self.proc.returncode == 0, err[-3000:]
        return np.load(self.out)


class Driver:
    """One FMU instance driven step by step through FMPy's FMU2Slave (steps of DT = 0.01 s
    unless a step says otherwise)."""

    def __init__(self, path, tmp, name):
        self.md = read_model_description(str(path))
        self.vr = {v.name: v for v in self.md.modelVariables}
        self.fmu = FMU2Slave(guid=self.md.guid, unzipDirectory=extract(str(path), unzipdir=str(tmp / name)),
                             modelIdentifier=self.md.coSimulation.modelIdentifier, instanceName=name)
        self.fmu.instantiate()

    def init(self, params):
        self.fmu.setupExperiment(startTime=0.0)
        for k, v in params.items():
            setter = {"Real": self.fmu.setReal, "Integer": self.fmu.setInteger, "String": self.fmu.setString}
            setter[self.vr[k].type]([self.vr[k].valueReference], [v])
        self.fmu.enterInitializationMode()
        self.fmu.exitInitializationMode()

    def step(self, k, inputs, outputs, booleans=("valid",), dt=DT):
        self.fmu.setReal([self.vr[n].valueReference for n in inputs], list(inputs.values()))
        status = self.fmu.doStep(currentCommunicationPoint=k * dt, communicationStepSize=dt)
        reals = self.fmu.getReal([self.vr[n].valueReference for n in outputs])
        return status, reals, self.fmu.getBoolean([self.vr[n].valueReference for n in booleans])

    def close(self):
        self.fmu.terminate()
        self.fmu.freeInstance()


# --- isolation: a test marked `isolated` runs in its own pytest subprocess --------------------
# pythonfmu FMUs loaded into one interpreter share its state, and a native crash (seen once,
# intermittently, inside libcosim's add_local_slave) would otherwise kill the whole run. In a
# child process a crash or a hang is one failed test with its output attached.
_CHILD_FLAG = "MARINEFMU_ISOLATED_CHILD"
ISOLATED_TIMEOUT = 300.0  # s; the slowest isolated test takes ~20 s on the 2-core CI machine


def pytest_pyfunc_call(pyfuncitem):
    import os
    import signal
    import subprocess
    import sys

    marker = pyfuncitem.get_closest_marker("isolated")
    if marker is None or os.environ.get(_CHILD_FLAG):
        return None
    timeout = marker.kwargs.get("timeout", ISOLATED_TIMEOUT)   # isolated(timeout=…) for a long one
    env = {**os.environ, _CHILD_FLAG: "1"}
    cmd = [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "--no-header", pyfuncitem.nodeid]
    # its own process group, so that a timeout (or an interrupt) also ends what the test started,
    # such as LibcosimBeside's second process, which would otherwise run on, orphaned
    child = subprocess.Popen(cmd, cwd=ROOT, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                             start_new_session=True)
    try:
        stdout, stderr = child.communicate(timeout=timeout)
    except BaseException as exc:
        try:
            os.killpg(child.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
        stdout, _ = child.communicate()
        if isinstance(exc, subprocess.TimeoutExpired):
            pytest.fail(f"isolated test timed out after {timeout:.0f} s\n{stdout[-4000:]}", pytrace=False)
        raise
    if child.returncode != 0:
        how = f"killed by signal {-child.returncode}" if child.returncode < 0 else f"exit code {child.returncode}"
        pytest.fail(f"isolated test failed in its subprocess ({how}):\n{stdout[-6000:]}\n{stderr[-3000:]}",
                    pytrace=False)
    return True


# --- order: the long files first --------------------------------------------------------------
# `make test` runs with --dist loadfile --no-loadscope-reorder: each file goes whole to the next
# free worker, in collection order. xdist's default order (most tests first) would start the
# files with few but long tests (the whole-system, AHC and heave runs) last, where one worker
# runs them while the other has nothing left. Longest first (a file not named keeps its place
# after these); re-rank when `make test`'s slowest-tests list says otherwise.
LONG_FIRST = (
    "tests/conformance/test_conformance.py",        # its session fixture starts every case, two at a time
    "tests/estimators/heave/test_heave.py",
    "tests/ahc/test_loop.py",
    "tests/test_whole_system.py",
    "tests/conformance/test_exit.py",
    "tests/estimators/gnss_fusion/test_gnss_fusion.py",
    "tests/campaign/test_campaign.py",
    "tests/test_docs.py",
    "tests/estimators/centre_of_rotation/test_centre_of_rotation.py",
    "tests/cosim/test_system.py",
    "tests/test_cli_examples.py",
)


def pytest_collection_modifyitems(config, items):
    rank = {path: i for i, path in enumerate(LONG_FIRST)}
    items.sort(key=lambda item: rank.get(item.nodeid.split("::", 1)[0], len(LONG_FIRST)))   # stable
