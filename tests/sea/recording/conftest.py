"""Small records and sidecars written on the fly."""
from __future__ import annotations

from pathlib import Path

import pytest

BASIC_MAPPING = """
[time]
column = "t"
unit = "s"
[imu]
max_gap = 0.15
acc = { x = "ax", y = "ay", z = "az" }
gyro = { x = "gx", y = "gy", z = "gz" }
[gnss]
max_gap = 0.5
ant1 = { n = "n1", e = "e1", d = "d1", lever_arm = [1.0, 0.0, -2.0] }
[ref]
roll = "roll"
"""


def write(tmp: Path, name: str, text: str) -> Path:
    p = tmp / name
    p.write_text(text, encoding="utf-8")
    return p


@pytest.fixture
def basic(tmp_path):
    """A 1 s record at 10 Hz (GNSS every 5th row, empty fields between) and its mapping."""
    lines = ["t,ax,ay,az,gx,gy,gz,n1,e1,d1,roll"]
    for k in range(11):
        t = k * 0.1
        gnss = f"{k * 1.0},{-k * 1.0},{0.5}" if k % 5 == 0 else ",,"
        lines.append(f"{t:.1f},{k},{2 * k},{-9.8},{0.1 * k},0,0,{gnss},{0.01 * k}")
    csv = write(tmp_path, "rec.csv", "\n".join(lines) + "\n")
    return csv, write(tmp_path, "rec.toml", BASIC_MAPPING)
