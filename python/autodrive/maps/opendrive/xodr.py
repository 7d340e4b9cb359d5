"""Reads an OpenDRIVE file (.xodr, ASAM OpenDRIVE 1.4 to 1.8) into plain dataclasses: the
reference line's geometries, lane offsets, lane sections with their lanes' width or border
records and links, road and junction links, signals and elevation. Every number is checked
(parsable, finite, widths >= 0, geometries that join): a bad file raises OpenDriveError naming
the file, the road id, the element and the field. Units are the file's: metres, radians."""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path
from typing import Literal, Optional

from autodrive.maps.model import MapDescriptionError

SUPPORTED_MINOR_VERSIONS = range(4, 9)  # OpenDRIVE 1.4 .. 1.8 (revMajor 1)
GEOMETRY_GAP_TOLERANCE_M = 0.01  # a geometry must start this close to where the previous ends
# roadMark types (OpenDRIVE 1.7 e_roadMarkType) drawn as lines; a double type names its lines
# from the inside of the road out (on the centre lane: left, then right)
MARK_LINES = {"solid": "s", "broken": "b", "solid solid": "ss", "solid broken": "sb",
              "broken solid": "bs", "broken broken": "bb"}  # fmt: skip
MARKS_NOT_DRAWN = ("none", "botts dots", "grass", "curb", "custom", "edge")
MARK_COLOURS = ("standard", "white", "yellow", "blue", "green", "red", "orange", "violet", "black")
# what the file leaves open (ours, not the standard's): a line's width by weight, a broken
# line's dash and space (scenariogeneration's standard broken mark), a double line's gap
MARK_WIDTH_M = {"standard": 0.12, "bold": 0.25}
BROKEN_DASH_M, BROKEN_SPACE_M = 3.0, 9.0


class OpenDriveError(MapDescriptionError):
    """An OpenDRIVE file that cannot be imported; the message names the file, the road (or
    junction) id, the element and the field."""


@dataclass(frozen=True)
class Poly3:
    """a + b*ds + c*ds^2 + d*ds^3 from s_m (a record's start, relative to its owner)."""

    s_m: float
    a: float
    b: float
    c: float
    d: float

    def at(self, s_m: float) -> float:
        ds = s_m - self.s_m
        return self.a + ds * (self.b + ds * (self.c + ds * self.d))

    def slope(self, s_m: float) -> float:
        ds = s_m - self.s_m
        return self.b + ds * (2 * self.c + 3 * ds * self.d)


@dataclass(frozen=True)
class Geometry:
    """One planView record; kind-specific parameters in params (the element's attributes)."""

    s_m: float
    x_m: float
    y_m: float
    hdg_rad: float
    length_m: float
    kind: Literal["line", "arc", "spiral", "poly3", "paramPoly3"]
    params: dict[str, float]
    p_range: Literal["normalized", "arcLength"] = "normalized"


@dataclass(frozen=True)
class MarkLine:
    """One painted line of a road mark: t_offset_m from the lane's border (+ left), dashes of
    length_m with space_m between them from s_offset_m after the mark's start (space_m 0: solid),
    width_m across."""

    t_offset_m: float
    length_m: float
    space_m: float
    s_offset_m: float
    width_m: float


@dataclass(frozen=True)
class RoadMark:
    """A <roadMark> on a lane's outer border (the centre lane's: on the reference line plus the
    lane offset), from s_m after its lane section's start to the next one's s_m. lines: what is
    painted (from its <type> lines, or from its type); empty when the type is drawn by nothing."""

    s_m: float
    type: str
    colour: str
    lines: tuple[MarkLine, ...]


@dataclass(frozen=True)
class Lane:
    id: int
    type: str
    widths: list[Poly3]  # sOffset from the lane section's start
    borders: list[Poly3]
    predecessor: Optional[int]
    successor: Optional[int]
    marks: list[RoadMark] = field(default_factory=list)


@dataclass(frozen=True)
class LaneSection:
    s_m: float
    lanes: list[Lane]  # left and right lanes (the centre lane 0 has no width)
    centre_marks: list[RoadMark] = field(default_factory=list)


@dataclass(frozen=True)
class Link:
    element_type: Literal["road", "junction"]
    element_id: str
    contact_point: Optional[Literal["start", "end"]]


@dataclass(frozen=True)
class Signal:
    id: str
    s_m: float
    t_m: float
    orientation: Literal["+", "-", "none"]
    dynamic: bool
    country: str
    type: str
    subtype: str
    value: Optional[float]
    unit: str
    name: str
    valid_lanes: Optional[tuple[int, int]]  # <validity fromLane toLane>, both inclusive


@dataclass(frozen=True)
class Road:
    id: str
    name: str
    length_m: float
    junction: str  # "-1" for none
    rule: Literal["RHT", "LHT"]
    geometries: list[Geometry]
    lane_offsets: list[Poly3]
    sections: list[LaneSection]
    predecessor: Optional[Link]
    successor: Optional[Link]
    signals: list[Signal]
    sloped: bool  # an elevation or superelevation record that is not flat


@dataclass(frozen=True)
class LaneLink:
    from_lane: int
    to_lane: int


@dataclass(frozen=True)
class Connection:
    id: str
    incoming_road: str
    connecting_road: str
    contact_point: Literal["start", "end"]
    lane_links: list[LaneLink]


@dataclass(frozen=True)
class Junction:
    id: str
    connections: list[Connection]


@dataclass(frozen=True)
class Controller:
    id: str
    signal_ids: list[str]


@dataclass(frozen=True)
class Network:
    source: Path
    version: str
    roads: dict[str, Road]
    junctions: dict[str, Junction]
    controllers: list[Controller] = field(default_factory=list)


class _Reader:
    def __init__(self, source: Path) -> None:
        self.source = source

    def fail(self, where: str, what: str) -> OpenDriveError:
        return OpenDriveError(f"{self.source}: {where}: {what}")

    def num(self, el: ET.Element, attr: str, where: str, default: Optional[float] = None) -> float:
        text = el.get(attr)
        if text is None:
            if default is not None:
                return default
            raise self.fail(f"{where}.{attr}", "missing")
        try:
            v = float(text)
        except ValueError:
            raise self.fail(f"{where}.{attr}", f"not a number: {text!r}") from None
        if not math.isfinite(v):
            raise self.fail(f"{where}.{attr}", f"not a finite number: {text!r}")
        return v

    def text(self, el: ET.Element, attr: str, where: str) -> str:
        v = el.get(attr)
        if v is None:
            raise self.fail(f"{where}.{attr}", "missing")
        return v

    def poly(self, el: ET.Element, where: str, s_attr: str) -> Poly3:
        if el.get(s_attr) is None and s_attr == "sOffset" and el.get("s") is not None:
            s_attr = "s"
        return Poly3(*(self.num(el, k, where) for k in (s_attr, "a", "b", "c", "d")))

    def polys(self, parent: ET.Element, tag: str, where: str, s_attr: str) -> list[Poly3]:
        """Every <tag> record of parent, the i-th named where[i]."""
        return [self.poly(e, f"{where}[{i}]", s_attr) for i, e in enumerate(parent.findall(tag))]

    def network(self, root: ET.Element) -> Network:
        if root.tag != "OpenDRIVE":
            raise self.fail("root", f"is <{root.tag}>, not <OpenDRIVE>")
        header = root.find("header")
        if header is None:
            raise self.fail("header", "missing")
        major = int(self.num(header, "revMajor", "header"))
        minor = int(self.num(header, "revMinor", "header"))
        if major != 1 or minor not in SUPPORTED_MINOR_VERSIONS:
            raise self.fail(
                "header.revMajor/revMinor",
                f"unsupported OpenDRIVE version {major}.{minor} (supported: 1.4 to 1.8)",
            )
        roads: dict[str, Road] = {}
        for el in root.findall("road"):
            r = self.road(el)
            if r.id in roads:
                raise self.fail(f"road '{r.id}'", "id given twice")
            roads[r.id] = r
        junctions = {j.id: j for j in (self.junction(el) for el in root.findall("junction"))}
        controllers = [
            Controller(
                self.text(c, "id", "controller"),
                [self.text(s, "signalId", "controller.control") for s in c.findall("control")],
            )
            for c in root.findall("controller")
        ]
        net = Network(self.source, f"{major}.{minor}", roads, junctions, controllers)
        self.check_links(net)
        return net

    def road(self, el: ET.Element) -> Road:
        rid = self.text(el, "id", "road")
        where = f"road '{rid}'"
        length = self.num(el, "length", where)
        if not length > 0:
            raise self.fail(f"{where}.length", f"must be > 0, got {length:g}")
        rule = el.get("rule", "RHT")
        if rule not in ("RHT", "LHT"):
            raise self.fail(f"{where}.rule", f"must be RHT or LHT, got {rule!r}")
        geoms = [
            self.geometry(g, f"{where}: planView.geometry[{i}]")
            for i, g in enumerate(el.findall("planView/geometry"))
        ]
        if not geoms:
            raise self.fail(f"{where}: planView", "no geometry")
        lanes_el = el.find("lanes")
        if lanes_el is None:
            raise self.fail(f"{where}: lanes", "missing")
        offsets = self.polys(lanes_el, "laneOffset", f"{where}: lanes.laneOffset", "s")
        sections = [
            self.section(s, f"{where}: laneSection[{i}]")
            for i, s in enumerate(lanes_el.findall("laneSection"))
        ]
        if not sections:
            raise self.fail(f"{where}: lanes", "no laneSection")
        link = el.find("link")
        pred = (
            self.link(link.find("predecessor"), f"{where}: link.predecessor")
            if link is not None
            else None
        )
        succ = (
            self.link(link.find("successor"), f"{where}: link.successor")
            if link is not None
            else None
        )
        signals = [
            self.signal(s, f"{where}: signals.signal[{i}]")
            for i, s in enumerate(el.findall("signals/signal"))
        ]
        sloped = False
        for tag in ("elevationProfile/elevation", "lateralProfile/superelevation"):
            for i, e in enumerate(el.findall(tag)):
                p = self.poly(e, f"{where}: {tag}[{i}]", "s")
                sloped = sloped or any(v != 0 for v in (p.b, p.c, p.d))
        r = Road(
            rid,
            el.get("name", ""),
            length,
            el.get("junction", "-1"),
            rule,  # type: ignore[arg-type]
            geoms,
            offsets,
            sections,
            pred,
            succ,
            signals,
            sloped,
        )
        self.check_plan_view(r)
        return r

    def geometry(self, g: ET.Element, where: str) -> Geometry:
        vals = [self.num(g, k, where) for k in ("s", "x", "y", "hdg", "length")]
        if not vals[4] > 0:
            raise self.fail(f"{where}.length", f"must be > 0, got {vals[4]:g}")
        kinds = {
            "line": (),
            "arc": ("curvature",),
            "spiral": ("curvStart", "curvEnd"),
            "poly3": ("a", "b", "c", "d"),
            "paramPoly3": ("aU", "bU", "cU", "dU", "aV", "bV", "cV", "dV"),
        }
        for child in g:
            if child.tag in kinds:
                params = {k: self.num(child, k, f"{where}.{child.tag}") for k in kinds[child.tag]}
                p_range = child.get("pRange", "normalized")
                if p_range not in ("normalized", "arcLength"):
                    raise self.fail(f"{where}.paramPoly3.pRange", f"unknown value {p_range!r}")
                s, x, y, hdg, length = vals
                return Geometry(s, x, y, hdg, length, child.tag, params, p_range)  # type: ignore[arg-type]
        tags = [c.tag for c in g]
        raise self.fail(where, f"unsupported geometry {tags} (supported: {', '.join(kinds)})")

    def section(self, el: ET.Element, where: str) -> LaneSection:
        s = self.num(el, "s", where)
        lanes = []
        for side in ("left", "right"):
            for ln in el.findall(f"{side}/lane"):
                lid = int(self.num(ln, "id", f"{where}.{side}.lane"))
                lw = f"{where}: lane {lid}"
                widths = self.polys(ln, "width", f"{lw}.width", "sOffset")
                borders = self.polys(ln, "border", f"{lw}.border", "sOffset")
                for i, w in enumerate(widths):
                    if w.a < 0:
                        raise self.fail(f"{lw}.width[{i}].a", f"negative width {w.a:g} m")
                link = ln.find("link")
                ids: list[Optional[int]] = []
                for k in ("predecessor", "successor"):
                    e = link.find(k) if link is not None else None
                    ids.append(int(self.num(e, "id", f"{lw}.link.{k}")) if e is not None else None)
                marks = self.marks(ln, lw, -1.0 if lid > 0 else 1.0)
                lanes.append(
                    Lane(lid, ln.get("type", "none"), widths, borders, ids[0], ids[1], marks)
                )
        centre = el.find("center/lane")
        centre_marks = self.marks(centre, f"{where}: lane 0", 1.0) if centre is not None else []
        return LaneSection(s, lanes, centre_marks)

    def marks(self, lane: ET.Element, where: str, inside: float) -> list[RoadMark]:
        """The lane's road marks; inside: the sign of t towards the road's inside (+1 on the
        right and centre lanes, -1 on the left ones)."""
        out = [self.mark(m, f"{where}.roadMark[{i}]", inside)
               for i, m in enumerate(lane.findall("roadMark"))]  # fmt: skip
        for i, (a, b) in enumerate(zip(out, out[1:])):
            if b.s_m < a.s_m:
                raise self.fail(f"{where}.roadMark[{i + 1}].sOffset",
                                f"{b.s_m:g} m is before the previous mark's {a.s_m:g} m")  # fmt: skip
        return out

    def mark(self, el: ET.Element, where: str, inside: float) -> RoadMark:
        """A roadMark and its lines; an unknown type or colour, a negative width or a broken
        line without a dash is refused."""
        kind = el.get("type", "none")
        colour = el.get("color", "standard")
        if kind not in MARK_LINES and kind not in MARKS_NOT_DRAWN:
            known = ", ".join([*MARK_LINES, *MARKS_NOT_DRAWN])
            raise self.fail(
                f"{where}.type", f"unknown road mark type {kind!r} (OpenDRIVE: {known})"
            )
        if colour not in MARK_COLOURS:
            raise self.fail(
                f"{where}.color",
                f"unknown colour {colour!r} (OpenDRIVE: {', '.join(MARK_COLOURS)})",
            )
        weight = el.get("weight", "standard")
        if weight not in MARK_WIDTH_M:
            raise self.fail(f"{where}.weight", f"must be standard or bold, got {weight!r}")
        width = self.num(el, "width", where, MARK_WIDTH_M[weight])
        if not width > 0:
            raise self.fail(f"{where}.width", f"must be > 0, got {width:g} m")
        typed = el.find("type")
        if typed is not None:
            lines = tuple(self.mark_line(ln, f"{where}.type.line[{i}]", width)
                          for i, ln in enumerate(typed.findall("line")))  # fmt: skip
        elif kind in MARK_LINES:
            lines = _lines_of(MARK_LINES[kind], width, inside)
        else:
            lines = ()
        return RoadMark(self.num(el, "sOffset", where), kind, colour, lines)

    def mark_line(self, el: ET.Element, where: str, width_m: float) -> MarkLine:
        t, length, space, s = (
            self.num(el, k, where, 0.0) for k in ("tOffset", "length", "space", "sOffset")
        )
        line = MarkLine(
            t, length, space, s, self.num(el, "width", where, width_m) or width_m
        )  # 0: the mark's
        for k, v in (("length", line.length_m), ("space", line.space_m), ("width", line.width_m)):
            if v < 0:
                raise self.fail(f"{where}.{k}", f"must be >= 0, got {v:g} m")
        if line.space_m > 0 and line.length_m == 0:
            raise self.fail(f"{where}.length", "a broken line (space > 0) needs a dash length > 0")
        return line

    def link(self, el: Optional[ET.Element], where: str) -> Optional[Link]:
        if el is None:
            return None
        kind = self.text(el, "elementType", where)
        if kind not in ("road", "junction"):
            raise self.fail(f"{where}.elementType", f"must be road or junction, got {kind!r}")
        cp = el.get("contactPoint")
        if cp not in (None, "start", "end"):
            raise self.fail(f"{where}.contactPoint", f"must be start or end, got {cp!r}")
        return Link(kind, self.text(el, "elementId", where), cp)  # type: ignore[arg-type]

    def signal(self, el: ET.Element, where: str) -> Signal:
        orientation = el.get("orientation", "none")
        if orientation not in ("+", "-", "none"):
            raise self.fail(f"{where}.orientation", f"must be +, - or none, got {orientation!r}")
        value = self.num(el, "value", where) if el.get("value") not in (None, "") else None
        validity = el.find("validity")
        valid = None
        if validity is not None:
            valid = (
                int(self.num(validity, "fromLane", f"{where}.validity")),
                int(self.num(validity, "toLane", f"{where}.validity")),
            )
        return Signal(
            self.text(el, "id", where),
            self.num(el, "s", where),
            self.num(el, "t", where),
            orientation,  # type: ignore[arg-type]
            el.get("dynamic", "no") == "yes",
            el.get("country", ""),
            el.get("type", ""),
            el.get("subtype", "-1"),
            value,
            el.get("unit", ""),
            el.get("name", ""),
            valid,
        )

    def junction(self, el: ET.Element) -> Junction:
        jid = self.text(el, "id", "junction")
        conns = []
        for i, c in enumerate(el.findall("connection")):
            where = f"junction '{jid}': connection[{i}]"
            cp = self.text(c, "contactPoint", where)
            if cp not in ("start", "end"):
                raise self.fail(f"{where}.contactPoint", f"must be start or end, got {cp!r}")
            links = [
                LaneLink(
                    int(self.num(ll, "from", f"{where}.laneLink[{k}]")),
                    int(self.num(ll, "to", f"{where}.laneLink[{k}]")),
                )
                for k, ll in enumerate(c.findall("laneLink"))
            ]
            conns.append(
                Connection(
                    c.get("id", str(i)),
                    self.text(c, "incomingRoad", where),
                    self.text(c, "connectingRoad", where),
                    cp,  # type: ignore[arg-type]
                    links,
                )
            )
        return Junction(jid, conns)

    def check_plan_view(self, r: Road) -> None:
        from autodrive.maps.opendrive.reference_line import geometry_end

        for i, (a, b) in enumerate(zip(r.geometries, r.geometries[1:])):
            x, y, _ = geometry_end(a)
            gap = math.hypot(b.x_m - x, b.y_m - y)
            if gap > GEOMETRY_GAP_TOLERANCE_M:
                raise self.fail(
                    f"road '{r.id}': planView.geometry[{i + 1}].x/y",
                    f"starts {gap:.3f} m from where geometry[{i}] ends (tolerance "
                    f"{GEOMETRY_GAP_TOLERANCE_M} m)",
                )

    def check_links(self, net: Network) -> None:
        for r in net.roads.values():
            for k, link in (("predecessor", r.predecessor), ("successor", r.successor)):
                if link is None:
                    continue
                known = net.roads if link.element_type == "road" else net.junctions
                if link.element_id not in known:
                    raise self.fail(
                        f"road '{r.id}': link.{k}.elementId",
                        f"links to a missing {link.element_type} '{link.element_id}'",
                    )
        for j in net.junctions.values():
            for i, c in enumerate(j.connections):
                for k, rid in (
                    ("incomingRoad", c.incoming_road),
                    ("connectingRoad", c.connecting_road),
                ):
                    if rid not in net.roads:
                        raise self.fail(
                            f"junction '{j.id}': connection[{i}].{k}",
                            f"links to a missing road '{rid}'",
                        )


def _lines_of(code: str, width_m: float, inside: float) -> tuple[MarkLine, ...]:
    """The lines of a roadMark type given by its letters (s solid, b broken), the inside one
    first (towards t's sign inside), a line's width apart on a double line."""
    offsets = [0.0] if len(code) == 1 else [inside * width_m, -inside * width_m]
    return tuple(
        MarkLine(t, BROKEN_DASH_M if c == "b" else 0.0, BROKEN_SPACE_M if c == "b" else 0.0,
                 0.0, width_m)
        for c, t in zip(code, offsets)
    )  # fmt: skip


def read(path: Path) -> Network:
    """The network of an .xodr file; raises OpenDriveError naming what is wrong."""
    try:
        root = ET.parse(path).getroot()
    except OSError as err:
        raise OpenDriveError(f"{path}: cannot read ({err.strerror})") from err
    except ET.ParseError as err:
        raise OpenDriveError(f"{path}: not well-formed XML ({err})") from err
    return _Reader(path).network(root)
