"""Every FMU's variable table, and the mapping from FMI values to each model's parameter object.

The estimator and AHC tables are defined here, kept out of ``estimators/`` and ``ahc/``, which
must not know about FMI names. VesselMotion's table is its truth model's record schema (the
model's output vector and :func:`~marinefmu.sea.motion_model.simulate_record` are keyed by it),
so it is defined in :mod:`marinefmu.sea.motion_model` and re-exported here as
``VESSEL_PARAMETERS``, ``VESSEL_REAL_OUTPUTS`` and ``VESSEL_BOOLEAN_OUTPUTS``.
"""
from __future__ import annotations

from dataclasses import replace
from typing import Any

from ..estimators.attitude.estimator import AID_SIZINGS, INIT_CHOICES, AttitudeEstimatorParams
from ..estimators.centre_of_rotation.filter import ANGLE_CHOICES as CR_ANGLE_CHOICES
from ..estimators.centre_of_rotation.filter import DIFF_SIZINGS as CR_DIFF_SIZINGS
from ..estimators.centre_of_rotation.filter import CentreOfRotationParams
from ..estimators.heave.band_bank import BAND_VARIANCES
from ..estimators.heave.common import MODEL_CHOICES, TRANSFER_CHOICES, VERTICAL_CHOICES, HeaveObserverParams
from ..estimators.heave.oscillator_bank import DISCRETISATIONS, MEASUREMENTS
from ..estimators.gnss_fusion.antenna_attitude import ANTENNAS
from ..errors import ParameterError
from ..estimators.mru.params import MAX_ARM, MAX_POINTS, MotionReferenceUnitParams, check_arm
from ..estimators.gnss_fusion.filter import ATTITUDE_CHOICES as FUSION_ATTITUDE_CHOICES
from ..estimators.gnss_fusion.filter import NOISE_SIZINGS as FUSION_NOISE_SIZINGS
from ..estimators.gnss_fusion.filter import COAST_CHOICES, PROPAGATION_CHOICES, STEP_INPUT_CHOICES, GnssAccFusionParams
from ..estimators.reconstruction.decomposition import TILT_CHOICES
from ..estimators.reconstruction.sliding import DisplacementReconstructorParams
from ..ahc.controller import AhcControllerParams
from ..ahc.winch import AhcWinchParams
from ..sea.motion_model import BOOLEAN_OUTPUTS as VESSEL_BOOLEAN_OUTPUTS  # noqa: F401  (re-exported)
from ..sea.motion_model import PARAMETERS as VESSEL_PARAMETERS  # noqa: F401
from ..sea.motion_model import REAL_OUTPUTS as VESSEL_REAL_OUTPUTS  # noqa: F401
from ..variables import Variable, real, resolve, vec

_ATT = AttitudeEstimatorParams()
ATTITUDE_PARAMETERS: list[Variable] = [
    Variable("mode", "integer", 1, "", "0 gyro-only quaternion integration (paper 000), 1 drift-corrected (aided)"),
    Variable("init", "string", "level", "", f"Initial attitude: one of {', '.join(INIT_CHOICES)}"),
    real("init.roll", 0.0, "rad", "Initial roll for init = given"),
    real("init.pitch", 0.0, "rad", "Initial pitch for init = given"),
    real("init.yaw", 0.0, "rad", "Initial yaw (init = given or level)"),
    real("level_time", _ATT.level_time, "s", "Levelling time for init = level, 0.1..600"),
    real("gyro_noise", _ATT.gyro_noise, "rad/s/sqrt(Hz)", "Gyro white-noise density, (0, 1]"),
    real("acc_noise", _ATT.acc_noise, "m/s2/sqrt(Hz)", "Accelerometer white-noise density, (0, 10]"),
    real("gyro_bias_sigma", _ATT.gyro_bias_sigma, "rad/s", "Gyro bias standard deviation, (0, 1]"),
    real("gyro_bias_tau", _ATT.gyro_bias_tau, "s", "Gyro bias correlation time, 1..1e6"),
    Variable("aid_sizing", "string", _ATT.aid_sizing, "", f"Aiding size: one of {', '.join(AID_SIZINGS)} (auto: vel_sigma and pos_sigma sized from the measured motion, gyro_noise and gyro_bias_sigma from the gyro's measured noise; fixed: as given)"),
    real("vel_sigma", _ATT.vel_sigma, "m/s", "Zero-velocity pseudo-measurement standard deviation (aid_sizing = fixed; the start of auto), (0, 100]"),
    real("pos_sigma", _ATT.pos_sigma, "m", "Zero-position pseudo-measurement standard deviation (aid_sizing = fixed; the start of auto), (0, 1000]"),
    real("aid_rate", _ATT.aid_rate, "Hz", "Pseudo-measurement rate, (0, 100]"),
]
ATTITUDE_INPUTS: list[Variable] = [
    *vec("gyro", "xyz", 0.0, "rad/s", "Angular rate, body frame"),
    *vec("acc", "xyz", (0.0, 0.0, -9.80665), "m/s2", "Specific force, body frame"),
]
ATTITUDE_OUTPUTS: list[Variable] = [
    real("roll", 0.0, "rad", "Estimated roll (ZYX Euler)"),
    real("pitch", 0.0, "rad", "Estimated pitch (ZYX Euler)"),
    real("yaw", 0.0, "rad", "Estimated yaw (ZYX Euler; gyro-integrated, drifts without a heading aid)"),
    *vec("q", "wxyz", (1.0, 0.0, 0.0, 0.0), "", "Unit quaternion of R_nb (body to NED)"),
    *vec("gyro_bias", "xyz", 0.0, "rad/s", "Estimated gyro bias, body frame (z not observable)"),
]
ATTITUDE_BOOLEANS: list[Variable] = [
    Variable("valid", "boolean", False, "", "False while levelling, on a rejected (NaN/Inf/absurd) sample, and after a gyro gap until the aid has removed its coast error"),
]

_SL = DisplacementReconstructorParams()
RECONSTRUCTOR_PARAMETERS: list[Variable] = [
    real("window", _SL.window, "s", "Sliding window length, >= 2/cutoff, <= 3600"),
    real("hop", _SL.hop, "s", "Refit interval, (0, window]"),
    real("cutoff", _SL.cutoff, "Hz", "Screening frequency F (paper 000 eq. 25), (0, Nyquist)"),
    Variable("max_components", "integer", _SL.max_components, "", "Most complex-exponential components per axis, 1..2000"),
    *vec("lever_arm", "xyz", 0.0, "m", "Sensor position relative to the COG, body frame"),
    real("fmax", _SL.fmax, "Hz", "Highest motion frequency (decimation), (cutoff, Nyquist]"),
    Variable("tilt", "string", _SL.tilt, "", f"Tilt correction: one of {', '.join(TILT_CHOICES)}"),
    real("max_damping", _SL.max_damping, "", "Screen components with |damping ratio| above this, (0, 1]"),
    real("sc_tol", _SL.sc_tol, "", "Relative residual stopping threshold, (0, 1)"),
]
RECONSTRUCTOR_INPUTS: list[Variable] = [
    *vec("acc", "xyz", (0.0, 0.0, -9.80665), "m/s2", "Specific force, body frame"),
    real("roll", 0.0, "rad", "Roll (ZYX Euler)"),
    real("pitch", 0.0, "rad", "Pitch (ZYX Euler)"),
    real("yaw", 0.0, "rad", "Yaw (ZYX Euler)"),
]
RECONSTRUCTOR_OUTPUTS: list[Variable] = [
    *vec("disp", "ned", 0.0, "m", "COG displacement at time - delay (the window centre), NED"),
    *vec("vel", "ned", 0.0, "m/s", "COG velocity at time - delay, NED"),
    real("delay", 0.5 * _SL.window, "s", "How late disp and vel are: window / 2"),
]
RECONSTRUCTOR_BOOLEANS: list[Variable] = [
    Variable("valid", "boolean", False, "", "False until the first window is full, on a rejected sample, and while >1 % of the fitted window was replaced"),
]


def attitude_params(values: dict[str, Any]) -> AttitudeEstimatorParams:
    """AttitudeEstimatorParams from FMI-named values."""
    v = resolve(ATTITUDE_PARAMETERS, values, "AttitudeEstimator")
    return AttitudeEstimatorParams(
        mode=v["mode"], init=v["init"], init_euler=(v["init.roll"], v["init.pitch"], v["init.yaw"]),
        level_time=v["level_time"], gyro_noise=v["gyro_noise"], acc_noise=v["acc_noise"],
        gyro_bias_sigma=v["gyro_bias_sigma"], gyro_bias_tau=v["gyro_bias_tau"], vel_sigma=v["vel_sigma"],
        pos_sigma=v["pos_sigma"], aid_rate=v["aid_rate"], aid_sizing=v["aid_sizing"],
    )


def sliding_params(values: dict[str, Any]) -> DisplacementReconstructorParams:
    """DisplacementReconstructorParams from FMI-named values."""
    v = resolve(RECONSTRUCTOR_PARAMETERS, values, "DisplacementReconstructor")
    return DisplacementReconstructorParams(
        window=v["window"], hop=v["hop"], cutoff=v["cutoff"], max_components=v["max_components"],
        lever_arm=(v["lever_arm.x"], v["lever_arm.y"], v["lever_arm.z"]), fmax=v["fmax"], tilt=v["tilt"],
        max_damping=v["max_damping"], sc_tol=v["sc_tol"],
    )


_FU = GnssAccFusionParams()
FUSION_PARAMETERS: list[Variable] = [
    Variable("attitude", "string", _FU.attitude, "", f"Attitude source: one of {', '.join(FUSION_ATTITUDE_CHOICES)} (the four antennas, or the roll/pitch/yaw inputs with one receiver on gnss.ant1 at ant1)"),
    real("attitude_lag", _FU.attitude_lag, "s", "With attitude = input: how long the roll and pitch inputs lag the accelerometer (one step for an estimator in the same co-simulation); turned forward with the gyro, [0, 1]"),
    *[v for i, arm in enumerate(_FU.antennas) for v in vec(f"ant{i + 1}", "xyz", arm, "m", f"GNSS antenna {i + 1} lever arm relative to the COG, body frame")],
    *vec("acc_lever_arm", "xyz", 0.0, "m", "Accelerometer position relative to the COG, body frame"),
    real("q", _FU.q, "m2/s3", "Acceleration process-noise density (paper 001 eq. 16), > 0"),
    real("q_down", _FU.q_down, "m2/s3", "Process-noise density of the down axis, > 0; 0 = the same as q (the paper)"),
    real("r", _FU.r, "m2*s", "GNSS position noise, R = r/dt (paper 001 eq. 17), > 0; with noise_sizing = auto the value for a 1 Hz receiver of 1 cm / 1.5 cm antenna noise"),
    Variable("noise_sizing", "string", _FU.noise_sizing, "", f"R from the data: one of {', '.join(FUSION_NOISE_SIZINGS)} (auto: r scaled by the measured epoch rate and antenna-fit residual; fixed: R = r/dt as given)"),
    Variable("attitude_correction", "boolean", True, "", "Rotate the specific force with the attitude (false: the paper's uncorrected case)"),
    Variable("propagation", "string", _FU.propagation, "", f"Attitude between GNSS epochs: one of {', '.join(PROPAGATION_CHOICES)} (gyro needs gyro.* inputs)"),
    Variable("step_input", "string", _FU.step_input, "", f"Acceleration and rate over a step: one of {', '.join(STEP_INPUT_CHOICES)} (mean of the two bounding samples, or the latest held as the paper)"),
    real("attitude_tau", _FU.attitude_tau, "s", "Time constant of the PI attitude correction, 0.1..1000"),
    real("gate", _FU.gate, "", "Mahalanobis innovation gate in standard deviations, > 0"),
    Variable("bias_states", "boolean", True, "", "Estimate an accelerometer bias per NED axis"),
    real("bias_rw", _FU.bias_rw, "m/s2/sqrt(s)", "Random-walk density of the bias states, (0, 10]"),
    real("max_residual", _FU.max_residual, "m", "Largest RMS antenna-fit residual of a usable fix, > 0"),
    real("reinit_time", _FU.reinit_time, "s", "Re-initialise on GNSS after rejecting fixes this long, > 0"),
    real("max_coast", _FU.max_coast, "s", "valid goes false this long after the last accepted fix (and without a coast the position is held), > 0"),
    Variable("coast", "string", _FU.coast, "", f"Through a GNSS gap: one of {', '.join(COAST_CHOICES)} (wave-model pseudo-fixes for a vessel on station or moving steadily, or prediction only)"),
    real("coast_sigma", _FU.coast_sigma, "m", "Standard deviation of a wave-model pseudo-fix, (0, 10]"),
    real("coast_attitude_tau", _FU.coast_attitude_tau, "s", "Time constant of the coast's own PI attitude (coast = band, propagation = gyro), 0.1..10000"),
    real("coast_window", _FU.coast_window, "s", "Memory of the drift model of coast = band, 10..3600"),
    Variable("coast_tilt", "boolean", _FU.coast_tilt, "", "Tilt-error states in the horizontal axes of coast = band (false: a loose offset takes the tilt)"),
    Variable("coast_tilt_band", "boolean", _FU.coast_tilt_band, "", "With coast_tilt: the tilt states also measured by the coast attitude's own tilt, the wave roll and pitch as a band (false: by the acceleration alone)"),
    real("gyro_bias_sigma", _FU.gyro_bias_sigma, "rad/s", "Gyro bias instability (Gauss-Markov standard deviation) for the tilt states, (0, 1]"),
    real("gyro_bias_tau", _FU.gyro_bias_tau, "s", "Gyro bias correlation time for the tilt states, 0.1..1e6"),
    real("antenna_sigma_h", _FU.antenna_sigma_h, "m", "Horizontal noise of one antenna position (the fix attitude's weight in the tilt states), (0, 100]"),
    real("antenna_sigma_v", _FU.antenna_sigma_v, "m", "Vertical noise of one antenna position, (0, 100]"),
    real("acc_noise", _FU.acc_noise, "m/s2/sqrt(Hz)", "Accelerometer white-noise density, for pos_std only (the filter blends with q), (0, 10]"),
    real("gyro_noise", _FU.gyro_noise, "rad/s/sqrt(Hz)", "Gyro white-noise density (angle random walk), for the tilt states and pos_std, (0, 1]"),
]
FUSION_INPUTS: list[Variable] = [
    *vec("acc", "xyz", (0.0, 0.0, -9.80665), "m/s2", "Specific force at the accelerometer, body frame"),
    *vec("gyro", "xyz", 0.0, "rad/s", "Angular rate, body frame (for propagation = gyro)"),
    *[v for i in range(ANTENNAS) for v in vec(f"gnss.ant{i + 1}", "ned", 0.0, "m", f"Measured position of GNSS antenna {i + 1}, NED")],
    real("roll", 0.0, "rad", "Roll (ZYX Euler) for attitude = input"),
    real("pitch", 0.0, "rad", "Pitch (ZYX Euler) for attitude = input"),
    real("yaw", 0.0, "rad", "Yaw (ZYX Euler; a compass heading) for attitude = input"),
    Variable("gnss.valid", "boolean", False, "", "True when the antenna positions hold a valid fix"),
    Variable("gnss.new", "boolean", False, "", "True on the step a new fix arrived (if unconnected, a change of the positions marks a new fix)"),
]
FUSION_OUTPUTS: list[Variable] = [
    *vec("pos", "ned", 0.0, "m", "Fused COG position, NED"),
    *vec("vel", "ned", 0.0, "m/s", "Fused COG velocity, NED"),
    *vec("pos_std", "ned", 0.0, "m", "Standard deviation of the fused position (the error covariance of the filter as run, with the sensor noises and the attitude error; in a gap the wave coast's own plus the output's spread about it), NED"),
    real("roll_used", 0.0, "rad", "Roll used for the correction (antennas, gyro-propagated; or the input)"),
    real("pitch_used", 0.0, "rad", "Pitch used for the correction"),
    real("yaw_used", 0.0, "rad", "Yaw used for the correction"),
    *vec("acc_n", "ned", 0.0, "m/s2", "Attitude-corrected acceleration at the accelerometer, NED"),
    *vec("acc_bias", "ned", 0.0, "m/s2", "Estimated accelerometer bias, NED"),
    real("gnss.residual", 0.0, "m", "RMS antenna-fit residual of the latest fix"),
]
FUSION_BOOLEANS: list[Variable] = [
    Variable("valid", "boolean", False, "", "Initialised, good sample, and an accepted GNSS fix within max_coast"),
    Variable("gnss.accepted", "boolean", False, "", "True on the step a GNSS fix was accepted"),
]


def fusion_params(values: dict[str, Any]) -> GnssAccFusionParams:
    """GnssAccFusionParams from FMI-named values."""
    v = resolve(FUSION_PARAMETERS, values, "GnssAccFusion")
    xyz = lambda prefix: tuple(v[f"{prefix}.{a}"] for a in "xyz")  # noqa: E731
    return GnssAccFusionParams(
        antennas=tuple(xyz(f"ant{i + 1}") for i in range(ANTENNAS)), acc_lever_arm=xyz("acc_lever_arm"),
        attitude=v["attitude"], attitude_lag=v["attitude_lag"], q=v["q"], q_down=v["q_down"] or None, r=v["r"],
        noise_sizing=v["noise_sizing"], attitude_correction=bool(v["attitude_correction"]), propagation=v["propagation"],
        step_input=v["step_input"], attitude_tau=v["attitude_tau"], gate=v["gate"], bias_states=bool(v["bias_states"]), bias_rw=v["bias_rw"],
        max_residual=v["max_residual"], reinit_time=v["reinit_time"], max_coast=v["max_coast"],
        coast=v["coast"], coast_sigma=v["coast_sigma"], coast_attitude_tau=v["coast_attitude_tau"],
        coast_window=v["coast_window"], coast_tilt=bool(v["coast_tilt"]),
        coast_tilt_band=bool(v["coast_tilt_band"]), gyro_bias_sigma=v["gyro_bias_sigma"],
        gyro_bias_tau=v["gyro_bias_tau"], antenna_sigma_h=v["antenna_sigma_h"], antenna_sigma_v=v["antenna_sigma_v"],
        acc_noise=v["acc_noise"], gyro_noise=v["gyro_noise"],
    )


_CR = CentreOfRotationParams()
CR_PARAMETERS: list[Variable] = [
    Variable("angles", "string", _CR.angles, "", f"Angle source: one of {', '.join(CR_ANGLE_CHOICES)} (high-pass integrated gyro as paper 002, or the roll/pitch/yaw inputs)"),
    real("hp_cutoff", _CR.hp_cutoff, "Hz", "Cutoff of the high-pass angle integration (paper 002 section 3.2), (0, 1]"),
    real("diff_window", _CR.diff_window, "s", "Savitzky-Golay window for the angular acceleration, (0, 10]; outputs lag by half of it; with diff_sizing = auto the window it starts with"),
    Variable("diff_sizing", "string", _CR.diff_sizing, "", f"Differentiation window: one of {', '.join(CR_DIFF_SIZINGS)} (sized from the gyro noise and the rotation as it runs, or diff_window throughout)"),
    Variable("centripetal", "boolean", _CR.centripetal, "", "Lever-arm term alpha x o + omega x (omega x o) (false: the paper's alpha x o)"),
    real("acc_sigma", _CR.acc_sigma, "m/s2", "Measurement noise of one specific-force sample, (0, 10]"),
    real("acc_rw", _CR.acc_rw, "m/s2/sqrt(s)", "Random-walk density of the CR acceleration states (paper 002 eq. 1), (0, 100]"),
    real("offset_rw", _CR.offset_rw, "m/sqrt(s)", "Random-walk density of the offset states, (0, 10]"),
    real("offset_sigma0", _CR.offset_sigma0, "m", "Initial standard deviation of the offset, (0, 1000]"),
    real("settle_time", _CR.settle_time, "s", "The offset is averaged after this time, [0, 1e6]"),
    *vec("sensor", "xyz", 0.0, "m", "Sensor position relative to the COG, body frame (for cr.*)"),
]
CR_INPUTS: list[Variable] = [
    *vec("acc", "xyz", (0.0, 0.0, -9.80665), "m/s2", "Specific force at the sensor, body frame"),
    *vec("gyro", "xyz", 0.0, "rad/s", "Angular rate, body frame"),
    real("roll", 0.0, "rad", "Roll (ZYX Euler), used when angles = input"),
    real("pitch", 0.0, "rad", "Pitch (ZYX Euler), used when angles = input"),
    real("yaw", 0.0, "rad", "Yaw (ZYX Euler), used when angles = input"),
]
CR_OUTPUTS: list[Variable] = [
    *vec("offset", "xyz", 0.0, "m", "Centre of rotation relative to the sensor, body frame"),
    *vec("offset_std", "xyz", 0.0, "m", "Standard deviation of the offset (filter covariance), body frame"),
    *vec("offset_mean", "xyz", 0.0, "m", "Running mean of the offset after settle_time, body frame"),
    *vec("cr", "xyz", 0.0, "m", "Centre of rotation relative to the COG (sensor + offset_mean), body frame"),
    *vec("acc_cr", "xyz", 0.0, "m/s2", "Specific force a sensor at the centre of rotation would read, body frame"),
    *vec("acc_cr_n", "ned", 0.0, "m/s2", "Acceleration of the centre of rotation, NED"),
    real("roll_used", 0.0, "rad", "Roll used by the filter"),
    real("pitch_used", 0.0, "rad", "Pitch used by the filter"),
    real("yaw_used", 0.0, "rad", "Yaw used by the filter"),
    real("delay", 0.0, "s", "Lag of all outputs behind the inputs (half the differentiation window)"),
]
CR_BOOLEANS: list[Variable] = [
    Variable("valid", "boolean", False, "", "Differentiation window full, the sample good, and rotation enough to observe the offset by (not in harbour)"),
    Variable("settled", "boolean", False, "", "settle_time has passed: offset_mean is an average"),
]


def cr_params(values: dict[str, Any]) -> CentreOfRotationParams:
    """CentreOfRotationParams from FMI-named values."""
    v = resolve(CR_PARAMETERS, values, "CentreOfRotation")
    return CentreOfRotationParams(
        angles=v["angles"], hp_cutoff=v["hp_cutoff"], diff_window=v["diff_window"], diff_sizing=v["diff_sizing"],
        centripetal=bool(v["centripetal"]),
        acc_sigma=v["acc_sigma"], acc_rw=v["acc_rw"], offset_rw=v["offset_rw"], offset_sigma0=v["offset_sigma0"],
        settle_time=v["settle_time"], sensor=(v["sensor.x"], v["sensor.y"], v["sensor.z"]),
    )


_HV = HeaveObserverParams()
HEAVE_PARAMETERS: list[Variable] = [
    real("window", _HV.window, "s", "First spectrum window (valid after it), >= two periods of omega_min (4 pi/omega_min), <= 3600"),
    real("window_max", _HV.window_max, "s", "Longest spectrum window: it grows with the data from window to this (= window: the paper's fixed window), [window, 3600]"),
    real("peak_interval", _HV.peak_interval, "s", "Time between peak detections (paper 003: T = 15 s), (0, 3600]"),
    Variable("model", "string", _HV.model, "", f"Observer model: one of {', '.join(MODEL_CHOICES)} (spectrum-weighted comb of band-pass elements, the paper's undamped modes at the peaks, the classical high-pass double integration as a baseline, or the causal Wiener filter designed from the spectrum)"),
    Variable("max_modes", "integer", _HV.max_modes, "", "Most oscillator modes (model = peaks), 1..20"),
    Variable("elements", "integer", _HV.elements, "", "Grid size of the band model, 2..100"),
    real("band_min", _HV.band_min, "rad/s", "Lowest band element (model = band; lower it for swell longer than about 16 s), (0, omega_max)"),
    real("damping", _HV.damping, "", "Damping ratio of the band elements' stages, (0, 1]"),
    Variable("stages", "integer", _HV.stages, "", "Cascaded oscillators per band element, 1..4"),
    Variable("band_variance", "string", _HV.band_variance, "", f"Band element variance from the spectrum: one of {', '.join(BAND_VARIANCES)} (integrated over the element's band, or read at its frequency)"),
    Variable("band_smoothing", "integer", _HV.band_smoothing, "", "Half-width of the log-domain smoothing of the band elements' heave densities over their neighbours (0: none), 0..5"),
    real("spectrum_floor", _HV.spectrum_floor, "", "Band elements below this fraction of the highest heave density are left out, [0, 1)"),
    real("omega_min", _HV.omega_min, "rad/s", "Lowest frequency searched for peaks, (0, omega_max)"),
    real("omega_max", _HV.omega_max, "rad/s", "Highest frequency searched for peaks, (omega_min, 20]"),
    real("min_separation", _HV.min_separation, "rad/s", "Peaks closer than this to a higher one are dropped, (0, 2]"),
    real("min_relative", _HV.min_relative, "", "Peaks lower than this fraction of the highest are dropped, [0, 1)"),
    real("acc_noise", _HV.acc_noise, "m/s2/sqrt(Hz)", "Accelerometer white-noise density, (0, 1]"),
    real("mode_noise", _HV.mode_noise, "m2/s2", "Mode process-noise density per rad/s of mode frequency, (0, 1000]"),
    real("offset_noise", _HV.offset_noise, "m/s2/sqrt(s)", "Random-walk density of the offset state (paper 003 eq. 7), (0, 10]"),
    Variable("discretisation", "string", _HV.discretisation, "", f"Mode transition: one of {', '.join(DISCRETISATIONS)} (rotation matrix, or the paper's eq. 9)"),
    Variable("measurement", "string", _HV.measurement, "", f"Measurement model: one of {', '.join(MEASUREMENTS)} (mean acceleration over the step, or the paper's y = Cx)"),
    Variable("vertical", "string", _HV.vertical, "", f"Vertical acceleration: one of {', '.join(VERTICAL_CHOICES)} (ned, exact, needs acc.x and acc.y connected; tilt needs only acc.z; paper is body f_z)"),
    Variable("transfer", "string", _HV.transfer, "", f"Transfer to the point: one of {', '.join(TRANSFER_CHOICES)} (exact 3-D lever arm, or the paper's eqs. 10-11)"),
    *vec("point", "xyz", 0.0, "m", "Monitoring point relative to the IMU, body frame"),
    real("smoother_lag", _HV.smoother_lag, "s", "Delay of the delayed heave (fixed-lag smoother), [0, 120]"),
    real("highpass_cutoff", _HV.highpass_cutoff, "rad/s", "Corner of the classical high-pass double integration (model = highpass), (0, omega_max)"),
    Variable("highpass_order", "integer", _HV.highpass_order, "", "Butterworth order of the classical filter (model = highpass), 2..8"),
]
HEAVE_INPUTS: list[Variable] = [
    real("acc.z", -9.80665, "m/s2", "Specific force along body z at the IMU"),
    real("acc.x", 0.0, "m/s2", "Specific force along body x (vertical = ned, the default: connect it)"),
    real("acc.y", 0.0, "m/s2", "Specific force along body y (vertical = ned, the default: connect it)"),
    real("roll", 0.0, "rad", "Roll (ZYX Euler)"),
    real("pitch", 0.0, "rad", "Pitch (ZYX Euler)"),
]
HEAVE_OUTPUTS: list[Variable] = [
    real("heave", 0.0, "m", "Heave at the IMU, positive down, NED"),
    real("heave_rate", 0.0, "m/s", "Heave rate at the IMU, positive down, NED"),
    real("point.heave", 0.0, "m", "Heave at the monitoring point, positive down, NED"),
    real("point.heave_rate", 0.0, "m/s", "Heave rate at the monitoring point, positive down, NED"),
    real("delayed.heave", 0.0, "m", "Fixed-lag smoothed heave at the IMU for time - delayed.delay, positive down"),
    real("delayed.heave_rate", 0.0, "m/s", "Fixed-lag smoothed heave rate at the IMU for time - delayed.delay"),
    real("delayed.point.heave", 0.0, "m", "Fixed-lag smoothed heave at the point for time - delayed.delay"),
    real("delayed.delay", 0.0, "s", "Delay of the delayed outputs"),
    real("offset", 0.0, "m/s2", "Offset state: vertical accelerometer bias (paper 003 eq. 7)"),
    real("peak_period", 0.0, "s", "Period of the highest peak of the position spectrum"),
]
HEAVE_DISCRETE: list[Variable] = [
    Variable("modes", "integer", 0, "", "Number of oscillator modes or band elements (0 before the first spectrum)"),
    Variable("valid", "boolean", False, "", "False until the first spectrum and on a rejected (NaN/Inf/absurd) sample"),
    Variable("delayed.valid", "boolean", False, "", "The delayed outputs refer to a time the observer has run through"),
]


def heave_params(values: dict[str, Any]) -> HeaveObserverParams:
    """HeaveObserverParams from FMI-named values."""
    v = resolve(HEAVE_PARAMETERS, values, "HeaveObserver")
    return HeaveObserverParams(
        window=v["window"], window_max=v["window_max"], peak_interval=v["peak_interval"], max_modes=v["max_modes"], omega_min=v["omega_min"],
        omega_max=v["omega_max"], min_separation=v["min_separation"], min_relative=v["min_relative"],
        model=v["model"], elements=v["elements"], band_min=v["band_min"], damping=v["damping"], stages=v["stages"],
        band_variance=v["band_variance"], band_smoothing=v["band_smoothing"], spectrum_floor=v["spectrum_floor"], acc_noise=v["acc_noise"], mode_noise=v["mode_noise"], offset_noise=v["offset_noise"],
        discretisation=v["discretisation"], measurement=v["measurement"], vertical=v["vertical"],
        transfer=v["transfer"], point=(v["point.x"], v["point.y"], v["point.z"]), smoother_lag=v["smoother_lag"],
        highpass_cutoff=v["highpass_cutoff"], highpass_order=v["highpass_order"],
    )


# --- MotionReferenceUnit ---

_MRU = MotionReferenceUnitParams()
_LOCATIONS = (("", "the IMU"), *((f"mp{i}.", f"monitoring point {i}") for i in range(1, MAX_POINTS + 1)))
MRU_PARAMETERS: list[Variable] = [
    *[v for i in range(1, MAX_POINTS + 1) for v in (
        Variable(f"mp{i}.enabled", "boolean", False, "", f"Monitoring point {i} is computed (off unless set)"),
        *vec(f"mp{i}", "xyz", 0.0, "m", f"Monitoring point {i} relative to the IMU, body frame; within {MAX_ARM:g} m "
             "of the IMU"))],
    real("window", _MRU.motion.window, "s", "First spectrum window of each axis (the motion is valid after it), "
         "[4 pi / omega_min, 3600]"),
    real("window_max", _MRU.motion.window_max, "s", "Longest spectrum window, [window, 3600]"),
    real("omega_min", _MRU.motion.omega_min, "rad/s", "Lowest wave frequency estimated, (0, omega_max)"),
    real("omega_max", _MRU.motion.omega_max, "rad/s", "Highest wave frequency estimated, (omega_min, 20]"),
    real("acc_noise", _MRU.motion.acc_noise, "m/s2/sqrt(Hz)", "Accelerometer white-noise density, (0, 1]"),
    real("delayed_lag", _MRU.motion.smoother_lag, "s", "Delay of the delayed outputs, [0, 120]"),
    real("heading_tau", _MRU.heading_tau, "s", "Time constant of the heading aid, [1, 3600]"),
    Variable("motion_model", "string", _MRU.motion_model, "", "Real-time motion at the IMU: one of joint, axis "
             "(joint: all six IMU channels, taught by the axis filters' delayed outputs; axis: one filter per axis, "
             "paper 003)"),
    real("joint_memory", _MRU.joint_memory, "s", "Span of the joint filter's past, [10, 300]"),
    Variable("aid_reference", "boolean", _MRU.aid_reference, "", "The joint filter's horizontal motion is the "
             "attitude's aid reference once it has taken over (roll and pitch err 2-3 x less in waves)"),
    real("tilt_tau", _MRU.tilt_tau, "s", "The horizontal axes' tilt follows the attitude below 1/tilt_tau and the "
         "integrated gyro above it; 0: the attitude's own tilt, else [10, 3600]"),
    Variable("aid_sizing", "string", _MRU.attitude.aid_sizing, "", f"Attitude aiding size: one of {', '.join(AID_SIZINGS)} (as the AttitudeEstimator's)"),
    real("vel_sigma", _MRU.attitude.vel_sigma, "m/s", "Attitude zero-velocity pseudo-measurement standard deviation (aid_sizing = fixed; the start of auto), (0, 100]"),
    real("pos_sigma", _MRU.attitude.pos_sigma, "m", "Attitude zero-position pseudo-measurement standard deviation (aid_sizing = fixed; the start of auto), (0, 1000]"),
    real("aid_rate", _MRU.attitude.aid_rate, "Hz", "Attitude pseudo-measurement rate, (0, 100]"),
]
MRU_INPUTS: list[Variable] = [
    *vec("gyro", "xyz", 0.0, "rad/s", "Angular rate, body frame"),
    *vec("acc", "xyz", (0.0, 0.0, -9.80665), "m/s2", "Specific force, body frame"),
    real("heading", 0.0, "rad", "True heading of the body x axis, clockwise from north (used while heading.valid)"),
    Variable("heading.valid", "boolean", False, "", "heading holds a measurement"),
]
MRU_OUTPUTS: list[Variable] = [
    real("roll", 0.0, "rad", "Roll (ZYX Euler)"),
    real("pitch", 0.0, "rad", "Pitch (ZYX Euler)"),
    real("yaw", 0.0, "rad", "Yaw (ZYX Euler): north-referenced once a valid heading arrived, else gyro-integrated"),
    *[v for prefix, where in _LOCATIONS for v in (
        real(f"{prefix}surge", 0.0, "m", f"Surge of {where} about its mean position, level frame (x along the mean heading)"),
        real(f"{prefix}sway", 0.0, "m", f"Sway of {where} about its mean position, level frame (y to starboard)"),
        real(f"{prefix}heave", 0.0, "m", f"Heave of {where} about its mean position, positive down"),
        real(f"{prefix}surge_rate", 0.0, "m/s", f"Surge velocity of {where}, level frame"),
        real(f"{prefix}sway_rate", 0.0, "m/s", f"Sway velocity of {where}, level frame"),
        real(f"{prefix}heave_rate", 0.0, "m/s", f"Heave velocity of {where}, positive down"),
        real(f"{prefix}heave_acc", 0.0, "m/s2", f"Vertical acceleration of {where}, positive down, bias removed"),
        real(f"{prefix}delayed.surge", 0.0, "m", f"Smoothed surge of {where} at time - delayed.delay"),
        real(f"{prefix}delayed.sway", 0.0, "m", f"Smoothed sway of {where} at time - delayed.delay"),
        real(f"{prefix}delayed.heave", 0.0, "m", f"Smoothed heave of {where} at time - delayed.delay, positive down"))],
    real("delayed.delay", 0.0, "s", "Delay of the delayed outputs"),
    real("wave_period", 0.0, "s", "Dominant wave period: the peak of the heave spectrum (0 before the first)"),
]
MRU_BOOLEANS: list[Variable] = [
    Variable("valid", "boolean", False, "", "roll, pitch, yaw: false while levelling, on a rejected (NaN/Inf/absurd) sample, and for 120 x the length of a gyro gap whose coast error can exceed the tilt's uncertainty"),
    Variable("motion.valid", "boolean", False, "", "The real-time motion: false until every axis's first spectrum, on a rejected sample and for 120 x a run of them after it"),
    Variable("delayed.valid", "boolean", False, "", "The delayed outputs refer to a time the filters have run through (and a run of rejected samples is 120 x its length and delayed_lag behind)"),
    Variable("heading.used", "boolean", False, "", "yaw is north-referenced"),
    Variable("motion.joint", "boolean", False, "", "The real-time motion is the joint filter's (taught), "
             "else the axis filters'"),
]


def mru_params(values: dict[str, Any]) -> MotionReferenceUnitParams:
    """MotionReferenceUnitParams from FMI-named values: the points enabled, in order, and the
    axes' filter parameters on the HeaveObserver's defaults."""
    v = resolve(MRU_PARAMETERS, values, "MotionReferenceUnit")
    # each enabled point checked under its own FMI name: the model numbers the enabled ones 1, 2, …
    points = tuple(check_arm(f"mp{i}", (v[f"mp{i}.x"], v[f"mp{i}.y"], v[f"mp{i}.z"])) for i in range(1, MAX_POINTS + 1)
                   if v[f"mp{i}.enabled"])
    try:
        motion = replace(_MRU.motion, window=v["window"], window_max=v["window_max"], omega_min=v["omega_min"],
                         omega_max=v["omega_max"], acc_noise=v["acc_noise"], smoother_lag=v["delayed_lag"])
    except ParameterError as exc:       # the heave observer's name for what this FMU calls delayed_lag
        message = str(exc)
        if not message.startswith("smoother_lag"):
            raise
        raise ParameterError("delayed_lag" + message[len("smoother_lag"):]) from None
    attitude = replace(_MRU.attitude, aid_sizing=v["aid_sizing"], vel_sigma=v["vel_sigma"], pos_sigma=v["pos_sigma"],
                       aid_rate=v["aid_rate"])
    return MotionReferenceUnitParams(attitude=attitude, motion=motion, points=points, heading_tau=v["heading_tau"],
                                     motion_model=v["motion_model"], joint_memory=v["joint_memory"],
                                     aid_reference=bool(v["aid_reference"]), tilt_tau=v["tilt_tau"])


# --- AHC FMUs: AhcWinch and AhcController ---

_W = AhcWinchParams()
WINCH_PARAMETERS: list[Variable] = [
    Variable("order", "integer", _W.order, "", "Winch speed servo: 1 first-order lag, 2 second order"),
    real("tau", _W.tau, "s", "First-order time constant, (0, 10]"),
    real("omega_n", _W.omega_n, "rad/s", "Second-order natural frequency, (0, 1000]"),
    real("zeta", _W.zeta, "", "Second-order damping ratio, (0, 10]"),
    real("max_speed", _W.max_speed, "m/s", "Winch speed limit, > 0"),
    real("max_acc", _W.max_acc, "m/s2", "Winch acceleration limit, > 0"),
    real("min_length", _W.min_length, "m", "Shortest wire paid out (stroke), >= 0"),
    real("max_length", _W.max_length, "m", "Longest wire paid out (stroke), > min_length"),
    real("length0", _W.length0, "m", "Initial wire length, within the stroke"),
    real("mass", _W.mass, "kg", "Load mass, > 0"),
    real("stiffness", _W.stiffness, "N/m", "Wire stiffness, > 0"),
    real("damping", _W.damping, "N*s/m", "Wire damping, >= 0"),
    real("max_substep", _W.max_substep, "s", "Longest integration substep, (0, 0.1]"),
]
WINCH_INPUTS: list[Variable] = [
    real("command", 0.0, "m/s", "Winch speed command (wire paid out per second)"),
    real("tip.n", 0.0, "m", "Crane tip position, north (the load hangs below it)"),
    real("tip.e", 0.0, "m", "Crane tip position, east"),
    real("tip.d", 0.0, "m", "Crane tip position, down (e.g. VesselMotion truth.point.d)"),
    real("tip_vel.d", 0.0, "m/s", "Crane tip velocity, down (e.g. VesselMotion truth.point_vel.d)"),
]
WINCH_OUTPUTS: list[Variable] = [
    real("length", _W.length0, "m", "Wire paid out"),
    real("speed", 0.0, "m/s", "Winch speed, dlength/dt"),
    real("acc", 0.0, "m/s2", "Winch acceleration"),
    real("load.n", 0.0, "m", "Load position, north (below the tip: pendulum motion not modelled)"),
    real("load.e", 0.0, "m", "Load position, east (below the tip)"),
    real("load.d", 0.0, "m", "Load position, down, NED"),
    real("load_vel.d", 0.0, "m/s", "Load velocity, down, NED"),
    real("tension", 0.0, "N", "Wire tension (>= 0: a wire cannot push)"),
]
WINCH_BOOLEANS: list[Variable] = [
    Variable("speed_limited", "boolean", False, "", "The command exceeded max_speed during the step"),
    Variable("acc_limited", "boolean", False, "", "The winch hit max_acc during the step"),
    Variable("stroke_limited", "boolean", False, "", "The wire sat at a stroke stop during the step"),
    Variable("slack", "boolean", False, "", "The wire went slack (tension 0) during the step"),
    Variable("valid", "boolean", False, "", "The step's inputs were usable (false: a NaN/Inf/absurd input was held)"),
]


def winch_params(values: dict[str, Any]) -> AhcWinchParams:
    """AhcWinchParams from FMI-named values."""
    return AhcWinchParams(**resolve(WINCH_PARAMETERS, values, "AhcWinch"))   # FMI names = field names


_C = AhcControllerParams()
CONTROLLER_PARAMETERS: list[Variable] = [
    real("length0", _C.length0, "m", "Nominal wire length, >= 0"),
    real("k_ff", _C.k_ff, "", "Feedforward gain on the estimated tip heave and heave rate, [0, 2] (1: full compensation)"),
    real("k_p", _C.k_p, "1/s", "Proportional gain on the wire-length error, >= 0"),
    real("k_i", _C.k_i, "1/s2", "Integral gain on the wire-length error, >= 0"),
    real("max_integral", _C.max_integral, "m*s", "Clamp of the integrated length error (anti-windup), > 0"),
    real("max_command", _C.max_command, "m/s", "Clip of the speed command (the winch's max_speed), > 0; no integration into the clip"),
    real("heave_ref", _C.heave_ref, "m", "Mean down position in the heave input, removed (0 for a heave estimate; the point's z for truth)"),
    real("engage_time", _C.engage_time, "s", "Time for the feedforward to fade in while heave_valid (and out while not), [0, 600]"),
]
CONTROLLER_INPUTS: list[Variable] = [
    real("heave", 0.0, "m", "Estimated crane-tip heave, down (e.g. HeaveObserver point.heave)"),
    real("heave_rate", 0.0, "m/s", "Estimated crane-tip heave rate, down (e.g. HeaveObserver point.heave_rate)"),
    real("length", _C.length0, "m", "Measured wire length (AhcWinch length)"),
    Variable("heave_valid", "boolean", True, "", "The heave estimate is usable (e.g. HeaveObserver valid): the feedforward fades in"),
]
CONTROLLER_OUTPUTS: list[Variable] = [
    real("command", 0.0, "m/s", "Winch speed command"),
    real("length_ref", _C.length0, "m", "Wire-length reference, length0 - k_ff * engagement * (heave - heave_ref)"),
    real("engagement", 0.0, "", "Weight of the feedforward, 0 (off) .. 1 (full), ramped by heave_valid"),
]
CONTROLLER_BOOLEANS: list[Variable] = [
    Variable("command_limited", "boolean", False, "", "The command was clipped to max_command this step"),
    Variable("valid", "boolean", False, "", "Full compensation with usable inputs (false while engagement < 1 or a NaN/Inf/absurd input was held)"),
]


def controller_params(values: dict[str, Any]) -> AhcControllerParams:
    """AhcControllerParams from FMI-named values."""
    return AhcControllerParams(**resolve(CONTROLLER_PARAMETERS, values, "AhcController"))   # FMI names = field names


# --- SensorRecording: a recorded file played back with VesselMotion's sensor names ---
# Its outputs are the record schema of marinefmu.sea.recording.schema (fixed at build time: a
# signal the record lacks comes out as zeros with its valid flag false), re-exported here.

from ..sea.recording.schema import BOOLEAN_OUTPUTS as SENSOR_RECORDING_BOOLEANS  # noqa: E402,F401
from ..sea.recording.schema import REAL_OUTPUTS as SENSOR_RECORDING_OUTPUTS  # noqa: E402,F401

SENSOR_RECORDING_PARAMETERS: list[Variable] = [
    Variable("file", "string", "", "", "Recorded file: CSV, CSV.gz or Parquet (relative paths: to the working folder, else to the mapping's folder); empty in a bundled FMU = its resources/recording/ record"),
    Variable("mapping", "string", "", "", "Mapping sidecar (TOML): time column and unit, a column per signal with scale and offset, units, frames, lever arms; empty in a bundled FMU = its resources/recording/ sidecar"),
    real("start", 0.0, "s", "Offset into the record played at the start time (record time 0 = first sample), [0, record length)"),
]


def sensor_recording_params(values: dict[str, Any]):
    """SensorRecordingParams from FMI-named values."""
    from ..sea.recording.player import SensorRecordingParams

    v = resolve(SENSOR_RECORDING_PARAMETERS, values, "SensorRecording")
    return SensorRecordingParams(file=v["file"], mapping=v["mapping"], start=v["start"])
