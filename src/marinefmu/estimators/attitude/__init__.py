"""Attitude from gyros by quaternion integration, and the accelerometer-aided variant.

Source: F. Liu, S. Gao, Y. Liu, D. Liu, "A motion tracking approach to position marine floating
structures based on measured acceleration and angular velocity", journal article (Ocean
University of China / University of East Anglia; its references run to 2022, the venue is not
printed in the project's copy of the text), section 3.1.

========================== ===============================================================
module                     paper 000
========================== ===============================================================
:mod:`.estimator`          quaternion kinematics (eqs. 6-7), Euler angles from the
                           quaternion (eqs. 8-9), exact rotation per step; the aided
                           variant (beyond the paper) that bounds the gyro drift
:mod:`.gyro_coast`         the coast error of a gyro gap in the aided variant's covariance,
                           and the recovery that holds ``valid`` after it (beyond the paper)
:mod:`.tilt_refinement`    batch refinement of roll and pitch from the record's gravity
                           direction (beyond the paper; post-processing)
========================== ===============================================================
"""
