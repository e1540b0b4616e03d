"""A ship's centre of rotation by a Kalman filter with lever-arm states.

Source: C. Zhang, A. Härting, B. Ntamba Ntamba, B. Schwarz-Röhr, "Estimation of the centre of
rotation for a ship in real sea state environment", conference/journal paper in RINA format
on trials of the S.A. Agulhas II (2017) and off Ostend (2017); the venue and year are not
printed in the project's copy of the text.

========================== ===============================================================
module                     paper 002
========================== ===============================================================
:mod:`.filter`             angles by high-pass filtering and integration of the rates; the
                           Kalman filter with state [a_n, r] and measurement model
                           eqs. 6-11, Joseph-form update (eq. 5)
:mod:`.centred_window`     the angular acceleration by a centred Savitzky-Golay derivative
                           (beyond the paper, which does not say how it differentiates)
========================== ===============================================================
"""
