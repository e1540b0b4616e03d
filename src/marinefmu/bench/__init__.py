"""``marinefmu bench``: the benchmark parts (:mod:`.parts`), the whole system (:mod:`.system`),
memory (:mod:`.memory`), campaigns (:mod:`.campaign`), heave compensation (:mod:`.ahc`) and the
comparisons with the peer library smsfusion on VesselMotion records (:mod:`.peer_smsfusion`) and
on its OrcaFlex record (:mod:`.peer_orcaflex`). Measured, never asserted in tests."""
