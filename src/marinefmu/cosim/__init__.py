"""Running systems of FMUs: SSP system files (:mod:`.ssp`), scenario files (:mod:`.scenarios`),
the static system check (:mod:`.system_check`), the FMPy master and its data exchange
(:mod:`.system`, :mod:`.exchange`) and the same system under OSP libcosim (:mod:`.libcosim`)."""
