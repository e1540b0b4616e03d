#!/usr/bin/env python3
"""Build every models/*.py into fmus/*.fmu, each with the part of marinefmu its slaves run and a
resources/requirements.txt; add units, validate, and verify that each runs from its own resources
(see marinefmu.fmu.build). Prints each FMU's size."""
import argparse
import sys

from marinefmu.fmu.build import BuildError, build_all

if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--force", action="store_true", help="rebuild even if nothing changed")
    args = parser.parse_args()
    try:
        build_all(force=args.force)
    except BuildError as exc:
        sys.exit(f"build_fmus.py: {exc}")
