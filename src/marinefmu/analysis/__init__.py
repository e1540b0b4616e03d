"""Scoring a run against truth or a reference (:mod:`.scoring`), the HTML report of a system run
(:mod:`.html_report`) and the plots of a vessel's motion (:mod:`.vessel_plots`)."""
