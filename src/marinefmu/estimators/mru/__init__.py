"""A virtual motion reference unit: attitude, and real-time and delayed three-axis motion at the
IMU and at monitoring points, from one strapdown IMU, in one process.

It composes paper 000's aided attitude (:mod:`marinefmu.estimators.attitude`) and paper 003's
heave observer generalised to the three axes of the vessel's level frame
(:class:`~marinefmu.estimators.heave.wiener.WienerAxis`, the HeaveObserver's default filter).

========================== ===============================================================
module                     holds
========================== ===============================================================
:mod:`.params`             parameters, their checks, the result of a step
:mod:`.level_frame`        the level frame, the slow low-pass, the lever-arm terms and
                           their derivatives
:mod:`.joint`              the joint motion filter: all six IMU channels, taught by the
                           axis filters' delayed outputs
:mod:`.unit`               :class:`~.unit.MotionReferenceUnit`: the MotionReferenceUnit
                           FMU's model
:mod:`.goals`              the accuracy goals and the monitoring points they are scored at
========================== ===============================================================
"""
