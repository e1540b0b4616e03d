"""Multi-antenna GNSS + accelerometer fusion with attitude correction (paper 001).

Frames: the paper works in ENU with z up; here everything is NED/FRD (see the design page) — positions
north, east, down; the body frame x forward, y starboard, z down; g_n = [0, 0, +g].

1. **Attitude from the antennas** (:mod:`.antenna_attitude`): the least-squares attitude
   (Wahba's problem) and COG position of the four measured antenna positions, and the RMS fit
   residual as the quality output. NaN coordinates or antennas that do not span a plane skip
   the epoch.
2. **Attitude-corrected acceleration** (eqs. 25-26 in our convention):
   a_n = R_nb f_b + g_n. Without correction (the paper's "before" case) the sensor axes are
   taken as the n axes: a_n = f_b + g_n. Between GNSS epochs the paper interpolates the
   antenna attitude, which needs the *next* epoch (a delay of one GNSS interval, and at 1 Hz
   a hold of a 3° roll at 0.1 Hz is already 2° off). We propagate instead
   (``propagation="gyro"``, default): the gyro integrates the attitude at the sample rate
   (exact rotation per step, :func:`~marinefmu.frames.quat_from_rotvec`) and each accepted
   fix pulls it towards the antenna attitude with a PI (Mahony-type) correction of time
   constant ``attitude_tau``, which also estimates the gyro bias. This averages the fix noise
   (≈ σ/baseline, 1.2 mrad for 1 cm on 8 m) instead of passing it on, and keeps the attitude
   through GNSS dropouts. ``propagation="hold"`` uses the latest fix's attitude until the next
   (the causal form of the paper's interpolation; no gyro needed). Once a fix is overdue
   (:data:`HOLD_OVERDUE` times the usual interval) and a gyro is given, it takes the wave
   coast's gyro attitude until the next fix: a held attitude is stale in a gap (metres of east
   error through a 30 s dropout). Without a gyro (or with ``coast="inertial"``, which keeps
   no gyro attitude) nothing follows the attitude in a gap: ``valid`` is false while a fix is
   overdue.
3. **Kalman fusion** (filterpy ``KalmanFilter``): per axis the constant-acceleration model of
   eqs. 13-19, x = [d, v], Φ = [[1, Δt], [0, 1]], G = [Δt²/2, Δt], u = a_n,
   Q = q·[[Δt³/3, Δt²/2], [Δt²/2, Δt]] (eq. 16), R = r/Δt (eq. 17), Δt the accelerometer
   interval, with r sized to the receiver's measured epoch rate and antenna noise
   (``noise_sizing="auto"``, default: :meth:`GnssAccFusion._sized_r`) or as given
   (``"fixed"``, the paper); multirate: predict every sample, update at GNSS epochs. The acceleration and
   the angular rate over a step are the means of the two samples that bound it
   (``step_input="mean"``, default), not the latest sample held (``"latest"``, the paper's
   eq. 15 with a_k): a held sample makes the predicted velocity err by (Δt/2)·a(t) and the
   attitude by (Δt/2)·ω(t), oscillations (±5 mm/s at 1 m/s², ±0.01° at 0.04 rad/s, 100 Hz)
   that the GNSS updates cannot see but that turn into drift the moment GNSS drops out
   (decimetres through a 30 s dropout with perfect sensors and ``"latest"``, see the tests).
   The fused point is the
   accelerometer (the GNSS measurement of it is p_c + R l_acc), so no lever-arm acceleration
   terms are needed; the outputs are transferred to the COG.
   Beyond the paper: an n-frame accelerometer-bias state per axis (``bias_states``; random
   walk of density ``bias_rw``), which also absorbs slowly varying tilt errors; a Mahalanobis
   gate on the 3-D innovation (``gate`` in σ) that rejects jumps and outliers, its variance
   per axis the filter's own or, where larger, the one the error covariance of
   :mod:`.error_model` predicts (with a held attitude the filter's own does not know the
   vessel's rotation since the fix, and near the roll resonance it would reject good fixes;
   docs/decisions/gnss-fusion-filter.md); coasting
   through dropouts (item 4), with ``valid`` false after ``max_coast`` s;
   re-initialisation on GNSS after ``reinit_time`` s of consecutive rejections (a real
   reposition, not a glitch) and on the first fix after a gap longer than ``max_coast`` (with
   the velocity the wave coast held, when it bridged the gap); and
   an RTS fixed-interval smoother for post-processing (:func:`~.runs.fuse`,
   ``smooth=True``; hand-written because filterpy's ``rts_smoother`` has no control input,
   and here x⁻_{k+1} = Φ x_k + G u_k).
4. **Coasting through GNSS dropouts** (``coast``, beyond the paper). ``"inertial"`` predicts
   only; with a MEMS gyro this drifts by metres in 30 s whatever the filter (the gyro bias
   wander alone: :func:`~.wave_coast.coast_floor`, 0.87 m RMS per axis after 30 s for
   VesselMotion's default gyro, perfectly initialised). ``"band"`` (default) assumes what holds
   for a floating platform or a vessel on station: the low-frequency position moves along a
   straight line through the gap. Once no fix has come for :data:`COAST_AFTER` s, the
   position of :class:`~.wave_coast.WaveCoast` (per axis, the band observer's wave model and a
   drift in one Kalman filter that the fixes update too, :mod:`.aided_band`; in the north and
   east filters also the tilt error of the attitude that corrects the coast's acceleration,
   ``coast_tilt``) updates the filter every
   :data:`COAST_INTERVAL` s as a pseudo-fix (not gated; ``fix`` is ``"wave"``) of variance
   ``coast_sigma``² plus the coast's own (which grows through the gap), until GNSS returns,
   however long the gap: on the paper's set-up a 5-min gap errs decimetres, where the
   inertial coast is kilometres off. The coast's variance goes back into the
   filter's covariance before the next fix is gated. In the gap ``pos_std`` is the coast's own
   standard deviation combined with the running RMS of the pseudo-fix innovations (how far the
   output strays from the coast between pseudo-fixes, :data:`TRACK_WEIGHT`), not the filter's:
   the filter takes the pseudo-fixes as independent and its covariance settles at a few
   centimetres whatever the error, far too cautious (docs/decisions/gnss-fusion-filter.md).
   Between fixes ``pos_std`` is not the filter's covariance either, whose q and r set the
   blend but not the size of the errors, but that of the error the filter makes as it runs
   (:mod:`.error_model`). Without a coast position for ``max_coast`` s (``"inertial"``, or a
   gap in the coast's first 3 minutes) the filter holds its position (velocity zero) until
   GNSS returns. The accuracy through dropouts is measured by ``make bench``, part
   ``dropout`` (the benchmarks page).
5. **One receiver and an external attitude** (``attitude="input"``, beyond the paper): for a
   vessel with one GNSS receiver and an attitude from elsewhere (an
   :class:`~marinefmu.estimators.attitude.estimator.AttitudeEstimator`'s roll and pitch, a
   compass's heading). Each step's roll, pitch, yaw rotate the specific force into NED
   (f_n = R_nb f_b) and move the receiver's fix of antenna 1 to the accelerometer point
   (p_acc = p_ant1 + R_nb (l_acc − l_ant1)); the filter then runs as above on that point with
   ``attitude_correction=False`` and ``propagation="hold"``, each fix handed to it as a rigid
   antenna set at identity attitude around the point (:func:`receiver_params`), so the
   antenna solution returns exactly the fix and the Kalman filter, gating, bias states, coast
   and re-initialisation are the same code as the four antennas'. The outputs are moved from
   the accelerometer point to the COG with the same angles. Roll and pitch that lag the
   accelerometer (an estimator in the same co-simulation delivers them one step late) are
   turned forward over ``attitude_lag`` with the gyro. A non-finite or implausible angle
   (:func:`~marinefmu.estimators.samples.angles_beyond_limit`) is a bad sample: the step
   coasts on the last good NED specific force, and a fix in it is placed with the last good
   angles.

Cost per step: every sample, the gyro attitude's exact rotation, the attitude-corrected
acceleration, the Kalman prediction and the output's position variance, and the wave coast's
tracking (:mod:`.wave_coast`: block sums every sample, its band filters every band step of
about 1/:data:`~.wave_coast.RATE` s, so that a dropout can be bridged at once; their covariance
work is structured, :mod:`.aided_band`); at each accepted GNSS epoch, the antenna attitude
(Wahba), the PI attitude correction and the Kalman update; every
:data:`~.wave_coast.PEAK_INTERVAL` s, the coast's band models rebuilt from the spectra, whose
steady-state Riccati solution is needed (and solved) only for an observer's first model and for
elements new to a later one (:class:`~marinefmu.estimators.heave.oscillator_bank.BankModel`).
The fix-to-fix rotation vectors are written out in floats
(:func:`~.antenna_attitude.matrix_rotvec`), equal to scipy's bit for bit.
"""
from __future__ import annotations

import logging
import math
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
from filterpy.kalman import KalmanFilter
from scipy.spatial.transform import Rotation

from ...errors import ParameterError, check_choice, check_range, check_vector
from ...frames import GRAVITY_N, cross3, euler_to_quat, floats, quat_from_rotvec, quat_mul, quat_to_euler, quat_to_rot, rot_nb
from ..samples import angles_beyond_limit, force_beyond_limit, force_sample_good, rate_sample_good
from .antenna_attitude import (ANTENNAS, DEFAULT_ANTENNAS, MIN_SPREAD, AntennaFix, antenna_attitude, antenna_attitude_std,
                               matrix_rotvec)
from .error_model import FusionError, pi_gains, skew
from .wave_coast import WaveCoast

log = logging.getLogger(__name__)

PROPAGATION_CHOICES = ("gyro", "hold")
STEP_INPUT_CHOICES = ("mean", "latest")
COAST_CHOICES = ("band", "inertial")
ATTITUDE_CHOICES = ("antennas", "input")
NOISE_SIZINGS = ("auto", "fixed")
#: ``noise_sizing="auto"``: ``r`` is the setting for a receiver that fixes once every
#: :data:`FIX_INTERVAL_REF` s [s] ...
FIX_INTERVAL_REF = 1.0
#: ... with antenna noise of these standard deviations, horizontal and vertical [m] (RTK;
#: VesselMotion's default receiver).
SIGMA_REF = (0.01, 0.015)
#: Memory of the running mean of the antenna-fit residual's square [usable epochs, accepted
#: or gated out]; before that many, the mean over all so far.
NOISE_MEMORY = 100
#: The interval T̂ of ``noise_sizing="auto"`` is the median of this many latest intervals
#: between GNSS epochs: a dropout or a skipped epoch moves it by one sample, a new receiver
#: rate takes over within half of them.
INTERVAL_MEMORY = 9
#: Bounds of the noise factor of ``noise_sizing="auto"`` (the measured antenna noise's
#: variance over the reference's): a noise-free record (a simulation without noise) would
#: otherwise give R = 0, and the largest usable residual (``max_residual``) is far inside the
#: upper bound.
NOISE_FACTOR_RANGE = (0.01, 1e4)
#: The rigid antenna set at identity attitude that carries one receiver's fix through the antenna
#: solution (``attitude="input"``, module docstring item 5): the default antennas about their
#: centroid, body frame [m].
RECEIVER_ANTENNAS = tuple(tuple(float(x) for x in a) for a in (np.array(DEFAULT_ANTENNAS) - np.mean(DEFAULT_ANTENNAS, axis=0)))
#: With ``coast="band"``, pseudo-fixes start this long [s] after the last accepted fix ...
COAST_AFTER = 2.0
#: ... and follow each other at this interval [s]: often enough that the fused output follows
#: the coast, whose own error is then what is left (more often gains nothing). At 0.1 s the
#: default ``coast_sigma`` is 15 cm, the information per second of 5 cm once a second
#: (docs/decisions/gnss-fusion-filter.md).
COAST_INTERVAL = 0.1
#: With ``propagation="hold"`` a fix is overdue once this many times the usual interval between
#: accepted fixes has passed without one; the attitude then follows the coast's gyro attitude
#: until the next fix (module docstring, item 2).
HOLD_OVERDUE = 1.5
#: Weight of each pseudo-fix in the running mean square of the pseudo-fix innovations, which
#: ``pos_std`` adds to the coast's own variance in a gap (a memory of about 2 s at
#: :data:`COAST_INTERVAL`; module docstring).
TRACK_WEIGHT = 0.05


@dataclass(frozen=True)
class GnssAccFusionParams:
    """Parameters of :class:`GnssAccFusion` (FMU names in brackets).

    Parameters
    ----------
    antennas : tuple
        Four antenna lever arms relative to the COG, body frame [m]; distinct, spanning a
        plane. With ``attitude="input"`` only the first is read: the receiver's antenna.
        [``ant{1..4}.{x,y,z}``]
    acc_lever_arm : tuple of float
        Accelerometer position relative to the COG, body frame [m]. [``acc_lever_arm.*``]
    attitude : {"antennas", "input"}
        Where the attitude comes from: the four antennas (the paper), or the roll, pitch, yaw
        given to :meth:`GnssAccFusion.step` with one receiver on antenna 1 (module docstring,
        item 5; ``attitude_correction``, ``propagation``, ``attitude_tau``,
        ``coast_attitude_tau``, ``coast_tilt``, ``coast_tilt_band``, ``max_residual`` and
        antennas 2-4 then have no effect, and ``antenna_sigma_h``, ``antenna_sigma_v`` are the
        receiver's noise, at most 50 m). [``attitude``]
    attitude_lag : float
        With ``attitude="input"``: how long the roll and pitch inputs lag the accelerometer
        sample they come with [s], [0, 1]. They are turned forward over it with the gyro (the
        rate over the step, ``step_input``); the yaw input is taken as it is (a compass). An
        attitude estimator in the same co-simulation delivers its roll and pitch one
        communication step late (Jacobi coupling): set the step, as ``marinefmu replay`` does.
        Left unturned, a lag τ tilts the specific force by the angular rate times τ, and g
        times that tilt goes into the horizontal acceleration (docs/fmus/GnssAccFusion.md has
        what it costs on a record). [``attitude_lag``]
    q : float
        Acceleration process-noise density of eq. 16 [m²/s³], > 0. The default 1e-3 is the
        best of the benchmark's grid (part ``defaults``: 3 vessels × 3 seas × 2 IMU
        placements, 5 Hz RTK; docs/decisions/gnss-fusion-defaults.md) with the auto-sized R;
        paper 001's reproduction (1 Hz) keeps its own tuning, 0.005 with R fixed. [``q``]
    q_down : float or None
        Process-noise density of the down axis [m²/s³], > 0; None (FMU: 0) = ``q`` as the
        paper. Beyond the paper: an attitude error ε puts g·ε into the horizontal a_n but only
        g·ε²/2 (plus the horizontal specific force times ε) into the vertical one, so the down
        axis can trust the accelerometer more. The default 1e-4 is the best of the
        benchmark's grid (part ``defaults``, docs/decisions/gnss-fusion-defaults.md) and of the
        ``system`` scenario's. [``q_down``]
    r : float
        GNSS position noise of eq. 17, R = r/Δt [m²·s], > 0, Δt the accelerometer interval.
        With ``noise_sizing="auto"`` the value for a receiver at 1 Hz (:data:`FIX_INTERVAL_REF`)
        with antenna noise :data:`SIGMA_REF` (1 cm, 1.5 cm), scaled to the receiver's measured
        rate and noise; with ``"fixed"`` R = r/Δt as given. The default 1e-5 (at Δt = 0.01 s
        and 1 Hz, R = (3 cm)²) is the best of a 3 × 3 grid with q on experiment (b) of
        :mod:`marinefmu.papers.paper001` (1 Hz RTK, 300 s; docs/decisions/gnss-fusion-filter.md):
        the ratio q/(R·T) sets the blend, T the interval between fixes, and R = σ² weights the
        fixes too much against 100 Hz predictions. [``r``]
    noise_sizing : {"auto", "fixed"}
        ``"auto"``: R is sized from the data as the filter runs,
        R = r · (T_ref/T̂) · (m̂/m_ref) / Δt, T̂ the median interval between GNSS epochs and
        m̂/m_ref the antenna-fit residual's mean square over its expectation at the reference
        noise (:meth:`GnssAccFusion._sized_r`; one receiver, ``attitude="input"``: the rate
        only), so that a 1 Hz and a 5 Hz receiver, or a noisier one, get the R of the same
        blend per unit time. ``"fixed"``: R = r/Δt. [``noise_sizing``]
    attitude_correction : bool
        Rotate the specific force with the attitude (True) or take the sensor axes as NED
        (the paper's uncorrected case). [``attitude_correction``]
    propagation : {"gyro", "hold"}
        Attitude between epochs: gyro-propagated with PI correction, or the latest fix held
        (through a gap, with a gyro, the coast's gyro attitude: module docstring).
        [``propagation``]
    step_input : {"mean", "latest"}
        Acceleration and rate over a step: the mean of the two samples that bound it, or the
        latest sample held (the paper's eq. 15). [``step_input``]
    attitude_tau : float
        Time constant of the PI attitude correction [s], 0.1 … 1000. [``attitude_tau``]
    gate : float
        Mahalanobis innovation gate [σ], > 0; ``math.inf`` disables gating. [``gate``]
    bias_states : bool
        Estimate an n-frame accelerometer bias per axis. [``bias_states``]
    bias_rw : float
        Random-walk density of the bias states [m/s²/√s], > 0. [``bias_rw``]
    max_residual : float
        Largest RMS antenna-fit residual [m] of a usable fix, > 0. [``max_residual``]
    reinit_time : float
        Consecutive rejections for this long [s] re-initialise the filter on GNSS, > 0.
        [``reinit_time``]
    max_coast : float
        ``valid`` goes false this long [s] after the last accepted fix, and the first fix after
        such a gap re-initialises the filter; without a coast position for this long the
        position is held, > 0. [``max_coast``]
    coast : {"band", "inertial"}
        Through a GNSS gap: wave-model pseudo-fixes (a vessel on station or moving steadily)
        or prediction only (module docstring). [``coast``]
    coast_sigma : float
        Standard deviation of a wave-model pseudo-fix [m], (0, 10]; one every
        :data:`COAST_INTERVAL` s. [``coast_sigma``]
    coast_attitude_tau : float
        Time constant of the coast's own PI attitude [s], 0.1 … 10000 (``coast="band"`` with
        the attitude correction and a gyro). The coast's acceleration is corrected with an attitude
        propagated by the same gyro but pulled to the fixes more slowly than the fusion's
        (``attitude_tau``): its horizontal offset takes a slowly wandering tilt, while the fix
        noise a fast PI lets through sits nearer the waves. Through 30 s dropouts the coast
        gains from a slow pull up to about 150 s and no more beyond; a fusion as slow would
        coast as well but makes the fused output worse all the time
        (docs/decisions/gnss-fusion-filter.md). [``coast_attitude_tau``]
    coast_window : float
        Memory of the drift model of ``coast="band"`` (:func:`~.aided_band.drift_noise`) [s],
        10 … 3600. The coast gives pseudo-fixes until GNSS returns, however long the gap. It
        has no position before its spectrum window
        (:data:`~.wave_coast.SPECTRUM_WINDOW`, 180 s) has passed. [``coast_window``]
    coast_tilt : bool
        Give the coast's north and east filters two tilt-error states (the error of the coast's
        attitude about E / N and the gyro-bias error that turns it), measured by each fix's
        antenna attitude (:class:`~.aided_band.Tilt`); their offset then takes only the
        accelerometer bias. False: a loose offset stands in for the tilt.
        Needs ``coast="band"``, the attitude correction and a gyro. With the heave observer's
        spectrum settings that the tilt states bring (:mod:`.wave_coast`) and the spectrum
        smoothed (:data:`~.wave_coast.BAND_SMOOTHING`) they cut the tail of the dropout errors
        (docs/decisions/gnss-fusion-coast.md). [``coast_tilt``]
    coast_tilt_band : bool
        With ``coast_tilt``: the tilt states are also measured, at every band step, by the
        coast attitude's own tilt about N / E, the vessel's wave roll and pitch modelled as a
        band from their spectrum (:mod:`.wave_coast`, "The wave tilt"). In a gap this is the
        second source of the tilt besides the acceleration. False: the acceleration alone.
        [``coast_tilt_band``]
    gyro_bias_sigma : float
        Gyro bias instability, the Gauss-Markov standard deviation of the tilt states' bias
        error [rad/s], (0, 1] (VesselMotion's default 5e-5; a larger value coasts worse).
        [``gyro_bias_sigma``]
    gyro_bias_tau : float
        Its correlation time [s], 0.1 … 1e6. [``gyro_bias_tau``]
    antenna_sigma_h, antenna_sigma_v : float
        Standard deviation of one antenna position, horizontal and vertical [m], (0, 100]: the
        weight of a fix's attitude in the tilt states (:func:`~.antenna_attitude.antenna_attitude_std`; RTK 1 and
        1.5 cm) and the fix noise of ``pos_std`` (:mod:`.error_model`). [``antenna_sigma_h``,
        ``antenna_sigma_v``]
    acc_noise : float
        Accelerometer white-noise density [m/s²/√Hz], (0, 10] (VesselMotion's default MEMS
        7e-4): the sensor's, for ``pos_std`` only (:mod:`.error_model`); the filter blends
        with ``q``. [``acc_noise``]
    gyro_noise : float
        Gyro white-noise density (angle random walk) [rad/s/√Hz], (0, 1] (VesselMotion's
        default 5e-5): the random walk of the tilt states' attitude error (``coast_tilt``,
        :class:`~.aided_band.Tilt`), and with
        ``gyro_bias_sigma`` and ``gyro_bias_tau`` the attitude error of ``pos_std``.
        [``gyro_noise``]
    """

    antennas: tuple = DEFAULT_ANTENNAS
    acc_lever_arm: tuple[float, float, float] = (0.0, 0.0, 0.0)
    q: float = 1e-3
    q_down: float | None = 1e-4
    r: float = 1e-5
    attitude_correction: bool = True
    propagation: str = "gyro"
    step_input: str = "mean"
    attitude_tau: float = 30.0
    gate: float = 5.0
    bias_states: bool = True
    bias_rw: float = 2e-4
    max_residual: float = 0.1
    reinit_time: float = 30.0
    max_coast: float = 60.0
    coast: str = "band"
    coast_sigma: float = 0.15
    coast_attitude_tau: float = 150.0
    coast_window: float = 120.0
    coast_tilt: bool = True
    coast_tilt_band: bool = True
    gyro_bias_sigma: float = 5e-5
    gyro_bias_tau: float = 50.0
    antenna_sigma_h: float = 0.01
    antenna_sigma_v: float = 0.015
    acc_noise: float = 7e-4
    gyro_noise: float = 5e-5
    attitude: str = "antennas"
    attitude_lag: float = 0.0
    noise_sizing: str = "auto"
    arms: np.ndarray = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        check_choice("attitude", self.attitude, ATTITUDE_CHOICES)
        check_choice("noise_sizing", self.noise_sizing, NOISE_SIZINGS)
        if len(self.antennas) != ANTENNAS:
            raise ParameterError(f"antennas: expected {ANTENNAS} lever arms ant1..ant4, got {len(self.antennas)}")
        arms = np.array([check_vector(f"ant{i + 1}.{{x,y,z}}", a, unit="m") for i, a in enumerate(self.antennas)])
        object.__setattr__(self, "arms", arms)
        if self.attitude == "antennas":     # with one receiver (attitude="input") only ant1 is read
            for i in range(ANTENNAS):
                for j in range(i + 1, ANTENNAS):
                    if np.linalg.norm(arms[i] - arms[j]) < 0.1:
                        raise ParameterError(f"ant{i + 1} and ant{j + 1} are closer than 0.1 m: antennas must be distinct")
            if np.linalg.svd(arms - arms.mean(axis=0), compute_uv=False)[1] < MIN_SPREAD * 2:
                raise ParameterError("ant1..ant4 are collinear: the antennas must span a plane (second singular value >= 0.1 m)")
        check_vector("acc_lever_arm", self.acc_lever_arm, unit="m")
        check_range("q", self.q, lo=0.0, lo_open=True, hi=1e6, unit="m2/s3")
        if self.q_down is not None:
            check_range("q_down", self.q_down, lo=0.0, lo_open=True, hi=1e6, unit="m2/s3")
        check_range("r", self.r, lo=0.0, lo_open=True, hi=1e6, unit="m2*s")
        check_choice("propagation", self.propagation, PROPAGATION_CHOICES)
        check_choice("step_input", self.step_input, STEP_INPUT_CHOICES)
        check_range("attitude_tau", self.attitude_tau, lo=0.1, hi=1000.0, unit="s")
        check_range("attitude_lag", self.attitude_lag, lo=0.0, hi=1.0, unit="s")
        if self.gate != math.inf:  # inf: no gating (the paper)
            check_range("gate", self.gate, lo=0.0, lo_open=True, unit="sigma")
        check_range("bias_rw", self.bias_rw, lo=0.0, lo_open=True, hi=10.0, unit="m/s2/sqrt(s)")
        check_range("max_residual", self.max_residual, lo=0.0, lo_open=True, unit="m")
        check_range("reinit_time", self.reinit_time, lo=0.0, lo_open=True, unit="s")
        check_range("max_coast", self.max_coast, lo=0.0, lo_open=True, unit="s")
        check_choice("coast", self.coast, COAST_CHOICES)
        check_range("coast_sigma", self.coast_sigma, lo=0.0, lo_open=True, hi=10.0, unit="m")
        check_range("coast_attitude_tau", self.coast_attitude_tau, lo=0.1, hi=10000.0, unit="s")
        check_range("coast_window", self.coast_window, lo=10.0, hi=3600.0, unit="s")
        check_range("gyro_bias_sigma", self.gyro_bias_sigma, lo=0.0, lo_open=True, hi=1.0, unit="rad/s")
        check_range("gyro_bias_tau", self.gyro_bias_tau, lo=0.1, hi=1e6, unit="s")
        # one receiver: its noise is doubled on the virtual antenna set (receiver_params)
        sigma_max = 100.0 if self.attitude == "antennas" else 50.0
        check_range("antenna_sigma_h", self.antenna_sigma_h, lo=0.0, lo_open=True, hi=sigma_max, unit="m")
        check_range("antenna_sigma_v", self.antenna_sigma_v, lo=0.0, lo_open=True, hi=sigma_max, unit="m")
        check_range("acc_noise", self.acc_noise, lo=0.0, lo_open=True, hi=10.0, unit="m/s2/sqrt(Hz)")
        check_range("gyro_noise", self.gyro_noise, lo=0.0, lo_open=True, hi=1.0, unit="rad/s/sqrt(Hz)")


@dataclass(frozen=True)
class GnssAccFusionResult:
    """One step of :class:`GnssAccFusion` (NED, COG unless said otherwise).

    Attributes
    ----------
    pos, vel : tuple of float
        COG position [m] and velocity [m/s], NED.
    pos_std : tuple of float
        1σ of the fused position [m]: the covariance of the error the filter makes as it runs,
        with the sensors' noises (:mod:`.error_model`), or in a GNSS gap bridged by the wave
        coast the coast's own and the output's spread about it (module docstring); 0 before
        initialisation.
    euler : tuple of float
        Roll, pitch, yaw [rad] used for the correction.
    acc_n : tuple of float
        Attitude-corrected acceleration at the accelerometer, NED [m/s²].
    acc_bias : tuple of float
        Estimated n-frame accelerometer bias [m/s²] (zeros without bias states).
    residual : float
        RMS antenna-fit residual of the latest usable fix [m] (0 before the first).
    fix : str
        What happened to a GNSS epoch this step: "", "accepted", "rejected", "skipped"; or
        "wave" for a wave-model pseudo-fix in a GNSS gap (``coast="band"``).
    valid : bool
        Initialised, samples good (no bad IMU sample, no skipped or rejected GNSS epoch this
        step), and an accepted fix within ``max_coast``.
    warning : str or None
        Reason for a rejected sample or epoch.
    """

    pos: tuple[float, float, float]
    vel: tuple[float, float, float]
    pos_std: tuple[float, float, float]
    euler: tuple[float, float, float]
    acc_n: tuple[float, float, float]
    acc_bias: tuple[float, float, float]
    residual: float
    fix: str
    valid: bool
    warning: str | None = None


def propagate(q: np.ndarray, rate: np.ndarray, dt: float) -> np.ndarray:
    """Attitude quaternion R_nb (scalar first) turned by the body rate ``rate`` [rad/s] over
    ``dt`` s (exact rotation), normalised."""
    r0, r1, r2 = floats(rate)
    q = quat_mul(q, quat_from_rotvec((r0 * dt, r1 * dt, r2 * dt)))
    return q / math.sqrt(q.dot(q))      # np.linalg.norm's own sum, without its dispatch


def pi_pull(q: np.ndarray, bias: np.ndarray, rot_fix: np.ndarray, dt_fix: float, tau: float,
            alpha: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """PI (Mahony-type) correction of a gyro-propagated attitude towards a fix.

    Parameters
    ----------
    q : numpy.ndarray
        (4,) propagated attitude R_nb, scalar first.
    bias : numpy.ndarray
        (3,) gyro bias estimate, body frame [rad/s].
    rot_fix : numpy.ndarray
        (3, 3) the fix's R_nb.
    dt_fix : float
        Time since the previous fix [s].
    tau : float
        Time constant [s]: k_p = 2/τ, k_i = 1/τ² (critically damped;
        :func:`~.error_model.pi_gains`).
    alpha : numpy.ndarray, optional
        (3,) proportional gains per NED axis to use instead of the PI's (at most its own:
        :meth:`GnssAccFusion._correct_attitude`).

    Returns
    -------
    tuple of numpy.ndarray
        The corrected attitude and bias.
    """
    rot = quat_to_rot(q)
    e_n = np.array(matrix_rotvec(rot_fix @ rot.T))  # small rotation est → fix, NED
    k_p, k_i = pi_gains(dt_fix, tau)
    q = quat_mul(quat_from_rotvec((k_p if alpha is None else alpha) * e_n), q)
    return q / np.linalg.norm(q), bias - k_i * (rot.T @ e_n)


def transition(dt: float, bias: bool) -> tuple[np.ndarray, np.ndarray]:
    """Φ and G of the constant-acceleration model (eq. 15) for the 3 axes, state
    [d_n, d_e, d_d, v_n, v_e, v_d (, b_n, b_e, b_d)], input a_n (bias subtracted)."""
    i3 = np.eye(3)
    g = np.vstack((0.5 * dt * dt * i3, dt * i3))
    if not bias:
        return np.block([[i3, dt * i3], [0 * i3, i3]]), g
    f = np.block([[i3, dt * i3, -0.5 * dt * dt * i3], [0 * i3, i3, -dt * i3], [0 * i3, 0 * i3, i3]])
    return f, np.vstack((g, 0 * i3))


def process_noise(dt: float, q: float, bias_rw: float | None, q_down: float | None = None) -> np.ndarray:
    """Q of eq. 16 for the 3 axes (``q_down`` on the down axis if given, else ``q``), plus
    bias_rw²·Δt on the bias states if given."""
    i3 = np.eye(3)
    qd = np.diag([q, q, q if q_down is None else q_down])
    qq = np.block([[dt ** 3 / 3 * qd, dt ** 2 / 2 * qd], [dt ** 2 / 2 * qd, dt * qd]])
    if bias_rw is None:
        return qq
    out = np.zeros((9, 9))
    out[:6, :6] = qq
    out[6:, 6:] = bias_rw ** 2 * dt * i3
    return out


def residual_ms(arms: np.ndarray, sigma_h: float, sigma_v: float) -> float:
    """Expected square of the RMS antenna-fit residual [m²] (the mean over the antennas of the
    squared 3-D residual, :func:`~.antenna_attitude.antenna_attitude`) for independent antenna
    errors of ``sigma_h`` (north, east) and ``sigma_v`` (down) [m], at level attitude, to
    first order: E = tr((I − P) Σ) / N, P the projection onto the fit's six directions (the
    COG's three and the attitude's, antenna i moving by −[r_i]× θ, r_i the centred arm) and
    Σ the antennas' noise covariance, N the number of antennas. With the default antennas
    (coplanar, level) five horizontal and one vertical degrees of freedom are left:
    (5 σ_h² + σ_v²) / 4.

    Examples
    --------
    >>> round(residual_ms(np.array(DEFAULT_ANTENNAS), 0.01, 0.015) / 1e-4, 6)  # (5 + 2.25)/4 cm²
    1.8125
    """
    arms = np.asarray(arms, dtype=float)
    n = len(arms)
    jac = np.vstack([np.hstack((np.eye(3), -skew(r))) for r in arms - arms.mean(axis=0)])
    proj = jac @ np.linalg.pinv(jac)
    sigma2 = np.tile([sigma_h ** 2, sigma_h ** 2, sigma_v ** 2], n)
    return float(np.sum((1.0 - np.diag(proj)) * sigma2) / n)


def receiver_params(params: GnssAccFusionParams) -> GnssAccFusionParams:
    """The parameters the filter runs with for ``attitude="input"`` (module docstring, item 5).

    The specific force arrives in NED and the fix at the accelerometer point, so there is no
    correction (``attitude_correction=False``, a_n = f_n + g_n), no lever arm and a held
    identity attitude (``propagation="hold"``); the fix is the rigid set
    :data:`RECEIVER_ANTENNAS` about the point. Its four antennas carry the receiver's one
    error, so their noise is twice the receiver's: the centroid of four independent antennas
    would have σ/2 (:mod:`.error_model`). The rigid set has no attitude error, so the fix
    attitude's share of ``pos_std`` is nil.
    """
    return replace(params, attitude="antennas", attitude_correction=False, propagation="hold",
                   acc_lever_arm=(0.0, 0.0, 0.0), antennas=RECEIVER_ANTENNAS,
                   antenna_sigma_h=2.0 * params.antenna_sigma_h, antenna_sigma_v=2.0 * params.antenna_sigma_v)


class GnssAccFusion:
    """Attitude-corrected GNSS + accelerometer Kalman fusion (paper 001), one sample per step.

    Parameters
    ----------
    params : GnssAccFusionParams
        Validated parameters.

    Examples
    --------
    >>> est = GnssAccFusion(GnssAccFusionParams(propagation="hold"))
    >>> arms = np.array(DEFAULT_ANTENNAS)
    >>> r = est.step([0.0, 0.0, -9.80665], arms, 0.01)   # level, at the origin
    >>> r.fix, round(abs(r.pos[0]), 9)
    ('accepted', 0.0)
    """

    def __init__(self, params: GnssAccFusionParams | None = None) -> None:
        self.params = params or GnssAccFusionParams()
        #: The parameters the filter runs with: :attr:`params`, or for ``attitude="input"``
        #: their one-receiver form (:func:`receiver_params`).
        self.run_params = self.params if self.params.attitude == "antennas" else receiver_params(self.params)
        self.reset()

    def reset(self) -> None:
        """Forget everything: the next good GNSS fix initialises the filter."""
        p = self.run_params
        self.angles: np.ndarray | None = None  # the last good roll, pitch, yaw input (attitude="input")
        nx = 9 if p.bias_states else 6
        self.kf = KalmanFilter(dim_x=nx, dim_z=3)
        self.kf.H = np.hstack((np.eye(3), np.zeros((3, nx - 3))))
        self.initialised = False
        self.q = np.array([1.0, 0.0, 0.0, 0.0])  # attitude R_nb used for the correction
        self.gyro_bias = np.zeros(3)
        self.q_coast = self.q.copy()             # the coast's attitude and gyro bias (coast_attitude_tau)
        self.coast_bias = np.zeros(3)
        self.last_acc = np.array([0.0, 0.0, -GRAVITY_N[2]])
        self.last_gyro: np.ndarray | None = None
        self.since_fix = math.inf  # time since the last accepted fix [s]
        self.since_epoch = 0.0  # time since the last GNSS epoch of any kind [s]
        self.rejecting = 0.0  # time spent rejecting consecutive fixes [s]
        self.prior: tuple[np.ndarray, np.ndarray] | None = None  # (x⁻, P⁻) of this step, for smoothing
        self._model_dt: float | None = None  # Φ, G, Q below are built for this step size
        self.residual = 0.0
        self.acc_n = np.zeros(3)
        # tilt states need the coast's own gyro attitude, whose errors they track
        tilt = ((p.gyro_bias_sigma, p.gyro_bias_tau, p.gyro_noise) if (p.coast_tilt and p.attitude_correction)
                else None)
        self.coaster = (WaveCoast(p.coast_window, tilt=tilt, tilt_band=p.coast_tilt_band and tilt is not None)
                        if p.coast == "band" else None)
        # the coast corrects its acceleration with its own gyro attitude (coast_attitude_tau)
        # when there is a correction and a gyro; otherwise it takes acc_n
        self.coast_attitude = self.coaster is not None and p.attitude_correction
        self.fix_interval = math.inf  # usual interval between accepted fixes [s] (HOLD_OVERDUE)
        self.since_pseudo = 0.0  # time since the last wave-model pseudo-fix [s]
        # noise_sizing="auto" (_sized_r): the last intervals between epochs [s], whether an
        # epoch has been seen, the running mean of the fit residual's square [m²] and its count
        self.intervals: list[float] = []
        self.epochs_seen = False
        self.noise_ms = 0.0
        self.noise_count = 0
        self.r_used = self.params.r  # the r of the latest epoch [m²·s]
        self.residual_ref = residual_ms(p.arms, *SIGMA_REF)
        self.coast_var: np.ndarray | None = None  # coast position variance at the last pseudo-fix [m²]
        self.coast_track: np.ndarray | None = None  # mean square of the pseudo-fix innovations [m²]
        # the covariance of the error as the filter runs, for pos_std outside gaps
        self.error = FusionError(p.arms, np.asarray(p.acc_lever_arm), p.acc_noise, p.gyro_noise, (p.antenna_sigma_h, p.antenna_sigma_v),
                                 p.gyro_bias_sigma, p.gyro_bias_tau, p.attitude_tau if p.propagation == "gyro" else None,
                                 p.attitude_correction)

    # ---- per step ----------------------------------------------------------------------------
    def step(self, acc: Any, gnss: Any | None, dt: float, gyro: Any | None = None,
             euler: Any | None = None) -> GnssAccFusionResult:
        """Advance by one accelerometer sample.

        Parameters
        ----------
        acc : array_like
            (3,) specific force at the accelerometer, body frame [m/s²].
        gnss : array_like or None
            (4, 3) or (12,) antenna positions of a GNSS epoch that arrived this step, NED [m];
            with ``attitude="input"`` (3,) the receiver's position (antenna 1; of a (4, 3) or
            (12,) array the first antenna is read). None when there is no new epoch.
        dt : float
            Step [s] since the previous sample.
        gyro : array_like, optional
            (3,) angular rate, body frame [rad/s] (``propagation="gyro"``; with ``"hold"`` the
            coast through a gap; with ``attitude="input"`` the COG velocity's lever-arm term).
        euler : array_like, optional
            (3,) roll, pitch, yaw [rad] (ZYX) with ``attitude="input"``; ignored otherwise.
            None, non-finite or beyond the limits of
            :func:`~marinefmu.estimators.samples.angles_beyond_limit`: a bad sample.
        """
        if self.params.attitude == "antennas":
            return self._step(acc, gnss, dt, gyro)
        f_n, fix, bad = self._receiver_inputs(acc, gnss, euler, gyro)
        return self._receiver_output(self._step(f_n, fix, dt, gyro, bad))

    def _receiver_inputs(self, acc: Any, gnss: Any | None, euler: Any | None,
                         gyro: Any | None) -> tuple[Any, np.ndarray | None, str | None]:
        """``attitude="input"``: the specific force rotated into NED by the input angles (roll
        and pitch turned forward over ``attitude_lag``), the fix moved to the accelerometer
        point as the rigid set of :func:`receiver_params`, and the reason if the angles are bad
        (the fix is then placed with the last good ones, and dropped before any)."""
        ang = np.full(3, math.nan) if euler is None else np.asarray(euler, dtype=float).reshape(3)
        if not np.all(np.isfinite(ang)):
            bad = "bad roll, pitch or yaw input (NaN/Inf)"
        else:
            bad = (why := angles_beyond_limit(ang)) and f"bad angle input: {why}"
        if bad is None:
            w = self._lag_rate(gyro)
            if w is not None:   # the roll and pitch of attitude_lag ago, turned to now; the yaw as given
                roll, pitch, _ = quat_to_euler(propagate(euler_to_quat(*ang), w, self.params.attitude_lag))
                ang = np.array([roll, pitch, ang[2]])
            self.angles = ang
        else:
            bad += ": coasting on the last good specific force"
        rot = None if self.angles is None else rot_nb(*self.angles)
        f_n = acc if bad is not None else rot @ np.asarray(acc, dtype=float).reshape(3)
        if gnss is None or rot is None:
            return f_n, None, bad
        p = self.params
        point = np.asarray(gnss, dtype=float).reshape(-1, 3)[0] + rot @ (np.asarray(p.acc_lever_arm) - p.arms[0])
        return f_n, point + self.run_params.arms, bad

    def _lag_rate(self, gyro: Any | None) -> np.ndarray | None:
        """The body rate [rad/s] over this step that turns the input attitude over
        ``attitude_lag`` (as the filter takes it: ``step_input``), or None without a lag or a
        good gyro sample."""
        if self.params.attitude_lag == 0.0 or gyro is None:
            return None
        w = np.asarray(gyro, dtype=float).reshape(3)
        if not rate_sample_good(w):
            w = self.last_gyro     # a bad sample: the step's warning comes from the filter
        if w is None or self.params.step_input == "latest" or self.last_gyro is None:
            return w
        return 0.5 * (self.last_gyro + w)

    def _receiver_output(self, r: GnssAccFusionResult) -> GnssAccFusionResult:
        """``attitude="input"``: the accelerometer point's estimate moved to the COG with the
        last good input angles, which are the ``euler`` output."""
        if self.angles is None:
            return r
        rot = rot_nb(*self.angles)
        arm = np.asarray(self.params.acc_lever_arm)
        pos, vel = np.array(r.pos), np.array(r.vel)
        if self.initialised:
            pos -= rot @ arm
            if self.last_gyro is not None:
                vel -= rot @ cross3(self.last_gyro, arm)
        return replace(r, pos=tuple(pos.tolist()), vel=tuple(vel.tolist()), euler=tuple(self.angles.tolist()))

    def _step(self, acc: Any, gnss: Any | None, dt: float, gyro: Any | None = None,
              bad: str | None = None) -> GnssAccFusionResult:
        """:meth:`step` with :attr:`run_params`; ``bad``: the reason this step's specific force
        is not to be used (it coasts on the last good one, as on a bad sample)."""
        p = self.run_params
        warning = None
        f_b = np.asarray(acc, dtype=float).reshape(3)
        good = bad is None and force_sample_good(f_b)
        if not good:
            warning = bad or "bad accelerometer sample (NaN/Inf/absurd): coasting on the last good one"
            f_b = self.last_acc
        self.last_acc = f_b
        w = None if gyro is None else np.asarray(gyro, dtype=float).reshape(3)
        if w is not None and not rate_sample_good(w):
            warning = warning or "bad gyro sample (NaN/Inf/absurd): holding the last good rate"
            good = False
            w = self.last_gyro
        w_prev = self.last_gyro if self.last_gyro is not None else w
        if w is not None:
            self.last_gyro = w
        if w is not None:
            w_step = w if p.step_input == "latest" else 0.5 * (w_prev + w)
            if p.propagation == "gyro":
                self.q = propagate(self.q, w_step - self.gyro_bias, dt)
            if self.coast_attitude:
                self.q_coast = propagate(self.q_coast, w_step - self.coast_bias, dt)
                if p.propagation == "hold" and self.since_fix > HOLD_OVERDUE * self.fix_interval:
                    self.q = self.q_coast.copy()    # no fix to hold: the gyro's attitude
        rot, q_rot = quat_to_rot(self.q), self.q
        start = self.acc_n if self.initialised else None  # a_n at the start of the step
        self.acc_n = (rot @ f_b if p.attitude_correction else f_b) + GRAVITY_N
        u = self.acc_n if p.step_input == "latest" or start is None else 0.5 * (start + self.acc_n)
        self.since_fix += dt
        self.since_epoch += dt
        self.prior = None
        if self.initialised and self._holding():
            self.kf.x[3:6] = 0.0  # no fix and no coast for max_coast s: hold the position
        elif self.initialised:
            if dt != self._model_dt:  # rebuilt only when the step size changes
                self.kf.F, self.kf.B = transition(dt, p.bias_states)
                self.kf.Q = process_noise(dt, p.q, p.bias_rw if p.bias_states else None, p.q_down)
                full = process_noise(dt, self.error.q_true, p.bias_rw if p.bias_states else None)
                acc_part = np.zeros_like(full)
                acc_part[:6, :6] = full[:6, :6]
                self.error.set_model(self.kf.F, self.kf.B, acc_part, full - acc_part, dt)
                self._model_dt = dt
            self.kf.predict(u=u.reshape(3, 1))
            self.error.predict()
            self.prior = (self.kf.x.copy(), self.kf.P.copy())
        if self.coaster is not None and self.initialised:
            if self._coast_gyro():
                rot_c = quat_to_rot(self.q_coast)
                self.coaster.add(rot_c @ f_b + GRAVITY_N, dt, rot_c)
            else:
                self.coaster.add(self.acc_n, dt, rot)
        fix = ""
        if gnss is not None:
            fix, why = self._epoch(gnss, dt)
            warning = warning or why
        if not fix and self._pseudo_fix(dt):
            fix = "wave"
        # a refused epoch (bad coordinates, poor fit, gated outlier) is a bad sample like a bad
        # accelerometer one: the output coasts and is flagged for that step
        valid = (good and fix not in ("skipped", "rejected") and self.initialised and self.since_fix <= p.max_coast
                 and not self._stale_attitude())
        # the output's rotation is this one unless a fix has turned the attitude since (every
        # change of q assigns a new array)
        return self._result(fix, valid, warning, w, rot if self.q is q_rot else None)

    def _epoch(self, gnss: Any, dt: float) -> tuple[str, str | None]:
        p = self.run_params
        gap, self.since_epoch = self.since_epoch, 0.0
        sol = antenna_attitude(np.asarray(gnss, dtype=float), p.arms)
        if isinstance(sol, str):
            return "skipped", f"GNSS epoch skipped: {sol}"
        self.residual = sol.residual
        if sol.residual > p.max_residual:
            return "skipped", f"GNSS epoch skipped: antenna fit residual {sol.residual:.3f} m > max_residual {p.max_residual} m"
        # the accelerometer point seen by GNSS; the lever arm is rotated with the propagated
        # attitude (a single fix's attitude noise, ~1 mrad, would add ~1 cm over a 10 m arm)
        # from the antenna centroid, the shortest arm (the fix's COG carries its attitude noise
        # times the centroid's arm). A (re)start uses the fix's own attitude: after a long gap
        # the propagated one is off by centiradians, decimetres over the arm.
        arm = np.asarray(p.acc_lever_arm) - p.arms.mean(axis=0)
        # after a gap longer than max_coast the output has been invalid for a while and the
        # coasted attitude and accelerometer bias are not worth keeping (after a 5-min gap
        # centiradians and centimetres per second squared off, slow to settle), nor the velocity
        # of an inertial coast (an update would pull the position but keep a metres-per-second
        # error, and gate out the next fixes). The velocity that the wave coast held (decimetres
        # per second off at most) is kept: a restart at rest errs decimetres in the first
        # seconds (docs/decisions/gnss-fusion-filter.md).
        restart = not self.initialised or self.since_fix > p.max_coast
        rot_arm = sol.rot if p.propagation == "hold" or restart else quat_to_rot(self.q)
        z = sol.centroid + rot_arm @ arm
        r_meas = np.eye(3) * (self._sized_r(gap, sol.residual) / dt)  # eq. 17
        if restart:
            gap_s, first = self.since_fix, not self.initialised
            bridged = not first and self.since_pseudo <= p.max_coast
            self._initialise(sol, z, r_meas, bridged)
            return "accepted", None if first else (f"GNSS back after {gap_s:.0f} s without a fix (> max_coast): "
                                                   "filter re-initialised on GNSS" +
                                                   (", velocity kept from the wave coast" if bridged else ""))
        if self.coast_var is not None:
            # the pseudo-fixes' error is one slowly growing error, which the filter took as
            # independent samples: its covariance goes back in before GNSS is weighed again
            self.kf.P[:3, :3] += np.diag(self.coast_var)
            self.coast_var = self.coast_track = None
            self.error.follow(self.kf.P)
        att_std = antenna_attitude_std(p.arms, sol.rot, p.antenna_sigma_h, p.antenna_sigma_v)
        held_std = att_std if p.propagation == "hold" else None
        y = z - self.kf.H @ self.kf.x.ravel()
        s = self.kf.H @ self.kf.P @ self.kf.H.T + r_meas
        # the gate weighs the innovation against at least the size that the error's covariance
        # expects: the filter's own does not know the rotation since the fix of a held attitude
        # (module docstring, item 3)
        expected = self.error.innovation_var(self.kf.H, rot_arm, held_std)
        s[np.diag_indices(3)] = np.maximum(np.diag(s), expected)
        d = math.sqrt(float(y @ np.linalg.solve(s, y)))
        if d > p.gate:
            self.rejecting += gap
            if self.rejecting >= p.reinit_time:
                self._initialise(sol, sol.centroid + sol.rot @ arm, r_meas)
                return "accepted", f"GNSS fixes rejected for {p.reinit_time} s: filter re-initialised on GNSS"
            return "rejected", f"GNSS epoch rejected: innovation {d:.1f} sigma > gate {p.gate}"
        self.kf.update(z, R=r_meas)
        since = min(self.since_fix, 1e9)
        self.error.fix(y, self.kf.K, self.kf.H, since, rot_arm, held_std, expected)
        if self.coaster is not None:
            self.coaster.anchor(z)
        self._correct_attitude(sol.rot, since, att_std)
        if since < HOLD_OVERDUE * self.fix_interval:
            self.fix_interval = since
        if self._coast_gyro():
            rot_c, bias_c = quat_to_rot(self.q_coast), self.coast_bias.copy()
            if self.coaster.tilt is not None:
                self.coaster.attitude_fix(np.array(matrix_rotvec(sol.rot @ rot_c.T)), att_std)
            self.q_coast, self.coast_bias = pi_pull(self.q_coast, self.coast_bias, sol.rot, since, p.coast_attitude_tau)
            if self.coaster.tilt is not None:
                # true = exp(e)·R = exp(e')·R' → e' = e + rotvec(R R'ᵀ); δ = −R(b − b̂)
                d_eps = np.array(matrix_rotvec(rot_c @ quat_to_rot(self.q_coast).T))
                self.coaster.shift_tilt(d_eps, rot_c @ (self.coast_bias - bias_c))
        self.since_fix = 0.0
        self.rejecting = 0.0
        return "accepted", None

    def _sized_r(self, gap: float, residual: float) -> float:
        """The r of eq. 17 for this epoch [m²·s]: ``r`` itself (``noise_sizing="fixed"``), or
        sized from the data (``"auto"``):

        r_k = r · (T_ref / T̂) · clip(m̂ / m_ref, :data:`NOISE_FACTOR_RANGE`),

        with T̂ the median of the last :data:`INTERVAL_MEMORY` intervals between GNSS epochs
        [s] (T_ref = :data:`FIX_INTERVAL_REF` until one is seen), m̂ the running mean of the
        antenna-fit residual's square (:attr:`~.antenna_attitude.AntennaFix.residual`², the
        mean over the antennas of the squared 3-D residual) over the last
        :data:`NOISE_MEMORY` usable epochs, and m_ref its expectation at the reference noise
        :data:`SIGMA_REF` (:func:`residual_ms`). Why: R·T, the fix noise per unit time, sets
        the blend of fixes and accelerometer, so a receiver ``k`` times faster with the same
        noise gets R ``k`` times larger (``r`` = 1e-5 at 1 Hz, 5e-5 at 5 Hz; the system
        scenario's best was 4.5e-5 there), and a receiver ``s`` times noisier in variance
        gets R ``s`` times larger. With one receiver (``attitude="input"``) the fit has no
        residual: the noise factor is 1. The intervals are those of ``gap``, the time since
        the previous epoch [s] (the first epoch's is not an interval), ``residual`` this
        epoch's [m].
        """
        p = self.params
        if p.noise_sizing == "fixed":
            self.r_used = p.r
            return p.r
        if self.epochs_seen:
            self.intervals = (self.intervals + [gap])[-INTERVAL_MEMORY:]
        self.epochs_seen = True
        interval = float(np.median(self.intervals)) if self.intervals else FIX_INTERVAL_REF
        factor = 1.0
        if p.attitude == "antennas":
            self.noise_count = min(self.noise_count + 1, NOISE_MEMORY)
            self.noise_ms += (residual ** 2 - self.noise_ms) / self.noise_count
            factor = min(max(self.noise_ms / self.residual_ref, NOISE_FACTOR_RANGE[0]), NOISE_FACTOR_RANGE[1])
        self.r_used = p.r * FIX_INTERVAL_REF / max(interval, 1e-6) * factor
        return self.r_used

    def _coast_gyro(self) -> bool:
        """The coast corrects its acceleration with its own gyro attitude (a correction, a band
        coast, and a gyro sample seen)."""
        return self.coast_attitude and self.last_gyro is not None

    def _stale_attitude(self) -> bool:
        """A held attitude with no fix to hold and no gyro attitude to follow (no gyro, or no
        band coast to keep one; module docstring, item 2): the acceleration is then turned by
        an attitude that the vessel has left, and the output is not valid. The wave coast
        still bounds the drift (metres through a 30 s dropout, against hundreds of metres
        without the coast), but neither it nor ``pos_std`` knows the attitude's error then."""
        return (self.run_params.propagation == "hold" and not self._coast_gyro()
                and self.since_fix > HOLD_OVERDUE * self.fix_interval)

    def _holding(self) -> bool:
        """No accepted fix and no pseudo-fix for ``max_coast`` s: the position is held (an
        inertial coast is kilometres off after minutes, and ``valid`` is false by then)."""
        p = self.run_params
        return self.since_fix > p.max_coast and self.since_pseudo > p.max_coast

    def _pseudo_fix(self, dt: float) -> bool:
        """In a GNSS gap, update the filter with the wave-model coast position once every
        :data:`COAST_INTERVAL` s (``coast="band"``); True if it did."""
        self.since_pseudo += dt
        # 1 µs of slack: ten steps of 0.01 s add up to 0.09999999999999999 s
        if (self.coaster is None or not self.initialised or self.since_fix < COAST_AFTER - 1e-6
                or self.since_pseudo < COAST_INTERVAL - 1e-6):
            return False
        z = self.coaster.position()
        if z is None:
            return False
        self.coast_var = self.coaster.position_std() ** 2
        # how far the filter strays from the coast between pseudo-fixes (pos_std in a gap)
        y2 = (z - self.kf.H @ self.kf.x.ravel()) ** 2
        self.coast_track = y2 if self.coast_track is None else self.coast_track + TRACK_WEIGHT * (y2 - self.coast_track)
        self.kf.update(z, R=np.diag(self.run_params.coast_sigma ** 2 + self.coast_var))
        self.error.follow(self.kf.P)
        self.since_pseudo = 0.0
        return True

    def _initialise(self, sol: AntennaFix, z: np.ndarray, r_meas: np.ndarray, keep_velocity: bool = False) -> None:
        """Start the filter on a fix: position ``z``, velocity 0 ± 1 m/s or (``keep_velocity``)
        the coasted one with its variance plus the wave coast's, bias 0 ± 0.01 m/s²."""
        p = self.run_params
        nx = self.kf.dim_x
        var = np.array([r_meas[0, 0]] * 3 + [1.0] * 3 + ([1e-4] * 3 if p.bias_states else []))
        x = np.zeros((nx, 1))
        x[:3, 0] = z
        if keep_velocity:
            x[3:6] = self.kf.x[3:6]
            var[3:6] = np.diag(self.kf.P)[3:6] + self.coaster.velocity_std() ** 2
        if self.coaster is not None:
            self.coaster.forget_position()
        self.prior = None  # a restart: nothing to smooth across
        self.kf.x = x
        self.kf.P = np.diag(var)
        self.error.start(self.kf.P, antenna_attitude_std(p.arms, sol.rot, p.antenna_sigma_h, p.antenna_sigma_v), sol.rot)
        self.q = Rotation.from_matrix(sol.rot).as_quat(scalar_first=True)
        self.q_coast = self.q.copy()
        self.coast_var = self.coast_track = None
        self.initialised = True
        self.since_fix = 0.0
        self.rejecting = 0.0

    def _correct_attitude(self, rot_fix: np.ndarray, dt_fix: float, fix_std: np.ndarray) -> None:
        """PI pull of the propagated attitude towards the fix (``gyro``), or a reset (``hold``);
        ``fix_std`` the fix attitude's standard deviations [rad, NED].

        Beyond a plain PI, each axis's proportional gain is at most the one-step Kalman gain of
        the attitude error's covariance (:meth:`~.error_model.FusionError.attitude_gain`). At
        steady rate the PI's own is the smaller (1 Hz, τ 30 s: 0.067 against 0.1-0.6), so
        nothing changes there; after a gap of τ/2 or more the PI's is 1, which hands the fix's
        attitude noise (1.9 mrad about N on the paper-001 set-up, 1.9 cm at the COG over the 10 m
        arm) to the output whole. The cap lowers the error in the first half minute after a
        gap and changes nothing before it (docs/decisions/gnss-fusion-filter.md).
        """
        p = self.run_params
        if p.propagation == "hold":
            if dt_fix <= HOLD_OVERDUE * self.fix_interval:     # held since the last fix (not the gyro's)
                self.error.held_rotation(np.array(matrix_rotvec(rot_fix @ quat_to_rot(self.q).T)), dt_fix, fix_std)
            self.q = Rotation.from_matrix(rot_fix).as_quat(scalar_first=True)
            return      # the error's ε was reset with the fix's position (FusionError.fix)
        alpha = np.minimum(pi_gains(dt_fix, p.attitude_tau)[0], self.error.attitude_gain(fix_std))
        self.q, self.gyro_bias = pi_pull(self.q, self.gyro_bias, rot_fix, dt_fix, p.attitude_tau, alpha)
        self.error.attitude_fix(fix_std, dt_fix, alpha)

    def _result(self, fix: str, valid: bool, warning: str | None, w: np.ndarray | None,
                rot: np.ndarray | None = None) -> GnssAccFusionResult:
        """The step's output; ``rot``: R_nb of the current ``q`` when already computed. On
        Python floats (every step; a 3 × 3 product is fewer operations than a numpy call's
        overhead): pos = x − R̂ l, vel = v − R̂ ((ω − b) × l)."""
        p = self.run_params
        rot = quat_to_rot(self.q) if rot is None else rot
        x = self.kf.x.ravel().tolist()
        (a, b, c), (d, e, f), (g, h, i) = rot.tolist()
        l0, l1, l2 = p.acc_lever_arm
        arm = (a * l0 + b * l1 + c * l2, d * l0 + e * l1 + f * l2, g * l0 + h * l1 + i * l2)
        vel = (x[3], x[4], x[5])
        if self.initialised:
            pos = (x[0] - arm[0], x[1] - arm[1], x[2] - arm[2])
            if w is not None:
                u0, u1, u2 = (w - self.gyro_bias).tolist()
                k0, k1, k2 = u1 * l2 - u2 * l1, u2 * l0 - u0 * l2, u0 * l1 - u1 * l0     # (ω − b) × l
                vel = (vel[0] - (a * k0 + b * k1 + c * k2), vel[1] - (d * k0 + e * k1 + f * k2),
                       vel[2] - (g * k0 + h * k1 + i * k2))
            if self.coast_var is None:     # the error as the filter runs (error_model)
                var = self.error.position_var(rot, arm)
            else:   # in a gap: the coast's own, and how far the output strays from it (module docstring)
                var = (self.coast_var + self.coast_track).tolist()
            std = (math.sqrt(var[0]), math.sqrt(var[1]), math.sqrt(var[2]))
        else:                              # valid is False then
            pos = std = (0.0, 0.0, 0.0)
        bias = (x[6], x[7], x[8]) if p.bias_states else (0.0, 0.0, 0.0)
        return GnssAccFusionResult(pos, vel, std, quat_to_euler(self.q), tuple(self.acc_n.tolist()), bias,
                                   self.residual, fix, valid, warning)

    # ---- FMU state ---------------------------------------------------------------------------
    def get_state(self) -> dict:
        """JSON-serialisable internal state."""
        return {
            "x": self.kf.x.tolist(), "P": self.kf.P.tolist(), "initialised": self.initialised,
            "q": self.q.tolist(), "gyro_bias": self.gyro_bias.tolist(), "last_acc": self.last_acc.tolist(),
            "q_coast": self.q_coast.tolist(), "coast_bias": self.coast_bias.tolist(),
            "last_gyro": None if self.last_gyro is None else self.last_gyro.tolist(), "since_fix": self.since_fix, "rejecting": self.rejecting,
            "residual": self.residual, "acc_n": self.acc_n.tolist(),
            "since_epoch": self.since_epoch, "since_pseudo": self.since_pseudo,
            "fix_interval": None if math.isinf(self.fix_interval) else self.fix_interval,
            "coast_var": None if self.coast_var is None else self.coast_var.tolist(),
            "coast_track": None if self.coast_track is None else self.coast_track.tolist(),
            "coaster": None if self.coaster is None else self.coaster.get_state(),
            "error": self.error.get_state(),
            "angles": None if self.angles is None else self.angles.tolist(),
            "intervals": list(self.intervals), "epochs_seen": self.epochs_seen,
            "noise_ms": self.noise_ms, "noise_count": self.noise_count, "r_used": self.r_used,
        }

    def set_state(self, s: dict) -> None:
        """Restore a state from :meth:`get_state`."""
        self.kf.x, self.kf.P = np.array(s["x"]), np.array(s["P"])
        self.initialised = bool(s["initialised"])
        self.q, self.gyro_bias = np.array(s["q"]), np.array(s["gyro_bias"])
        self.q_coast, self.coast_bias = np.array(s["q_coast"]), np.array(s["coast_bias"])
        self.last_acc = np.array(s["last_acc"])
        self.last_gyro = None if s["last_gyro"] is None else np.array(s["last_gyro"])
        self.since_fix, self.rejecting = float(s["since_fix"]), float(s["rejecting"])
        self.residual, self.acc_n = float(s["residual"]), np.array(s["acc_n"])
        self.since_epoch = float(s["since_epoch"])
        self.fix_interval = math.inf if s.get("fix_interval") is None else float(s["fix_interval"])
        self.since_pseudo = float(s["since_pseudo"])
        self.coast_var = None if s["coast_var"] is None else np.array(s["coast_var"])
        self.coast_track = None if s.get("coast_track") is None else np.array(s["coast_track"])
        if self.coaster is not None:
            self.coaster.set_state(s["coaster"])
        self.error.set_state(s["error"])
        self.angles = None if s.get("angles") is None else np.array(s["angles"])
        self.intervals = [float(x) for x in s.get("intervals", [])]
        self.epochs_seen = bool(s.get("epochs_seen", False))
        self.noise_ms, self.noise_count = float(s.get("noise_ms", 0.0)), int(s.get("noise_count", 0))
        self.r_used = float(s.get("r_used", self.params.r))
