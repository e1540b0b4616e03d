"""A heave-compensation design loop to copy and change.

It does by hand what ``marinefmu design-ahc`` does, so each step can be swapped for your own:

1. identify the heave estimator in co-simulation (the built-in scenario ``ahc``: VesselMotion →
   AttitudeEstimator → HeaveObserver at the crane tip);
2. tune the PI length loop with python-control for several phase margins, fit the feedforward
   gain to the identified estimator, and predict the load's residual heave for each;
3. verify the best design in co-simulation (estimator, controller, winch);
4. write its gains into a copy of the scenario, ready for ``marinefmu simulate``.

Run from the repository (after ``make test`` or ``make demo`` has built the FMUs)::

    .venv/bin/python examples/ahc_design_loop.py --out results/ahc_example

Change the sea, the crane tip or the winch in the scenario file (``--scenario``), or replace
:func:`marinefmu.ahc.design.design` with your own tuning (LQG, H∞, …): anything that yields a
``AhcControllerParams`` can be predicted, verified and written the same way.
"""
from __future__ import annotations

import argparse
from dataclasses import replace
from pathlib import Path

from marinefmu.ahc.design import design, fit_feedforward, predicted_residual
from marinefmu.ahc.loop import GAINS, find_loop, identify, verify, write_gains
from marinefmu.fmu.tables import controller_params, winch_params
from marinefmu.fmu.build import build_all, repo_root
from marinefmu.cosim.scenarios import load_scenario


def main(argv: list[str] | None = None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenario", default="ahc", help="scenario TOML or built-in name (default ahc)")
    ap.add_argument("--controller", default="ctrl_observer", help="the AhcController to design")
    ap.add_argument("--identify", type=float, default=420.0, help="identification run [s]")
    ap.add_argument("--verify", type=float, default=600.0, help="verification run [s] (0: skip)")
    ap.add_argument("--out", default="results/ahc_example", help="folder for the scenario with the new gains")
    args = ap.parse_args(argv)

    build_all(verbose=False)                       # FMUs up to date (only what changed is rebuilt)
    fmus = repo_root() / "fmus"
    scenario = load_scenario(args.scenario)
    system = scenario.system
    parts = find_loop(system, args.controller)     # the estimator, the winch and the true tip it hangs off
    comps = {c.name: c for c in system.components}
    winch = winch_params(comps[parts.winch].parameters)
    base = controller_params(comps[parts.controller].parameters)

    # 1. identify: the estimator's heave and heave-rate responses and noise over the sea's band
    resp = identify(system, parts, fmus, args.identify)
    print(f"identified {parts.estimator}: heave gain {resp.heave_model[0]:.4f}, delay {1000 * resp.heave_model[1]:.1f} ms; "
          f"rate gain {resp.rate_model[0]:.4f}, delay {1000 * resp.rate_model[1]:.1f} ms")

    # 2. tune for several phase margins; predict each design's residual with the identified estimator
    designs = {}
    for margin in (45.0, 60.0, 75.0):
        d = design(winch, phase_margin=margin)
        ctrl = fit_feedforward(resp, winch, replace(base, k_p=d.controller.k_p, k_i=d.controller.k_i), system.step)
        designs[margin] = (d, ctrl, 100 * predicted_residual(resp, winch, ctrl, system.step))
        print(f"phase margin {margin:4.0f}°: k_p {ctrl.k_p:.3f} /s, k_i {ctrl.k_i:.3f} /s², k_ff {ctrl.k_ff:.4f}, "
              f"crossover {d.crossover:.2f} rad/s -> predicted residual {designs[margin][2]:.2f} % of the tip's heave")
    margin = min(designs, key=lambda m: designs[m][2])
    d, ctrl, predicted = designs[margin]
    print(f"chosen: phase margin {margin:.0f}° (closed-loop poles {', '.join(f'{p:.2f}' for p in d.closed_loop_poles)})")

    # 3. verify in co-simulation
    measured = verify(system, parts, ctrl, fmus, args.verify) if args.verify > 0 else {}
    if measured:
        print(f"verified: residual heave {measured['residual_pct']:.2f} % (predicted {predicted:.2f} %), "
              f"a winch limit acting {measured['limited_pct']:.2f} % of the time")

    # 4. write the gains into a copy of the scenario
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    target = out / f"{scenario.name}.toml"
    target.write_text(Path(scenario.source).read_text() if Path(scenario.source).is_file() else
                      (Path(__file__).resolve().parents[1] / "src/marinefmu/data/scenarios" / f"{scenario.name}.toml").read_text())
    write_gains(target, parts.controller, {g: round(float(getattr(ctrl, g)), 6) for g in GAINS})
    print(f"gains written into {target}; run it with: marinefmu simulate {target}")
    return {"margin": margin, "controller": ctrl, "predicted_pct": predicted, "measured": measured, "file": target}


if __name__ == "__main__":
    main()
