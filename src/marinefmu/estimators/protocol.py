"""The estimator pattern every in-process model of an FMU follows (design page, "Estimator
pattern").

A model is built from a frozen, validated parameter dataclass (its ``params``), steps one sample
at a time, and can save and restore its whole state as a JSON-serialisable dict: that is what the
FMU's ``fmi2GetFMUstate``/``fmi2SetFMUstate`` carry. The FMU slave only moves numbers in and out
of these four methods.
"""
from __future__ import annotations

from typing import Any, Protocol, runtime_checkable


@runtime_checkable
class Estimator(Protocol):
    """A stateful model stepped sample by sample.

    Attributes
    ----------
    params : dataclass
        The frozen parameters it was built from.
    """

    params: Any

    def reset(self) -> None:
        """Back to the state it was built in."""

    def step(self, *args: Any, **kwargs: Any) -> Any:
        """Process one sample; the last positional argument or ``dt`` is the step [s]. Returns a
        small typed result (or the output vector, for VesselMotion)."""

    def get_state(self) -> dict:
        """The whole state, JSON-serialisable."""

    def set_state(self, state: dict) -> None:
        """Restore a state from :meth:`get_state`."""
