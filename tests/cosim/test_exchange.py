"""The master's data exchange (marinefmu.cosim.exchange): one read per component and type,
recording, gathered sets, errors naming the component."""
import numpy as np
import pytest

from marinefmu.cosim.exchange import Exchange, ExchangeError, Port


class FakeChannels:
    """Components whose outputs are {vr: value}; counts every get and keeps every set."""

    def __init__(self, outputs):
        self.outputs = outputs            # (component, kind) -> {vr: value}
        self.gets = []
        self.sets = []
        self.fail = None

    def __call__(self, comp, op, kind, vrs):
        buf = np.zeros(len(vrs), dtype=np.float64 if kind == "Real" else np.int32)
        vrs = list(vrs)
        if op == "get":
            def call():
                self.gets.append((comp, kind, tuple(vrs)))
                if self.fail == comp:
                    raise ExchangeError("fmi2GetReal returned ERROR")
                buf[:] = [self.outputs[comp, kind][vr] for vr in vrs]
        else:
            def call():
                self.sets.append((comp, kind, tuple(vrs), buf.tolist()))
        return buf, call


def test_each_source_is_read_once_and_inputs_are_gathered_from_the_reads():
    ch = FakeChannels({("v", "Real"): {1: 1.5, 2: 2.5, 3: 3.5}, ("v", "Boolean"): {9: 1},
                       ("a", "Real"): {5: -7.0}})
    wires = [(Port("v", "Real", 2), Port("a", "Real", 100)), (Port("v", "Real", 1), Port("a", "Real", 101)),
             (Port("v", "Boolean", 9), Port("a", "Boolean", 102)),
             (Port("v", "Real", 2), Port("b", "Real", 200)), (Port("a", "Real", 5), Port("b", "Real", 201))]
    recorded = [Port("v", "Real", 3), Port("a", "Real", 5), Port("v", "Boolean", 9), Port("v", "Real", 2)]
    ex = Exchange(ch, wires, recorded)
    ex.read()
    # one read per (component, type), every needed reference in it once
    assert sorted(ch.gets) == [("a", "Real", (5,)), ("v", "Boolean", (9,)), ("v", "Real", (2, 1, 3))]
    row = np.zeros(5)
    ex.record(row, 0.25)
    assert row.tolist() == [0.25, 3.5, -7.0, 1.0, 2.5]
    ex.write(["a"])                          # b is not due: nothing set on it
    assert sorted(ch.sets) == [("a", "Boolean", (102,), [1]), ("a", "Real", (100, 101), [2.5, 1.5])]
    ch.sets.clear()
    ex.write(["b", "v"])                     # v has no inputs
    assert ch.sets == [("b", "Real", (200, 201), [2.5, -7.0])]


def test_a_failing_call_names_its_component():
    ch = FakeChannels({("v", "Real"): {1: 0.0}, ("a", "Real"): {5: 0.0}})
    ex = Exchange(ch, [(Port("v", "Real", 1), Port("a", "Real", 100))], [Port("a", "Real", 5)])
    ch.fail = "a"
    with pytest.raises(ExchangeError, match="ERROR") as err:
        ex.read()
    assert err.value.component == "a"
