"""Campaigns: many co-simulations of one system over a grid of sea states, seeds and sensor
placements, run on Dask.

``marinefmu campaign SPEC.toml [--scheduler ADDRESS] [--workers N] [--out DIR]`` reads a
campaign file (:mod:`.spec`), runs each run as a Dask task (:mod:`.engine`, :mod:`.worker`),
writes the results as they come (:mod:`.table`) and draws accuracy maps and comparisons
(:mod:`.plots`).
"""
from .engine import CampaignError, CampaignOutcome, run_campaign
from .spec import CampaignSpec, CampaignSpecError, Run, load_spec, parse_spec

__all__ = ["CampaignError", "CampaignOutcome", "CampaignSpec", "CampaignSpecError", "Run", "load_spec", "parse_spec",
           "run_campaign"]
