"""The whole system in the bench: accuracy in three seas, speed under three engines
(and the master alone, on do-nothing FMUs: :func:`master_floor`),
and memory over three hours.

Every measurement runs in a fresh process (as :mod:`marinefmu.bench.memory` does: clean
memory figures, and a native crash of one engine cannot take the bench down)::

    python -m marinefmu.bench.system ENGINE FMU_DIR DURATION OUT_DIR [HS TP] [--no-score]

with ENGINE ``fmpy`` (the FMUs through FMI with FMPy), ``python`` (the same slave code
in-process without FMI, ``SystemRunner(engine="python")``) or ``libcosim`` (OSP libcosim from
the scenario's ``OspSystemStructure.xml``), the ``system`` scenario at its 100 Hz base step
(optionally in another sea: Hs [m], Tp [s]), its ``[record]`` list streamed to
``OUT_DIR/results.npy`` (libcosim: sampled every second). It prints one JSON line: wall time
[s], real-time factor, peak resident memory [MB] (:func:`peak_rss_mb`) and, for the runners that
record every step, the accuracy table of :func:`marinefmu.analysis.scoring.score` and each component's
mean wall time per base step in its ``doStep`` [µs] (``SystemRunner.step_seconds``).
"""
from __future__ import annotations

import json
import math
import resource
import subprocess
import sys
import time
from pathlib import Path

#: Seas of the whole-system accuracy, calm / moderate / rough (Hs [m], Tp [s]), as the peer part.
SYSTEM_SEAS = {"calm": (1.0, 6.0), "moderate": (3.0, 9.0), "rough": (6.0, 11.0)}
ENGINES = ("fmpy", "python", "libcosim")


def _system(hs: float | None, tp: float | None):
    from dataclasses import replace

    from ..cosim.scenarios import load_scenario

    sc = load_scenario("system")
    if hs is None:
        return sc
    return replace(sc, system=sc.system.with_parameters({"vessel": {"sea.hs": hs, "sea.tp": tp}}))


def peak_rss_mb() -> float:
    """Peak resident memory of this process's own image [MB]: ``VmHWM`` of /proc/self/status,
    which starts afresh at ``exec``. Not ``ru_maxrss``: Linux keeps that across ``execve``, so
    a worker started by a large parent (the bench after its OrcaFlex and accuracy parts) would
    report the parent's peak as its own. ``ru_maxrss`` where /proc is absent."""
    return _proc_status_mb("VmHWM") or resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def rss_mb() -> float | None:
    """Resident memory of this process now [MB] (``VmRSS`` of /proc/self/status; None where
    /proc is absent)."""
    return _proc_status_mb("VmRSS")


def _proc_status_mb(key: str) -> float | None:
    try:
        with open("/proc/self/status", encoding="ascii") as f:
            for line in f:
                if line.startswith(f"{key}:"):
                    return int(line.split()[1]) / 1024.0
    except OSError:
        pass
    return None


def measure(engine: str, fmu_dir: str, duration: float, out_dir: str, hs: float | None = None,
            tp: float | None = None, scored: bool = True) -> dict:
    """One run in this process (the worker's job); see the module docstring. ``peak_rss_mb``
    is the peak of the run itself; scoring afterwards reads the whole memory-mapped result
    (its pages count as resident), so ``scored=False`` leaves it out of a long run."""
    sc = _system(hs, tp)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    # the estimators' imports (scipy, control, filterpy: seconds) happen once per process in
    # every engine (the FMUs share this interpreter); done here, they stay out of the timing
    import marinefmu.fmu.tables  # noqa: F401
    import marinefmu.estimators.heave.observer  # noqa: F401
    t0 = time.perf_counter()
    scores, steps = None, None
    if engine == "libcosim":
        from ..cosim.libcosim import run_libcosim

        run_libcosim(sc.system, fmu_dir, out, duration, list(sc.record), 1.0)
        wall, peak = time.perf_counter() - t0, peak_rss_mb()
    else:
        from ..cosim.system import SystemRunner
        from ..analysis.scoring import score

        runner = SystemRunner(sc.system, fmu_dir, engine=engine)
        result = runner.run(duration, record=sc.record, progress=False, out_file=out / "results.npy")
        wall, peak = time.perf_counter() - t0, peak_rss_mb()
        steps = {name: 1e6 * sec / (len(result) - 1) for name, sec in runner.step_seconds.items()}
        scores = score(result, sc.system, "vessel") if scored else {}
    return {"engine": engine, "duration_s": duration, "wall_s": wall, "rtf": duration / wall,
            "peak_rss_mb": peak, "scores": scores, "step_us": steps}


def run_isolated(engine: str, fmu_dir: Path, duration: float, out_dir: Path, sea: tuple[float, float] | None = None,
                 timeout: float = 4 * 3600.0, scored: bool = True) -> dict:
    """:func:`measure` in a fresh Python process; its JSON result."""
    cmd = [sys.executable, "-m", "marinefmu.bench.system", engine, str(fmu_dir), repr(duration), str(out_dir)]
    if sea is not None:
        cmd += [repr(sea[0]), repr(sea[1])]
    if not scored:
        cmd.append("--no-score")
    done = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
    lines = [ln for ln in done.stdout.splitlines() if ln.startswith("{")]
    if done.returncode != 0 or not lines:
        raise RuntimeError(f"bench_system {engine} failed ({done.returncode}):\n{done.stdout[-2000:]}\n{done.stderr[-3000:]}")
    return json.loads(lines[-1])


def system_accuracy(fmu_dir: Path, work: Path, duration: float = 600.0) -> dict:
    """Accuracy of every estimator of the ``system`` scenario in :data:`SYSTEM_SEAS` (FMPy
    runner, ``duration`` s each, :func:`marinefmu.analysis.scoring.score`)."""
    seas = {}
    for name, sea in SYSTEM_SEAS.items():
        r = run_isolated("fmpy", fmu_dir, duration, work / f"sea_{name}", sea)
        seas[name] = {"hs_m": sea[0], "tp_s": sea[1], "scores": r["scores"]}
        print(f"system, {name} sea (Hs {sea[0]:g} m, Tp {sea[1]:g} s), {duration:g} s: " + "; ".join(
            f"{comp} " + ", ".join(f"{k} {v:.3g}" for k, v in m.items() if not k.endswith(("_s", "fraction")))
            for comp, m in r["scores"].items()), flush=True)
    return seas


_IDLE_SCRIPT = """\
from pythonfmu import Fmi2Slave, Fmi2Causality, Fmi2Variability, Real, Integer, Boolean, String

TYPES = {{"Real": (Real, float), "Integer": (Integer, int), "Boolean": (Boolean, lambda s: s in ("true", "1")),
          "String": (String, str)}}
VARIABLES = {variables!r}


class {cls}(Fmi2Slave):
    \"\"\"The variables of {model}, and a doStep that does nothing (marinefmu.bench.system).\"\"\"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.values = {{}}
        for name, causality, variability, kind, start in VARIABLES:
            fmi_type, cast = TYPES[kind]
            self.values[name] = cast(start) if start is not None else cast("0") if kind != "Boolean" else False
            setter = None
            if causality in ("input", "parameter"):
                setter = lambda x, name=name: self.values.__setitem__(name, x)
            self.register_variable(fmi_type(name, causality=getattr(Fmi2Causality, causality),
                                            variability=getattr(Fmi2Variability, variability),
                                            getter=lambda name=name: self.values[name], setter=setter))

    def do_step(self, current_time, step_size):
        return True
"""


def idle_fmus(fmu_dir: Path, dest: Path, models: tuple[str, ...]) -> Path:
    """FMUs with the variables of ``fmu_dir/<model>.fmu`` (names, types, causalities, start
    values) whose ``doStep`` does nothing, written as ``dest/<model>.fmu`` with the real FMU's
    ``<model>_OspModelDescription.xml`` beside it where there is one (libcosim reads it): the
    ``system`` scenario run on them measures what the master, FMPy or libcosim, and pythonfmu
    cost by themselves."""
    import shutil
    import tempfile

    from fmpy import read_model_description
    from pythonfmu.builder import FmuBuilder

    dest.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        for model in models:
            md = read_model_description(str(fmu_dir / f"{model}.fmu"))
            variables = [(v.name, v.causality, v.variability, v.type, v.start) for v in md.modelVariables]
            cls = f"Idle{model}"
            script = Path(tmp) / f"{cls}.py"
            script.write_text(_IDLE_SCRIPT.format(variables=variables, cls=cls, model=model))
            built = Path(FmuBuilder.build_FMU(script, dest=tmp))
            shutil.move(built, dest / f"{model}.fmu")
            osp = fmu_dir / f"{model}_OspModelDescription.xml"
            if osp.exists():
                shutil.copy(osp, dest / osp.name)
    return dest


def master_floor(fmu_dir: Path, work: Path, duration: float = 600.0, engine: str = "fmpy") -> dict:
    """The ``system`` scenario under ``engine`` (the FMPy runner, or libcosim as
    :func:`~marinefmu.cosim.libcosim.run_libcosim` runs it, sampling every second) with
    :func:`idle_fmus`: the wall time of a base step when the components compute nothing (the
    master's exchange and recording, the engine's and pythonfmu's calls), the real-time factor
    no Python estimator set can pass on that engine. The idle FMUs are built once in ``work``."""
    system = _system(None, None).system
    models = tuple(sorted({Path(c.source).stem for c in system.components}))
    idle = work / "idle_fmus"
    if not all((idle / f"{m}{end}").exists() for m in models for end in (".fmu", "_OspModelDescription.xml")):
        idle_fmus(fmu_dir, idle, models)
    run = work / f"idle_run_{engine}"
    r = run_isolated(engine, idle, duration, run, scored=False)
    r.pop("scores", None)
    (run / "results.npy").unlink(missing_ok=True)
    r["base_step_us"] = 1e6 * r["wall_s"] / round(duration / system.step)
    print(f"system speed, FMUs that do nothing (the master and FMI alone), {engine}: {duration:g} s in "
          f"{r['wall_s']:.2f} s, real-time factor {r['rtf']:.0f}, {r['base_step_us']:.0f} µs per base step", flush=True)
    return r


#: Goals of the ``system`` part's speed (issue: the whole system at a 100 Hz base step): real-time
#: factors under the FMPy runner and under libcosim, the FMI / in-process time ratio, and the peak
#: memory of the 3-hour run [MB].
SPEED_GOALS = {"rtf_fmpy": 50.0, "rtf_libcosim": 25.0, "fmi_over_in_process": 1.1, "peak_rss_mb_3h": 500.0}


def component_budget_us(rtf_goal: float, floor_rtf: float, step: float = 0.01) -> float:
    """What the components of a system may spend together per base step [µs] for a real-time
    factor ``rtf_goal``, when the master and FMI alone (do-nothing FMUs, :func:`master_floor`)
    run at ``floor_rtf``: 1e6 · step · (1/rtf_goal − 1/floor_rtf). Zero or less: the goal is out
    of reach whatever the components do."""
    if rtf_goal <= 0 or floor_rtf <= 0 or step <= 0:
        raise ValueError(f"rtf_goal, floor_rtf and step must be > 0, got {rtf_goal}, {floor_rtf}, {step}")
    return 1e6 * step * (1.0 / rtf_goal - 1.0 / floor_rtf)


def speed_table(speed: dict) -> list[dict]:
    """Rows of the speed table from :func:`whole_system`'s ``speed`` entry: per component, its
    mean wall time per base step in ``doStep`` [µs] in-process (``python``) and through FMI
    (``fmpy``), and their ratio; then the rest of each engine's base step (the master's exchange,
    recording and FMI calls: wall time per base step minus the components' own), and the whole
    base step (µs per base step = 1e6 × step / real-time factor)."""
    step = _system(None, None).step
    rows = []
    fmi, inproc = speed["fmpy"].get("step_us") or {}, speed["python"].get("step_us") or {}
    for comp in fmi:
        rows.append({"component": comp, "in_process_us": inproc.get(comp, math.nan), "fmi_us": fmi[comp],
                     "fmi_over_in_process": fmi[comp] / inproc[comp] if inproc.get(comp) else math.nan})
    base = {e: 1e6 * speed[e]["wall_s"] / (speed[e]["duration_s"] / step) for e in ("python", "fmpy")}
    rest = {e: base[e] - sum((speed[e].get("step_us") or {}).values()) for e in base}
    rows.append({"component": "master and calls", "in_process_us": rest["python"], "fmi_us": rest["fmpy"],
                 "fmi_over_in_process": rest["fmpy"] / rest["python"]})
    rows.append({"component": "base step", "in_process_us": base["python"], "fmi_us": base["fmpy"],
                 "fmi_over_in_process": base["fmpy"] / base["python"]})
    return rows


def first_second(fmu_dir: Path, work: Path) -> dict:
    """The first second of a run under the FMPy runner, in a fresh process: ``wall_s`` from
    loading the FMUs (unzip, instantiate, initialise) to the end of 1 simulated second, and
    ``process_s``, the whole worker process (interpreter start and imports included)."""
    t0 = time.perf_counter()
    r = run_isolated("fmpy", fmu_dir, 1.0, work / "first_second", scored=False)
    return {"wall_s": r["wall_s"], "process_s": time.perf_counter() - t0}


def whole_system(fmu_dir: Path, work: Path, duration: float = 600.0, long_duration: float = 3 * 3600.0) -> dict:
    """The bench part ``system``: accuracy per sea (:func:`system_accuracy`), speed of the three
    engines on the default sea (``duration`` s each) with the FMI / in-process ratio, the floor
    (:func:`master_floor`) and each engine's ratio to it, the per-component table
    (:func:`speed_table`), the first second (:func:`first_second`), and peak memory of a
    ``long_duration`` run under the FMPy runner (results streamed)."""
    result: dict = {"seas": system_accuracy(fmu_dir, work, duration), "speed": {}}
    for engine in ENGINES:
        r = run_isolated(engine, fmu_dir, duration, work / f"speed_{engine}")
        r.pop("scores", None)
        result["speed"][engine] = r
        print(f"system speed, {engine:8s}: {duration:g} s in {r['wall_s']:.1f} s, real-time factor {r['rtf']:.1f}, "
              f"peak memory {r['peak_rss_mb']:.0f} MB" + ("" if not r.get("step_us") else "; per base step in doStep: "
              + ", ".join(f"{k} {v:.0f} µs" for k, v in r["step_us"].items())), flush=True)
    result["speed"]["idle_fmus"] = master_floor(fmu_dir, work, duration)
    result["speed"]["idle_fmus_libcosim"] = master_floor(fmu_dir, work, duration, "libcosim")
    speed = result["speed"]
    result["fmi_over_in_process"] = speed["python"]["rtf"] / speed["fmpy"]["rtf"]
    # each engine against its own floor (libcosim's: the idle FMUs under libcosim)
    result["floor_over"] = {e: speed["idle_fmus_libcosim" if e == "libcosim" else "idle_fmus"]["rtf"] / speed[e]["rtf"]
                            for e in ENGINES}
    result["table"] = speed_table(speed)
    goals = SPEED_GOALS
    print(f"FMI / in-process time ratio (FMPy runner / same code without FMI): {result['fmi_over_in_process']:.2f} "
          f"(project goal <= {goals['fmi_over_in_process']:g})", flush=True)
    print(f"real-time factor: FMPy runner {speed['fmpy']['rtf']:.1f} (goal >= {goals['rtf_fmpy']:g}), libcosim "
          f"{speed['libcosim']['rtf']:.1f} (goal >= {goals['rtf_libcosim']:g}); the floor's over each engine's: "
          + ", ".join(f"{e} {v:.1f}" for e, v in result["floor_over"].items()), flush=True)
    print("µs per base step, in-process / through FMI (FMPy runner) / ratio:", flush=True)
    for row in result["table"]:
        print(f"  {row['component']:18s} {row['in_process_us']:7.0f} {row['fmi_us']:7.0f} "
              f"{row['fmi_over_in_process']:6.2f}", flush=True)
    step = _system(None, None).step
    budget = component_budget_us(goals["rtf_fmpy"], speed["idle_fmus"]["rtf"], step)
    spent = sum(speed["fmpy"]["step_us"].values())
    budget_libcosim = component_budget_us(goals["rtf_libcosim"], speed["idle_fmus_libcosim"]["rtf"], step)
    result["component_budget_us"] = {"budget": budget, "spent": spent, "budget_libcosim": budget_libcosim}
    print(f"for a real-time factor of {goals['rtf_fmpy']:g} under the FMPy runner the components may spend "
          f"{budget:.0f} µs per base step together beside the floor; they spend {spent:.0f} µs", flush=True)
    print(f"for a real-time factor of {goals['rtf_libcosim']:g} under libcosim (sampled as run_libcosim does) "
          f"the components may spend {budget_libcosim:.0f} µs per base step beside its floor "
          f"(below zero: out of reach whatever they do)", flush=True)
    result["first_second"] = first_second(fmu_dir, work)
    print(f"first second under the FMPy runner: {result['first_second']['wall_s']:.2f} s from loading the FMUs, "
          f"{result['first_second']['process_s']:.2f} s for the whole process", flush=True)
    if long_duration:
        r = run_isolated("fmpy", fmu_dir, long_duration, work / "long", scored=False)
        r.pop("scores", None)
        (work / "long" / "results.npy").unlink(missing_ok=True)   # 0.6 GB
        result["long_run"] = r
        print(f"system, {long_duration / 3600:g} h under the FMPy runner, results streamed to disk: "
              f"{r['wall_s']:.0f} s (real-time factor {r['rtf']:.1f}), peak memory {r['peak_rss_mb']:.0f} MB "
              f"(project goal <= {goals['peak_rss_mb_3h']:g} MB)", flush=True)
    result["goals"] = dict(goals)
    print("the docs' speed tables:\n" + markdown(result), flush=True)
    return result


def markdown(data: dict) -> str:
    """The docs' speed table (Markdown) from :func:`whole_system`'s result."""
    speed = data["speed"]
    lines = ["| engine | wall time | real-time factor | floor's factor / this | peak memory |",
             "|---|---:|---:|---:|---:|"]
    names = {"fmpy": "FMPy runner (FMI)", "python": "the same slave code in-process, without FMI",
             "libcosim": "OSP libcosim (sampled every second)", "idle_fmus": "FMPy runner, FMUs whose `doStep` does nothing",
             "idle_fmus_libcosim": "OSP libcosim, FMUs whose `doStep` does nothing"}
    for e, label in names.items():
        if e not in speed:
            continue
        r = speed[e]
        ratio = data["floor_over"].get(e)
        lines.append(f"| {label} | {r['wall_s']:.1f} s | {r['rtf']:.1f} | {'—' if ratio is None else f'{ratio:.1f}'} | "
                     f"{r['peak_rss_mb']:.0f} MB |")
    lines += ["", "| component | in-process [µs] | through FMI [µs] | FMI / in-process |", "|---|---:|---:|---:|"]
    for row in data["table"]:
        lines.append(f"| {row['component']} | {row['in_process_us']:.0f} | {row['fmi_us']:.0f} | "
                     f"{row['fmi_over_in_process']:.2f} |")
    return "\n".join(lines)


def main(argv: list[str]) -> None:
    scored = "--no-score" not in argv
    argv = [a for a in argv if a != "--no-score"]
    engine, fmu_dir, duration, out_dir = argv[:4]
    sea = (float(argv[4]), float(argv[5])) if len(argv) > 5 else (None, None)
    if engine not in ENGINES:
        raise SystemExit(f"engine must be one of {', '.join(ENGINES)}, got {engine!r}")
    print(json.dumps(measure(engine, fmu_dir, float(duration), out_dir, *sea, scored=scored)), flush=True)


if __name__ == "__main__":
    main(sys.argv[1:])
