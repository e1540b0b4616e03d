"""Plumbing shared by the pythonfmu slaves in ``models/``.

pythonfmu's C++ loader finds the slave class by the literal text ``class X(Fmi2Slave):`` in
the script, so the scripts cannot inherit from a common base; they compose a :class:`SlaveIO`
instead. It registers a model's variable tables (``marinefmu.variables.Variable``) with
getters and setters on plain dicts and lists, and saves/restores the model's internal state
together with the registered variables (pythonfmu's default state only covers registered
variables).

**Slaves never raise.** pythonfmu turns a Python exception into fmi2Fatal, and in 0.7.0 its
handler releases the slave class once more than it should (``handle_py_exception`` and the
instance destructor both call ``cleanPyObject``): after about three exceptions in one
process the interpreter crashes. So a refused parameter is logged with status error (naming
the parameter and its range) at initialisation, the model is not built, and every
``doStep`` logs the refusal again and returns ``False`` (fmi2Discard); an unexpected error in
a step is handled the same way. :class:`~marinefmu.cosim.system.SystemRunner` treats an
error logged during initialisation as a refusal and raises with that message.

**Memory per instantiation.** pythonfmu 0.7.0's loader executes the model script again for
every instance (``findClass``) and never releases the list it makes of each class's MRO, so
the class made by that execution, with its methods, stays alive (about 5 KB), and it inserts
the resources folder into ``sys.path`` once more. The model scripts therefore bind the class
made by their import when they run again (:meth:`SlaveIO.rerun`) instead of making a new
one, and :class:`SlaveIO` drops repeated ``sys.path`` entries. What remains (the MRO lists
and class-name strings) is measured by ``marinefmu bench`` (the FMU contract page).

**Reading outputs.** A master reads the real outputs of every FMU at every step, and
pythonfmu's ``get_real`` looks up each variable, checks its type and calls its getter. Each
:class:`SlaveIO` therefore gives its slave a ``get_real`` that reads registered real outputs
from :attr:`SlaveIO.real_out` by value reference and hands any other request to pythonfmu's
(:meth:`SlaveIO._real_output_reader`): the values returned are the same. Its ``set_real``
stores real inputs in :attr:`SlaveIO.inputs` the same way (:meth:`SlaveIO._real_input_writer`).

**The estimators' own log.** What an estimator reports through :mod:`logging` while a slave
steps it (a heave observer that finds no sea, a centre of rotation with no rotation to see,
a bias step found) goes to that instance's FMU log as a warning, at the step's time: one
handler on the ``marinefmu`` logger hands each record to the slave stepping on the thread that
made it (libcosim may step instances on several threads). A bad-sample message the slave
already reports through :meth:`SlaveIO.warn` is not repeated.

**Process exit.** At ``exit()`` pythonfmu 0.7.0's library writes into memory its own static
destructor has freed. Every :class:`SlaveIO` therefore arms :func:`marinefmu.fmu.host_exit.guard`
for the library it runs in (once per loaded copy), which empties that pointer first, so any
host, Python or not, exits cleanly (``host_exit``'s module doc has the mechanism).
"""
from __future__ import annotations

import copy
import logging
import math
import sys
import threading
import traceback
from collections.abc import Callable, Sequence
from typing import Any, TypeVar

from pythonfmu import Boolean, Fmi2Causality, Fmi2Variability, Integer, Real, String
from pythonfmu.enums import Fmi2Status
from pythonfmu.fmi2slave import Fmi2Slave

from ..errors import MarineFmuError
from ..variables import Variable
from . import host_exit

M = TypeVar("M")
_FMI_TYPES = {"real": Real, "integer": Integer, "boolean": Boolean, "string": String}
_CAST: dict[str, Callable[[Any], Any]] = {"real": float, "integer": int, "boolean": bool, "string": str}


#: The SlaveIO stepping on each thread (thread id → SlaveIO), for :class:`_ToFmuLog`.
_STEPPING: dict[int, "SlaveIO"] = {}


class _ToFmuLog(logging.Handler):
    """Collects a ``marinefmu`` log record for the slave stepping on the record's thread."""

    def emit(self, record: logging.LogRecord) -> None:
        io = _STEPPING.get(record.thread)
        if io is not None:
            io._logged.append(record)


if not any(isinstance(h, _ToFmuLog) for h in logging.getLogger("marinefmu").handlers):
    logging.getLogger("marinefmu").addHandler(_ToFmuLog(logging.WARNING))


def _describe(var: Variable) -> str:
    return f"{var.description} [{var.unit}]" if var.unit else var.description


#: One reference to a model script's namespace per run of the script by pythonfmu (SlaveIO.rerun).
_NAMESPACE_REFS: list[dict] = []


def _drop_repeated_sys_path() -> None:
    """Remove repeated ``sys.path`` entries, keeping the first of each (pythonfmu 0.7.0 inserts
    the FMU's resources folder once more at every instantiation)."""
    seen: set[str] = set()
    sys.path[:] = [p for p in sys.path if not (p in seen or seen.add(p))]


class SlaveIO:
    """Variables of one slave instance.

    Parameters
    ----------
    slave : Fmi2Slave
        The instance to register variables on.
    parameters : sequence of Variable
        Parameters (variability ``fixed``: set before initialisation).
    outputs : sequence of Variable
        Real outputs, in the order of the model's output list.
    boolean_outputs : sequence of Variable
        Discrete outputs (boolean or integer), in the order of the model's discrete list.
    inputs : sequence of Variable
        Inputs (real, integer or boolean), stored in :attr:`inputs` by name.
    """

    def __init__(self, slave: Fmi2Slave, parameters: Sequence[Variable], outputs: Sequence[Variable],
                 boolean_outputs: Sequence[Variable] = (), inputs: Sequence[Variable] = ()) -> None:
        _drop_repeated_sys_path()
        host_exit.guard(getattr(slave, "resources", None))
        self.slave = slave
        self.params: dict[str, Any] = {v.name: v.default for v in parameters}
        self.inputs: dict[str, Any] = {v.name: v.default for v in inputs}
        self.real_out: list[float] = [float(v.default) for v in outputs]
        self.bool_out: list[Any] = [_CAST[v.kind](v.default) for v in boolean_outputs]
        self.start_time = 0.0
        #: Why the slave cannot step (refused parameter or failed step), else None.
        self.error: str | None = None
        self._warning: str | None = None
        self._repeats = 0
        self._logged: list[logging.LogRecord] = []
        #: FMI unit of every registered variable (read by the build to write UnitDefinitions).
        self.units: dict[str, str] = {v.name: v.unit for v in (*parameters, *inputs, *outputs, *boolean_outputs)}
        for v in parameters:
            self._register(v, Fmi2Causality.parameter, Fmi2Variability.fixed, self.params)
        in_index: dict[int, str] = {}  # value reference → name of a real input
        for v in inputs:
            vr = self._register(v, Fmi2Causality.input, Fmi2Variability.continuous if v.kind == "real" else Fmi2Variability.discrete, self.inputs)
            if v.kind == "real":
                in_index[vr] = v.name
        slave.set_real = self._real_input_writer(slave.set_real, in_index)
        out_index: dict[int, int] = {}  # value reference → index in real_out
        for i, v in enumerate(outputs):
            var = Real(v.name, causality=Fmi2Causality.output, variability=Fmi2Variability.continuous,
                       description=_describe(v), getter=self._item_getter(self.real_out, i))
            slave.register_variable(var, nested=False)
            out_index[var.value_reference] = i
        slave.get_real = self._real_output_reader(slave.get_real, out_index)
        for i, v in enumerate(boolean_outputs):
            slave.register_variable(_FMI_TYPES[v.kind](v.name, causality=Fmi2Causality.output, variability=Fmi2Variability.discrete,
                                                       description=_describe(v), getter=self._item_getter(self.bool_out, i)), nested=False)

    def _register(self, v: Variable, causality: Fmi2Causality, variability: Fmi2Variability, store: dict) -> int:
        """Register ``v`` with a getter and setter on ``store``; return its value reference."""
        cast = _CAST[v.kind]

        def setter(value: Any, name: str = v.name) -> None:
            store[name] = cast(value)

        var = _FMI_TYPES[v.kind](v.name, causality=causality, variability=variability, description=_describe(v),
                                 getter=lambda name=v.name: store[name], setter=setter)
        self.slave.register_variable(var, nested=False)
        return var.value_reference

    @staticmethod
    def rerun(namespace: dict[str, Any], name: str) -> type:
        """The slave class ``name`` made when the model script was imported, for the script's
        later runs by pythonfmu's loader (one per instance), which would otherwise make a new
        class each time.

        pythonfmu 0.7.0's ``findClass`` runs the script again in the module's namespace, keeps
        every class that run makes alive (the MRO list it takes of each is never released:
        about 5 KB per instance with the methods), and releases a reference to the module's
        namespace it never took (``Py_DECREF`` of the borrowed ``PyModule_GetDict``). The new
        methods' references to the namespace used to hide that; with no new methods the
        namespace would be freed after a few instances, so one reference is kept here for each
        run (8 bytes).
        """
        _NAMESPACE_REFS.append(namespace)
        return namespace[name]

    @staticmethod
    def _item_getter(values: list, i: int) -> Callable[[], Any]:
        return lambda: values[i]

    def _real_output_reader(self, get_real: Callable[[list[int]], list[float]], index: dict[int, int]) -> Callable[[list[int]], list[float]]:
        """The slave's ``get_real``: a read of real outputs only (what a master does every step)
        indexes :attr:`real_out` directly; any other read (an input, a parameter, a value
        reference of another type) goes to pythonfmu's own ``get_real``, which gives the same
        values, the same ``float`` conversion and the same TypeError."""
        values = self.real_out

        def read(vrs: list[int]) -> list[float]:
            try:
                return [float(values[index[vr]]) for vr in vrs]
            except (KeyError, TypeError):
                return get_real(vrs)

        return read

    def _real_input_writer(self, set_real: Callable[[list[int], list[float]], None], index: dict[int, str]) -> Callable[[list[int], list[float]], None]:
        """The slave's ``set_real``: real inputs (what a master sets every step) are stored in
        :attr:`inputs` directly, as their setters would (``float(value)``); from the first value
        reference that is not a real input on, the rest of the call goes to pythonfmu's own
        ``set_real`` (parameters, type errors)."""
        store = self.inputs

        def write(vrs: list[int], values: list[float]) -> None:
            for k, (vr, value) in enumerate(zip(vrs, values)):
                name = index.get(vr)
                if name is None:
                    set_real(list(vrs)[k:], list(values)[k:])
                    return
                store[name] = float(value)

        return write

    def build(self, factory: Callable[[dict[str, Any]], M]) -> M | None:
        """Build the model from the parameter values; on refusal log it and return None.

        A :class:`~marinefmu.errors.MarineFmuError` (e.g. ``sea.hs = -1.0 is out of range``) is
        logged with status error so the importing tool shows which parameter was refused;
        :attr:`error` keeps the message and :meth:`step` then refuses to step.
        """
        self.error = None
        try:
            return factory(dict(self.params))
        except MarineFmuError as exc:
            self.error = f"invalid parameter: {exc}"
        except Exception as exc:  # noqa: BLE001 - never let pythonfmu see an exception (module doc)
            self.error = f"initialisation failed: {type(exc).__name__}: {exc}"
        self.slave.log(f"{self.slave.instance_name}: {self.error}", Fmi2Status.error)
        return None

    def step(self, fn: Callable[[float, float], None], current_time: float, step_size: float) -> bool:
        """Run one step's work ``fn(t, dt)`` with ``t = current_time + step_size``; return False
        (fmi2Discard) after logging if the slave was refused at initialisation or ``fn`` raises.

        An exception in ``fn`` is logged with its traceback once; every later step is refused.
        A step size that is not a positive finite number is refused the same way, but only for
        that call: nothing is changed, so the host can retry with a valid step.
        """
        if self.error is None and not (math.isfinite(step_size) and step_size > 0.0 and math.isfinite(current_time)):
            self.slave.log(f"{self.slave.instance_name}: t = {current_time!r} s: communication step size {step_size!r} s "
                           "refused: must be a finite number > 0; nothing was changed", Fmi2Status.error)
            return False
        if self.error is None:
            thread = threading.get_ident()
            try:
                _STEPPING[thread] = self
                fn(current_time + step_size, step_size)
                return True
            except Exception as exc:  # noqa: BLE001 - never let pythonfmu see an exception
                self.error = f"step failed at t = {current_time!r} s: {type(exc).__name__}: {exc}"
                self.slave.log(f"{self.slave.instance_name}: {self.error}\n{traceback.format_exc()}", Fmi2Status.error)
                return False
            finally:
                _STEPPING.pop(thread, None)
                if self._logged:
                    self._forward_log(current_time + step_size)
        self.slave.log(f"{self.slave.instance_name}: {self.error}; the FMU cannot step", Fmi2Status.error)
        return False

    def _forward_log(self, time: float) -> None:
        """The step's ``marinefmu`` log records to the FMU log (module doc), less the bad-sample
        message :meth:`warn` already logged."""
        records, self._logged = self._logged, []
        for record in records:
            text = record.getMessage()
            if self._warning is not None and self._warning in text:
                continue
            self.slave.log(f"{self.slave.instance_name}: t = {time:.4f} s: {text}", Fmi2Status.warning)

    def warn(self, message: str | None, time: float, valid: bool = False) -> None:
        """Report a rejected sample (``message``) or a good one (None) as an FMU warning.

        ``valid`` is the estimator's ``valid`` output on this step: a rejected sample says
        "holding/coasting, valid = false"; an event the estimator handled with a valid output
        (a GNSS re-initialisation) says "valid = true".

        A run of identical rejections is logged once when it starts and once, with its
        length, when it ends, so a long sensor outage is visible without flooding the log.
        """
        if message == self._warning:
            self._repeats += message is not None
            return
        if self._warning is not None:
            self.slave.log(f"{self.slave.instance_name}: t = {time:.4f} s: {self._warning} ended after {self._repeats + 1} step(s)",
                           Fmi2Status.warning)
        if message is not None:
            consequence = "valid = true" if valid else "holding/coasting, valid = false"
            self.slave.log(f"{self.slave.instance_name}: t = {time:.4f} s: {message}; {consequence}",
                           Fmi2Status.warning)
        self._warning, self._repeats = message, 0

    def set_outputs(self, reals: list[float], booleans: list[bool] | None = None) -> None:
        """Replace the output values in place (the getters hold references to these lists)."""
        self.real_out[:] = reals
        if booleans is not None:
            self.bool_out[:] = booleans

    def get_state(self, model: Any) -> dict:
        """FMU state: parameters, inputs, outputs and the model's own state (JSON-serialisable)."""
        return {
            "params": dict(self.params), "inputs": dict(self.inputs), "real_out": list(self.real_out),
            "bool_out": list(self.bool_out), "start_time": self.start_time,
            "model": copy.deepcopy(model.get_state()) if model is not None else None,
        }

    def set_state(self, model: Any, state: dict) -> None:
        """Restore a state from :meth:`get_state`."""
        self.params.update(state["params"])
        self.inputs.update(state["inputs"])
        self.set_outputs(state["real_out"], state["bool_out"])
        self.start_time = state["start_time"]
        if model is not None and state["model"] is not None:
            model.set_state(copy.deepcopy(state["model"]))
