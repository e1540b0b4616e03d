"""Heave at the IMU and at a remote point from a strapdown IMU, by an adaptive observer.

Source: Ø. F. Auestad, J. T. Gravdahl, T. I. Fossen, "Heave motion estimation on a craft using
a strapdown inertial measurement unit", IFAC conference paper, 2013 (the text cites 2013
sources; NTNU and Umoe Mandal).

========================== ===============================================================
module                     paper 003
========================== ===============================================================
:mod:`.observer`           :class:`~.observer.HeaveObserver`: the FMU's model, which runs
                           one of the four models below
:mod:`.common`             parameters, the vertical acceleration (eq. 6), the transfer to a
                           point (eqs. 10-11 and their exact 3-D form), the result
:mod:`.spectrum`           step 1-2: the spectrum A(ω) = Ä(ω)/ω² (eq. 2) and its peaks
:mod:`.oscillator_bank`    step 3: undamped oscillator modes + random-walk offset
                           (eqs. 3-9), exact or Euler discretisation
:mod:`.bank`               the observer over the bank (``model="peaks"``, the paper's; and
                           ``model="band"``)
:mod:`.band_bank`          the band comb of damped resonators (beyond the paper)
:mod:`.wiener`             the causal Wiener filter designed from the spectrum (default,
                           beyond the paper)
:mod:`.highpass`           the classical high-pass double integration (baseline)
:mod:`.fixed_lag`          the delayed (smoothed) heave
:mod:`.bias_step`          detection of an accelerometer bias step (the paper's +2 m/s² case)
========================== ===============================================================
"""
