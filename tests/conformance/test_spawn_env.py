"""Children started from worker threads while the main thread changes the environment, as the
conformance and exit fixtures do while pytest sets ``PYTEST_CURRENT_TEST`` test after test."""
from __future__ import annotations

import os
import subprocess
import threading
from concurrent.futures import ThreadPoolExecutor

import pytest

from tests.conftest import spawn_env

SPAWNS = 150  # per run; with env=None 9-12 of them failed on the 2-core machine
VAR = "MARINEFMU_TEST_SPAWN_CHURN"


def _spawn_failures(env_of) -> int:
    """Children started two at a time while another thread sets and unsets ``VAR``; how many
    failed to start (OSError)."""
    stop = threading.Event()

    def churn() -> None:
        i = 0
        while not stop.is_set():
            os.environ[f"{VAR}_{i % 64}"] = "x" * (i % 40)
            os.environ.pop(f"{VAR}_{(7 * i) % 64}", None)
            i += 1

    def one(_: int) -> int:
        try:
            subprocess.run(["true"], capture_output=True, env=env_of(), timeout=60)
        except OSError:
            return 1
        return 0

    churner = threading.Thread(target=churn)
    churner.start()
    try:
        with ThreadPoolExecutor(max_workers=2) as pool:
            return sum(pool.map(one, range(SPAWNS)))
    finally:
        stop.set()
        churner.join()
        for key in [k for k in os.environ if k.startswith(VAR)]:
            del os.environ[key]


def test_a_child_given_its_environment_starts_while_another_thread_changes_it():
    assert _spawn_failures(spawn_env) == 0


#: Runs of :data:`SPAWNS` before the hazard test gives up: a race, it failed 4-7 of 150 spawns
#: a run alone and none in one run of the full suite (the other worker's load changes the timing).
HAZARD_ROUNDS = 10


@pytest.mark.skipif(not getattr(subprocess, "_USE_VFORK", False), reason="this Python does not vfork")
def test_a_child_sharing_the_environment_can_fail_to_start_so_the_first_test_can_fail():
    """The hazard ``spawn_env`` avoids: with ``env=None`` some children fail with EFAULT, within
    :data:`HAZARD_ROUNDS` runs (most runs show it; the first that does ends the test)."""
    assert any(_spawn_failures(lambda: None) > 0 for _ in range(HAZARD_ROUNDS))
