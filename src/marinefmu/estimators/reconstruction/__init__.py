"""Displacement reconstruction from acceleration without integration drift.

Source: F. Liu, S. Gao, Y. Liu, D. Liu, "A motion tracking approach to position marine floating
structures based on measured acceleration and angular velocity", journal article (its
references run to 2022; the venue is not printed in the project's copy of the text), sections
3.2-3.5 and 4.

========================== ===============================================================
module                     paper 000
========================== ===============================================================
:mod:`.decomposition`      tilt correction (eqs. 10-15); Hankel matrix, SVD and complex
                           exponentials (eqs. 16-23); drift-term screening and the
                           non-integral displacement (eqs. 24-31); transfer to the COG
                           (eq. 32); the batch function :func:`~.decomposition.reconstruct_displacement`
:mod:`.sliding`            the same method online on a sliding window: the
                           DisplacementReconstructor (beyond the paper)
========================== ===============================================================
"""
