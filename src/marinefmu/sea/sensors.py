"""Sensor models: a strapdown IMU at a lever arm and multi-antenna GNSS.

IMU errors per axis: white noise of density N [unit/√Hz] (per-sample standard deviation
N/√Δt, i.e. band-limited to the sample rate), a constant bias, and a first-order
Gauss–Markov bias (bias instability) with stationary standard deviation σ_b and correlation
time τ, discretised exactly: b_{k+1} = φ b_k + σ_b √(1−φ²) w_k, φ = e^{−Δt/τ}. The
Gauss–Markov state starts from its stationary distribution, so the bias is present at t = 0.

Sensor grades (:data:`IMU_GRADES`): the five random-error figures of three classes of unit,
``mems`` (the defaults: accelerometer 0.0007 m/s²/√Hz, bias 0.0005 m/s²; gyro 5e-5 rad/s/√Hz,
bias 5e-5 rad/s; bias correlation time 50 s), ``tactical`` and ``mru``; each grade's sources
are in its ``source``. A datasheet's figures map onto the model as: noise density N = angle
random walk [°/√h] / 60 (gyro, then to rad/s/√Hz) or velocity random walk [m/s/√h] / 60
(accelerometer); the Gauss–Markov σ_b = the in-run bias stability (bias instability); τ = the
averaging time at which the class's Allan deviation reaches that floor.

GNSS: each antenna reports its NED position at epochs t_k = k / rate with independent white
noise σ_h (north, east) and σ_v (down), default RTK 1 cm / 1.5 cm; an optional dropout window
(no fixes, ``valid`` false, last fix held) and an optional position jump (a constant offset
added to all antennas inside a window, like the DGPS jumps of 10-65 m that paper 000 cites).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import ParameterError, check_choice, check_range, check_vector

ANTENNAS = 4

#: Conversions for the grades' sources: 1 µg [m/s²], 1 °/h [rad/s], and an angle random walk of
#: 1 °/√h as a white-noise density [rad/s/√Hz] (a velocity random walk of 1 m/s/√h is 1/60 m/s²/√Hz).
MICRO_G = 9.80665e-6
DEG_PER_HOUR = math.radians(1.0) / 3600.0
DEG_PER_SQRT_HOUR = math.radians(1.0) / 60.0


@dataclass(frozen=True)
class ImuGrade:
    """The random-error figures of one class of IMU (:data:`IMU_GRADES`).

    Parameters
    ----------
    acc_noise : float
        Accelerometer white-noise density [m/s²/√Hz] (velocity random walk).
    acc_bias_instability : float
        Accelerometer Gauss–Markov bias σ [m/s²] (in-run bias stability).
    gyro_noise : float
        Gyro white-noise density [rad/s/√Hz] (angle random walk).
    gyro_bias_instability : float
        Gyro Gauss–Markov bias σ [rad/s] (in-run bias stability).
    bias_tau : float
        Gauss–Markov correlation time of both biases [s].
    source : str
        Where the figures come from, and what they mean on the datasheets.
    """

    acc_noise: float
    acc_bias_instability: float
    gyro_noise: float
    gyro_bias_instability: float
    bias_tau: float
    source: str


#: The error figures a grade sets (the names of :class:`ImuParams` and of ``imu.*`` in VesselMotion).
GRADE_FIGURES = ("acc_noise", "acc_bias_instability", "gyro_noise", "gyro_bias_instability", "bias_tau")

#: IMU classes by name (``imu.grade`` of VesselMotion). ``mems`` is the default of every figure.
IMU_GRADES: dict[str, ImuGrade] = {
    "mems": ImuGrade(
        acc_noise=7e-4, acc_bias_instability=5e-4, gyro_noise=5e-5, gyro_bias_instability=5e-5, bias_tau=50.0,
        source="An industrial MEMS motion sensor (VesselMotion's figures since 0.1): accelerometer 71 µg/√Hz, "
               "bias instability 51 µg; gyro angle random walk 0.17 °/√h, bias instability 10 °/h; τ 50 s. "
               "Of the class of the Xsens MTi-1 datasheet (gyro bias instability 10 °/h, noise "
               "0.007 °/s/√Hz = 0.42 °/√h; accelerometer 120 µg/√Hz), with lower noise."),
    "tactical": ImuGrade(
        acc_noise=5e-4, acc_bias_instability=25 * MICRO_G, gyro_noise=1.5e-5, gyro_bias_instability=1e-5,
        bias_tau=100.0,
        source="A tactical-grade IMU: gyro bias instability 2 °/h and angle random walk 0.05 °/√h (paper 001's "
               "dropout study, on the cautious side of the class: Honeywell HG4930 datasheet 0.25 °/h and "
               "0.04 °/√h, Analog Devices ADIS16495 0.8 °/h and 0.09 °/√h); accelerometer velocity random "
               "walk 0.03 m/s/√h (51 µg/√Hz) and bias instability 25 µg (HG4930); τ 100 s."),
    "mru": ImuGrade(
        acc_noise=15 * MICRO_G, acc_bias_instability=5 * MICRO_G, gyro_noise=0.01 * DEG_PER_SQRT_HOUR,
        gyro_bias_instability=0.05 * DEG_PER_HOUR, bias_tau=300.0,
        source="A survey motion reference unit with fibre-optic or high-end MEMS gyros, stated roll and pitch "
               "0.01 ° or better (Kongsberg Seatex MRU 5+ datasheet: 0.008 ° RMS; iXblue Octans: 0.01 °; "
               "SBG Apogee: 0.008 °): gyro bias instability 0.05 °/h and angle random walk 0.01 °/√h; "
               "accelerometer 15 µg/√Hz and bias instability 5 µg (SBG Apogee-class accelerometers, "
               "14 µg/√Hz and a few µg); τ 300 s."),
}
_MEMS = IMU_GRADES["mems"]


@dataclass(frozen=True)
class ImuParams:
    """IMU placement and error model.

    Parameters
    ----------
    lever_arm : tuple of float
        IMU position relative to the COG, body frame [m].
    acc_noise, gyro_noise : float
        White-noise densities [m/s²/√Hz], [rad/s/√Hz]; 0 … 1.
    acc_bias, gyro_bias : tuple of float
        Constant biases [m/s²], [rad/s], body frame.
    acc_bias_instability, gyro_bias_instability : float
        Stationary standard deviation of the Gauss–Markov bias [m/s²], [rad/s]; 0 … 1.
    bias_tau : float
        Gauss–Markov correlation time [s], 0.1 … 1e6.
    """

    lever_arm: tuple[float, float, float] = (0.0, 0.0, 0.0)
    acc_noise: float = _MEMS.acc_noise
    gyro_noise: float = _MEMS.gyro_noise
    acc_bias: tuple[float, float, float] = (0.0, 0.0, 0.0)
    gyro_bias: tuple[float, float, float] = (0.0, 0.0, 0.0)
    acc_bias_instability: float = _MEMS.acc_bias_instability
    gyro_bias_instability: float = _MEMS.gyro_bias_instability
    bias_tau: float = _MEMS.bias_tau

    def __post_init__(self) -> None:
        check_vector("imu.{x,y,z}", self.lever_arm, unit="m")
        check_range("imu.acc_noise", self.acc_noise, lo=0.0, hi=1.0, unit="m/s2/sqrt(Hz)")
        check_range("imu.gyro_noise", self.gyro_noise, lo=0.0, hi=1.0, unit="rad/s/sqrt(Hz)")
        for axis, v in zip("xyz", check_vector("imu.acc_bias", self.acc_bias, unit="m/s2")):
            check_range(f"imu.acc_bias.{axis}", v, lo=-10.0, hi=10.0, unit="m/s2")
        for axis, v in zip("xyz", check_vector("imu.gyro_bias", self.gyro_bias, unit="rad/s")):
            check_range(f"imu.gyro_bias.{axis}", v, lo=-1.0, hi=1.0, unit="rad/s")
        check_range("imu.acc_bias_instability", self.acc_bias_instability, lo=0.0, hi=1.0, unit="m/s2")
        check_range("imu.gyro_bias_instability", self.gyro_bias_instability, lo=0.0, hi=1.0, unit="rad/s")
        check_range("imu.bias_tau", self.bias_tau, lo=0.1, hi=1e6, unit="s")

    @classmethod
    def from_grade(cls, grade: str = "mems", **fields: Any) -> "ImuParams":
        """The error model of ``grade`` (:data:`IMU_GRADES`), with any field given here replacing
        the grade's: ``ImuParams.from_grade("mru", lever_arm=(50.0, 0.0, -10.0), acc_noise=0.0)``.

        Raises
        ------
        ParameterError
            For a grade that does not exist (naming the grades) or an invalid field value.
        """
        g = IMU_GRADES[check_choice("imu.grade", grade, IMU_GRADES)]
        return cls(**{**{name: getattr(g, name) for name in GRADE_FIGURES}, **fields})


class Imu:
    """Adds the configured errors to true specific force and angular rate.

    Cost per step: :meth:`measure_values` draws the step's 12 normal numbers into a buffer made
    once and works on Python floats; the Gauss–Markov factor φ = e^{−Δt/τ} and the noise scales
    are computed again only when Δt changes (they are functions of Δt alone, so the numbers are
    those of evaluating them every step).

    Parameters
    ----------
    params : ImuParams
        Error model.
    rng : numpy.random.Generator
        Seeded generator owned by this sensor.
    """

    def __init__(self, params: ImuParams, rng: np.random.Generator) -> None:
        self.params = params
        self._rng = rng
        self._const = np.concatenate([params.acc_bias, params.gyro_bias])
        self._sigma_b = np.repeat([params.acc_bias_instability, params.gyro_bias_instability], 3)
        self._density = np.repeat([params.acc_noise, params.gyro_noise], 3)
        self._const_l: list[float] = self._const.tolist()
        self._sigma_l: list[float] = self._sigma_b.tolist()
        self._density_l: list[float] = self._density.tolist()
        self._w = np.empty(12)
        self._dt: float | None = None  # the step the factors below belong to
        self._phi = 0.0
        self._gm_scale: list[float] = []
        self._noise_scale: list[float] = []
        self._gm: list[float] = (self._sigma_b * self._rng.standard_normal(6)).tolist()

    @property
    def gm_bias(self) -> np.ndarray:
        """(6,) Gauss–Markov part of the bias [acc (m/s²), gyro (rad/s)], body frame (a copy)."""
        return np.array(self._gm)

    @gm_bias.setter
    def gm_bias(self, value: Any) -> None:
        self._gm = [float(v) for v in value]

    @property
    def bias(self) -> np.ndarray:
        """(6,) total bias [acc (m/s²), gyro (rad/s)], body frame."""
        return np.array(self.bias_values())

    def bias_values(self) -> list[float]:
        """:attr:`bias` as 6 Python floats."""
        c, g = self._const_l, self._gm
        return [c[0] + g[0], c[1] + g[1], c[2] + g[2], c[3] + g[3], c[4] + g[4], c[5] + g[5]]

    def _factors(self, dt: float) -> None:
        """φ = e^{−Δt/τ}, σ_b √(1−φ²) and N/√Δt for step ``dt`` [s]."""
        phi = math.exp(-dt / self.params.bias_tau)
        s = math.sqrt(1.0 - phi * phi)
        r = math.sqrt(dt)
        self._phi = phi
        self._gm_scale = [sb * s for sb in self._sigma_l]
        self._noise_scale = [d / r for d in self._density_l]
        self._dt = dt

    def measure(self, f_true: Any, w_true: Any, dt: float) -> np.ndarray:
        """Advance the bias by ``dt`` [s] and return (6,) [f_b (m/s²), ω_b (rad/s)] measured.

        .. math:: b_k = φ b_{k−1} + σ_b \\sqrt{1−φ^2}\\, w_k,\\quad
                  y_k = x_k + b_c + b_k + N/\\sqrt{Δt}\\, v_k,\\quad φ = e^{−Δt/τ}
        """
        return np.array(self.measure_values(f_true, w_true, dt))

    def measure_values(self, f_true: Any, w_true: Any, dt: float) -> list[float]:
        """:meth:`measure` on and to Python floats: ``f_true`` and ``w_true`` are 3 values each."""
        if dt != self._dt:
            self._factors(dt)
        w = self._rng.standard_normal(out=self._w).tolist()
        phi, gs, ns, c, g = self._phi, self._gm_scale, self._noise_scale, self._const_l, self._gm
        g = [phi * g[i] + gs[i] * w[i] for i in range(6)]
        self._gm = g
        return [f_true[0] + c[0] + g[0] + ns[0] * w[6], f_true[1] + c[1] + g[1] + ns[1] * w[7],
                f_true[2] + c[2] + g[2] + ns[2] * w[8], w_true[0] + c[3] + g[3] + ns[3] * w[9],
                w_true[1] + c[4] + g[4] + ns[4] * w[10], w_true[2] + c[5] + g[5] + ns[5] * w[11]]

    def measure_many(self, f_true: np.ndarray, w_true: np.ndarray, dt: float) -> np.ndarray:
        """:meth:`measure` at each of n steps of ``dt`` [s], vectorised: the same numbers, drawn
        from the generator in the same order, as n calls would return.

        Parameters
        ----------
        f_true, w_true : numpy.ndarray
            (n, 3) true specific force [m/s², b] and angular rate [rad/s, b].
        dt : float
            Step [s].

        Returns
        -------
        numpy.ndarray
            (n, 6) measured [f_b (m/s²), ω_b (rad/s)]; the bias is left at its value after the
            last step.
        """
        from scipy.signal import lfilter

        true = np.column_stack([f_true, w_true]).astype(float)
        phi = math.exp(-dt / self.params.bias_tau)
        w = self._rng.standard_normal((len(true), 12))
        # b_k = φ b_{k−1} + σ_b √(1−φ²) w_k from b_{−1} = the current bias (lfilter's state is φ b_{−1})
        gm = lfilter([1.0], [1.0, -phi], self._sigma_b * math.sqrt(1.0 - phi * phi) * w[:, :6], axis=0,
                     zi=(phi * self.gm_bias)[None, :])[0]
        if len(gm):
            self.gm_bias = gm[-1].copy()
        return true + self._const + gm + self._density / math.sqrt(dt) * w[:, 6:]

    def get_state(self) -> dict:
        """JSON-serialisable state (generator and bias)."""
        return {"rng": self._rng.bit_generator.state, "gm_bias": list(self._gm)}

    def set_state(self, state: dict) -> None:
        """Restore a state from :meth:`get_state`."""
        self._rng.bit_generator.state = state["rng"]
        self.gm_bias = state["gm_bias"]


@dataclass(frozen=True)
class GnssParams:
    """Multi-antenna GNSS receiver.

    Parameters
    ----------
    antennas : tuple
        Four antenna positions relative to the COG, body frame [m].
    rate : float
        Fix rate [Hz], 0.1 … 100.
    sigma_h, sigma_v : float
        White-noise standard deviation, horizontal and vertical [m], 0 … 100.
    dropout_start, dropout_duration : float
        Dropout window [s]; duration 0 = no dropout.
    jump_start, jump_duration : float
        Jump window [s]; duration 0 = no jump.
    jump : tuple of float
        Offset added to every antenna inside the jump window, NED [m].
    """

    antennas: tuple = ((10.0, -4.0, -10.0), (10.0, 4.0, -10.0), (-10.0, -4.0, -10.0), (-10.0, 4.0, -10.0))
    rate: float = 5.0
    sigma_h: float = 0.01
    sigma_v: float = 0.015
    dropout_start: float = 0.0
    dropout_duration: float = 0.0
    jump_start: float = 0.0
    jump_duration: float = 0.0
    jump: tuple[float, float, float] = (0.0, 0.0, 0.0)

    def __post_init__(self) -> None:
        if len(self.antennas) != ANTENNAS:
            raise ParameterError(f"gnss antennas: expected {ANTENNAS} lever arms, got {len(self.antennas)}")
        arms = np.array([check_vector(f"gnss.ant{i + 1}.{{x,y,z}}", a, unit="m") for i, a in enumerate(self.antennas)])
        for i in range(ANTENNAS):
            for j in range(i + 1, ANTENNAS):
                if np.linalg.norm(arms[i] - arms[j]) < 0.1:
                    raise ParameterError(f"gnss.ant{i + 1} and gnss.ant{j + 1} are closer than 0.1 m: antennas must be distinct")
        centred = arms - arms.mean(axis=0)
        if np.linalg.matrix_rank(centred, tol=0.05) < 2:
            raise ParameterError("gnss.ant1..4 are collinear: attitude needs antennas spanning a plane")
        check_range("gnss.rate", self.rate, lo=0.1, hi=100.0, unit="Hz")
        check_range("gnss.sigma_h", self.sigma_h, lo=0.0, hi=100.0, unit="m")
        check_range("gnss.sigma_v", self.sigma_v, lo=0.0, hi=100.0, unit="m")
        check_range("gnss.dropout.start", self.dropout_start, lo=0.0, unit="s")
        check_range("gnss.dropout.duration", self.dropout_duration, lo=0.0, unit="s")
        check_range("gnss.jump.start", self.jump_start, lo=0.0, unit="s")
        check_range("gnss.jump.duration", self.jump_duration, lo=0.0, unit="s")
        for axis, v in zip("ned", check_vector("gnss.jump", self.jump, unit="m")):
            check_range(f"gnss.jump.{axis}", v, lo=-1000.0, hi=1000.0, unit="m")

    def in_dropout(self, t: float) -> bool:
        """True when ``t`` [s] is inside the dropout window."""
        return self.dropout_duration > 0 and self.dropout_start <= t < self.dropout_start + self.dropout_duration

    def in_jump(self, t: float) -> bool:
        """True when ``t`` [s] is inside the jump window."""
        return self.jump_duration > 0 and self.jump_start <= t < self.jump_start + self.jump_duration


class Gnss:
    """Samples antenna positions at the fix epochs and adds noise, dropouts and jumps.

    Parameters
    ----------
    params : GnssParams
        Receiver model.
    rng : numpy.random.Generator
        Seeded generator owned by this sensor.
    """

    def __init__(self, params: GnssParams, rng: np.random.Generator) -> None:
        self.params = params
        self._rng = rng
        self._sigma = np.tile([params.sigma_h, params.sigma_h, params.sigma_v], ANTENNAS)
        self.last_epoch = -1
        self.positions = np.zeros(3 * ANTENNAS)
        self.valid = False

    def epoch_due(self, t: float) -> int | None:
        """Index k of the newest epoch t_k = k/rate ≤ t if not yet reported, else None."""
        k = math.floor(t * self.params.rate + 1e-9)
        return k if k > self.last_epoch else None

    def measure(self, k: int, truth: np.ndarray) -> None:
        """Record epoch ``k`` from (12,) true antenna positions (NED [m], ant1 n,e,d, ant2 …)."""
        self.last_epoch = k
        t = k / self.params.rate
        noise = self._sigma * self._rng.standard_normal(3 * ANTENNAS)
        if self.params.in_dropout(t):
            self.valid = False
            return
        meas = truth + noise
        if self.params.in_jump(t):
            meas = meas + np.tile(self.params.jump, ANTENNAS)
        self.positions = meas
        self.valid = True

    def get_state(self) -> dict:
        """JSON-serialisable state."""
        return {"rng": self._rng.bit_generator.state, "last_epoch": self.last_epoch,
                "positions": self.positions.tolist(), "valid": self.valid}

    def set_state(self, state: dict) -> None:
        """Restore a state from :meth:`get_state`."""
        self._rng.bit_generator.state = state["rng"]
        self.last_epoch = int(state["last_epoch"])
        self.positions = np.array(state["positions"], dtype=float)
        self.valid = bool(state["valid"])
