"""VesselMotion: waves → 6-DOF motion → IMU and GNSS signals, with exact truth.

Everything is one analytic sum of sinusoids per DOF (:class:`~marinefmu.sea.vessel.MotionSeries`),
so position, velocity, acceleration, Euler angles, body rates and angular accelerations are
exact derivatives of each other, and the sensors see those plus only their configured errors.

Kinematics of a point P at body lever arm l (relative to the COG) with the reference point O
at body lever arm c (c = 0 in RAO mode, c = CR in independent-rotation mode):

.. math::
    p_n = r_O + R_{nb}(l - c),\\quad
    v_n = \\dot r_O + R_{nb}(ω × (l - c)),\\quad
    a_n = \\ddot r_O + R_{nb}(α × (l - c) + ω × (ω × (l - c)))

and the IMU reads f_b = R_nbᵀ (a_n − g_n). Translations are those of the seakeeping frame
that moves with the vessel's mean forward speed (NED axes, origin at the reference point's
mean position, mean heading north).

Motion modes (``vessel.mode``):

0. RAO response: all six DOFs from one wave realisation, referenced to the COG.
1. Independent rotations: translations of the rotation centre ``vessel.cr`` and the rotations
   are driven by two independent realisations of the same sea state (own frequencies and
   phases), so the CR's acceleration is uncorrelated with the rotations, also within one
   record (shared frequencies with independent phases would leave a sample correlation of
   ~1/√N_eff that never averages out): the known truth for paper 002's estimator.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import ParameterError, check_choice, check_int, check_vector
from ..frames import G, attitude_kinematics, rigid_point_operator, rot_nb, specific_force
from ..variables import Variable, real, resolve, vec
from .sensors import ANTENNAS, GRADE_FIGURES, IMU_GRADES, Gnss, GnssParams, Imu, ImuParams
from .vessel import PRESET_NAMES, MotionSeries, RaoTable, check_speed, load_rao_csv, preset_raos
from .waves import SPECTRA, SeaState, realise

MODES = {0: "RAO response about the COG", 1: "independent rotations about vessel.cr"}
_MEMS = IMU_GRADES["mems"]

PARAMETERS: list[Variable] = [
    real("sea.hs", 2.5, "m", "Significant wave height Hs, 0 < Hs <= 30"),
    real("sea.tp", 9.0, "s", "Peak period Tp, 1 <= Tp <= 40"),
    real("sea.gamma", 3.3, "", "JONSWAP peak enhancement factor, 1 <= gamma <= 10"),
    Variable("sea.spectrum", "string", "jonswap", "", f"Wave spectrum: one of {', '.join(SPECTRA)}"),
    real("sea.heading", math.pi, "rad", "Mean wave travel direction relative to the bow (0 following, pi head seas)"),
    real("sea.spreading", 0.0, "", "cos-2s spreading exponent s; 0 = long-crested, else 1..100"),
    Variable("sea.seed", "integer", 1, "", "Seed of the wave realisation (phases, frequencies, directions)"),
    Variable("sea.components", "integer", 200, "", "Number of regular wave components, 10..5000"),
    real("sea.omega_min", 0.0, "rad/s", "Lowest wave frequency; 0 = 0.5 x peak frequency"),
    real("sea.omega_max", 0.0, "rad/s", "Highest wave frequency; 0 = 5 x peak frequency"),
    Variable("vessel.preset", "string", "polar_supply", "", f"Built-in hull: one of {', '.join(PRESET_NAMES)}"),
    Variable("vessel.rao_file", "string", "", "", "RAO table CSV (overrides the preset's RAOs when not empty)"),
    real("vessel.speed", 0.0, "m/s", "Forward speed (encounter frequency), 0..20"),
    Variable("vessel.mode", "integer", 0, "", "0 RAO response about the COG, 1 rotations independent of translations about vessel.cr"),
    *vec("vessel.cr", "xyz", 0.0, "m", "Rotation centre for vessel.mode = 1, relative to the COG, body frame"),
    *vec("imu", "xyz", 0.0, "m", "IMU lever arm relative to the COG, body frame"),
    Variable("imu.grade", "string", "mems", "",
             f"IMU class: one of {', '.join(IMU_GRADES)}; sets imu.acc_noise, imu.gyro_noise, "
             "imu.acc_bias_instability, imu.gyro_bias_instability and imu.bias_tau, each of which, set to other than "
             "its default (the mems figure), replaces the grade's"),
    real("imu.acc_noise", _MEMS.acc_noise, "m/s2/sqrt(Hz)", "Accelerometer white-noise density, 0..1 (left at its default: imu.grade's)"),
    real("imu.gyro_noise", _MEMS.gyro_noise, "rad/s/sqrt(Hz)", "Gyro white-noise density, 0..1 (left at its default: imu.grade's)"),
    *vec("imu.acc_bias", "xyz", 0.0, "m/s2", "Accelerometer constant bias, body frame"),
    *vec("imu.gyro_bias", "xyz", 0.0, "rad/s", "Gyro constant bias, body frame"),
    real("imu.acc_bias_instability", _MEMS.acc_bias_instability, "m/s2",
         "Accelerometer Gauss-Markov bias standard deviation, 0..1 (left at its default: imu.grade's)"),
    real("imu.gyro_bias_instability", _MEMS.gyro_bias_instability, "rad/s",
         "Gyro Gauss-Markov bias standard deviation, 0..1 (left at its default: imu.grade's)"),
    real("imu.bias_tau", _MEMS.bias_tau, "s", "Gauss-Markov bias correlation time, 0.1..1e6 (left at its default: imu.grade's)"),
    Variable("sensors.seed", "integer", 1, "", "Seed of the sensor noise (IMU and GNSS streams)"),
    real("gnss.rate", 5.0, "Hz", "GNSS fix rate, 0.1..100"),
    real("gnss.sigma_h", 0.01, "m", "GNSS horizontal noise standard deviation, 0..100"),
    real("gnss.sigma_v", 0.015, "m", "GNSS vertical noise standard deviation, 0..100"),
    *[v for i, arm in enumerate(GnssParams().antennas) for v in vec(f"gnss.ant{i + 1}", "xyz", arm, "m", f"GNSS antenna {i + 1} lever arm relative to the COG, body frame")],
    real("gnss.dropout.start", 0.0, "s", "Start of the GNSS dropout window"),
    real("gnss.dropout.duration", 0.0, "s", "Length of the GNSS dropout window; 0 = none"),
    real("gnss.jump.start", 0.0, "s", "Start of the GNSS position-jump window"),
    real("gnss.jump.duration", 0.0, "s", "Length of the GNSS position-jump window; 0 = none"),
    *vec("gnss.jump", "ned", 0.0, "m", "GNSS position jump added to every antenna inside the window, NED"),
    *vec("point", "xyz", (60.0, 0.0, -10.0), "m", "Monitoring point (e.g. bow or crane tip) relative to the COG, body frame"),
]

_NED = "ned"
REAL_OUTPUTS: list[Variable] = [
    *vec("imu.acc", "xyz", 0.0, "m/s2", "Measured specific force at the IMU, body frame"),
    *vec("imu.gyro", "xyz", 0.0, "rad/s", "Measured angular rate, body frame"),
    *[v for i in range(ANTENNAS) for v in vec(f"gnss.ant{i + 1}", _NED, 0.0, "m", f"Measured position of GNSS antenna {i + 1}, NED")],
    *vec("truth.cog", _NED, 0.0, "m", "True COG position, NED (heave positive down)"),
    *vec("truth.cog_vel", _NED, 0.0, "m/s", "True COG velocity, NED"),
    *vec("truth.cog_acc", _NED, 0.0, "m/s2", "True COG acceleration, NED"),
    real("truth.roll", 0.0, "rad", "True roll angle (ZYX Euler)"),
    real("truth.pitch", 0.0, "rad", "True pitch angle (ZYX Euler)"),
    real("truth.yaw", 0.0, "rad", "True yaw angle (ZYX Euler) about the mean heading"),
    *vec("truth.rate", "xyz", 0.0, "rad/s", "True angular rate, body frame"),
    *vec("truth.ang_acc", "xyz", 0.0, "rad/s2", "True angular acceleration, body frame"),
    *vec("truth.imu", _NED, 0.0, "m", "True IMU position, NED"),
    *vec("truth.imu_vel", _NED, 0.0, "m/s", "True IMU velocity, NED"),
    *vec("truth.imu_acc", _NED, 0.0, "m/s2", "True IMU acceleration, NED"),
    *vec("truth.imu_f", "xyz", 0.0, "m/s2", "True (error-free) specific force at the IMU, body frame"),
    *vec("truth.point", _NED, 0.0, "m", "True monitoring-point position, NED"),
    *vec("truth.point_vel", _NED, 0.0, "m/s", "True monitoring-point velocity, NED"),
    *vec("truth.point_acc", _NED, 0.0, "m/s2", "True monitoring-point acceleration, NED"),
    *vec("truth.cr", "xyz", 0.0, "m", "True rotation centre relative to the COG, body frame (COG itself in vessel.mode 0)"),
    *vec("truth.acc_bias", "xyz", 0.0, "m/s2", "True total accelerometer bias, body frame"),
    *vec("truth.gyro_bias", "xyz", 0.0, "rad/s", "True total gyro bias, body frame"),
    real("truth.wave", 0.0, "m", "Wave elevation at the reference point's mean position (positive up)"),
]
BOOLEAN_OUTPUTS: list[Variable] = [
    Variable("gnss.valid", "boolean", False, "", "True when the held GNSS fix is valid (false before the first fix and in dropouts)"),
    Variable("gnss.new", "boolean", False, "", "True on the step in which a new GNSS fix arrived"),
    Variable("truth.cr.defined", "boolean", False, "", "True when the motion mode defines a rotation centre (vessel.mode = 1)"),
]
#: Index of each real output in the vector returned by :meth:`VesselMotion.step`.
REAL_INDEX = {v.name: i for i, v in enumerate(REAL_OUTPUTS)}


@dataclass(frozen=True)
class VesselMotionParams:
    """Validated parameters of the VesselMotion model (see :data:`PARAMETERS` for names)."""

    sea: SeaState = field(default_factory=SeaState)
    preset: str = "polar_supply"
    rao_file: str = ""
    speed: float = 0.0
    mode: int = 0
    cr: tuple[float, float, float] = (0.0, 0.0, 0.0)
    imu: ImuParams = field(default_factory=ImuParams)
    gnss: GnssParams = field(default_factory=GnssParams)
    point: tuple[float, float, float] = (60.0, 0.0, -10.0)
    sensor_seed: int = 1

    def __post_init__(self) -> None:
        check_choice("vessel.preset", self.preset, PRESET_NAMES)
        if not isinstance(self.rao_file, str):
            raise ParameterError(f"vessel.rao_file must be a path string, got {self.rao_file!r}")
        check_speed(self.speed)
        check_int("vessel.mode", self.mode, lo=0, hi=1)
        check_vector("vessel.cr", self.cr, unit="m")
        check_vector("point", self.point, unit="m")
        check_int("sensors.seed", self.sensor_seed, lo=0, hi=2**31 - 1)

    @classmethod
    def from_flat(cls, values: dict[str, Any]) -> "VesselMotionParams":
        """Build from FMI-named values (``{"sea.hs": 3.0, …}``); missing names take defaults.

        Raises
        ------
        ParameterError
            For an unknown name (with the closest known names) or an invalid value.
        """
        v = resolve(PARAMETERS, values, "VesselMotion")

        def xyz(p: str, axes: str = "xyz") -> tuple[float, ...]:
            return tuple(v[f"{p}.{a}"] for a in axes)

        sea = SeaState(
            hs=v["sea.hs"], tp=v["sea.tp"], gamma=v["sea.gamma"], spectrum=v["sea.spectrum"],
            heading=v["sea.heading"], spreading=v["sea.spreading"], seed=v["sea.seed"],
            n_components=v["sea.components"], omega_min=v["sea.omega_min"], omega_max=v["sea.omega_max"],
        )
        imu = ImuParams.from_grade(v["imu.grade"], lever_arm=xyz("imu"), acc_bias=xyz("imu.acc_bias"),
                                   gyro_bias=xyz("imu.gyro_bias"), **grade_overrides(v))
        gnss = GnssParams(
            antennas=tuple(xyz(f"gnss.ant{i + 1}") for i in range(ANTENNAS)), rate=v["gnss.rate"],
            sigma_h=v["gnss.sigma_h"], sigma_v=v["gnss.sigma_v"],
            dropout_start=v["gnss.dropout.start"], dropout_duration=v["gnss.dropout.duration"],
            jump_start=v["gnss.jump.start"], jump_duration=v["gnss.jump.duration"], jump=xyz("gnss.jump", "ned"),
        )
        return cls(sea=sea, preset=v["vessel.preset"], rao_file=v["vessel.rao_file"], speed=v["vessel.speed"],
                   mode=v["vessel.mode"], cr=xyz("vessel.cr"), imu=imu, gnss=gnss, point=xyz("point"),
                   sensor_seed=v["sensors.seed"])


def grade_overrides(values: dict[str, Any]) -> dict[str, float]:
    """The ``imu.*`` error figures of ``values`` (FMI names) that replace those of ``imu.grade``:
    each set to other than its default, the ``mems`` figure (an FMI parameter cannot tell "set"
    from "left at its default", so a figure equal to the mems one keeps the grade's; to mix that
    figure with another grade's, set ``imu.grade = mems`` and all five)."""
    defaults = {v.name: v.default for v in PARAMETERS}
    return {f: values[f"imu.{f}"] for f in GRADE_FIGURES if values.get(f"imu.{f}", defaults[f"imu.{f}"]) != defaults[f"imu.{f}"]}


@dataclass(frozen=True)
class RigidBodyState:
    """Exact rigid-body state at one time.

    Attributes
    ----------
    pos, vel, acc : numpy.ndarray
        (3,) reference-point position [m], velocity [m/s], acceleration [m/s²], NED.
    euler : list of float
        Roll, pitch, yaw [rad].
    rot : numpy.ndarray
        (3, 3) R_nb.
    rate, ang_acc : list of float
        Body angular rate [rad/s] and angular acceleration [rad/s²].
    wave : float
        Wave elevation at the reference point's mean position [m, up].
    """

    pos: np.ndarray
    vel: np.ndarray
    acc: np.ndarray
    euler: list[float]
    rot: np.ndarray
    rate: list[float]
    ang_acc: list[float]
    wave: float

    def points(self, arms: np.ndarray) -> np.ndarray:
        """(k, 9) NED position [m], velocity [m/s] and acceleration [m/s²] of body points.

        Parameters
        ----------
        arms : numpy.ndarray
            (k, 3) lever arms from the reference point, body frame [m].
        """
        body = arms @ rigid_point_operator(self.rate, self.ang_acc).T  # (k, 9): l, ω×l, α×l+ω×(ω×l)
        n = (body.reshape(-1, 3) @ self.rot.T).reshape(-1, 9)
        n[:, 0:3] += self.pos
        n[:, 3:6] += self.vel
        n[:, 6:9] += self.acc
        return n


class VesselMotion:
    """The in-process VesselMotion model: call :meth:`step` with the end time of each step.

    Parameters
    ----------
    params : VesselMotionParams
        Validated parameters; the RAO file (if any) is read here.

    Notes
    -----
    Cost per step: one complex exponential per wave component and one matrix-vector product
    give all 19 DOF values (:meth:`MotionSeries.at`); two small products with the arms'
    operator and R_nb give the COG, IMU and point, and one more the specific force. These are
    the numpy calls of :meth:`rigid_body`, :meth:`RigidBodyState.points` and
    :func:`~marinefmu.frames.specific_force`, on operands of the same layout, so the outputs are
    theirs bit for bit (the products use the BLAS's fused multiply-adds, which Python floats
    cannot repeat); they write into arrays made once, and the sums, the IMU's errors and the
    output list are on Python floats. The antennas are computed only at GNSS epochs.

    Examples
    --------
    >>> m = VesselMotion(VesselMotionParams())
    >>> y = m.step(0.01, 0.01)          # outputs at t = 0.01 s, ordered as REAL_OUTPUTS
    >>> y[REAL_INDEX["truth.cog.d"]]    # heave of the COG [m, down]  # doctest: +SKIP
    """

    def __init__(self, params: VesselMotionParams) -> None:
        self.params = params
        table: RaoTable = load_rao_csv(params.rao_file) if params.rao_file else preset_raos(params.preset, params.speed)
        self.waves = realise(params.sea)
        rot_waves = realise(params.sea, stream=1) if params.mode == 1 else None
        self.series = MotionSeries.build(table, self.waves, params.speed, rot_waves)
        self.cr = np.array(params.cr if params.mode == 1 else (0.0, 0.0, 0.0))
        ant = np.array(params.gnss.antennas, dtype=float)
        # lever arms from the reference point: COG, IMU, point (per step) and antennas (per fix)
        self._arms = np.array([[0.0, 0.0, 0.0], params.imu.lever_arm, params.point]) - self.cr
        self._ant_arms = ant - self.cr
        self._cr_out = self.cr.copy()
        self._cr_list: list[float] = self._cr_out.tolist()
        self._buffers()
        self.reset()

    def _buffers(self) -> None:
        """Work arrays of the per-step path, made once (their contents never outlive a step)."""
        self._coef, self._omega_e = self.series.coef, self.series.omega_e
        self._arg = np.zeros(self._omega_e.size, dtype=complex)  # i ω_e t: real part 0
        self._arg_imag = self._arg.imag
        self._phasor = np.empty_like(self._arg)
        self._x = np.empty(self._coef.shape[0], dtype=complex)
        self._x_real = self._x.real
        self._body = np.empty((len(self._arms), 9))
        self._body_rows = self._body.reshape(-1, 3)
        self._arms_n = np.empty_like(self._body_rows)
        self._acc_minus_g = np.empty(3)
        self._f_imu = np.empty(3)
        self._op = rigid_point_operator([0.0, 0.0, 0.0], [0.0, 0.0, 0.0])  # identity rows stay
        self._op_flat = self._op.reshape(-1)
        self._op_t = self._op.T

    def _point_operator(self, w: list[float], a: list[float]) -> np.ndarray:
        """:func:`~marinefmu.frames.rigid_point_operator` ``(w, a).T``, its entries written into
        an array made once (building the (9, 3) array from lists costs more than the product)."""
        wx, wy, wz = w
        ax, ay, az = a
        o = self._op_flat
        o[10], o[11], o[12], o[14], o[15], o[16] = -wz, wy, wz, -wx, -wy, wx
        o[18], o[19], o[20] = -wy * wy - wz * wz, wx * wy - az, wx * wz + ay
        o[21], o[22], o[23] = wx * wy + az, -wx * wx - wz * wz, wy * wz - ax
        o[24], o[25], o[26] = wx * wz - ay, wy * wz + ax, -wx * wx - wy * wy
        return self._op_t

    def reset(self) -> None:
        """Return to t = 0 with freshly seeded sensor noise."""
        imu_seed, gnss_seed = np.random.SeedSequence(self.params.sensor_seed).spawn(2)
        self.imu = Imu(self.params.imu, np.random.default_rng(imu_seed))
        self.gnss = Gnss(self.params.gnss, np.random.default_rng(gnss_seed))
        self.gnss_new = False
        self._gnss_out: list[float] = self.gnss.positions.tolist()

    def rigid_body(self, t: float) -> RigidBodyState:
        """Exact rigid-body state of the reference point at time ``t`` [s]."""
        x = self.series.at(t)
        xl = x.tolist()
        rot, rate, ang_acc = attitude_kinematics(xl[3:6], xl[9:12], xl[15:18])
        return RigidBodyState(x[0:3], x[6:9], x[12:15], xl[3:6], rot, rate, ang_acc, xl[18])

    def antenna_positions(self, t: float) -> np.ndarray:
        """(12,) true antenna positions at ``t`` [s], NED [m], ant1 (n, e, d), ant2, …"""
        s = self.rigid_body(t)
        return (s.pos + self._ant_arms @ s.rot.T).ravel()

    def step(self, t: float, dt: float) -> list[float]:
        """Advance the sensors by ``dt`` [s] and return the real outputs at time ``t`` [s].

        Returns
        -------
        list of float
            Values ordered as :data:`REAL_OUTPUTS`; booleans are in :meth:`boolean_outputs`.
        """
        return self._outputs(t, dt)

    def peek(self, t: float) -> list[float]:
        """Outputs at ``t`` [s] without advancing the sensors (IMU = truth + current bias, no
        white noise; GNSS unchanged). Used for the values an FMU shows after initialisation."""
        return self._outputs(t, None)

    def _outputs(self, t: float, dt: float | None) -> list[float]:
        # The sum of sinusoids and the three products with R_nb and the arms' operator are the
        # operations of rigid_body(), RigidBodyState.points() and specific_force() (same numpy
        # calls on operands of the same layout), into buffers made in _buffers(); the sums
        # and the sensors' arithmetic are on Python floats, elementwise as before.
        np.multiply(self._omega_e, t, out=self._arg_imag)
        np.exp(self._arg, out=self._phasor)
        np.matmul(self._coef, self._phasor, out=self._x)
        x = self._x_real.tolist()
        euler = x[3:6]
        rot, rate, ang_acc = attitude_kinematics(euler, x[9:12], x[15:18])
        np.matmul(self._arms, self._point_operator(rate, ang_acc), out=self._body)
        np.matmul(self._body_rows, rot.T, out=self._arms_n)
        n = self._arms_n.tolist()  # rows: (offset, velocity, acceleration) of COG, IMU, point
        p0, p1, p2, v0, v1, v2, a0, a1, a2 = x[0], x[1], x[2], x[6], x[7], x[8], x[12], x[13], x[14]
        pts = []
        for i in (0, 3, 6):
            r, v, a = n[i], n[i + 1], n[i + 2]
            pts.append([r[0] + p0, r[1] + p1, r[2] + p2, v[0] + v0, v[1] + v1, v[2] + v2, a[0] + a0, a[1] + a1, a[2] + a2])
        imu = pts[1]
        d = self._acc_minus_g
        d[0], d[1], d[2] = imu[6], imu[7], imu[8] - G  # a_n − g_n
        np.matmul(rot.T, d, out=self._f_imu)
        f_imu = self._f_imu.tolist()
        bias = self.imu.bias_values()
        if dt is None:
            meas = [f_imu[0] + bias[0], f_imu[1] + bias[1], f_imu[2] + bias[2],
                    rate[0] + bias[3], rate[1] + bias[4], rate[2] + bias[5]]
        else:
            meas = self.imu.measure_values(f_imu, rate, dt)
            bias = self.imu.bias_values()
            k = self.gnss.epoch_due(t)
            self.gnss_new = k is not None
            if k is not None:
                self.gnss.measure(k, self.antenna_positions(k / self.params.gnss.rate))
                self._gnss_out = self.gnss.positions.tolist()
        return [*meas, *self._gnss_out, *pts[0], *euler, *rate, *ang_acc, *imu, *f_imu, *pts[2],
                *self._cr_list, *bias, x[18]]

    def boolean_outputs(self) -> list[bool]:
        """Values ordered as :data:`BOOLEAN_OUTPUTS`."""
        return [self.gnss.valid, self.gnss_new, self.params.mode == 1]

    def get_state(self) -> dict:
        """JSON-serialisable sensor state (the motion itself is a function of time)."""
        return {"imu": self.imu.get_state(), "gnss": self.gnss.get_state(), "gnss_new": self.gnss_new}

    def set_state(self, state: dict) -> None:
        """Restore a state from :meth:`get_state`."""
        self.imu.set_state(state["imu"])
        self.gnss.set_state(state["gnss"])
        self.gnss_new = bool(state["gnss_new"])
        self._gnss_out = self.gnss.positions.tolist()


def simulate_record(params: VesselMotionParams, duration: float, dt: float = 0.01) -> dict[str, np.ndarray]:
    """Run the in-process model and return every output as a named array.

    Parameters
    ----------
    params : VesselMotionParams
        Model parameters.
    duration : float
        Record length [s]; samples at t_k = (k + 1)·dt.
    dt : float
        Step [s].

    Returns
    -------
    dict of numpy.ndarray
        (N,) arrays keyed by the FMU output names of :data:`REAL_OUTPUTS` and
        :data:`BOOLEAN_OUTPUTS` (``"imu.acc.x"``, ``"truth.roll"``, ``"gnss.valid"``, …).
    """
    model = VesselMotion(params)
    n = int(round(duration / dt))
    y = np.empty((n, len(REAL_OUTPUTS)))
    flags = np.empty((n, len(BOOLEAN_OUTPUTS)), dtype=bool)
    for k in range(n):
        y[k] = model.step((k + 1) * dt, dt)
        flags[k] = model.boolean_outputs()
    out = {v.name: y[:, i] for i, v in enumerate(REAL_OUTPUTS)}
    out.update({v.name: flags[:, i] for i, v in enumerate(BOOLEAN_OUTPUTS)})
    return out


def stack(record: dict[str, np.ndarray], prefix: str, axes: Any = "xyz") -> np.ndarray:
    """(N, len(axes)) array of the outputs ``prefix.axis`` of a :func:`simulate_record` record,
    e.g. ``stack(rec, "imu.acc")`` or ``stack(rec, "truth", ("roll", "pitch", "yaw"))``."""
    return np.column_stack([record[f"{prefix}.{a}"] for a in axes])


def point_truth(record: dict[str, np.ndarray], arm: Any) -> tuple[np.ndarray, np.ndarray]:
    """True position and velocity [m], [m/s] (N, 3) of the point at ``arm`` [m] from the IMU
    (body frame) in a :func:`simulate_record` record's NED, whose north is the mean heading:
    surge, sway, heave of the vessel's level frame. p = p_imu + R_nb r, v = v_imu + R_nb (ω × r)."""
    r = np.asarray(arm, dtype=float)
    rots = np.array([rot_nb(*a) for a in stack(record, "truth", ("roll", "pitch", "yaw"))])
    rate = stack(record, "truth.rate")
    pos = stack(record, "truth.imu", "ned") + rots @ r
    vel = stack(record, "truth.imu_vel", "ned") + np.einsum("nij,nj->ni", rots, np.cross(rate, r))
    return pos, vel
