"""Multi-antenna GNSS + accelerometer Kalman fusion with attitude correction.

Source: X. Gao, J. Jiang, G. Xu, Z. Chang, J. Yang, "Multi-Antenna GNSS-Accelerometer Fusion
Attitude Correction Algorithm for Offshore Floating Platform Displacement Monitoring",
*Sensors* 24 (2024) 7804, https://doi.org/10.3390/s24237804.

========================== ===============================================================
module                     paper 001
========================== ===============================================================
:mod:`.antenna_attitude`   attitude and COG position from four antennas (least squares,
                           Wahba's problem), the input of eqs. 20-26
:mod:`.filter`             attitude-corrected acceleration (eqs. 20-26) and the
                           constant-acceleration Kalman fusion (eqs. 13-19), multi-rate
:mod:`.runs`               whole-record runs and the RTS smoother the paper mentions for
                           post-processing
:mod:`.error_model`        the error covariance behind ``pos_std`` (beyond the paper)
:mod:`.wave_coast`         coasting through GNSS dropouts on a wave model (beyond the paper;
                           it reuses paper 003's observer, :mod:`marinefmu.estimators.heave`)
:mod:`.aided_band`         the GNSS-aided band observer of one axis used by the coast
========================== ===============================================================

The time- and frequency-domain integration baselines of the paper's section 2.1 (eqs. 1-12)
are in :mod:`marinefmu.estimators.numerics`.
"""
