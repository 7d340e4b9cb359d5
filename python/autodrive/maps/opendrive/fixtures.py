"""OpenDRIVE test networks written by scenariogeneration (a third-party writer, not our hands),
for the tests and tools/bench opendrive. Where scenariogeneration has no writer for a record
(poly3 geometry, lane border), one of its records is rewritten in the XML it wrote, and the
docstring says so. Full-size networks in metres."""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any, Callable

from scenariogeneration import xodr  # type: ignore[import-untyped]

LANE_W_M = 3.5


def _light(sid: int, s_m: float, t_m: float, kind: str = "1000001", **kw: Any) -> Any:
    """A signal for the traffic driving along +s (t < 0) or against it (t > 0)."""
    dyn = xodr.Dynamic.yes if kind.startswith("1000") else xodr.Dynamic.no
    way = xodr.Orientation.positive if t_m < 0 else xodr.Orientation.negative
    return xodr.Signal(
        s=s_m, t=t_m, country="DEU", Type=kind, id=str(sid), dynamic=dyn, orientation=way, **kw
    )


def crossing(path: Path) -> Path:
    """A 4-way junction (1 lane each way) of a spiral-arc-spiral road, two paramPoly3 roads
    (pRange normalized and arcLength) and a sloped straight one; traffic lights on three
    approaches (two opposite, one crossing them), a stop sign, a speed limit and a signal type
    the kit does not know. Road marks: solid white edges; the centre lines of roads 1 and 4
    broken (scenariogeneration's standard: 0.15 m, 3 m dashes, 9 m gaps), of road 3 solid
    yellow, of road 2 and the junction's roads solid white."""
    roads = [
        xodr.create_road(
            [
                xodr.Line(20),
                xodr.Spiral(0.0001, 0.02, 20),
                xodr.Arc(0.02, length=15),
                xodr.Spiral(0.02, 0.0001, 20),
            ],
            1,
            1,
            1,
            center_road_mark=xodr.std_roadmark_broken(),
            lane_width=LANE_W_M,
        ),
        xodr.create_road(
            [xodr.Line(10), xodr.ParamPoly3(0, 40, 0, 0, 0, 0, 6, -4, "normalized")],
            2,
            1,
            1,
            lane_width=LANE_W_M,
        ),
        xodr.create_road(
            [xodr.Line(10), xodr.ParamPoly3(0, 1, 0, 0, 0, 0, 0.004, -0.00007, "arcLength", 40)],
            3,
            1,
            1,
            center_road_mark=xodr.RoadMark(xodr.RoadMarkType.solid, 0.2, color=xodr.RoadMarkColor.yellow),
            lane_width=LANE_W_M,
        ),
        xodr.create_road(xodr.Line(50), 4, 1, 1, center_road_mark=xodr.std_roadmark_broken(),
                         lane_width=LANE_W_M),  # fmt: skip
    ]
    roads[3].add_elevation(0, 0, 0.02, 0, 0)
    roads[0].add_signal(_light(1, 50, -4.5))
    roads[2].add_signal(_light(2, 2, 4.5))  # roads 2 and 3 start at the junction
    roads[1].add_signal(_light(3, 2, 4.5, kind="206"))
    roads[3].add_signal(_light(4, 20, -4.5, kind="274", value=50, unit="km/h"))
    roads[3].add_signal(_light(5, 25, -4.5, kind="138"))  # "cyclists": not a kit sign
    roads[3].add_signal(_light(6, 48, -4.5))  # crosses lights 1 and 2 at the junction
    jc = xodr.CommonJunctionCreator(100, "crossing")
    for i, r in enumerate(roads):  # its paramPoly3 roads start at the junction: scenariogeneration
        # 0.16.7 places a road ending in a paramPoly3 at the junction from the wrong end
        link = "predecessor" if i in (1, 2) else "successor"
        jc.add_incoming_road_circular_geometry(r, 14, i * math.pi / 2, link)
    for a in range(4):
        for b in range(a + 1, 4):
            jc.add_connection(a + 1, b + 1)
    odr = xodr.OpenDrive("crossing")
    for r in roads:
        odr.add_road(r)
    odr.add_junction_creator(jc)
    odr.adjust_roads_and_lanes()
    odr.write_xml(str(path))
    return path


def sections(path: Path) -> Path:
    """One road of three lane sections (two right lanes become three, widths changing), a
    lane offset, an arc, and a last geometry rewritten as poly3; its left lane's width record in
    the last section rewritten as the equivalent border record."""
    road = xodr.create_road(
        [xodr.Line(30), xodr.Arc(-0.015, length=40), xodr.Line(40)],
        1,
        left_lanes=1,
        right_lanes=[xodr.LaneDef(40, 60, 2, 3, -3)],
        lane_width=LANE_W_M,
    )
    road.lanes.add_laneoffset(xodr.LaneOffset(0, 0.5, 0.0, 0.0005, -0.00001))
    odr = xodr.OpenDrive("sections")
    odr.add_road(road)
    odr.adjust_roads_and_lanes()
    odr.write_xml(str(path))
    tree = ET.parse(path)
    geom = tree.getroot().findall("road/planView/geometry")[-1]
    line = geom.find("line")
    assert line is not None
    geom.remove(line)
    ET.SubElement(geom, "poly3", {"a": "0", "b": "0", "c": "0.002", "d": "-0.00002"})
    last = tree.getroot().findall("road/lanes/laneSection")[-1]
    lane = last.find("left/lane")
    assert lane is not None
    width = lane.find("width")
    assert width is not None
    width.tag = "border"
    tree.write(path)
    return path


FIXTURES: dict[str, Callable[[Path], Path]] = {"crossing": crossing, "sections": sections}


def write_all(folder: Path) -> dict[str, Path]:
    folder.mkdir(parents=True, exist_ok=True)
    return {n: f(folder / f"{n}.xodr") for n, f in FIXTURES.items()}


def light_scenario(path: Path, road_network: str = "crossing.xodr") -> Path:
    """An OpenSCENARIO file for crossing(): car1 starts on road 1's right lane (file frame
    x 10 m, y -1.75 m, heading east) at 5 m/s; at 2 s of sim time signal 1 turns red; when
    car1 is within 2 m of its start (at once), signal 2 turns green."""
    from scenariogeneration import xosc

    init = xosc.Init()
    init.add_init_action("car1", xosc.TeleportAction(xosc.WorldPosition(10, -1.75, 0, 0)))
    step = xosc.TransitionDynamics(xosc.DynamicsShapes.step, xosc.DynamicsDimension.time, 1)
    init.add_init_action("car1", xosc.AbsoluteSpeedAction(5, step))
    ent = xosc.Entities()
    box = xosc.BoundingBox(1.8, 4.5, 1.5, 1.3, 0, 0.75)
    front, rear = xosc.Axle(0.5, 0.6, 1.6, 2.9, 0.3), xosc.Axle(0, 0.6, 1.6, 0, 0.3)
    ent.add_scenario_object(
        "car1", xosc.Vehicle("car", xosc.VehicleCategory.car, box, front, rear, 40, 3, 5)
    )
    red = xosc.Event("signal_1_red", xosc.Priority.overwrite)
    red.add_action("red", xosc.TrafficSignalStateAction("1", "red"))
    at_2s = xosc.SimulationTimeCondition(2, xosc.Rule.greaterThan)
    red.add_trigger(xosc.ValueTrigger("at_2s", 0, xosc.ConditionEdge.rising, at_2s))
    green = xosc.Event("signal_2_green", xosc.Priority.overwrite)
    green.add_action("green", xosc.TrafficSignalStateAction("2", "green"))
    there = xosc.ReachPositionCondition(xosc.WorldPosition(10, -1.75, 0, 0), 2.0)
    green.add_trigger(xosc.EntityTrigger("car1_there", 0, xosc.ConditionEdge.rising, there, "car1"))
    man = xosc.Maneuver("lights")
    man.add_event(red)
    man.add_event(green)
    group = xosc.ManeuverGroup("lights")
    group.add_maneuver(man)
    act = xosc.Act("lights")
    act.add_maneuver_group(group)
    story = xosc.Story("lights")
    story.add_act(act)
    board = xosc.StoryBoard(init)
    board.add_story(story)
    sc = xosc.Scenario(
        "light change",
        "autodrive",
        xosc.ParameterDeclarations(),
        ent,
        board,
        xosc.RoadNetwork(road_network),
        xosc.Catalog(),
        osc_minor_version=1,
    )  # ReachPositionCondition: OpenSCENARIO 1.1
    sc.write_xml(str(path))
    return path
