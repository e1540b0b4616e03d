"""First-order hydrodynamics from a boundary-element solver (Capytaine): hull meshes → RAO tables.

This package computes what :mod:`marinefmu.sea.vessel`'s closed-form presets only imitate:
added mass, radiation damping and wave excitation of a hull mesh, solved by Capytaine (the
open BEM solver descended from Nemoh), and from them the six RAOs about the centre of gravity,
written as the RAO CSV that ``vessel.rao_file`` reads.

- :mod:`~marinefmu.sea.hydro.hulls`: parametric hull meshes (box barge, a Wigley-type ship
  hull, a semi-submersible of columns and pontoons), mesh files, and the checks that refuse a
  mesh that is not closed or not watertight at the waterline;
- :mod:`~marinefmu.sea.hydro.bem`: mass properties, the Capytaine solve, the RAO assembly
  with optional viscous roll damping, natural periods;
- :mod:`~marinefmu.sea.hydro.export`: the RAO table in the project's frames and phase
  convention, the CSV file and the plot of the six RAOs;
- :mod:`~marinefmu.sea.hydro.presets`: the BEM presets shipped under ``marinefmu/data/hydro``;
- :mod:`~marinefmu.sea.hydro.validation`: the Haskind-Newman check of a result and the bound on
  the motion above a table's last frequency.

Capytaine is an optional dependency (``pip install marinefmu[hydro]``) imported only inside
the functions that solve or read meshes, never at module import; VesselMotion and the FMUs read
the CSV and never need it.

Frames: the solver works in Capytaine's frame (x forward, y to port, z up, origin on the
waterline), every argument and result of this package is in the project's frames (x forward,
y starboard, z down, the design page); the conversion is diag(1, −1, −1) and is done in
:mod:`~marinefmu.sea.hydro.hulls` (geometry) and :mod:`~marinefmu.sea.hydro.export` (RAOs).
"""
