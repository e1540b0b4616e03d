"""The benchmark grid that the ``defaults`` and ``mru`` parts share: the three vessel presets ×
three seas (:data:`SEAS`: Hs 1 m / Tp 5 s, 3 m / 10 s, 6 m / 14 s, bow-quartering, :data:`HEADING`)
× two IMU placements (:func:`placements`: at the COG, and 40 % of the length forward, 40 % of
the beam to starboard and 10 m above the COG), default MEMS IMU, one seed (:data:`SEED`) per
case (:data:`CASES`), each a VesselMotion record (:func:`case_record`) sampled at :data:`DT`.
"""
from __future__ import annotations

import math

import numpy as np

from ..sea.motion_model import VesselMotionParams, simulate_record
from ..sea.vessel import PRESETS

#: Sample interval of every record [s] (100 Hz).
DT = 0.01
#: The seas: (Hs [m], Tp [s]).
SEAS = ((1.0, 5.0), (3.0, 10.0), (6.0, 14.0))
#: Wave direction [rad]: bow-quartering.
HEADING = 0.75 * math.pi
#: Default record length [s].
DURATION = 600.0
#: Start of the scored span [s], unless an estimator's first valid output is later.
SETTLE = 150.0
#: The sea's seed of every case.
SEED = 3
#: The ``defaults`` part's goal: an estimator at its defaults within this factor of the best
#: fixed setting the project knows, on every case.
RATIO_GOAL = 1.15


def placements(preset: str) -> dict[str, tuple[float, float, float]]:
    """The two IMU positions of a preset relative to its COG, body frame [m]."""
    h = PRESETS[preset]
    return {"cog": (0.0, 0.0, 0.0), "far": (round(0.4 * h.length, 1), round(0.4 * h.beam, 1), -10.0)}


def monitoring_point(preset: str, place: str) -> tuple[float, float, float]:
    """The heave figure's monitoring point relative to the COG, body frame [m]: on the
    centreline 10 m above the COG, 45 % of the length forward (a bow crane or gangway tip) for
    the IMU at the COG, 45 % aft for the IMU forward (:func:`placements`), so that the point is
    far from the IMU in both and the attitude error's lever arm is long."""
    x = 0.45 * PRESETS[preset].length
    return (round(x if place == "cog" else -x, 1), 0.0, -10.0)


CASES: tuple[tuple[str, float, float, str], ...] = tuple(
    (preset, hs, tp, place) for preset in PRESETS for hs, tp in SEAS for place in ("cog", "far"))


def case_record(preset: str, hs: float, tp: float, place: str, duration: float = DURATION,
                extra: dict | None = None, dt: float = DT) -> dict[str, np.ndarray]:
    """VesselMotion record of one case (:data:`SEED`, bow-quartering) at the step ``dt`` [s];
    ``extra``: more VesselMotion parameters (e.g. ``{"imu.grade": "mru"}``)."""
    imu = placements(preset)[place]
    flat = {"sea.hs": hs, "sea.tp": tp, "sea.seed": SEED, "sea.heading": HEADING, "vessel.preset": preset,
            **{f"imu.{a}": v for a, v in zip("xyz", imu)},
            **{f"point.{a}": v for a, v in zip("xyz", monitoring_point(preset, place))}, **(extra or {})}
    return simulate_record(VesselMotionParams.from_flat(flat), duration, dt)
