"""``marinefmu hydro``: the arguments and the run of the command (kept here, beside the code it
drives; :mod:`marinefmu.cli` registers it).

Examples
--------
::

    marinefmu hydro --preset all --out src/marinefmu/data/hydro --plots docs   # regenerate the shipped presets
    marinefmu hydro --preset box_barge --coarse --out results/hydro
    marinefmu hydro --hull box --length 100 --beam 20 --draft 5 --cog 0 0 0 --radii 7 25 26 --out results/hydro
    marinefmu hydro --hull ship --length 120 --beam 20 --draft 7 --gm 1.5 --radii 8 30 30 --roll-damping 0.05
    marinefmu hydro --mesh hull.gdf --cog 0 0 -2 --radii 9 30 30 --omega-max 2 --out results/hydro
"""
from __future__ import annotations

import argparse
import math
from pathlib import Path

REGENERATE = "marinefmu hydro --preset all --out src/marinefmu/data/hydro --plots docs"


def add_arguments(p: argparse.ArgumentParser) -> None:
    """Add the options of ``marinefmu hydro`` to ``p``."""
    from ..vessel import BEM_PRESETS

    src = p.add_mutually_exclusive_group(required=True)
    src.add_argument("--preset", choices=(*BEM_PRESETS, "all"), help="a shipped BEM preset, or all of them")
    src.add_argument("--hull", choices=("box", "ship", "semisub", "hemisphere"), help="a parametric hull")
    src.add_argument("--mesh", help="a hull mesh file (x fwd, y port, z up, waterline z = 0; "
                                    "formats gdf, mar/nemoh, pnl, hst, … as Capytaine reads them)")
    p.add_argument("--out", default="results/hydro", help="folder for <name>.csv (default results/hydro)")
    p.add_argument("--plots", help="folder for hydro_<name>.png (default: --out)")
    p.add_argument("--json", action="store_true", help="also write <name>.json: hydrostatics, natural periods, peaks")
    p.add_argument("--name", help="table name (default: the preset or hull name)")
    p.add_argument("--coarse", action="store_true", help="presets: the coarse mesh of the tests (omega <= 1.5 rad/s)")
    g = p.add_argument_group("parametric hull [m]")
    g.add_argument("--length", type=float, help="length (semisub: overall length)")
    g.add_argument("--beam", type=float, help="beam (semisub: overall width); hemisphere: the radius")
    g.add_argument("--draft", type=float, help="draft")
    g.add_argument("--freeboard", type=float, help="deck height above the waterline (for the COG check)")
    g.add_argument("--column", type=float, help="semisub: square column side")
    g.add_argument("--pontoon", type=float, nargs=2, metavar=("WIDTH", "HEIGHT"), help="semisub: pontoon section")
    g.add_argument("--p", type=float, default=2.0, help="ship: waterline exponent (2 = Wigley)")
    g.add_argument("--q", type=float, default=2.0, help="ship: section exponent (2 = Wigley)")
    m = p.add_argument_group("mass properties (body frame x fwd, y stbd, z down, from the waterline origin) [m]")
    m.add_argument("--cog", type=float, nargs=3, metavar=("X", "Y", "Z"), help="centre of gravity (z < 0 above the waterline)")
    m.add_argument("--gm", type=float, help="place the COG height for this transverse GM instead of --cog's z")
    m.add_argument("--radii", type=float, nargs=3, metavar=("RXX", "RYY", "RZZ"), help="radii of gyration about the COG")
    m.add_argument("--roll-damping", type=float, default=0.0, help="viscous roll damping, fraction of critical (default 0)")
    m.add_argument("--heave-damping", type=float, default=0.0, help="viscous heave damping, fraction of critical (default 0)")
    m.add_argument("--pitch-damping", type=float, default=0.0, help="viscous pitch damping, fraction of critical (default 0)")
    f = p.add_argument_group("frequencies [rad/s]")
    f.add_argument("--omega-min", type=float, default=0.1, help="lowest wave frequency (default 0.1)")
    f.add_argument("--omega-max", type=float, help="highest wave frequency (default: the preset's, else 2.5)")
    f.add_argument("--omega-step", type=float, default=0.05, help="frequency step (default 0.05)")
    f.add_argument("--panel", type=float, help="largest panel side [m] (default: fine enough for --omega-max)")
    p.add_argument("--no-lid", action="store_true", help="no irregular-frequency lid (the affected rows are flagged)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")


def _need(args: argparse.Namespace, *names: str) -> None:
    from ...errors import ParameterError

    missing = [n for n in names if getattr(args, n) is None]
    if missing:
        raise ParameterError(f"marinefmu hydro --hull {args.hull} needs " + ", ".join(f"--{n.replace('_', '-')}" for n in missing))


def _jobs(args: argparse.Namespace) -> list[dict]:
    """(name, hull, mass properties, omega, viscous damping) of each table to compute."""
    from . import bem, hulls, presets

    jobs = []
    if args.preset:
        names = list(presets.BEM_PRESETS) if args.preset == "all" else [args.preset]
        for n in names:
            pr = presets.preset(n)
            w_max = args.omega_max or pr.omega_limit(args.coarse)
            hull = pr.build(args.panel) if args.panel else pr.hull(omega_max=w_max)
            jobs.append(dict(name=n, hull=hull, mass=presets.mass_properties(pr, hull),
                             omega=bem.default_omega(w_max, args.omega_min, args.omega_step),
                             damping=dict(roll_damping=pr.roll_damping, heave_damping=pr.heave_damping,
                                          pitch_damping=pr.pitch_damping)))
        return jobs
    w_max = args.omega_max or 2.5
    if args.hull == "box":
        _need(args, "length", "beam", "draft")

        def build(panel):
            return hulls.box_barge(args.length, args.beam, args.draft, panel, args.freeboard)
    elif args.hull == "ship":
        _need(args, "length", "beam", "draft")

        def build(panel):
            return hulls.ship_hull(args.length, args.beam, args.draft, panel, args.p, args.q, args.freeboard)
    elif args.hull == "semisub":
        _need(args, "length", "beam", "draft", "column", "pontoon")

        def build(panel):
            return hulls.semisubmersible(args.length, args.beam, args.draft, args.column, args.pontoon[0],
                                         args.pontoon[1], panel, args.freeboard)
    elif args.hull == "hemisphere":
        _need(args, "beam")

        def build(panel):
            return hulls.hemisphere(args.beam, panel, args.freeboard)
    if args.mesh:
        hull = hulls.load_mesh_file(args.mesh, args.freeboard)
    else:
        hull = build(args.panel) if args.panel else bem.fit_panels(build, w_max)
    if args.radii is None:
        from ...errors import ParameterError

        raise ParameterError("marinefmu hydro needs --radii RXX RYY RZZ (radii of gyration about the COG [m])")
    cog = list(args.cog) if args.cog is not None else [0.0, 0.0, math.nan]
    if args.gm is not None:
        cog[2] = bem.cog_for_gm(hull, args.gm)
    elif args.cog is None:
        from ...errors import ParameterError

        raise ParameterError("marinefmu hydro needs --cog X Y Z or --gm GM")
    mass = bem.MassProperties(cog=tuple(cog), radii=tuple(args.radii))
    jobs.append(dict(name=args.name or hull.name.replace(" ", "_"), hull=hull, mass=mass,
                     omega=bem.default_omega(w_max, args.omega_min, args.omega_step),
                     damping=dict(roll_damping=args.roll_damping, heave_damping=args.heave_damping,
                                  pitch_damping=args.pitch_damping)))
    return jobs


def run(args: argparse.Namespace) -> int:
    """Run ``marinefmu hydro``: solve, write the CSV tables and plots, print a summary."""
    from . import bem, export

    out = Path(args.out)
    plots = Path(args.plots) if args.plots else out
    command = REGENERATE if args.preset == "all" and not args.coarse else ""
    for job in _jobs(args):
        name = args.name if args.name and not args.preset else job["name"]
        r = bem.solve(job["hull"], job["mass"], job["omega"], **job["damping"], lid=not args.no_lid,
                      progress=not args.no_progress)
        csv = export.write_rao_csv(r, out / f"{name}.csv", command)
        png = export.plot_raos(r, plots / f"hydro_{name}.png")
        t = r.natural_periods
        print(f"{name}: {r.panels} panels, {r.omega.size} frequencies × {r.heading.size} headings in {r.seconds:.0f} s; "
              f"natural periods heave {t['heave']:.2f} s, roll {t['roll']:.2f} s, pitch {t['pitch']:.2f} s; "
              f"GM_T {r.gm_t:.2f} m")
        if args.json:
            print(f"  summary {export.write_summary(r, out / f'{name}.json')}")
        print(f"  table {csv}\n  plot  {png}")
        if r.irregular.any():
            print(f"  warning: {int(r.irregular.sum())} frequencies at or above the irregular frequency "
                  f"{r.irregular_omega:.3g} rad/s are flagged in the table header")
    return 0
