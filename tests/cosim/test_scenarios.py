"""Scenario files: built-ins load; malformed files name the offending key."""
import pytest

from marinefmu.errors import ScenarioError
from marinefmu.cosim.scenarios import builtin_scenarios, load_scenario, parse_scenario

GOOD = """
[scenario]
name = "t"
duration = 10.0
step = 0.01
[components.vessel]
fmu = "VesselMotion"
[components.vessel.parameters]
sea = { hs = 2.0, tp = 7.0 }
"vessel.preset" = "semisub"
"""


def test_builtin_default_is_the_vessel_alone_scenario():
    s = load_scenario("default")
    p = s.system.components[0].parameters
    assert s.duration == 600.0 and p["sea.hs"] == 2.5 and p["sea.tp"] == 9.0
    assert set(builtin_scenarios()) >= {"default", "independent_cr"}


def test_nested_parameter_tables_are_flattened_to_dotted_names():
    s = parse_scenario(GOOD)
    assert s.system.components[0].parameters == {"sea.hs": 2.0, "sea.tp": 7.0, "vessel.preset": "semisub"}
    assert s.system.components[0].source == "VesselMotion.fmu"


@pytest.mark.parametrize(
    "text,match",
    [
        (GOOD.replace("duration = 10.0", "duraton = 10.0"), r"\[scenario\]: unknown key\(s\) duraton"),
        (GOOD.replace("duration = 10.0", "duration = -1.0"), r"scenario\.duration = -1\.0 is out of range"),
        (GOOD.replace("step = 0.01", 'step = "fast"'), r"scenario\.step must be a number"),
        (GOOD.replace('fmu = "VesselMotion"', "fmu = 3"), r"components\.vessel\.fmu must name an FMU"),
        (GOOD + '[components.w]\nfmu = "X"\nrate = 0\n', r"components\.w\.rate = 0 is out of range: must be an integer >= 1"),
        (GOOD.replace("[scenario]", "[scenaro]"), r"unknown key\(s\) scenaro"),
        (GOOD + '[[connections]]\nfrom = "vessel.imu.acc.x"\n', r"connections\[0\] needs string keys 'from' and 'to'"),
        (GOOD + '[[connections]]\nfrom = "vessel.x"\nto = "att.u"\n', r"unknown component 'att'"),
        (GOOD + '[[connections]]\nfrom = "vessel.x"\nto = "vessel.y"\ndelay = "yes"\n',
         r"connections\[0\]\.delay = 'yes' must be true or false"),
        (GOOD + "[record]\nvariables = 3\n", r"record\.variables must be a list"),
        (GOOD + '[components.w]\nfmu = "X"\n[components.w.parameters]\nsea = { hs = [1, 2] }\n',
         r"components\.w\.parameters\.sea\.hs must be a number"),
        ("[scenario\n", r"not valid TOML"),
    ],
)
def test_malformed_scenarios_name_the_key(text, match):
    with pytest.raises(ScenarioError, match=match):
        parse_scenario(text, "s.toml")


def test_unknown_builtin_and_unreadable_file(tmp_path):
    with pytest.raises(ScenarioError, match="neither a file nor a built-in scenario"):
        load_scenario("stormy")
    with pytest.raises(ScenarioError, match="cannot be read"):
        load_scenario(tmp_path / "missing.toml")
