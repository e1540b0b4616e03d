"""The joint motion filter: its blocks, its folded prediction, its teaching's alignment, its bad
samples and its state."""
from __future__ import annotations

import json

import numpy as np
import pytest

from marinefmu.estimators.mru.joint import (AGREEMENT_SETTLE, BLEND, CHANNELS, GATE, JointMotion, block_edges,
                                           linear_channels, slow_rows)

DT = 0.05
LAG = 40
#: Forgetting [s]: long, so that the fit comes within the tests' records.
FORGET = 6000.0


def test_block_edges_start_with_the_newest_sample_and_keep_the_shortest_and_longest_blocks():
    edges = block_edges(60.0, 0.01, longest=2.0, shortest=0.05)
    lengths = np.diff(edges)
    assert edges[:2].tolist() == [0, 1] and edges[-1] == 6000
    assert lengths[1:-1].min() == 5 and lengths.max() == 200
    assert np.all(np.diff(lengths[:-1]) >= 0)
    # without a shortest block, every young block is one sample (the tilt bound's rows)
    assert np.diff(block_edges(60.0, 0.01, longest=2.0))[:10].tolist() == [1] * 10


def white_channels(n: int, seed: int = 1) -> np.ndarray:
    return np.random.default_rng(seed).normal(size=(n, 6))


def test_the_folded_prediction_is_the_rows_times_the_weights():
    """The per-step product with the running sums at the edges (V folded from W) equals the
    explicit row (block means, angle changes, 1) times W."""
    joint = JointMotion(10.0, DT, LAG, FORGET)
    for x in white_channels(500):
        joint.push(tuple(x))
    joint.weights = np.random.default_rng(2).normal(size=(joint.features_count, 6))
    joint._fold()
    expected = (joint.features() @ joint.weights).reshape(2, 3)
    np.testing.assert_allclose(joint.predict(), expected, rtol=1e-10, atol=1e-10)


def teacher(target: np.ndarray) -> np.ndarray:
    """The axis filters' (3, 4) outputs whose delayed position and rate (columns 2, 3) are
    ``target`` (6,): position (3), then rate (3)."""
    out = np.full((3, 4), np.nan)
    out[:, 2:] = target.reshape(2, 3).T
    return out


def taught(channels: np.ndarray, targets: np.ndarray, bad: int | None = None) -> tuple[JointMotion, list]:
    """A filter fed ``channels`` and taught ``targets`` ``LAG`` samples late; its predictions
    once it has a fit. The bare least squares (``slow=False``): white-noise targets answer
    constants and ramps too."""
    joint = JointMotion(10.0, DT, LAG, FORGET, slow=False)
    predictions = []
    for k, x in enumerate(channels):
        joint.push(None if k == bad else tuple(x))
        if k >= LAG:
            joint.teach(teacher(targets[k - LAG]), True)
        if joint.ready:
            predictions.append((k, joint.predict()))
    return joint, predictions


def test_a_target_that_is_a_linear_function_of_the_past_is_predicted_now():
    """Targets that are the newest samples of three channels and a constant, taught ``LAG``
    samples late: once fitted the filter gives them now, to the ridge's bias. A row one sample
    off in time would see white noise uncorrelated with its target."""
    n = 14000
    x = white_channels(n)
    targets = np.column_stack([x[:, 3], x[:, 0], 0.3 + x[:, 5], 0.5 * x[:, 4], np.zeros(n), -x[:, 1]])
    joint, predictions = taught(x, targets)
    assert len(predictions) > 2000
    err = np.array([p.ravel() - targets[k] for k, p in predictions])
    assert np.abs(err).max() < 1e-3, np.abs(err).max()


def test_rows_spanning_a_bad_sample_are_not_taught():
    """A bad sample at 75 s: the rows whose span (the lag and the memory) holds it are left out
    of the fit folded at 120 s, and only those."""
    n, bad = 2500, 1500
    x = white_channels(n)
    targets = np.zeros((n, 6))
    clean, _ = taught(x, targets)
    spoilt, _ = taught(x, targets, bad=bad)
    span = LAG + int(spoilt.edges[-1])                 # [samples]
    # a row is taught after the push that makes the count k, every stride; it spans k - 1 - span … k - 1
    spanning = [k for k in range(bad + 1, bad + span + 2) if k % spoilt.stride == 0]
    assert len(spanning) > 20
    assert clean.rows - spoilt.rows == len(spanning)


def test_a_restored_state_continues_identically():
    n = 14000
    x = white_channels(n)
    targets = np.column_stack([x[:, 3], x[:, 0], 0.3 + x[:, 5], 0.5 * x[:, 4], np.zeros(n), -x[:, 1]])
    joint = JointMotion(10.0, DT, LAG, FORGET)
    copy = None
    for k, row in enumerate(x):
        if k == 12000:
            assert joint.ready
            copy = JointMotion(10.0, DT, LAG, FORGET)
            copy.set_state(json.loads(json.dumps(joint.get_state())))
        for j in (joint, copy) if copy else (joint,):
            j.push(tuple(row))
            j.teach(teacher(targets[k - LAG]), k >= LAG)
        if copy:
            np.testing.assert_array_equal(copy.predict(), joint.predict())


def test_the_linear_channels_are_the_euler_rates_and_the_tilted_force():
    """Euler rates T(φ, θ) ω and a_h + g [θ, −φ, 0]: level, they are the body rate and the
    force; a pure pitch rate turns into φ̇ and ψ̇ through tan θ and 1/cos θ."""
    level = linear_channels((0.1, 0.2, 0.3), 0.0, 0.0, (1.0, 2.0, 3.0))
    np.testing.assert_allclose(level, (0.1, 0.2, 0.3, 1.0, 2.0, 3.0))
    roll, pitch = 0.2, 0.1
    u = linear_channels((0.0, 0.0, 0.05), roll, pitch, (0.0, 0.0, 0.0))
    np.testing.assert_allclose(u[:3], (0.05 * np.cos(roll) * np.tan(pitch), -0.05 * np.sin(roll),
                                       0.05 * np.cos(roll) / np.cos(pitch)), rtol=1e-12)
    np.testing.assert_allclose(u[3:], (9.80665 * pitch, -9.80665 * roll, 0.0), rtol=1e-12)
    assert CHANNELS == 9


@pytest.mark.parametrize("memory, dt", [(60.0, 0.01), (10.0, 0.1)])
def test_the_first_fit_waits_for_two_rows_per_weight(memory, dt):
    joint = JointMotion(memory, dt, 10, 600.0)
    assert joint.warmup_rows == 2 * joint.features_count


@pytest.mark.parametrize("channel", (6, 7))
def test_the_slow_rows_are_the_filters_own_rows_of_a_constant_force(channel):
    """Each slow row is the row the filter builds from its own running sums when one horizontal
    level specific force has been a unit constant for the memory's span and more."""
    joint = JointMotion(10.0, DT, LAG, FORGET)
    fed = JointMotion(10.0, DT, LAG, FORGET)
    for _ in range(2 * int(joint.edges[-1]) + 1):
        x = np.zeros(6)
        x[channel - 3] = 1.0
        fed.push(tuple(x))
    row = fed.features()
    row[-1] = 0.0
    np.testing.assert_allclose(row, slow_rows(joint.edges)[channel - 6], rtol=1e-9, atol=1e-12)


def test_a_departure_from_the_axis_filters_withholds_the_output_for_the_memory():
    """Agreeing with the axis filters' real-time outputs (to white noise of 1 cm), the fitted
    filter's check passes its prediction; one step beyond GATE × their RMS difference withholds
    it, and the output comes back, blended in afresh, once the memory has passed that step."""
    rng = np.random.default_rng(3)
    joint = JointMotion(10.0, DT, LAG, FORGET)
    joint.weights = rng.normal(size=(joint.features_count, 6))
    joint._fold()
    joint.fitted_at = joint.blend_from = 0

    def step(offset: float = 0.0):
        joint.push(tuple(rng.normal(size=6)))
        now = joint.predict()
        out = np.zeros((3, 4))
        out[:, :2] = now.T + rng.normal(0.0, 0.01, (3, 2))
        out[1, 0] += offset
        return joint.check(now, out)

    settle = int(AGREEMENT_SETTLE / DT)
    got = [step() for _ in range(settle + 100)]
    assert all(g is not None for g in got)
    assert GATE * 0.01 < 0.5 < 100 * 0.01         # the offset below is far beyond the gate
    k = joint.k
    assert step(offset=0.5) is None and joint.disagreed and joint.distrusted_until == k + 1 + joint.edges[-1]
    assert not joint.blended and joint.share() == 0.0
    span = int(joint.edges[-1])
    withheld = [step() for _ in range(span)]
    assert all(g is None for g in withheld[:-1]) and withheld[-1] is not None    # k reaches event + span
    assert joint.share() == 0.0 and step() is not None and joint.share() == DT / BLEND
