"""scripts/evaluate_real_junctions.py's ``--city`` cases: parsed, or refused with one line."""

from __future__ import annotations

from pathlib import Path

import pytest

from .helpers import load_script


def test_a_city_case_names_its_network_route_and_demand(tmp_path: Path) -> None:
    script = load_script("evaluate_real_junctions")
    net, demand = tmp_path / "city.net.xml", tmp_path / "city.rou.xml"
    net.write_text("<net/>")
    demand.write_text("<routes/>")
    case = script.city(["acosta", str(net), "78[0],204[1][1]", str(demand)])
    assert (case.name, case.net, case.route, case.demand) == (
        "acosta",
        net,
        ("78[0]", "204[1][1]"),
        demand,
    )


@pytest.mark.parametrize(
    ("route", "net_exists", "message"),
    [
        ("78[0]", True, "route '78[0]' is not FROM,TO"),
        ("a,b,c", True, "route 'a,b,c' is not FROM,TO"),
        ("a,b", False, "no such file"),
    ],
)
def test_a_bad_city_case_ends_with_one_line(
    tmp_path: Path, route: str, net_exists: bool, message: str
) -> None:
    script = load_script("evaluate_real_junctions")
    net, demand = tmp_path / "city.net.xml", tmp_path / "city.rou.xml"
    demand.write_text("<routes/>")
    if net_exists:
        net.write_text("<net/>")
    with pytest.raises(SystemExit, match=message.replace("[", r"\[").replace("]", r"\]")):
        script.city(["acosta", str(net), route, str(demand)])
