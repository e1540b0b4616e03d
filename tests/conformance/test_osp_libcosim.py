"""OSP-IS descriptions and all FMUs together under libcosim.

* Every FMU passes FMPy's validation and its ``_OspModelDescription.xml`` agrees with its
  modelDescription.xml (names, causality, units).
* libcosim loads an ``OspSystemStructure.xml`` that wires VesselMotion to all five estimators
  by variable groups alone, runs them in one execution (worker threads), and every estimator
  ends bit-identical to a separate execution of VesselMotion and that estimator alone.
"""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest
from fmpy import read_model_description
from fmpy.validation import validate_fmu

from marinefmu.fmu import osp

sys.path.insert(0, str(Path(__file__).resolve().parent))
from fmu_worker import FMUS, PARAMS  # noqa: E402

pytestmark = pytest.mark.fmu
STEP, STEPS = 0.05, 1400  # 70 s: every estimator valid (HeaveObserver's 60 s window included)
#: input group of each estimator <- output group of VesselMotion
WIRING = {
    "AttitudeEstimator": {"gyro": "imu.gyro", "acc": "imu.acc"},
    "DisplacementReconstructor": {"acc": "imu.acc", "roll": "truth.roll", "pitch": "truth.pitch", "yaw": "truth.yaw"},
    "GnssAccFusion": {"acc": "imu.acc", "gyro": "imu.gyro", **{f"gnss.ant{i}": f"gnss.ant{i}" for i in range(1, 5)},
                      "gnss.valid": "gnss.valid", "gnss.new": "gnss.new"},
    "CentreOfRotation": {"acc": "imu.acc", "gyro": "imu.gyro", "roll": "truth.roll", "pitch": "truth.pitch",
                         "yaw": "truth.yaw"},
    "HeaveObserver": {"acc": "imu.acc", "roll": "truth.roll", "pitch": "truth.pitch"},
    "MotionReferenceUnit": {"gyro": "imu.gyro", "acc": "imu.acc"},
}


@pytest.mark.parametrize("name", FMUS)
def test_validation_and_osp_description_agree_with_the_model_description(fmu_dir, name):
    import zipfile

    assert validate_fmu(str(fmu_dir / f"{name}.fmu")) == []
    with zipfile.ZipFile(fmu_dir / f"{name}.fmu") as z:
        md_xml = z.read("modelDescription.xml")
    osp_xml = (fmu_dir / f"{name}_OspModelDescription.xml").read_bytes()
    assert osp.check(md_xml, osp_xml) == []
    # and the check is not blind: a wrong unit and a lost output are reported
    import re

    broken = re.sub(rb'unit="[^"]+"', b'unit="deg"', osp_xml, count=1)
    last = broken.rfind(b"<Variable ")
    broken = broken[:last] + b"<Unused " + broken[last + len(b"<Variable "):]
    problems = osp.check(md_xml, broken)
    assert any("has unit 'deg'" in p for p in problems) and any("is in no group" in p for p in problems), problems


def test_osp_check_reports_each_kind_of_disagreement(fmu_dir):
    import zipfile

    with zipfile.ZipFile(fmu_dir / "HeaveObserver.fmu") as z:
        md_xml = z.read("modelDescription.xml")
    good = (fmu_dir / "HeaveObserver_OspModelDescription.xml").read_text()
    cases = {
        "is not in modelDescription.xml": good.replace('ref="heave_rate"', 'ref="heave_speed"'),
        "has causality parameter": good.replace('ref="heave_rate"', 'ref="window"'),
        "is in more than one group": good.replace('ref="heave_rate"', 'ref="heave"'),
        "mixes input and output": good.replace('ref="acc.x" unit="m/s2"', 'ref="heave" unit="m"'),
        "is in no group": good.replace('ref="offset"', 'ref="heave"'),
    }
    for expected, text in cases.items():
        assert any(expected in p for p in osp.check(md_xml, text.encode())), expected


def _execute(fmu_dir: Path, tmp: Path, estimators: list[str]) -> dict[str, np.ndarray]:
    """Run VesselMotion + ``estimators`` from an OspSystemStructure.xml; the final outputs of
    each estimator (reals, booleans, then ``valid`` again) by name."""
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver

    log_output_level(CosimLogLevel.ERROR)
    simulators = {"vessel": (fmu_dir / "VesselMotion.fmu", PARAMS["VesselMotion"])}
    connections = []
    for name in estimators:
        simulators[name] = (fmu_dir / f"{name}.fmu", PARAMS[name])
        connections += [(("vessel", src), (name, dst)) for dst, src in WIRING[name].items()]
    structure = osp.write_system_structure(tmp / f"OspSystemStructure-{len(estimators)}-{estimators[0]}.xml", STEP,
                                           simulators, connections)
    ex = CosimExecution.from_osp_config_file(str(structure))
    assert ex.num_slaves() == len(simulators)
    obs = CosimObserver.create_last_value()
    ex.add_observer(obs)
    assert ex.simulate_until(round(STEPS * STEP * 1e9))
    out = {}
    for name in estimators:
        index = ex.slave_index_from_instance_name(name)
        md = read_model_description(str(fmu_dir / f"{name}.fmu"))
        reals = [v.valueReference for v in md.modelVariables if v.causality == "output" and v.type == "Real"]
        bools = [v.valueReference for v in md.modelVariables if v.causality == "output" and v.type == "Boolean"]
        valid = next(v.valueReference for v in md.modelVariables if v.name == "valid")
        out[name] = np.array([*obs.last_real_values(index, reals), *map(float, obs.last_boolean_values(index, bools)),
                              float(obs.last_boolean_values(index, [valid])[0])])
    return out


@pytest.mark.libcosim
@pytest.mark.isolated
def test_all_fmus_in_one_libcosim_execution_equal_each_alone(fmu_dir, tmp_path):
    pytest.importorskip("libcosimpy")
    estimators = [n for n in FMUS if n in WIRING]   # the FMUs fed by VesselMotion alone
    together = _execute(fmu_dir, tmp_path, estimators)
    for name in estimators:
        alone = _execute(fmu_dir, tmp_path, [name])[name]
        assert np.array_equal(together[name], alone), name
        assert np.all(np.isfinite(alone)) and alone[-1] == 1.0, (name, alone)  # finite and valid at the end
