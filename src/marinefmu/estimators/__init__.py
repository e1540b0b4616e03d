"""The estimators from the literature, one package per estimated quantity.

Each package implements one paper's method as written (equation numbers in the docstrings),
keeps that variant selectable, and adds what the paper lacks where the benchmark shows it
matters. Every estimator follows :class:`~marinefmu.estimators.protocol.Estimator`; none of them
imports FMPy or pythonfmu.

================================ ============================================ ==========
package                          estimates                                    paper
================================ ============================================ ==========
:mod:`.attitude`                 roll, pitch, yaw from gyros (+ aiding)        000
:mod:`.reconstruction`           displacement from acceleration, no drift      000
:mod:`.gnss_fusion`              position from multi-antenna GNSS + acc        001
:mod:`.centre_of_rotation`       a ship's centre of rotation                   002
:mod:`.heave`                    heave at the IMU and at a remote point        003
================================ ============================================ ==========

Shared by them: :mod:`.numerics` (direct integration, single-thread BLAS), :mod:`.samples`
(plausibility limits of single IMU samples), :mod:`.noise_meter` (a sensor's white noise from
its second difference) and :mod:`.protocol` (the estimator pattern).
"""
