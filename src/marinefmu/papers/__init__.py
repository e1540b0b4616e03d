"""Worked examples that reproduce the papers; each module has a ``run(out=None)`` that returns
its figures as a dict (and writes plots when ``out`` is a folder). The test suite runs them;
``marinefmu example NAME`` runs one from the command line."""
