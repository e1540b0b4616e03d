"""``marinefmu build-recording``: a self-contained SensorRecording FMU with its record bundled.

The FMU is the SensorRecording script (``models/SensorRecording.py``) built as every marinefmu
FMU is (pythonfmu's ``FmuBuilder`` with the package in ``resources/``, then units and initial
unknowns by :mod:`marinefmu.fmu.units`, the OSP model description by :mod:`marinefmu.fmu.osp`,
and ``fmpy.validation.validate_fmu``), plus ``resources/recording/``: the record gzip-compressed
(a CSV; a ``.gz`` or Parquet file as it is) and its sidecar as ``mapping.toml``. Its ``file`` and
``mapping`` parameters left empty then mean those, so the FMU can be mailed to a colleague or
dropped into libcosim without the original file. The record and its sidecar are checked (a full
scan, :class:`~marinefmu.sea.recording.reader.Record`) before anything is built.
"""
from __future__ import annotations

import gzip
import shutil
import tempfile
import zipfile
from pathlib import Path

from ..sea.recording.mapping import load_mapping
from ..sea.recording.player import BUNDLE_DIR, BUNDLE_MAPPING
from ..sea.recording.reader import Record, is_parquet
from .build import BuildError, check_and_describe, repack, repo_root, slave_units

MODEL = "SensorRecording"
#: The package bundled into the FMU's resources (as every marinefmu FMU bundles it).
PACKAGE_DIR = Path(__file__).resolve().parents[1]


def _script() -> Path:
    return repo_root() / "models" / f"{MODEL}.py"


def _bundle(record: Path, mapping: Path, folder: Path) -> Path:
    """``folder/recording/`` with the compressed record and ``mapping.toml``."""
    dest = folder / BUNDLE_DIR
    dest.mkdir(parents=True)
    with open(record, "rb") as fh:
        gz = fh.read(2) == b"\x1f\x8b"
    if gz or is_parquet(record):
        shutil.copyfile(record, dest / record.name)
    else:
        with open(record, "rb") as src, gzip.open(dest / f"{record.name}.gz", "wb", compresslevel=9) as out:
            shutil.copyfileobj(src, out, 1 << 20)
    shutil.copyfile(mapping, dest / BUNDLE_MAPPING)
    return dest


def build_recording(record: str | Path, mapping: str | Path, output: str | Path) -> Path:
    """Build ``output`` (``NAME.fmu``) playing ``record`` with ``mapping``; return its path.

    ``NAME_OspModelDescription.xml`` is written beside it.

    Raises
    ------
    RecordingError
        The record or its sidecar is refused (before building).
    BuildError
        The FMU does not validate.
    """
    from pythonfmu.builder import FmuBuilder

    record, mapping, output = Path(record), Path(mapping), Path(output)
    if output.suffix != ".fmu":
        raise BuildError(f"-o {output}: the FMU's name must end in .fmu")
    Record(record, load_mapping(mapping))    # refuse a bad record or mapping before building
    script = _script()
    output.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        bundle = _bundle(record, mapping, Path(tmp) / "bundle")
        raw = Path(FmuBuilder.build_FMU(script, dest=tmp, project_files=[PACKAGE_DIR, bundle],
                                        canGetAndSetFMUstate=True, canSerializeFMUstate=True))
        repack(raw, output, slave_units(script))
    with zipfile.ZipFile(output) as z:
        names = z.namelist()
    if f"resources/{BUNDLE_DIR}/{BUNDLE_MAPPING}" not in names:
        output.unlink()
        raise BuildError(f"{output.name}: the bundled record did not reach resources/{BUNDLE_DIR}/")
    check_and_describe(output, output.with_name(f"{output.stem}_OspModelDescription.xml"))
    return output
