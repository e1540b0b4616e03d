"""Accuracy of the estimator components of a system run against a VesselMotion component's truth.

Each estimator is scored from ``settle`` s after its ``valid`` output first went true, on the
samples where it is valid, against the matching ``truth.*`` outputs recorded in the same run:

=========================  ====================================================================
FMU                         metrics (RMS errors)
=========================  ====================================================================
AttitudeEstimator           ``roll_deg``, ``pitch_deg`` (truth.roll, truth.pitch)
GnssAccFusion               ``pos_n_cm``, ``pos_e_cm``, ``pos_d_cm`` (truth.cog); with the
                            antenna positions and ``gnss.new`` recorded, ``raw_gnss_*_cm``: the
                            COG fixed from the antennas alone at each epoch
HeaveObserver               ``heave_cm`` (truth.imu.d), ``point_heave_cm`` (truth.point.d), each
                            about its mean over the scored span as the observer has no mean;
                            ``heave_std_cm``, ``point_heave_std_cm`` of the truth for scale
DisplacementReconstructor   ``disp_n_cm``, ``disp_e_cm``, ``disp_d_cm``: its output (the window
                            centre) against truth.cog ``delay`` s earlier, each about its
                            mean (a reconstruction from acceleration has no absolute position)
CentreOfRotation            ``cr_x_m``, ``cr_y_m``, ``cr_z_m`` (truth.cr, when the vessel runs in
                            the independent-rotation-centre mode and ``truth.cr.defined``)
MotionReferenceUnit         ``roll_deg``, ``pitch_deg`` (truth.roll, truth.pitch; from ``valid``);
                            from ``motion.valid``: ``surge_cm``, ``sway_cm``, ``heave_cm`` at the
                            IMU (truth.imu.n/e/d), ``delayed_surge_cm`` … (its ``delayed.*``
                            against the truth ``delayed.delay`` s earlier), ``*_std_cm`` of the
                            truth; and the same with a ``point_`` prefix for the monitoring
                            point whose lever arm is the vessel's point relative to its IMU
                            (:func:`mru_point`), with ``point_3d_cm`` (the RMS length of the
                            error vector) and ``point_distance_m`` (the lever arm's length)
=========================  ====================================================================

The MotionReferenceUnit's surge, sway and heave are in its vessel-level frame (north along its
mean heading), VesselMotion's truth in its NED (north along the vessel's mean heading): the same
frame but for the unit's error in the mean heading, which is part of its error. All its
positions are scored about their means (the filters have no output at zero frequency).

AhcWinch components are scored together, on one span: from ``settle`` s after the
last AhcController of the system first reports ``valid`` (full compensation) to the end, so the
winches of one run are compared on the same waves. Per winch: ``tip_heave_cm`` and
``load_heave_cm``, the standard deviations of the crane tip (the source of the winch's
``tip.d``) and of the load in the heave band, and ``residual_pct`` = 100 × their ratio;
``tip_motion_cm``, ``load_motion_cm`` and ``residual_total_pct`` the same over all
frequencies; ``limited_pct``, the percentage of steps with any limit flag set, and
``speed_limited_pct``, ``acc_limited_pct``, ``stroke_limited_pct``, ``slack_pct`` per flag.
**Heave** is the vertical motion at periods shorter than 2π/:data:`~marinefmu.frames.HEAVE_CUTOFF` = 31 s (wave
periods at sea are 3-25 s; slower vertical motion, such as a drift of the attitude input times
a lever arm, is not heave and is not what heave compensation is for), taken with a zero-phase
4th-order Butterworth high pass (``scipy.signal.sosfiltfilt``: no phase error in the band).
A winch whose controller is fed by a heave estimator (HeaveObserver, not ``model =
"highpass"``) also gets ``vs_ideal`` and ``vs_classical``: its ``residual_pct`` over that of
the winch fed by a VesselMotion's truth and of the one fed by the classical estimator
(``model = "highpass"``), when the system has them.

Every estimator also gets ``valid_fraction`` (of the whole run) and ``scored_s`` (the length of
the span scored [s]). Other components, and metrics whose fields were not recorded, are left out.
The estimator's lever arms must match the vessel's (a HeaveObserver's ``point`` is the vessel's
point relative to its IMU), as in the built-in scenario ``system``.
"""
from __future__ import annotations

import math

import numpy as np

from ..cosim.ssp import SystemDescription
from ..frames import HEAVE_CUTOFF
#: The winch's limit flags, scored as percentages of time.
LIMIT_FLAGS = ("speed_limited", "acc_limited", "stroke_limited", "slack")
#: Every metric :func:`score` can give, per FMU (module docstring); which ones a run gives
#: depends on what it recorded.
METRICS: dict[str, tuple[str, ...]] = {
    "AttitudeEstimator": ("roll_deg", "pitch_deg"),
    "GnssAccFusion": ("pos_n_cm", "pos_e_cm", "pos_d_cm", "raw_gnss_n_cm", "raw_gnss_e_cm", "raw_gnss_d_cm"),
    "HeaveObserver": ("heave_cm", "heave_std_cm", "point_heave_cm", "point_heave_std_cm"),
    "DisplacementReconstructor": ("disp_n_cm", "disp_e_cm", "disp_d_cm"),
    "CentreOfRotation": ("cr_x_m", "cr_y_m", "cr_z_m"),
    "MotionReferenceUnit": ("roll_deg", "pitch_deg",
                            *(f"{p}{d}{a}_{u}" for p in ("", "point_") for d, u in (("", "cm"), ("", "std_cm"), ("delayed_", "cm"))
                              for a in ("surge", "sway", "heave")), "point_3d_cm", "point_distance_m"),
    "AhcWinch": ("tip_heave_cm", "load_heave_cm", "residual_pct", "tip_motion_cm", "load_motion_cm",
                 "residual_total_pct", "limited_pct", *(f"{n}_pct" for n in LIMIT_FLAGS), "vs_ideal", "vs_classical"),
}
#: Metrics of every scored component.
COMMON_METRICS = ("valid_fraction", "scored_s")


def _rms(e: np.ndarray) -> float:
    return float(np.sqrt(np.mean(e ** 2))) if e.size else math.nan


def _about_mean(x: np.ndarray) -> np.ndarray:
    return x - x.mean() if x.size else x


def _span(result: np.ndarray, comp: str, settle: float, flag: str = "valid") -> np.ndarray:
    """Boolean mask: ``comp.flag`` true, and at least ``settle`` s after it first went true."""
    valid = np.array(result[f"{comp}.{flag}"], dtype=bool)   # a copy: the result may be a read-only memory map
    if not valid.any():
        return valid
    t = np.asarray(result["time"], dtype=float)
    return valid & (t >= t[np.argmax(valid)] + settle)


def _raw_gnss(result: np.ndarray, comp, vessel: str, antennas: list[str], span: np.ndarray) -> dict[str, float]:
    """RMS error [cm] per NED axis of the COG fixed from the raw antenna positions alone
    (:func:`~marinefmu.estimators.gnss_fusion.antenna_attitude.antenna_attitude` with the
    fusion's lever arms) at the GNSS epochs in ``span``: the yardstick of the project goal for
    the fusion, fused error ≤ 0.5 × raw."""
    from ..estimators.gnss_fusion.antenna_attitude import DEFAULT_ANTENNAS, antenna_attitude

    arms = np.array([[float(comp.parameters.get(f"ant{i + 1}.{a}", DEFAULT_ANTENNAS[i][j])) for j, a in enumerate("xyz")]
                     for i in range(4)])
    epochs = np.flatnonzero(np.asarray(result[f"{vessel}.gnss.new"], dtype=bool) & span)
    pos = np.column_stack([np.asarray(result[n], dtype=float) for n in antennas])
    err = []
    for k in epochs:
        fix = antenna_attitude(pos[k], arms)
        if not isinstance(fix, str):
            err.append(fix.cog - [float(result[f"{vessel}.truth.cog.{a}"][k]) for a in "ned"])
    e = np.array(err).reshape(-1, 3)
    return {f"raw_gnss_{a}_cm": 100.0 * _rms(e[:, i]) for i, a in enumerate("ned")}


def score(result: np.ndarray, system: SystemDescription, vessel: str, settle: float = 60.0,
          delay: int = 1) -> dict[str, dict[str, float]]:
    """Metrics of every estimator component of ``system`` (module docstring).

    Parameters
    ----------
    result : numpy.ndarray
        Structured array of :meth:`~.cosim.system.SystemRunner.run` (``time`` and
        ``component.variable`` fields).
    system : SystemDescription
        The system that produced it (component FMU types come from the sources).
    vessel : str
        Name of the VesselMotion component whose truth is the reference.
    settle : float
        Time after ``valid`` first went true that is not scored [s].
    delay : int
        Communication delay [base steps] between the vessel and the estimators: under Jacobi
        coupling (both runners) an estimator fed by the vessel outputs at t_{k+1} what it
        computed from the vessel's outputs at t_k, so its output is compared with the truth
        ``delay`` rows earlier (0 for records where estimates and truth share their time).

    Returns
    -------
    dict
        Component name -> metric name -> value.
    """
    fields = set(result.dtype.names)
    t = np.asarray(result["time"], dtype=float)

    def has(*names: str) -> bool:
        return all(n in fields for n in names)

    def f(name: str) -> np.ndarray:
        x = np.asarray(result[name], dtype=float)
        if delay and name.startswith(f"{vessel}.truth."):   # the truth at the estimates' time
            x = np.concatenate([np.full(delay, np.nan), x[:-delay]])
        return x

    out: dict[str, dict[str, float]] = {}
    for comp in system.components:
        kind = comp.kind
        if f"{comp.name}.valid" not in fields or comp.name == vessel or kind == "AhcWinch":
            continue
        m = _span(result, comp.name, settle)
        m[:delay] = False
        row = {"valid_fraction": float(np.mean(np.asarray(result[f"{comp.name}.valid"], dtype=bool))),
               "scored_s": float(np.sum(m) * (t[1] - t[0])) if len(t) > 1 else 0.0}
        c, v = comp.name, vessel
        if kind == "AttitudeEstimator" and has(f"{c}.roll", f"{v}.truth.roll"):
            for a in ("roll", "pitch"):
                row[f"{a}_deg"] = math.degrees(_rms(f(f"{c}.{a}")[m] - f(f"{v}.truth.{a}")[m]))
        elif kind == "GnssAccFusion" and has(f"{c}.pos.n", f"{v}.truth.cog.n"):
            for a in "ned":
                row[f"pos_{a}_cm"] = 100.0 * _rms(f(f"{c}.pos.{a}")[m] - f(f"{v}.truth.cog.{a}")[m])
            antennas = [f"{v}.gnss.ant{i}.{a}" for i in range(1, 5) for a in "ned"]
            if has(*antennas, f"{v}.gnss.new"):
                row.update(_raw_gnss(result, comp, v, antennas, m))
        elif kind == "HeaveObserver" and has(f"{c}.heave", f"{v}.truth.imu.d"):
            truth = f(f"{v}.truth.imu.d")[m]
            row["heave_cm"] = 100.0 * _rms(f(f"{c}.heave")[m] - _about_mean(truth))
            row["heave_std_cm"] = 100.0 * float(np.std(truth)) if truth.size else math.nan
            if has(f"{c}.point.heave", f"{v}.truth.point.d"):
                point = f(f"{v}.truth.point.d")[m]
                row["point_heave_cm"] = 100.0 * _rms(f(f"{c}.point.heave")[m] - _about_mean(point))
                row["point_heave_std_cm"] = 100.0 * float(np.std(point)) if point.size else math.nan
        elif kind == "DisplacementReconstructor" and has(f"{c}.disp.d", f"{c}.delay", f"{v}.truth.cog.d"):
            lag = int(round(float(f(f"{c}.delay")[-1]) / (t[1] - t[0]))) if len(t) > 1 else 0
            k = np.flatnonzero(m)
            k = k[k >= lag]
            for a in "ned":
                truth = f(f"{v}.truth.cog.{a}")[k - lag]
                est = f(f"{c}.disp.{a}")[k]
                row[f"disp_{a}_cm"] = 100.0 * _rms(_about_mean(est) - _about_mean(truth))
        elif (kind == "CentreOfRotation" and has(f"{c}.cr.x", f"{v}.truth.cr.x", f"{v}.truth.cr.defined")
              and np.asarray(result[f"{v}.truth.cr.defined"], dtype=bool).any()):
            m &= np.asarray(result[f"{v}.truth.cr.defined"], dtype=bool)
            for a in "xyz":
                row[f"cr_{a}_m"] = _rms(f(f"{c}.cr.{a}")[m] - f(f"{v}.truth.cr.{a}")[m])
        elif kind == "MotionReferenceUnit" and has(f"{c}.roll", f"{v}.truth.roll"):
            for a in ("roll", "pitch"):
                row[f"{a}_deg"] = math.degrees(_rms(f(f"{c}.{a}")[m] - f(f"{v}.truth.{a}")[m]))
            if has(f"{c}.motion.valid"):
                mm = _span(result, c, settle, "motion.valid")
                mm[:delay] = False
                point = mru_point(system, c, v)
                for prefix, out_prefix, truth in (("", "", "imu"), (point, "point_", "point")):
                    if prefix is not None and has(f"{c}.{prefix}heave", f"{v}.truth.{truth}.d"):
                        row.update(_mru_location(f, t, mm, f"{c}.{prefix}", f"{v}.truth.{truth}", out_prefix,
                                                 f"{c}.delayed.delay" if has(f"{c}.delayed.delay") else None))
                if "point_surge_cm" in row:
                    row["point_distance_m"] = float(np.linalg.norm(mru_arm(system, c, point)))
        out[comp.name] = row
    out.update(ahc_scores(result, system, settle))
    return out


_MRU_AXES = (("surge", "n"), ("sway", "e"), ("heave", "d"))


def _mru_location(f, t: np.ndarray, m: np.ndarray, est: str, truth: str, prefix: str, delay_name: str | None
                  ) -> dict[str, float]:
    """A MotionReferenceUnit's metrics [cm] at one location (module docstring): ``est`` is the
    output prefix (``mru.`` or ``mru.mp1.``), ``truth`` the VesselMotion position prefix,
    ``f`` the field reader of :func:`score` (the truth at the estimates' time)."""
    row: dict[str, float] = {}
    err3 = []
    for axis, ned in _MRU_AXES:
        tr = f(f"{truth}.{ned}")[m]
        e = _about_mean(f(f"{est}{axis}")[m] - tr)
        err3.append(e)
        row[f"{prefix}{axis}_cm"] = 100.0 * _rms(e)
        row[f"{prefix}{axis}_std_cm"] = 100.0 * float(np.std(tr)) if tr.size else math.nan
    if prefix:
        row[f"{prefix}3d_cm"] = 100.0 * _rms(np.sqrt(sum(e ** 2 for e in err3)))
    if delay_name is not None and len(t) > 1:
        valid = np.flatnonzero(m)
        if valid.size:
            lag = int(round(float(f(delay_name)[valid[-1]]) / (t[1] - t[0])))
            k = valid[valid >= lag]
            for axis, ned in _MRU_AXES:
                e = f(f"{est}delayed.{axis}")[k] - f(f"{truth}.{ned}")[k - lag]
                row[f"{prefix}delayed_{axis}_cm"] = 100.0 * _rms(_about_mean(e))
    return row


def mru_arm(system: SystemDescription, comp: str, prefix: str) -> np.ndarray:
    """Lever arm [m] of a MotionReferenceUnit's monitoring point ``prefix`` (``mp<i>.``)."""
    params = next(c for c in system.components if c.name == comp).parameters
    return np.array([float(params.get(f"{prefix}{a}", 0.0)) for a in "xyz"])


def mru_point(system: SystemDescription, comp: str, vessel: str, tol: float = 1e-6) -> str | None:
    """The output prefix (``mp<i>.``) of the first enabled monitoring point of the
    MotionReferenceUnit ``comp`` that sits at the VesselMotion ``vessel``'s point (its lever
    arm equals the vessel's ``point`` minus its ``imu``, within ``tol`` m, body frame), or None.
    Unset vessel parameters take VesselMotion's defaults."""
    from ..estimators.mru.params import MAX_POINTS
    from ..sea.motion_model import PARAMETERS

    defaults = {p.name: p.default for p in PARAMETERS}
    vp = {**defaults, **next(c for c in system.components if c.name == vessel).parameters}
    target = np.array([float(vp[f"point.{a}"]) - float(vp[f"imu.{a}"]) for a in "xyz"])
    params = next(c for c in system.components if c.name == comp).parameters
    for i in range(1, MAX_POINTS + 1):
        prefix = f"mp{i}."
        if params.get(f"{prefix}enabled") and np.all(np.abs(mru_arm(system, comp, prefix) - target) <= tol):
            return prefix
    return None


def _source(system: SystemDescription, comp: str, var: str) -> tuple[str, str] | None:
    """(component, variable) feeding input ``comp.var``, or None."""
    for c in system.connections:
        if c.end == comp and c.end_var == var:
            return c.start, c.start_var
    return None


def _heave_band(x: np.ndarray, dt: float) -> np.ndarray:
    """``x`` without its content below :data:`HEAVE_CUTOFF` (zero phase), about its mean."""
    from scipy import signal

    sos = signal.butter(4, HEAVE_CUTOFF, btype="highpass", fs=2.0 * math.pi / dt, output="sos")
    return signal.sosfiltfilt(sos, x - x.mean())


def ahc_scores(result: np.ndarray, system: SystemDescription, settle: float = 60.0) -> dict[str, dict[str, float]]:
    """Metrics of every AhcWinch of ``system`` on one span (module docstring); {} without one.

    Parameters
    ----------
    result : numpy.ndarray
        Structured array of a run recording each winch's ``load.d`` and limit flags, the source
        of its ``tip.d`` and the AhcControllers' ``valid``.
    system : SystemDescription
        The system that produced it.
    settle : float
        Time after the last controller first reports ``valid`` that is not scored [s].
    """
    fields = set(result.dtype.names)
    kinds = {c.name: c for c in system.components}
    winches = [c.name for c in system.components if c.kind == "AhcWinch" and f"{c.name}.load.d" in fields]
    if not winches:
        return {}
    t = np.asarray(result["time"], dtype=float)
    dt = t[1] - t[0]
    start = t[0]
    for c in system.components:
        if c.kind == "AhcController" and f"{c.name}.valid" in fields:
            valid = np.asarray(result[f"{c.name}.valid"], dtype=bool)
            start = max(start, t[np.argmax(valid)] if valid.any() else math.inf)
    span = t >= start + settle
    if span.sum() < 10:
        return {w: {"scored_s": 0.0} for w in winches}
    out: dict[str, dict[str, float]] = {}
    feeds: dict[str, str] = {}
    for w in winches:
        tip_src = _source(system, w, "tip.d")
        load = np.asarray(result[f"{w}.load.d"], dtype=float)[span]
        row: dict[str, float] = {"scored_s": float(span.sum() * dt)}
        if tip_src is not None and ".".join(tip_src) in fields:
            tip = np.asarray(result[".".join(tip_src)], dtype=float)[span]
            row["tip_heave_cm"] = 100.0 * float(np.std(_heave_band(tip, dt)))
            row["load_heave_cm"] = 100.0 * float(np.std(_heave_band(load, dt)))
            row["residual_pct"] = 100.0 * row["load_heave_cm"] / row["tip_heave_cm"]
            row["tip_motion_cm"] = 100.0 * float(np.std(tip))
            row["load_motion_cm"] = 100.0 * float(np.std(load))
            row["residual_total_pct"] = 100.0 * row["load_motion_cm"] / row["tip_motion_cm"]
        flags = [n for n in LIMIT_FLAGS if f"{w}.{n}" in fields]
        if flags:
            hit = np.zeros(int(span.sum()), dtype=bool)
            for n in flags:
                x = np.asarray(result[f"{w}.{n}"], dtype=bool)[span]
                row[f"{n}_pct"] = 100.0 * float(np.mean(x))
                hit |= x
            row["limited_pct"] = 100.0 * float(np.mean(hit))
        ctrl = _source(system, w, "command")
        heave = _source(system, ctrl[0], "heave") if ctrl and ctrl[0] in kinds else None
        if heave is not None and heave[0] in kinds:
            feeder = kinds[heave[0]]
            if feeder.kind == "VesselMotion":
                feeds[w] = "truth"
            elif feeder.kind == "HeaveObserver":
                feeds[w] = "classical" if feeder.parameters.get("model") == "highpass" else "observer"
            elif feeder.kind == "MotionReferenceUnit":
                feeds[w] = "mru"
        out[w] = row
    for w, feed in feeds.items():
        if feed in ("observer", "mru") and "residual_pct" in out[w]:
            for other, key in (("truth", "vs_ideal"), ("classical", "vs_classical"), ("observer", "vs_observer")):
                if other == feed:
                    continue
                ref = [out[o]["residual_pct"] for o, f in feeds.items() if f == other and "residual_pct" in out[o]]
                if ref:
                    out[w][key] = out[w]["residual_pct"] / ref[0]
    return out
