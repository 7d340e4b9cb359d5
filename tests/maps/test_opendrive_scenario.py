"""maps.opendrive_scenario: the OpenSCENARIO subset. scenariogeneration writes a scenario for the
imported crossing (car1 teleported onto road 1 at 5 m/s; signal 1 red at 2 s of sim time; signal
2 green when car1 reaches its start); it is read (positions and speeds taken to our scale) and
played in autodrive-sim: the car starts at the teleport pose and light 1, green on its program
until 8 s, shows red from 2 s of sim time, light 2 (red on its program then) green. Actions,
positions and conditions outside the subset are refused by name."""

from __future__ import annotations

import json
import math
import subprocess
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from autodrive.maps.opendrive import fixtures, scenario
from pyhelpers import REPO_ROOT

TOOL = REPO_ROOT / "tools" / "map"
RED, GREEN = 1, 3


@pytest.fixture(scope="module")
def crossing(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict]:
    folder = tmp_path_factory.mktemp("xosc")
    xodr = fixtures.crossing(folder / "crossing.xodr")
    subprocess.run([str(TOOL), "import", str(xodr), "--name", "crossing", "--out", str(folder)],
                   check=True, capture_output=True)  # fmt: skip
    fixtures.light_scenario(folder / "light.xosc")
    return folder, json.loads((folder / "crossing.json").read_text())


def test_scripted_light_change_in_the_simulator(crossing: tuple[Path, dict], build_dir: Path,
                                                lcm_url: str, tmp_path: Path) -> None:  # fmt: skip
    folder, doc = crossing
    imp = doc["imported_from"]
    plan = scenario.read(folder / "light.xosc", imp)
    x, y, yaw = plan.starts["car1"]
    assert (x, y) == pytest.approx((imp["scale"] * 10 + imp["offset_m"][0],
                                    imp["scale"] * -1.75 + imp["offset_m"][1]))  # fmt: skip
    assert plan.speeds_m_s["car1"] == pytest.approx(5 / 14)
    # the simulator runs in real time: on a loaded machine the commands come late in sim time,
    # so the test only asks for them before the programs would change the lights (8 s, 12 s)
    played = scenario.run(plan, folder / "crossing.xml", build_dir, lcm_url, tmp_path, 7.0, print)
    print(played)
    light1, light2 = played.light_states[1], played.light_states[2]
    assert light1[0][1] == GREEN and light1[0][0] < 2.0  # its program's green first
    assert light1[1][1] == RED and 2.0 <= light1[1][0] < 8.0, light1  # no yellow: commanded
    assert light2[0][1] == RED and any(s == GREEN and t < 8.0 for t, s in light2), light2
    fired = dict((e, t) for t, e in played.fired)
    assert fired["signal_1_red"] >= 2.0
    px, py, pyaw = played.first_poses["car1"]
    assert math.dist((px, py), (x, y)) < 0.01 and abs(pyaw - yaw) < 0.01


def _spoil(src: Path, dst: Path, change: str) -> Path:
    tree = ET.parse(src)
    root = tree.getroot()
    if change == "action":
        a = root.find(".//TrafficSignalStateAction/..")
        assert a is not None
        a.remove(a[0])
        ET.SubElement(
            a, "TrafficSignalControllerAction", {"trafficSignalControllerRef": "c1", "phase": "p"}
        )
    elif change == "signal":
        a = root.find(".//TrafficSignalStateAction")
        assert a is not None
        a.set("name", "42")
    tree.write(dst)
    return dst


@pytest.mark.parametrize("change,words", [
    ("action", "unsupported action"),
    ("signal", "TrafficSignalStateAction.name: no light for signal '42'".split(".")[1]),
])  # fmt: skip
def test_outside_the_subset_is_refused(crossing: tuple[Path, dict], tmp_path: Path, change: str,
                                       words: str) -> None:  # fmt: skip
    folder, doc = crossing
    bad = _spoil(folder / "light.xosc", tmp_path / "bad.xosc", change)
    with pytest.raises(scenario.ScenarioError) as err:
        scenario.read(bad, doc["imported_from"])
    assert str(err.value).startswith(f"{bad}: ") and words in str(err.value), err.value
