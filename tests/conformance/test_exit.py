"""Process exit with FMUs loaded: every host leaves normally, with exit code 0, and nothing
writes into freed memory at exit (``marinefmu.fmu.host_exit``; docs/fmu_contract.md, "Process
exit"). Each run is a fresh process with its output piped, as a user's script or a CI job is:

- FMPy (``fmu_worker.py exit_*``): each FMU alone, one instance freed and one still alive; all
  of them together, none freed; all of them freed (FMPy unloads every library copy it can) and
  instantiated again, left alive. The guard must be armed on every loaded library copy.
- a host that is not Python (``c_host.c``: dlopen, so pythonfmu starts and owns the
  interpreter), all FMUs together, freed and unloaded or left alive;
- the ``marinefmu`` command line (``python -m marinefmu.cli simulate``, FMPy engine);
- valgrind: a Python host (``ctypes_host.py``, no FMPy) and the C host each run one FMU and
  exit; no invalid read or write may pass through an FMU library. They run the test relay FMU:
  the same pythonfmu library and guard as every FMU of the catalogue, without the catalogue's
  imports (scipy, filterpy, python-control), which make a run under valgrind last minutes.
"""
from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
import sysconfig
import zipfile
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from fmu_worker import FMUS  # noqa: E402
from test_conformance import run_worker  # noqa: E402

from tests.conftest import spawn_env  # noqa: E402

pytestmark = pytest.mark.fmu
ALL = ",".join(FMUS)
#: (case, FMUs run together in one process)
FMPY_RUNS = [("exit_mixed", name) for name in FMUS] + [("exit_kept", ALL), ("exit_reloaded", ALL)]
VALGRIND_TIMEOUT = 900.0   # s; each valgrind run of the relay FMU takes ~15 s on the 2-core CI machine


@pytest.fixture(scope="module")
def fmpy_runs(fmu_dir, tmp_path_factory):
    """Futures of every FMPy exit run, started two at a time."""
    work = tmp_path_factory.mktemp("exit")
    pool = ThreadPoolExecutor(max_workers=2)
    yield {(case, names): pool.submit(run_worker, case, names, fmu_dir, work) for case, names in FMPY_RUNS}
    pool.shutdown(wait=True, cancel_futures=True)


@pytest.mark.parametrize("case, names", FMPY_RUNS, ids=[f"{c}-{'all' if n == ALL else n}" for c, n in FMPY_RUNS])
def test_an_fmpy_script_exits_with_code_0(fmpy_runs, case, names):
    r = fmpy_runs[(case, names)].result()
    assert "_failure" not in r, r.get("_failure")
    assert r.get("_exit", 0) == 0, f"{case} {names}: exit code {r['_exit']}: {r['_stderr']}"
    assert r["statuses"] == [0], r
    assert r["libraries"] == len(names.split(",")) and r["guarded"] == r["libraries"], r
    if case == "exit_reloaded":
        assert r["first"] == {"libraries": len(FMUS), "guarded": len(FMUS)}, r
        # FMPy unloaded every copy but the first loaded (pythonfmu's library binds C++ "unique"
        # symbols, which pins the first copy): the guards of the others ran then, and the
        # copies loaded again were guarded again
        assert r["after_free"] == {"libraries": 1, "guarded": 1}, r


def test_the_command_line_exits_with_code_0(fmu_dir, tmp_path):
    done = subprocess.run([sys.executable, "-m", "marinefmu.cli", "simulate", "default", "--duration", "2",
                           "--engine", "fmpy", "--fmus", str(fmu_dir), "--out", str(tmp_path), "--no-progress"],
                          capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-3000:]
    assert (tmp_path / "results.npy").exists()


def test_every_fmu_library_has_the_symbols_the_guard_needs(fmu_dir, tmp_path):
    """The guard reads ``finalizePythonInterpreter`` and the local ``__dso_handle`` from the
    library's symbol table; a stripped library would leave a host unguarded."""
    from marinefmu.fmu.host_exit import elf_symbols

    for name in FMUS:
        with zipfile.ZipFile(fmu_dir / f"{name}.fmu") as z:
            lib = Path(z.extract(f"binaries/linux64/{name}.so", tmp_path / name))
        assert set(elf_symbols(lib)) == {"finalizePythonInterpreter", "__dso_handle"}, name


def test_the_guard_does_nothing_where_the_library_is_not_loaded(fmu_dir, tmp_path):
    """At build time and in-process the slave runs without its library: nothing is registered."""
    from marinefmu.fmu import host_exit

    with zipfile.ZipFile(fmu_dir / "AhcWinch.fmu") as z:
        z.extractall(tmp_path)
    before = host_exit.guarded()
    assert host_exit.guard(None) is False
    assert host_exit.guard(tmp_path / "resources") is False   # extracted, not loaded in this process
    assert host_exit.guarded() == before


# --- a host that is not Python ------------------------------------------------------------

def _unzip(fmu: Path, where: Path) -> tuple[str, str, str]:
    """Extract ``fmu``; its library path, GUID and resource URI (the C host's arguments)."""
    with zipfile.ZipFile(fmu) as z:
        z.extractall(where)
        guid = re.search(r'guid="([^"]+)"', z.read("modelDescription.xml").decode()).group(1)
    return str(where / "binaries" / "linux64" / f"{fmu.stem}.so"), guid, (where / "resources").as_uri()


@pytest.fixture(scope="module")
def c_host(tmp_path_factory) -> tuple[Path, dict]:
    """``c_host.c`` compiled and linked against this Python's shared library (pythonfmu's library
    takes the Python C API from the host), and the environment its embedded interpreter needs
    to find this environment's packages."""
    cc = shutil.which(os.environ.get("CC", "cc")) or shutil.which("gcc")
    libdir, ldlibrary = sysconfig.get_config_var("LIBDIR"), sysconfig.get_config_var("LDLIBRARY")
    if cc is None:
        pytest.skip("no C compiler (cc or gcc) to build the C host")
    if not (libdir and ldlibrary and ldlibrary.endswith(".so") and (Path(libdir) / ldlibrary).exists()):
        pytest.skip(f"this Python has no shared library to link the C host against ({ldlibrary!r} in {libdir!r})")
    exe = tmp_path_factory.mktemp("c_host") / "c_host"
    subprocess.run([cc, "-O1", "-o", str(exe), str(HERE / "c_host.c"), "-ldl", "-Wl,--no-as-needed", f"-L{libdir}",
                    f"-l{ldlibrary[3:-3]}", f"-Wl,-rpath,{libdir}"], check=True, capture_output=True, text=True)
    import site

    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME", "VIRTUAL_ENV")}
    env["PYTHONHOME"] = sys.base_prefix
    env["PYTHONPATH"] = os.pathsep.join(site.getsitepackages())
    return exe, env


def _c_host_args(fmus: list[Path], where: Path) -> list[str]:
    return [a for i, fmu in enumerate(fmus) for a in _unzip(fmu, where / f"{i}_{fmu.stem}")]


@pytest.mark.parametrize("mode", ["free", "keep"])
def test_a_host_that_is_not_python_exits_with_code_0(c_host, fmu_dir, tmp_path, mode):
    exe, env = c_host
    args = _c_host_args([fmu_dir / f"{n}.fmu" for n in FMUS], tmp_path)
    done = subprocess.run([str(exe), mode, "100", *args], capture_output=True, text=True, timeout=600, env=env)
    assert done.returncode == 0, done.stderr[-3000:]
    assert done.stdout.strip() == "worst status 0", (done.stdout, done.stderr[-3000:])


# --- valgrind -------------------------------------------------------------------------------

def fmu_library_errors(log: str) -> list[str]:
    """The invalid reads and writes in a valgrind log whose faulting stack (the frames before
    "Address") passes through an FMU library (``.../binaries/linux64/*.so``). Others, such as
    the dynamic loader's ``strncmp`` over-reads, are not the FMUs'."""
    blocks = re.split(r"\n==\d+== \n", log)
    return [b for b in blocks if re.search(r"Invalid (read|write)", b) and "/binaries/linux64/" in b.split("Address")[0]]


#: valgrind's report of a run of VesselMotion.fmu without the exit guard (pythonfmu 0.7.0).
UNGUARDED_EXIT = """==16965== 
==16965== Invalid read of size 4
==16965==    at 0xF267865: finalizePythonInterpreter (in /tmp/tmpngfc5kvl/binaries/linux64/VesselMotion.so)
==16965==    by 0x4001129: _dl_call_fini (dl-call_fini.c:43)
==16965==    by 0x400486D: _dl_fini (dl-fini.c:114)
==16965==    by 0x4E5355C: __run_exit_handlers (exit.c:116)
==16965==    by 0x4E53699: exit (exit.c:146)
==16965==  Address 0x6591ed8 is 8 bytes inside a block of size 128 free'd
==16965==    at 0x484499B: operator delete(void*, unsigned long) (in /usr/libexec/valgrind/vgpreload_memcheck-amd64-linux.so)
==16965== 
==16965== Invalid read of size 8
==16965==    at 0x4023C6C: strncmp (strcmp-sse2.S:160)
==16965==    by 0x4004BEE: is_dst (dl-load.c:216)
==16965==  Address 0x6b576c1 is 1 bytes inside a block of size 8 alloc'd
==16965==    by 0x4005F84: decompose_rpath (dl-load.c:629)
==16965== 
"""


def test_the_valgrind_check_finds_the_unguarded_exit_write():
    errors = fmu_library_errors(UNGUARDED_EXIT)
    assert len(errors) == 1 and "finalizePythonInterpreter" in errors[0]


@pytest.fixture(scope="module")
def valgrind() -> str:
    """valgrind, installed from Debian with apt-get where it is missing and this is root."""
    found = shutil.which("valgrind")
    if found is None and hasattr(os, "geteuid") and os.geteuid() == 0 and shutil.which("apt-get"):
        install = ["apt-get", "install", "-y", "--no-install-recommends", "valgrind"]
        env = {**os.environ, "DEBIAN_FRONTEND": "noninteractive"}
        if subprocess.run(install, capture_output=True, env=env, timeout=600).returncode != 0:
            subprocess.run(["apt-get", "update"], capture_output=True, env=env, timeout=600)
            subprocess.run(install, capture_output=True, env=env, timeout=600)
        found = shutil.which("valgrind")
    if found is None:
        pytest.skip("valgrind is not installed and cannot be installed here (needs root and apt-get)")
    return found


@pytest.fixture(scope="module")
def valgrind_runs(request, valgrind, relay_fmu, tmp_path_factory):
    """The valgrind runs of the relay FMU, the Python host's and (if it can be built) the C
    host's, started together: futures of (exit code, output, valgrind log), or the reason the
    C host cannot run."""
    work = tmp_path_factory.mktemp("valgrind")

    def run(tag: str, cmd: list[str], env: dict | None) -> tuple[int, str, str]:
        log = work / f"{tag}.log"
        done = subprocess.run([valgrind, "--undef-value-errors=no", "--leak-check=no", f"--log-file={log}", *cmd],
                              capture_output=True, text=True, timeout=VALGRIND_TIMEOUT, env=spawn_env(env))
        return done.returncode, done.stdout + done.stderr[-2000:], log.read_text()

    pool = ThreadPoolExecutor(max_workers=2)
    runs: dict = {"python": pool.submit(run, "python", [sys.executable, str(HERE / "ctypes_host.py"), str(relay_fmu), "100"],
                                        None)}
    try:
        exe, c_env = request.getfixturevalue("c_host")
        runs["c"] = pool.submit(run, "c", [str(exe), "keep", "100", *_c_host_args([relay_fmu], work)], c_env)
    except pytest.skip.Exception as exc:
        runs["c"] = str(exc)
    yield runs
    pool.shutdown(wait=True)


@pytest.mark.parametrize("host", ["python", "c"])
def test_no_fmu_library_touches_freed_memory_at_exit(valgrind_runs, host):
    if isinstance(valgrind_runs[host], str):
        pytest.skip(valgrind_runs[host])
    code, out, log = valgrind_runs[host].result()
    assert code == 0, out
    assert ("statuses [0]" if host == "python" else "worst status 0") in out, out
    assert "ERROR SUMMARY" in log, log[-2000:]   # valgrind ran to the end of the process
    errors = fmu_library_errors(log)
    assert not errors, "\n\n".join(errors)
