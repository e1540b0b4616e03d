"""The FMI side: slave plumbing, FMU build and units, system files and the FMPy runner."""
