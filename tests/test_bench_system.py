"""The bench's memory figure for the whole system (bench_system.peak_rss_mb): a worker reports
its own peak, not the peak of the process that started it."""
import subprocess
import sys

import numpy as np

from marinefmu.bench_system import peak_rss_mb


def test_a_worker_reports_its_own_peak_not_its_parents():
    """Linux keeps ``ru_maxrss`` across ``execve``: a worker started by a bench process holding
    300 MB read 300 MB or more, whatever it used itself (2026-11-23: 313 MB for every engine).
    VmHWM starts afresh at exec."""
    held = np.ones(300 * 2**20 // 8)                       # 300 MB resident in this process
    assert peak_rss_mb() > 300.0
    code = "from marinefmu.bench_system import peak_rss_mb; print(peak_rss_mb())"
    child = float(subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout)
    assert 1.0 < child < 150.0, child                      # a bare interpreter and this module: ~20-80 MB
    assert held[-1] == 1.0
