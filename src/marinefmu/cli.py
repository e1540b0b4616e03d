"""The ``marinefmu`` command line: build FMUs, simulate scenarios, benchmark.

Examples
--------
::

    marinefmu build
    marinefmu simulate default --duration 120 --out results/default
    marinefmu simulate my_scenario.toml
    marinefmu simulate results/system/system.ssp
    marinefmu bench
    marinefmu example --list
    marinefmu example paper001-fig7 --out results/examples
    marinefmu design-ahc ahc --out results/ahc_design --write
    marinefmu campaign examples/campaigns/scatter.toml --workers 2
    marinefmu hydro --preset all --out src/marinefmu/data/hydro --plots docs
    marinefmu record system --duration 600 --out results/rec/system.csv
    marinefmu replay results/rec/system.csv --mapping results/rec/system.toml --estimators attitude,heave
    marinefmu build-recording results/rec/system.csv --mapping results/rec/system.toml -o system_rec.fmu
"""
from __future__ import annotations

import argparse
import logging
import sys
import time
from pathlib import Path

from .errors import MarineFmuError


#: Longest result also written as CSV [rows] (an hour at 100 Hz); longer runs only as .npy.
CSV_MAX_ROWS = 360_001


def _fmu_dir(given: str | None) -> Path:
    """``--fmus`` if given, else the checkout's ``fmus/`` (built first where stale)."""
    if given:
        return Path(given)
    from .fmu.build import build_all, repo_root

    build_all(verbose=False)
    return repo_root() / "fmus"


def _cmd_build(args: argparse.Namespace) -> int:
    from .fmu.build import build_all

    build_all(force=args.force)
    return 0


def _cmd_simulate(args: argparse.Namespace) -> int:
    from .cosim.libcosim import write_osp_system
    from .cosim.ssp import read_ssp, write_ssd, write_ssp
    from .cosim.system import SystemRunner, save_csv
    from .analysis.vessel_plots import plot_vessel, vessel_components, vessel_summary
    from .cosim.scenarios import Scenario, load_scenario

    package = str(args.scenario).endswith(".ssp")
    if package:   # an SSP package: its own FMUs, unpacked next to the results
        out = Path(args.out or f"results/{Path(args.scenario).stem}")
        system = read_ssp(args.scenario, out / "ssp")
        scenario = Scenario(system.name, f"SSP package {args.scenario}", system.stop_time - system.start_time,
                            system.step, system, None, str(args.scenario))
    else:
        scenario = load_scenario(args.scenario)
    fmu_dir = Path(args.fmus) if args.fmus else (Path(".") if package else None)
    if fmu_dir is None:
        from .fmu.build import build_all, repo_root

        build_all(verbose=False)
        fmu_dir = repo_root() / "fmus"
    duration = scenario.duration if args.duration is None else args.duration
    if not duration > 0:
        raise MarineFmuError(f"--duration = {duration} is out of range: must be > 0 [s]")
    if not package:
        out = Path(args.out or f"results/{scenario.name}")
    out.mkdir(parents=True, exist_ok=True)
    ssd = write_ssd(scenario.system, out / "SystemStructure.ssd")
    print(f"scenario {scenario.name}: {scenario.description}")
    print(f"  {len(scenario.system.components)} component(s), {duration:g} s at {scenario.step:g} s; system file {ssd}")
    if not package:
        ssp = write_ssp(scenario.system, fmu_dir, out / f"{scenario.name}.ssp")
        osp = write_osp_system(scenario.system, fmu_dir, out / "OspSystemStructure.xml")
        print(f"  SSP package {ssp} (run it with `marinefmu simulate {ssp}`); OSP libcosim system {osp}")
    runner = SystemRunner(scenario.system, fmu_dir, engine=args.engine)
    t0 = time.perf_counter()
    # streamed to disk as the run goes: memory stays flat however long the run
    result = runner.run(scenario.system.start_time + duration, record=scenario.record,
                        progress=False if args.no_progress else None, out_file=out / "results.npy")
    wall = time.perf_counter() - t0
    print(f"  simulated in {wall:.1f} s ({(result.size - 1) / wall:,.0f} base steps/s, real-time factor "
          f"{duration / wall:.1f}, engine {args.engine}); results {out / 'results.npy'} (numpy.load)")
    if result.size <= CSV_MAX_ROWS:
        print(f"  results as CSV {save_csv(result, out / 'results.csv')}")
    else:
        print(f"  no CSV: {result.size:,} rows is more than {CSV_MAX_ROWS:,} (use results.npy)")
    for comp in vessel_components(result):
        for p in plot_vessel(result, comp, out):
            print(f"  plot {p}")
        print(f"  summary of {comp}:")
        for k, v in vessel_summary(result, comp).items():
            print(f"    {k:28s} {v:.6g}")
    # the truth comes from the system's VesselMotion, whatever of it was recorded (plots need more)
    vessels = [c.name for c in scenario.system.components if c.kind == "VesselMotion"] or vessel_components(result)
    scores = {}
    if vessels:
        from .analysis.scoring import score

        scores = score(result, scenario.system, vessels[0])
        for comp, metrics in scores.items():
            print(f"  accuracy of {comp} against {vessels[0]}'s truth:")
            for k, v in metrics.items():
                print(f"    {k:28s} {v:.6g}")
    if scores:
        from .analysis.html_report import write_report

        page = write_report(result, scenario.system, scores, vessels[0], out, f"marinefmu: scenario {scenario.name}",
                            scenario.description)
        print(f"  report {page}")
    problems = [m for m in runner.messages if m.status in ("WARNING", "ERROR", "FATAL")]
    for m in problems:
        print(f"  FMU {m.status.lower()}: {m.instance}: {m.text}")
    return 0


def _bench_parts(text: str) -> str:
    from .bench.parts import PARTS

    bad = [p for p in text.split(",") if p not in PARTS]
    if bad:
        raise argparse.ArgumentTypeError(f"unknown part(s) {', '.join(bad)}: choose from {', '.join(PARTS)}")
    return text


def _cmd_bench(args: argparse.Namespace) -> int:
    from .bench.parts import run_benchmarks

    run_benchmarks(Path(args.out), steps=args.steps, memory_steps=args.memory_steps, memory_cycles=args.memory_cycles,
                   parts=tuple(args.parts.split(",")))
    return 0


def _cmd_design_ahc(args: argparse.Namespace) -> int:
    import shutil

    from .ahc.loop import GAINS, design_loop, find_loop, write_gains
    from .cosim.scenarios import load_scenario

    scenario = load_scenario(args.scenario)
    out = Path(args.out)
    fmu_dir = _fmu_dir(args.fmus)
    controller = args.controller
    if controller is None:   # the controller fed by a heave observer (not the classical filter)
        kinds = {c.name: c for c in scenario.system.components}
        for c in scenario.system.components:
            if c.kind == "AhcController":
                src = find_loop(scenario.system, c.name).estimator
                if kinds[src].kind == "HeaveObserver" and kinds[src].parameters.get("model") != "highpass":
                    controller = c.name
                    break
        if controller is None:
            raise MarineFmuError(f"scenario {scenario.name}: no AhcController fed by a HeaveObserver; name one with --controller")
    print(f"design-ahc: scenario {scenario.name}, controller {controller}")
    t0 = time.perf_counter()
    r = design_loop(scenario, controller, fmu_dir, out, args.identify, args.verify, args.phase_margin,
                    progress=not args.no_progress)
    total = time.perf_counter() - t0
    d, c = r.design, r.design.controller
    resp = r.response
    print(f"  identified {find_loop(scenario.system, controller).estimator} over the heave band "
          f"{resp.omega[resp.band()][0]:.2f}-{resp.omega[resp.band()][-1]:.2f} rad/s: heave gain {resp.heave_model[0]:.4f}, "
          f"delay {1000 * resp.heave_model[1]:.1f} ms; heave rate gain {resp.rate_model[0]:.4f}, "
          f"delay {1000 * resp.rate_model[1]:.1f} ms")
    print(f"  tuned: k_p {c.k_p:.4g} /s, k_i {c.k_i:.4g} /s², k_ff {c.k_ff:.4g}; crossover {d.crossover:.3g} rad/s, "
          f"phase margin {d.phase_margin:.1f}°, gain margin {d.gain_margin:.3g}")
    print(f"  predicted residual heave {r.predicted_pct:.2f} % of the tip's (fed the truth: {r.predicted_ideal_pct:.2f} %)")
    m = r.measured
    if "residual_pct" in m:
        print(f"  verified in co-simulation ({m['scored_s']:.0f} s scored): residual heave {m['residual_pct']:.2f} %, "
              f"all frequencies {m['residual_total_pct']:.2f} %, a winch limit acting {m.get('limited_pct', 0.0):.2f} % of the time")
    for p in r.plots:
        print(f"  plot {p}")
    if args.write:
        target = Path(args.scenario)
        if target.suffix != ".toml" or not target.exists():   # a built-in scenario: write a copy
            out.mkdir(parents=True, exist_ok=True)
            target = out / f"{scenario.name}.toml"
            if Path(scenario.source).is_file():
                shutil.copyfile(scenario.source, target)
            else:
                from importlib import resources

                target.write_text(resources.files("marinefmu").joinpath(f"data/scenarios/{scenario.name}.toml")
                                  .read_text(encoding="utf-8"), encoding="utf-8")
        # every controller of the system gets the gains: the comparison is of one controller fed
        # different heave signals (truth, classical, observer)
        names = [k.name for k in scenario.system.components if k.kind == "AhcController"]
        for name in names:
            write_gains(target, name, {g: round(float(getattr(c, g)), 6) for g in GAINS})
        print(f"  gains written into {target} for {', '.join(names)}")
    print(f"  design loop {total:.1f} s (identify {r.seconds['identify']:.1f}, tune {r.seconds['tune']:.1f}, "
          f"verify {r.seconds['verify']:.1f}, plots {r.seconds['plots']:.1f})")
    return 0


def _cmd_example(args: argparse.Namespace) -> int:
    from .papers.registry import EXAMPLES, format_value

    if args.list or not args.name:
        for name, (text, _) in EXAMPLES.items():
            print(f"  {name:24s} {text}")
        return 0
    if args.name not in EXAMPLES:
        print(f"marinefmu: error: unknown example {args.name!r}; one of: {', '.join(EXAMPLES)}", file=sys.stderr)
        return 2
    text, run = EXAMPLES[args.name]
    out = Path(args.out)
    print(f"{args.name}: {text}")
    t0 = time.perf_counter()
    figures = run(out)
    for key, value in figures.items():
        print(f"  {key:40s} {format_value(value)}")
    pngs = sorted(out.glob("*.png")) if out.is_dir() else []
    for png in pngs:
        print(f"  plot {png}")
    print(f"  ({time.perf_counter() - t0:.0f} s)")
    return 0


def _cmd_campaign(args: argparse.Namespace) -> int:
    from .campaign import load_spec, run_campaign
    from .campaign.plots import plot_campaign
    from .campaign.table import read_log, read_table

    if args.workers is not None and args.workers < 1:
        raise MarineFmuError(f"--workers = {args.workers} is out of range: must be an integer >= 1")
    fmu_dir = _fmu_dir(args.fmus)
    spec = load_spec(args.spec, fmu_dir)   # every refusal before anything runs
    out = Path(args.out or f"results/campaign/{spec.name}")
    runs = spec.runs()
    print(f"campaign {spec.name}: {len(runs)} run(s) of scenario {spec.scenario.name}, {spec.duration:g} s each, "
          f"varying {', '.join(spec.axes)}; "
          + (f"scheduler {args.scheduler}" if args.scheduler else f"local cluster of {args.workers or 'one per core'} worker(s)"))
    try:
        outcome = run_campaign(spec, out, scheduler=args.scheduler, workers=args.workers,
                               retry_failed=args.retry_failed, progress=not args.no_progress)
    except KeyboardInterrupt:
        done = read_log(out)
        print(f"\ninterrupted: {sum(r.id in done for r in runs)} of {len(runs)} run(s) are in {out / 'results.csv'}; "
              "run the same command again to go on", file=sys.stderr)
        return 130
    print(f"  {outcome.ran} run(s) now, {outcome.skipped} already in the table; {outcome.ok} succeeded, "
          f"{outcome.failed} failed of {outcome.total}"
          + (f"; {outcome.wall_s:.1f} s, {outcome.ran / outcome.wall_s * 3600:.0f} runs/h" if outcome.ran else ""))
    print(f"  table {outcome.table}")
    rows = read_table(outcome.table)   # the campaign's runs only, whatever else the folder's log holds
    for row in rows:
        if row["status"] != "ok":
            print(f"  failed {row['id']} {({a: row[a] for a in spec.axes})}: {row['error'][:300]}")
    if not args.no_plots:
        for path in plot_campaign(spec, rows, out):
            print(f"  plot {path}")
    return 0 if outcome.failed == 0 else 1


def _cmd_hydro(args: argparse.Namespace) -> int:
    from .sea.hydro.command import run

    return run(args)


def _cmd_record(args: argparse.Namespace) -> int:
    from .cosim.record import record

    r = record(args.scenario, args.out, args.duration, component=args.component, progress=not args.no_progress)
    print(f"record: {r.component} of scenario {args.scenario}, {r.rows:,} rows at {r.step:g} s")
    print(f"  recording {r.csv}\n  mapping   {r.mapping}")
    return 0


def _set_values(items: list[str]) -> dict:
    out = {}
    for item in items:
        key, sep, value = item.partition("=")
        if not sep or "." not in key:
            raise MarineFmuError(f"--set {item!r} must be component.parameter=value")
        for cast in (int, float):
            try:
                out[key] = cast(value)
                break
            except ValueError:
                continue
        else:
            out[key] = {"true": True, "false": False}.get(value.lower(), value)
    return out


def _cmd_replay(args: argparse.Namespace) -> int:
    from .analysis.replay_report import replay_and_report
    from .cosim.replay import plan_replay

    fmu_dir = _fmu_dir(args.fmus)
    plan = plan_replay(args.record, args.mapping, args.estimators, imu=args.imu, point=args.point, step=args.step,
                       duration=args.duration, start=args.start, parameters=_set_values(args.set))
    s = plan.summary
    print(f"replay {args.record}: {s.rows:,} rows, {s.duration:.6g} s; estimators {', '.join(plan.estimators)}; "
          f"{plan.duration:.6g} s at {plan.system.step:.6g} s")
    for group in s.samples:
        print(f"  {group:12s} {s.samples[group]:>10,} samples, {s.bad[group]:,} bad, {s.gaps[group]:,} gap(s) > max_gap")
    for note in plan.notes:
        print(f"  note: {note}")
    out = Path(args.out or f"results/replay/{Path(args.record).stem}")
    r = replay_and_report(plan, fmu_dir, out, progress=False if args.no_progress else None)
    print(f"  ran in {r['wall_s']:.1f} s; results {r['npy']}" + (f", {r['csv']}" if r["csv"] else ""))
    for name, sc in r["scores"].items():
        print(f"  {name:24s} RMS {sc['rms']:.4g} {sc['unit']} against the record's reference, lag {sc['lag_s']:.4g} s "
              f"(at lag 0: {sc['rms_lag0']:.4g} {sc['unit']})")
    for group, n, bad, gaps, steps, _ in r["validity"]:
        if steps:
            print(f"  {group}: valid false on {steps:,} step(s)")
    print(f"  report {r['report']}")
    return 0


def _cmd_build_recording(args: argparse.Namespace) -> int:
    from .fmu.recording_build import build_recording

    fmu = build_recording(args.record, args.mapping, args.output)
    print(f"build-recording: {fmu} (record and mapping bundled, validated)")
    return 0


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``marinefmu`` console script."""
    parser = argparse.ArgumentParser(prog="marinefmu", description="Marine motion estimation FMUs: build, simulate, benchmark.")
    parser.add_argument("-v", "--verbose", action="store_true", help="show FMU debug messages")
    sub = parser.add_subparsers(dest="command", required=True)
    b = sub.add_parser("build", help="build models/*.py into fmus/*.fmu and validate them")
    b.add_argument("--force", action="store_true", help="rebuild even if nothing changed")
    b.set_defaults(func=_cmd_build)
    s = sub.add_parser("simulate", help="run a scenario (TOML file, built-in name or .ssp package) and write CSV, "
                                        "PNG plots, the SSP package and the OSP libcosim system file")
    s.add_argument("scenario", help="scenario TOML file, a built-in name such as 'default' or 'system', or an .ssp package")
    s.add_argument("--duration", type=float, help="simulated time [s] (default: the scenario's)")
    s.add_argument("--out", help="output folder (default results/<scenario name>)")
    s.add_argument("--fmus", help="folder holding the FMUs (default: build into the checkout's fmus/)")
    s.add_argument("--no-progress", action="store_true", help="no progress bar")
    s.add_argument("--engine", choices=("fmpy", "python"), default="fmpy",
                   help="fmpy: the FMUs through FMI (default); python: their slave code in-process, without FMI")
    s.set_defaults(func=_cmd_simulate)
    k = sub.add_parser("bench", help="measure speed (writes JSON and prints a table)")
    k.add_argument("--out", default="bench", help="output folder for bench.json (default bench/)")
    k.add_argument("--steps", type=int, default=60000, help="FMU steps per measurement (default 60000)")
    from .bench.parts import PARTS

    k.add_argument("--parts", default=",".join(PARTS), type=_bench_parts,
                   help=f"comma-separated parts to (re)measure, merged into bench.json (default {','.join(PARTS)})")
    k.add_argument("--memory-steps", type=int, default=1_000_000,
                   help="steps per FMU of the memory measurement (default 1000000; 0 skips it)")
    k.add_argument("--memory-cycles", type=int, default=1000,
                   help="instantiate/free cycles per FMU of the memory measurement (default 1000; 0 skips it)")
    k.set_defaults(func=_cmd_bench)
    a = sub.add_parser("design-ahc", help="heave-compensation design loop: identify the estimator in co-simulation, "
                                          "tune the controller with python-control, verify, plot, write the gains")
    a.add_argument("scenario", nargs="?", default="ahc", help="scenario TOML file or built-in name (default ahc)")
    a.add_argument("--controller", help="the AhcController to design (default: the one fed by a HeaveObserver)")
    a.add_argument("--identify", type=float, default=420.0, help="simulated time of the identification run [s] (default 420)")
    a.add_argument("--verify", type=float, default=600.0, help="simulated time of the verification run [s] (default 600)")
    a.add_argument("--phase-margin", type=float, default=60.0, help="phase margin of the length loop [deg] (default 60)")
    a.add_argument("--out", default="results/ahc_design", help="folder for the plots (default results/ahc_design)")
    a.add_argument("--fmus", help="folder holding the FMUs (default: build into the checkout's fmus/)")
    a.add_argument("--write", action="store_true", help="write the gains into every AhcController of the scenario "
                                                          "file (a built-in scenario: into a copy in --out)")
    a.add_argument("--no-progress", action="store_true", help="no progress bars")
    a.set_defaults(func=_cmd_design_ahc)
    c = sub.add_parser("campaign", help="run many co-simulations of one system over a grid (sea states, seeds, "
                                        "sensor placements) on Dask; resumable; table and accuracy maps")
    c.add_argument("spec", help="campaign TOML file (format: marinefmu.campaign.spec)")
    c.add_argument("--scheduler", help="address of a running Dask scheduler, e.g. tcp://10.0.0.5:8786 "
                                       "(default: start a local cluster)")
    c.add_argument("--workers", type=int, help="worker processes of the local cluster (default: one per core)")
    c.add_argument("--out", help="output folder (default results/campaign/<name>); rerun into it to resume")
    c.add_argument("--fmus", help="folder holding the FMUs (default: build into the checkout's fmus/)")
    c.add_argument("--retry-failed", action="store_true", help="run again the runs the table holds as failed")
    c.add_argument("--no-plots", action="store_true", help="no accuracy maps or comparisons")
    c.add_argument("--no-progress", action="store_true", help="no progress bar")
    c.set_defaults(func=_cmd_campaign)
    e = sub.add_parser("example", help="run one of the papers' examples (list them with --list)")
    e.add_argument("name", nargs="?", help="example name, e.g. paper001-fig7")
    e.add_argument("--list", action="store_true", help="list the examples")
    e.add_argument("--out", default="results/examples", help="folder for plots (default results/examples)")
    e.set_defaults(func=_cmd_example)
    from .sea.hydro.command import add_arguments as _hydro_arguments

    h = sub.add_parser("hydro", help="RAOs of a hull from the BEM solver Capytaine (pip install marinefmu[hydro]): "
                                     "writes the RAO CSV vessel.rao_file reads, and a plot")
    _hydro_arguments(h)
    h.set_defaults(func=_cmd_hydro)
    r = sub.add_parser("record", help="write a scenario's VesselMotion run as a recording (CSV) plus its mapping "
                                      "sidecar (TOML), truth as ref.*")
    r.add_argument("scenario", help="scenario TOML file or built-in name, e.g. system")
    r.add_argument("--duration", type=float, help="simulated time [s] (default: the scenario's)")
    r.add_argument("--out", required=True, help="the CSV to write (the sidecar goes beside it as .toml)")
    r.add_argument("--component", help="the VesselMotion component to record (default the first)")
    r.add_argument("--no-progress", action="store_true", help="no progress bar")
    r.set_defaults(func=_cmd_record)
    p = sub.add_parser("replay", help="run a recording through the estimator FMUs; results and an HTML report that "
                                      "scores the estimates against the record's ref.* signals")
    p.add_argument("record", help="the recorded file (CSV, CSV.gz or Parquet)")
    p.add_argument("--mapping", required=True, help="its mapping sidecar (TOML)")
    p.add_argument("--estimators", default="attitude,heave",
                   help="comma-separated: attitude, reconstruction, fusion, cr, heave (default attitude,heave)")
    p.add_argument("--imu", help="IMU lever arm x,y,z [m] relative to the COG, body frame (default the mapping's)")
    p.add_argument("--point", help="monitoring point x,y,z [m] relative to the COG, body frame (default the mapping's)")
    p.add_argument("--step", type=float, help="co-simulation step [s] (default the record's mean interval)")
    p.add_argument("--duration", type=float, help="simulated time [s] (default the record's length)")
    p.add_argument("--start", type=float, default=0.0, help="offset into the record [s] (default 0)")
    p.add_argument("--set", action="append", default=[], metavar="COMP.PARAM=VALUE",
                   help="an estimator parameter, e.g. --set att.acc_noise=0.002 (repeatable)")
    p.add_argument("--out", help="output folder (default results/replay/<record name>)")
    p.add_argument("--fmus", help="folder holding the FMUs (default: build into the checkout's fmus/)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.set_defaults(func=_cmd_replay)
    g = sub.add_parser("build-recording", help="a self-contained SensorRecording FMU with the record and its "
                                               "mapping bundled (compressed) in its resources")
    g.add_argument("record", help="the recorded file (CSV, CSV.gz or Parquet)")
    g.add_argument("--mapping", required=True, help="its mapping sidecar (TOML)")
    g.add_argument("-o", "--output", required=True, help="the FMU to write, NAME.fmu")
    g.set_defaults(func=_cmd_build_recording)
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.DEBUG if args.verbose else logging.WARNING, format="%(levelname)s %(name)s: %(message)s")
    try:
        return args.func(args)
    except MarineFmuError as exc:
        print(f"marinefmu: error: {exc}", file=sys.stderr)
        return 2


def console() -> None:
    """The ``marinefmu`` console script: :func:`main`, whose return value is the exit code."""
    sys.exit(main())


if __name__ == "__main__":
    console()
