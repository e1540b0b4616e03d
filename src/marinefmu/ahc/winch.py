"""An active-heave-compensation winch at a crane tip with a load on an elastic wire.

Frames and signs (the design page): NED, z down. The crane tip moves with the vessel (VesselMotion's
``truth.point.d`` and ``truth.point_vel.d``); the winch there pays out wire of length L
(positive, more wire = load lower); the load hangs at z below the tip.

Model, states [L, v, a, z, ż]:

- **Motor** (speed servo): the command u is clipped to ±``max_speed``; first order
  v̇ = (u − v)/τ (``order=1``), or second order v̈ = ω_n²(u − v) − 2ζω_n v̇ (``order=2``); the
  acceleration v̇ is clipped to ±``max_acc``. L̇ = v, held inside [``min_length``,
  ``max_length``] (at a stop the speed into it is zeroed).
- **Wire**: extension e = z − z_tip − L, tension T = k e + c ė (ė = ż − ż_tip − v), and a
  wire cannot push: T ≥ 0 (``slack`` flags T = 0).
- **Load**: m z̈ = m g − T.

At rest the wire is stretched by e₀ = m g / k. Every limit that acts is reported by a flag
(``speed_limited``, ``acc_limited``, ``stroke_limited``, ``slack``), never hidden.

Integration. Away from every limit the model is linear and time-invariant over a step (the
inputs are held), so the step is exact: x ← Φx + Γ[u, z_tip, ż_tip, 1] with Φ, Γ from the
matrix exponential of the augmented system (``scipy.linalg.expm``, once per step size). The
exact step is taken only when no limit can act within it: the acceleration inside its limit
(order 1: at the start, |u − v| only decays; order 2: at both ends, with 10 % margin), the
tension above 5 % of m g and the wire length more than 1 mm inside the stroke at both ends (over
a 10 ms step they move by less than 1e-3 of their swing between the ends). Otherwise:
classical Runge-Kutta 4 on substeps of at most ``max_substep`` s (the wire-load mode is
ω = √(k/m), 10 rad/s for the defaults; RK4 at 2 ms resolves it to 1e-9); the clips are
continuous functions of the state, the stroke stops are applied after each substep. The two
agree to 2e-9 m where both apply (test); the exact step costs about a third of an RK4 step, and a
winch at sea spends almost all its steps in the linear regime. The RK4 is hand-written (not
``scipy.integrate.solve_ivp``):
a fixed-step co-simulation slave advances by a known step and must be cheap and deterministic.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.linalg import expm

from ..errors import ParameterError, check_int, check_range
from ..estimators.samples import bad_scalar

G = 9.80665
#: The exact linear step is taken only with the tension above this fraction of m g at both ends.
TENSION_MARGIN = 0.05
#: … and the wire length at least this far inside the stroke at both ends [m].
STROKE_MARGIN = 1e-3
#: … and (order 2) the winch acceleration within this fraction of ``max_acc`` at both ends.
ACC_MARGIN = 0.9


@dataclass(frozen=True)
class AhcWinchParams:
    """Parameters of :class:`AhcWinch` (FMU names in brackets).

    Parameters
    ----------
    order : int
        Motor dynamics: 1 (first-order lag) or 2 (second order). [``order``]
    tau : float
        First-order time constant [s], (0, 10]. [``tau``]
    omega_n, zeta : float
        Second-order natural frequency [rad/s], (0, 1000], and damping ratio, (0, 10].
        [``omega_n``, ``zeta``]
    max_speed : float
        Winch speed limit [m/s], > 0. [``max_speed``]
    max_acc : float
        Winch acceleration limit [m/s²], > 0. [``max_acc``]
    min_length, max_length : float
        Stroke: wire paid out [m], 0 ≤ min < max. [``min_length``, ``max_length``]
    length0 : float
        Initial wire length [m], in the stroke. [``length0``]
    mass : float
        Load mass [kg], > 0. [``mass``]
    stiffness : float
        Wire stiffness [N/m], > 0. [``stiffness``]
    damping : float
        Wire damping [N·s/m], ≥ 0. [``damping``]
    max_substep : float
        Longest integration substep [s], (0, 0.1]. [``max_substep``]
    """

    order: int = 1
    tau: float = 0.1
    omega_n: float = 20.0
    zeta: float = 0.7
    max_speed: float = 2.0
    max_acc: float = 2.0
    min_length: float = 10.0
    max_length: float = 30.0
    length0: float = 20.0
    mass: float = 1.0e4
    stiffness: float = 1.0e6
    damping: float = 1.0e4
    max_substep: float = 0.002

    def __post_init__(self) -> None:
        check_int("order", self.order, lo=1, hi=2)
        check_range("tau", self.tau, lo=0.0, lo_open=True, hi=10.0, unit="s")
        check_range("omega_n", self.omega_n, lo=0.0, lo_open=True, hi=1000.0, unit="rad/s")
        check_range("zeta", self.zeta, lo=0.0, lo_open=True, hi=10.0)
        check_range("max_speed", self.max_speed, lo=0.0, lo_open=True, hi=100.0, unit="m/s")
        check_range("max_acc", self.max_acc, lo=0.0, lo_open=True, hi=1000.0, unit="m/s2")
        check_range("min_length", self.min_length, lo=0.0, hi=1e4, unit="m")
        check_range("max_length", self.max_length, lo=self.min_length, lo_open=True, hi=1e4, unit="m")
        check_range("length0", self.length0, lo=self.min_length, hi=self.max_length, unit="m")
        check_range("mass", self.mass, lo=0.0, lo_open=True, hi=1e9, unit="kg")
        check_range("stiffness", self.stiffness, lo=0.0, lo_open=True, hi=1e12, unit="N/m")
        check_range("damping", self.damping, lo=0.0, hi=1e12, unit="N*s/m")
        check_range("max_substep", self.max_substep, lo=0.0, lo_open=True, hi=0.1, unit="s")

    @property
    def static_stretch(self) -> float:
        """Wire extension at rest, m g / k [m]."""
        return self.mass * G / self.stiffness


@dataclass(frozen=True)
class WinchState:
    """Outputs after a step (NED, z down)."""

    length: float          # wire paid out [m]
    speed: float           # winch speed dL/dt [m/s]
    acc: float             # winch acceleration [m/s²]
    load: float            # load position, down [m]
    load_vel: float        # load velocity, down [m/s]
    tension: float         # wire tension [N]
    speed_limited: bool    # the command exceeded max_speed during the step
    acc_limited: bool      # the motor hit max_acc during the step
    stroke_limited: bool   # the wire length sat at a stroke stop during the step
    slack: bool            # the wire went slack (tension 0) during the step
    valid: bool = True     # the inputs of the step were usable
    warning: str | None = None
    load_n: float = 0.0    # load position, north: below the tip [m]
    load_e: float = 0.0    # load position, east [m]


class AhcWinch:
    """The winch, wire and load (module docstring), one co-simulation step at a time.

    Parameters
    ----------
    params : AhcWinchParams
        Validated parameters.
    tip : float
        Crane-tip position at the start, down [m]: the load starts at rest below it.
    """

    def __init__(self, params: AhcWinchParams | None = None, tip: float = 0.0) -> None:
        self.params = params or AhcWinchParams()
        self.reset(tip)

    def reset(self, tip: float = 0.0) -> None:
        """At rest: the load hangs at tip + L₀ + m g / k."""
        p = self.params
        self.inputs = (0.0, float(tip), 0.0)   # last good command, tip, tip velocity
        self.tip_ne = (0.0, 0.0)               # last good tip north, east
        self.x = np.array([p.length0, 0.0, 0.0, tip + p.length0 + p.static_stretch, 0.0])
        self.flags = [False] * 4
        self.tension = p.mass * G
        self.acc = 0.0
        self._exact: tuple[float, list[list[float]]] | None = None   # (dt, rows of [Φ | Γ])

    def _linear_step(self, dt: float) -> list[list[float]]:
        """Rows of [Φ | Γ] (5 × 9) of the exact step of the linear regime, for inputs
        [u, z_tip, ż_tip, 1] held over ``dt`` (cached per step size)."""
        if self._exact is None or self._exact[0] != dt:
            p = self.params
            k, c = p.stiffness / p.mass, p.damping / p.mass
            a = np.zeros((9, 9))                       # states L, v, a, z, ż; inputs u, tip, tip_vel, 1
            a[0, 1] = 1.0
            if p.order == 1:
                a[1, 1], a[1, 5] = -1.0 / p.tau, 1.0 / p.tau
            else:
                a[1, 2] = 1.0
                a[2, 1], a[2, 2], a[2, 5] = -p.omega_n**2, -2.0 * p.zeta * p.omega_n, p.omega_n**2
            a[3, 4] = 1.0
            # ż' = g − (k (z − tip − L) + c (ż − tip_vel − v)) / m
            a[4, 0], a[4, 1], a[4, 3], a[4, 4] = k, c, -k, -c
            a[4, 6], a[4, 7], a[4, 8] = k, c, G
            self._exact = (dt, expm(a * dt)[:5].tolist())
        return self._exact[1]

    def _in_linear_regime(self, x: tuple[float, ...], u: float, tip: float, tip_vel: float) -> bool:
        """Whether no limit acts at state ``x`` (with the margins of the module docstring)."""
        p = self.params
        length, v, a, z, zd = x
        if not p.min_length + STROKE_MARGIN < length < p.max_length - STROKE_MARGIN:
            return False
        if p.order == 1:
            if abs(u - v) > p.tau * p.max_acc:
                return False
        elif abs(a) > ACC_MARGIN * p.max_acc:
            return False
        return p.stiffness * (z - tip - length) + p.damping * (zd - tip_vel - v) > TENSION_MARGIN * p.mass * G

    def _deriv(self, x: tuple[float, ...], u: float, tip: float, tip_vel: float
               ) -> tuple[tuple[float, ...], float, bool]:
        """State derivative, tension [N] and whether the acceleration limit acts (plain floats:
        this runs 21 times a step)."""
        p = self.params
        length, v, a, z, zd = x
        acc = (u - v) / p.tau if p.order == 1 else a
        limited = abs(acc) > p.max_acc
        acc = max(-p.max_acc, min(p.max_acc, acc))
        v_eff = 0.0 if (length <= p.min_length and v < 0.0) or (length >= p.max_length and v > 0.0) else v
        tension = max(p.stiffness * (z - tip - length) + p.damping * (zd - tip_vel - v_eff), 0.0)
        jerk = 0.0
        if p.order == 2:
            raw = p.omega_n ** 2 * (u - v) - 2.0 * p.zeta * p.omega_n * a
            # a is held inside the acceleration limit: no further push against it
            jerk = 0.0 if (a >= p.max_acc and raw > 0.0) or (a <= -p.max_acc and raw < 0.0) else raw
        return (v_eff, acc, jerk, zd, G - tension / p.mass), tension, limited

    def step(self, command: float, tip: float, tip_vel: float, dt: float,
             tip_ne: tuple[float, float] = (0.0, 0.0)) -> WinchState:
        """Advance by ``dt`` [s] with speed command ``command`` [m/s] and the crane tip at
        ``tip`` [m, down] moving at ``tip_vel`` [m/s] (both held over the step); ``tip_ne`` is
        the tip's north and east [m], where the load hangs (``load_n``, ``load_e``).

        A bad input (NaN, ±Inf, a command beyond 1000 m/s, a tip beyond 10 km or faster than
        100 m/s) is not used: the last good inputs are held, and the result has ``valid`` False
        and a ``warning``."""
        p = self.params
        warning = bad_scalar((("command", command, 1e3), ("tip", tip, 1e4), ("tip velocity", tip_vel, 100.0),
                              ("tip north", tip_ne[0], 1e7), ("tip east", tip_ne[1], 1e7)))
        if warning is None:
            self.inputs = (float(command), float(tip), float(tip_vel))
            self.tip_ne = (float(tip_ne[0]), float(tip_ne[1]))
        command, tip, tip_vel = self.inputs
        u = max(-p.max_speed, min(p.max_speed, float(command)))
        flags = [abs(float(command)) > p.max_speed, False, False, False]
        x = tuple(float(v) for v in self.x)
        f = self._deriv
        exact = None
        if self._in_linear_regime(x, u, tip, tip_vel):
            w = (*x, u, tip, tip_vel, 1.0)
            exact = tuple(sum(r * wi for r, wi in zip(row, w)) for row in self._linear_step(dt))
            if not self._in_linear_regime(exact, u, tip, tip_vel):
                exact = None
        n = 0 if exact is not None else max(1, math.ceil(dt / p.max_substep - 1e-9))
        h = dt / max(n, 1)
        if exact is not None:
            x = exact
        for _ in range(n):
            k1, t1, l1 = f(x, u, tip, tip_vel)
            k2, _, l2 = f(tuple(xi + 0.5 * h * ki for xi, ki in zip(x, k1)), u, tip, tip_vel)
            k3, _, l3 = f(tuple(xi + 0.5 * h * ki for xi, ki in zip(x, k2)), u, tip, tip_vel)
            k4, _, l4 = f(tuple(xi + h * ki for xi, ki in zip(x, k3)), u, tip, tip_vel)
            x = tuple(xi + (h / 6.0) * (a + 2.0 * b + 2.0 * c + d) for xi, a, b, c, d in zip(x, k1, k2, k3, k4))
            flags[1] |= l1 or l2 or l3 or l4
            flags[3] |= t1 <= 0.0
            if x[0] <= p.min_length or x[0] >= p.max_length:
                length, v, a = min(max(x[0], p.min_length), p.max_length), x[1], x[2]
                if (length == p.min_length and v < 0.0) or (length == p.max_length and v > 0.0):
                    v, a = 0.0, 0.0
                x = (length, v, a, x[3], x[4])
                flags[2] = True
        self.x = np.array(x)
        d, self.tension, _ = f(x, u, tip, tip_vel)
        self.acc = float(d[1])
        self.flags = [bool(f) for f in flags]
        if not np.all(np.isfinite(x)):   # cannot happen for valid parameters; never pass NaN on
            raise ParameterError("winch model diverged: check max_substep against sqrt(stiffness / mass)")
        return self.state(warning is None, warning)

    def state(self, valid: bool = True, warning: str | None = None) -> WinchState:
        """The current outputs."""
        length, v, _, z, zd = (float(v) for v in self.x)
        return WinchState(length, v, self.acc, z, zd, float(self.tension), *self.flags, valid, warning, *self.tip_ne)

    def get_state(self) -> dict:
        """JSON-serialisable state."""
        return {"x": self.x.tolist(), "flags": [bool(f) for f in self.flags], "tension": float(self.tension), "acc": self.acc,
                "inputs": list(self.inputs), "tip_ne": list(self.tip_ne)}

    def set_state(self, s: dict) -> None:
        """Restore from :meth:`get_state`."""
        self.x = np.array(s["x"], dtype=float)
        self.flags = [bool(f) for f in s["flags"]]
        self.tension, self.acc = float(s["tension"]), float(s["acc"])
        self.inputs = tuple(float(v) for v in s["inputs"])
        self.tip_ne = tuple(float(v) for v in s["tip_ne"])

