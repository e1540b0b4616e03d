"""The heave-compensation design loop: identify, tune, verify, write back
(``marinefmu design-ahc``).

Given a system (scenario TOML) and the name of one AhcController in it, whose ``heave`` input
comes from an estimator and whose ``command`` drives an AhcWinch:

1. **Identify**: co-simulate the estimator's upstream part of the system (every component the
   controller's ``heave`` input depends on) for ``identify`` s and identify the transfer H(ω)
   from the true crane-tip heave (the source of the winch's ``tip.d``, minus its mean) to
   the estimate (:func:`~marinefmu.ahc.design.identify_response`), on the span where the
   estimator is ``valid``.
2. **Tune**: the PI length loop for the winch's parameters
   (:func:`~marinefmu.ahc.design.design`, python-control, phase margin ``phase_margin``), then
   the feedforward gain fitted to the identified responses
   (:func:`~marinefmu.ahc.design.fit_feedforward`) with the co-simulation's delays, and the
   residual it predicts.
3. **Verify**: co-simulate the estimator, the controller with the new gains and the winch for
   ``verify`` s and score the load's residual heave
   (:func:`~marinefmu.analysis.scoring.ahc_scores`).
4. **Write**: Bode and step plots (PNG), and, when asked, the gains into the system file.

A design that cannot be made (no crossover with the margin, an unstable loop) is refused by
:func:`~marinefmu.ahc.design.design` with the cause; a system without the pieces named above
is refused here, naming what is missing.
"""
from __future__ import annotations

import re
import time
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from .controller import AhcControllerParams
from .winch import AhcWinchParams
from .design import AhcDesign, EstimatorResponse, check_phase_margin, design, fit_feedforward, identify_response, load_tf, \
    predicted_residual, residual_response, winch_tf
from ..fmu.tables import controller_params, winch_params
from ..cosim.ssp import SystemDescription
from ..errors import ParameterError, check_range
from ..cosim.scenarios import Scenario
from ..analysis.scoring import ahc_scores

#: Gains the design writes into the system file.
GAINS = ("k_ff", "k_p", "k_i")


@dataclass(frozen=True)
class LoopParts:
    """The components of one heave-compensation loop in a system."""

    controller: str
    winch: str
    estimator: str           # the component feeding the controller's heave input
    estimate: str            # that output, "component.variable"
    estimate_rate: str       # the output feeding the controller's heave_rate
    estimate_valid: str | None   # the estimator's valid output, if it has one
    tip: str                 # the true crane-tip heave: the source of the winch's tip.d


@dataclass(frozen=True)
class DesignResult:
    """What one pass of the loop found.

    Attributes
    ----------
    design : AhcDesign
        The PI length loop (margins, poles) with the fitted feedforward in ``design.controller``.
    response : EstimatorResponse
        The identified estimator.
    predicted_pct, predicted_ideal_pct : float
        Predicted load heave / tip heave [%] with the estimator, and fed the truth.
    measured : dict
        :func:`~marinefmu.analysis.scoring.ahc_scores` of the verification run's winch.
    seconds : dict
        Wall time of each stage [s] (identify, tune, verify, plots).
    plots : list of Path
        PNG files written.
    """

    design: AhcDesign
    response: EstimatorResponse
    predicted_pct: float
    predicted_ideal_pct: float
    measured: dict
    seconds: dict
    plots: list


def find_loop(system: SystemDescription, controller: str) -> LoopParts:
    """The loop around ``controller`` (module docstring); refuses with the missing piece named."""
    comps = {c.name: c for c in system.components}
    if controller not in comps or comps[controller].kind != "AhcController":
        ctrls = [c.name for c in system.components if c.kind == "AhcController"]
        raise ParameterError(f"controller {controller!r} is not an AhcController of system {system.name!r} "
                             f"(its AhcControllers: {', '.join(ctrls) or 'none'})")

    def source(comp: str, var: str) -> tuple[str, str] | None:
        return next(((c.start, c.start_var) for c in system.connections if c.end == comp and c.end_var == var), None)

    heave = source(controller, "heave")
    if heave is None:
        raise ParameterError(f"controller {controller!r}: its heave input is not connected (connect an estimator's point.heave)")
    winch = next((c.end for c in system.connections if c.start == controller and c.start_var == "command"
                  and comps[c.end].kind == "AhcWinch"), None)
    if winch is None:
        raise ParameterError(f"controller {controller!r}: its command drives no AhcWinch")
    tip = source(winch, "tip.d")
    if tip is None:
        raise ParameterError(f"winch {winch!r}: its tip.d input is not connected (connect VesselMotion truth.point.d)")
    rate = source(controller, "heave_rate")
    if rate is None:
        raise ParameterError(f"controller {controller!r}: its heave_rate input is not connected (connect the estimator's point.heave_rate)")
    valid = source(controller, "heave_valid")
    return LoopParts(controller, winch, heave[0], ".".join(heave), ".".join(rate), None if valid is None else ".".join(valid),
                     ".".join(tip))


def _upstream(system: SystemDescription, names: set[str]) -> set[str]:
    """``names`` and every component they depend on through connections."""
    out, todo = set(), list(names)
    while todo:
        n = todo.pop()
        if n in out:
            continue
        out.add(n)
        todo.extend(c.start for c in system.connections if c.end == n)
    return out


def subsystem(system: SystemDescription, keep: set[str], overrides: dict[str, dict] | None = None,
              stop_time: float | None = None) -> SystemDescription:
    """``system`` restricted to the components ``keep`` (and the connections among them), with
    parameter ``overrides`` per component."""
    comps = tuple(c for c in system.with_parameters(overrides or {}).components if c.name in keep)
    conns = tuple(c for c in system.connections if c.start in keep and c.end in keep)
    return replace(system, components=comps, connections=conns,
                   stop_time=system.stop_time if stop_time is None else stop_time)


def identify(system: SystemDescription, parts: LoopParts, fmu_dir: str | Path, duration: float,
             progress: bool = False) -> EstimatorResponse:
    """Stage 1: run the estimator's part of ``system`` for ``duration`` s and identify H(ω)."""
    from ..cosim.system import SystemRunner

    keep = _upstream(system, {parts.estimator, parts.tip.split(".", 1)[0]})
    record = [parts.tip, parts.estimate, parts.estimate_rate] + ([parts.estimate_valid] if parts.estimate_valid else [])
    r = SystemRunner(subsystem(system, keep), fmu_dir).run(system.start_time + duration, record=record, progress=progress)
    span = np.ones(len(r), dtype=bool)
    if parts.estimate_valid:
        valid = np.asarray(r[parts.estimate_valid], dtype=bool)
        if not valid.any():
            raise ParameterError(f"{parts.estimator} never reported valid in {duration:g} s: identify for longer")
        span = np.arange(len(r)) >= np.argmax(valid)
    tip, est, rate = (np.asarray(r[v], dtype=float)[span] for v in (parts.tip, parts.estimate, parts.estimate_rate))
    return identify_response(tip, est, rate, system.step, segment=min(100.0, 0.25 * len(tip) * system.step))


def verify(system: SystemDescription, parts: LoopParts, ctrl: AhcControllerParams, fmu_dir: str | Path,
           duration: float, progress: bool = False) -> dict:
    """Stage 3: the estimator, the controller with ``ctrl``'s gains and the winch for
    ``duration`` s; :func:`~marinefmu.analysis.scoring.ahc_scores` of the winch."""
    from ..cosim.system import SystemRunner

    keep = _upstream(system, {parts.winch})
    gains = {g: getattr(ctrl, g) for g in GAINS}
    record = [parts.tip, f"{parts.winch}.load.d", f"{parts.controller}.valid",
              *(f"{parts.winch}.{f}" for f in ("speed_limited", "acc_limited", "stroke_limited", "slack"))]
    sub = subsystem(system, keep, {parts.controller: gains})
    r = SystemRunner(sub, fmu_dir).run(system.start_time + duration, record=record, progress=progress)
    return ahc_scores(r, sub).get(parts.winch, {})


def write_gains(path: str | Path, component: str, values: dict[str, float]) -> None:
    """Set ``values`` in ``[components.<component>.parameters]`` of the scenario TOML ``path``,
    keeping everything else (comments included); the section is made if missing. The file is
    read back and checked.

    Raises
    ------
    ParameterError
        When the file has no ``[components.<component>]`` table.
    """
    import tomllib

    path = Path(path)
    lines = path.read_text(encoding="utf-8").splitlines()
    header = f"[components.{component}.parameters]"
    stamp = f"# marinefmu design-ahc, {time.strftime('%Y-%m-%d')}"

    def section_end(start: int) -> int:
        k = start + 1
        while k < len(lines) and not lines[k].lstrip().startswith("["):
            k += 1
        while k > start + 1 and not lines[k - 1].strip():
            k -= 1
        return k

    try:
        start = next(i for i, ln in enumerate(lines) if ln.strip() == header)
    except StopIteration:
        comp = next((i for i, ln in enumerate(lines) if ln.strip() == f"[components.{component}]"), None)
        if comp is None:
            raise ParameterError(f"{path}: no [components.{component}] table to write the gains into") from None
        end = section_end(comp)
        lines[end:end] = ["", header]
        start = end + 1
    for key, value in values.items():
        end = section_end(start)
        text = f"{key} = {value!r}"
        text = f"{text:<50} {stamp}"
        pattern = re.compile(rf"^\s*{re.escape(key)}\s*=")
        hit = next((i for i in range(start + 1, end) if pattern.match(lines[i])), None)
        if hit is None:
            lines.insert(end, text)
        else:
            lines[hit] = text
    new = "\n".join(lines) + "\n"
    written = tomllib.loads(new)["components"][component]["parameters"]
    if any(abs(float(written[k]) - v) > 0 for k, v in values.items()):
        raise ParameterError(f"{path}: writing the gains into [components.{component}] did not round-trip")
    path.write_text(new, encoding="utf-8")


def plot_design(result: DesignResult, winch: AhcWinchParams, out_dir: str | Path, dt: float) -> list[Path]:
    """Bode plots of the length loop, the identified estimator and the predicted residual, and
    step responses of the length loop and of the load, as PNG files in ``out_dir``."""
    import control
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    ctrl = result.design.controller
    c = control.tf([ctrl.k_p, ctrl.k_i], [1.0, 0.0])
    loop = c * winch_tf(winch)
    w = np.geomspace(0.01, 100.0, 600)
    fig, ax = plt.subplots(2, 1, figsize=(9, 6), sharex=True)
    resp = loop(1j * w)
    ax[0].loglog(w, np.abs(resp), label="length loop C P")
    ax[0].axhline(1.0, color="0.6", lw=0.8)
    ax[0].axvline(result.design.crossover, color="0.6", ls="--", lw=0.8)
    ax[1].semilogx(w, np.degrees(np.unwrap(np.angle(resp))), label="C P")
    ax[1].axhline(-180.0 + result.design.phase_margin, color="0.6", ls="--", lw=0.8,
                  label=f"phase margin {result.design.phase_margin:.0f}° at {result.design.crossover:.2f} rad/s")
    ax[0].set_ylabel("|C P|")
    ax[1].set_ylabel("phase [deg]")
    ax[1].set_xlabel("ω [rad/s]")
    ax[1].legend(fontsize=8)
    ax[0].set_title("AHC length loop (python-control)")
    paths = [out / "ahc_loop_bode.png"]
    fig.savefig(paths[-1], dpi=110, bbox_inches="tight")
    plt.close(fig)

    r = result.response
    m = r.band()
    fig, ax = plt.subplots(3, 1, figsize=(9, 8), sharex=True)
    for h, model, label in ((r.heave, r.heave_model, "heave"), (r.rate, r.rate_model, "heave rate")):
        line, = ax[0].plot(r.omega[m], np.abs(h[m]), lw=0.8, label=f"{label}, identified")
        fit = r.evaluate(model, r.omega[m])
        ax[0].plot(r.omega[m], np.abs(fit), "--", color=line.get_color(),
                   label=f"{label}, model: gain {model[0]:.4f}, delay {1000 * model[1]:.1f} ms")
        ax[1].plot(r.omega[m], np.degrees(np.angle(h[m])), lw=0.8, color=line.get_color())
        ax[1].plot(r.omega[m], np.degrees(np.angle(fit)), "--", color=line.get_color())
    ax[0].axhline(1.0, color="0.6", lw=0.8)
    ax[0].set_ylabel("|estimate / truth|")
    ax[0].legend(fontsize=7)
    ax[1].set_ylabel("phase [deg]")
    models = (r.evaluate(r.heave_model, r.omega[m]), r.evaluate(r.rate_model, r.omega[m]))
    for est, label in ((models, "with the estimator's models (predicted)"), (None, "fed the truth (predicted)")):
        ax[2].semilogy(r.omega[m], np.abs(residual_response(r.omega[m], winch, ctrl, est, dt)), label=label)
    ax[2].set_ylabel("|load / tip|")
    ax[2].set_xlabel("ω [rad/s]")
    ax[2].legend(fontsize=8)
    ax2 = ax[0].twinx()
    ax2.fill_between(r.omega[m], r.spectrum[m], color="0.85", zorder=0)
    ax2.set_yticks([])
    ax[0].set_title("identified estimator over the heave band (grey: the tip's heave spectrum)")
    paths.append(out / "ahc_estimator_bode.png")
    fig.savefig(paths[-1], dpi=110, bbox_inches="tight")
    plt.close(fig)

    t = np.linspace(0.0, 10.0, 1001)
    closed = control.feedback(loop, 1)
    fig, ax = plt.subplots(2, 1, figsize=(9, 5.5), sharex=True)
    _, y = control.step_response(closed, t)
    ax[0].plot(t, np.squeeze(y), label="wire length / reference")
    ax[0].set_ylabel("length loop step")
    _, y = control.step_response(closed * load_tf(winch), t)
    ax[1].plot(t, np.squeeze(y), label="load position / reference")
    ax[1].set_ylabel("load step")
    ax[1].set_xlabel("time [s]")
    for a in ax:
        a.axhline(1.0, color="0.6", lw=0.8)
        a.legend(fontsize=8)
    paths.append(out / "ahc_step.png")
    fig.savefig(paths[-1], dpi=110, bbox_inches="tight")
    plt.close(fig)
    return paths


def design_loop(scenario: Scenario, controller: str, fmu_dir: str | Path, out_dir: str | Path,
                identify_s: float = 420.0, verify_s: float = 600.0, phase_margin: float = 60.0,
                progress: bool = False) -> DesignResult:
    """Identify, tune, verify and plot (module docstring) for ``controller`` of ``scenario``.

    Parameters
    ----------
    scenario : Scenario
        The system.
    controller : str
        Name of its AhcController.
    fmu_dir : str or Path
        Folder of the FMUs.
    out_dir : str or Path
        Folder for the PNG files.
    identify_s, verify_s : float
        Simulated time of the identification and verification runs [s], each at least the
        estimator's start-up plus 200 s.
    phase_margin : float
        Phase margin of the length loop [deg], (0, 90).
    """
    check_range("identify_s", identify_s, lo=60.0, hi=1e5, unit="s")
    check_range("verify_s", verify_s, lo=60.0, hi=1e5, unit="s")
    check_phase_margin(phase_margin)                 # refused before anything runs
    system = scenario.system
    parts = find_loop(system, controller)
    comps = {c.name: c for c in system.components}
    winch = winch_params(comps[parts.winch].parameters)
    ctrl0 = controller_params(comps[parts.controller].parameters)
    seconds = {}
    t0 = time.perf_counter()
    resp = identify(system, parts, fmu_dir, identify_s, progress)
    seconds["identify"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    d = design(winch, phase_margin)
    tuned = replace(ctrl0, k_p=d.controller.k_p, k_i=d.controller.k_i)
    tuned = fit_feedforward(resp, winch, tuned, system.step)
    d = replace(d, controller=tuned)
    predicted = 100.0 * predicted_residual(resp, winch, tuned, system.step)
    ideal = 100.0 * predicted_residual(resp, winch, replace(tuned, k_ff=1.0), system.step, estimator=False)
    seconds["tune"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    measured = verify(system, parts, tuned, fmu_dir, verify_s, progress)
    seconds["verify"] = time.perf_counter() - t0
    result = DesignResult(d, resp, predicted, ideal, measured, seconds, [])
    t0 = time.perf_counter()
    plots = plot_design(result, winch, out_dir, system.step)
    seconds["plots"] = time.perf_counter() - t0
    return replace(result, plots=plots)
