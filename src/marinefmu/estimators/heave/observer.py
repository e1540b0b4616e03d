"""The HeaveObserver: heave at the IMU and at a remote point by whichever of the four observer
models ``model`` of :class:`~.common.HeaveObserverParams` names. This is the in-process model of the
HeaveObserver FMU.

========== ================================================ ==========================
``model``  estimator                                        source
========== ================================================ ==========================
"wiener"   :class:`~.wiener.WienerHeave` (default)          beyond paper 003
"band"     :class:`~.bank.OscillatorBankHeave`, band comb   beyond paper 003
"peaks"    :class:`~.bank.OscillatorBankHeave`, peak modes  paper 003, eqs. 1-11
"highpass" :class:`~.highpass.HighpassHeave`                the classical baseline
========== ================================================ ==========================
"""
from __future__ import annotations

from typing import Any

from .bank import OscillatorBankHeave
from .common import HeaveObserverParams, HeaveResult
from .highpass import HighpassHeave
from .wiener import WienerHeave

HeaveModel = OscillatorBankHeave | HighpassHeave | WienerHeave


class HeaveObserver:
    """Heave at the IMU and at a point, by the model ``params.model`` names (module docstring).

    Parameters
    ----------
    params : HeaveObserverParams, optional
        Validated parameters (the defaults if omitted).
    quiet : bool
        Log nothing (inside another estimator that reports for itself).

    Attributes
    ----------
    estimator : OscillatorBankHeave | HighpassHeave | WienerHeave
        The model that does the work; attributes not defined here are read from it.

    Examples
    --------
    >>> obs = HeaveObserver(HeaveObserverParams(model="highpass", highpass_cutoff=0.1))
    >>> type(obs.estimator).__name__
    'HighpassHeave'
    >>> obs.step((0.0, 0.0, -9.80665), 0.0, 0.0, 0.01).valid   # at rest, not yet settled
    False
    """

    def __init__(self, params: HeaveObserverParams | None = None, *, quiet: bool = False) -> None:
        self.params = params or HeaveObserverParams()
        self.estimator: HeaveModel = build_heave_model(self.params, quiet=quiet)

    def __getattr__(self, name: str) -> Any:
        # Only called for names not found on the facade itself: the model's own attributes.
        if name == "estimator":
            raise AttributeError(name)
        return getattr(self.estimator, name)

    def reset(self) -> None:
        """Back to the initial state."""
        self.estimator.reset()

    def step(self, acc: Any, roll: float, pitch: float, dt: float) -> HeaveResult:
        """One IMU sample: specific force ``acc`` [m/s², body frame], ``roll``, ``pitch`` [rad],
        step ``dt`` [s]; see :meth:`.OscillatorBankHeave.step`."""
        return self.estimator.step(acc, roll, pitch, dt)

    def get_state(self) -> dict:
        """The model's whole state, JSON-serialisable."""
        return self.estimator.get_state()

    def set_state(self, s: dict) -> None:
        """Restore a state from :meth:`get_state`."""
        self.estimator.set_state(s)


def build_heave_model(params: HeaveObserverParams, *, quiet: bool = False) -> HeaveModel:
    """The estimator ``params.model`` names: :class:`.HighpassHeave` for ``"highpass"``,
    :class:`.WienerHeave` for ``"wiener"``, else :class:`.OscillatorBankHeave`."""
    if params.model == "highpass":
        return HighpassHeave(params, quiet=quiet)
    if params.model == "wiener":
        return WienerHeave(params, quiet=quiet)
    return OscillatorBankHeave(params, quiet=quiet)
