"""The road kit: what a tile (TileSpec) contains, in the world frame. Each tile expands into its
lanes (one centre line per movement through it: a chain of straight lines and quarter arcs),
its stop lines and its parking slots; tools draw and check them, and its texture is painted from
the same shapes (textures.py).

Right-hand traffic. A tile is a square; its arms open at the middle of some of its sides (e, n,
w, s). On an arm with k lanes per direction, inbound lane i (0 = next to the road's centre) runs
(i + 1/2) lane widths right of the centre, outbound lane i the same on the other side; a
one-lane road carries both directions on its centre line. Intersections (tee, cross) and parking
lots are two cells wide: the turns fit a box of half a cell around the centre (a right turn
bends about the box corner on its right with radius half a cell minus the lane offset, a left
turn about the far corner on its left with radius half a cell plus it), and the stop lines stand
just before that box. A curve is one cell and joins the middles of two sides with the same arcs.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from autodrive.maps.geometry import piece_point
from autodrive.maps.model import (
    Arc,
    Lane,
    LaneSpec,
    Line,
    ParkingSlot,
    Piece,
    Road,
    StopLine,
    TileKit,
)
from autodrive.maps.model import TileSpec, Vec2
from autodrive.core.geometry import wrap

SIDES = ("e", "n", "w", "s")  # counter-clockwise; index * 90 deg is the outward direction
LANE_COUNTS = (1, 2, 4, 6)
TWO_CELL_TYPES = ("tee", "cross", "parking_lot")
# arms of each type, unrotated
ARMS: dict[str, tuple[str, ...]] = {
    "straight": ("w", "e"),
    "curve": ("w", "s"),
    "dead_end": ("w",),
    "tee": ("w", "e", "s"),
    "cross": ("e", "n", "w", "s"),
    "parking_lot": ("w",),
    "roadside_parking": ("w", "e"),
    "patch": (),
}


def _unit(side_index: int) -> Vec2:
    a = side_index * math.pi / 2
    return (round(math.cos(a)), round(math.sin(a)))


def _add(*vs: tuple[float, Vec2]) -> Vec2:
    return (sum(k * v[0] for k, v in vs), sum(k * v[1] for k, v in vs))


@dataclass
class TileContent:
    """A tile's parts in the world frame, named after the tile (name_...)."""

    spec: TileSpec
    size_m: float  # side of the square
    road_width_m: float
    lanes: list[Lane] = field(default_factory=list)
    stop_lines: list[StopLine] = field(default_factory=list)
    slots: list[ParkingSlot] = field(default_factory=list)
    kerb_of_stop_line: dict[str, Vec2] = field(default_factory=dict)  # where its light stands
    ports: list[tuple[str, str, Vec2, float]] = field(default_factory=list)
    # (lane, "start" | "end", point, heading) for each lane end on the tile's edge

    @property
    def texture(self) -> str:
        return texture_name(self.spec.type, self.spec.lanes)


def texture_name(tile_type: str, lanes: int) -> str:
    return f"tile_{tile_type}_{lanes}" if tile_type != "patch" else "tile_patch"


def lane_offsets_m(kit: TileKit, lanes: int) -> list[float]:
    """Offsets of one direction's lanes from the road centre [m], innermost first."""
    if lanes == 1:
        return [0.0]
    return [(i + 0.5) * kit.lane_width_m for i in range(lanes // 2)]


def road_width_m(kit: TileKit, lanes: int) -> float:
    return lanes * kit.lane_width_m + 2 * kit.shoulder_m


def cell_m(kit: TileKit, lanes: int) -> float:
    return kit.cell_m[str(lanes)]


def tile_size_m(kit: TileKit, spec: TileSpec) -> float:
    return cell_m(kit, spec.lanes) * (2 if spec.type in TWO_CELL_TYPES else 1)


class _Builder:
    """Builds one tile's lanes in its own frame (centre 0, unrotated), then moves them."""

    def __init__(self, kit: TileKit, spec: TileSpec) -> None:
        self.kit, self.spec = kit, spec
        self.quarter = round(spec.rotation_deg / 90) % 4
        self.rot = self.quarter * math.pi / 2
        self.size = tile_size_m(kit, spec)
        self.half = self.size / 2
        self.box = cell_m(kit, spec.lanes) / 2  # turn box half size (two-cell tiles)
        self.offsets = lane_offsets_m(kit, spec.lanes)
        self.width = road_width_m(kit, spec.lanes)
        self.out = TileContent(spec, self.size, self.width)

    # --- frames ---------------------------------------------------------------------------------

    def world(self, p: Vec2) -> Vec2:
        c, s = math.cos(self.rot), math.sin(self.rot)
        x, y = p
        cx, cy = self.spec.centre_m
        return (round(cx + c * x - s * y, 12), round(cy + s * x + c * y, 12))

    def world_side(self, local: str) -> str:
        return SIDES[(SIDES.index(local) + self.quarter) % 4]

    def lane_name(self, a: str, b: str, i: int) -> str:
        suffix = f"_{i}" if len(self.offsets) > 1 else ""
        return f"{self.spec.name}_{a}_{b}{suffix}"

    # --- lanes ----------------------------------------------------------------------------------

    def add_lane(self, name: str, pieces: list[Piece], offset_m: float) -> None:
        kit = self.kit
        half_lane = kit.lane_width_m / 2
        road = Road(name=self.spec.name, width_m=self.width, centre_marking="none",
                    pieces=pieces, lanes=[LaneSpec(name, 0.0, "forward")])  # fmt: skip
        kerb = self.width / 2 - offset_m
        self.out.lanes.append(Lane(name, road, 0.0, "forward", half_lane, kerb))

    def line(self, name: str, a: Vec2, b: Vec2) -> Piece:
        return Piece(name=name, line=Line(self.world(a), self.world(b)))

    def arc(self, name: str, centre: Vec2, start: Vec2, sweep_deg: float) -> Piece:
        r = math.dist(centre, start)
        a0 = math.degrees(math.atan2(start[1] - centre[1], start[0] - centre[0]))
        a0 = math.degrees(wrap(math.radians(a0 + math.degrees(self.rot))))
        return Piece(name=name, arc=Arc(self.world(centre), r, round(a0, 9), sweep_deg))

    def movement(self, a: str, b: str, i: int, d_m: float) -> list[Piece]:
        """Inbound lane i of arm a to outbound lane i of arm b (local sides)."""
        ua = _unit(SIDES.index(a))
        va = (-ua[1], ua[0])
        ub = _unit(SIDES.index(b))
        h, bx = self.half, self.box
        start = _add((h, ua), (d_m, va))
        name = self.lane_name(self.world_side(a), self.world_side(b), i)
        if ub == (-ua[0], -ua[1]):  # straight through
            return [self.line(name, start, _add((-h, ua), (d_m, va)))]
        right = ub == va
        corner = _add((bx, ua), (bx if right else -bx, va))
        arc_start = _add((bx, ua), (d_m, va))
        arc_end = _add((bx, ub), (-d_m, (-ub[1], ub[0])))
        pieces = []
        if h - bx > 1e-12:
            pieces.append(self.line(f"{name}_in", start, arc_start))
        pieces.append(self.arc(f"{name}_turn", corner, arc_start, -90.0 if right else 90.0))
        if h - bx > 1e-12:
            pieces.append(self.line(f"{name}_out", arc_end, _add((h, ub), (-d_m, (-ub[1], ub[0])))))
        return pieces

    def through_lanes(self, arms: tuple[str, ...]) -> None:
        """Every movement between arms that the lanes allow: straight on every lane, right turns
        from the outermost lane, left turns from the innermost; at a 3-way's stem the middle lanes
        turn too (left out of the stem, right into it), so every lane has a way on."""
        k = len(self.offsets)
        for a in arms:
            ua = _unit(SIDES.index(a))
            va = (-ua[1], ua[0])
            # with no road straight on (a 3-way's stem), the middle lanes turn left too
            straight_on = SIDES[(SIDES.index(a) + 2) % 4] in arms
            for b in arms:
                if a == b:
                    continue
                ub = _unit(SIDES.index(b))
                kind = "straight" if ub == (-ua[0], -ua[1]) else ("right" if ub == va else "left")
                for i, d in enumerate(self.offsets):
                    fed_straight = SIDES[(SIDES.index(b) + 2) % 4] in arms
                    if kind == "right" and i != k - 1 and self.spec.type != "curve":
                        if fed_straight or i == 0:  # into a stem: the middle lanes turn right
                            continue
                    if kind == "left" and self.spec.type != "curve":
                        if i != 0 and (straight_on or i == k - 1):
                            continue
                    name = self.lane_name(self.world_side(a), self.world_side(b), i)
                    self.add_lane(name, self.movement(a, b, i, d), d)

    def stub_lanes(self, arm: str, end_m: float, tag: str) -> None:
        """A dead end or a parking aisle: inbound lanes end end_m from the centre (a stop line
        there), outbound lanes start there."""
        ua = _unit(SIDES.index(arm))
        va = (-ua[1], ua[0])
        h = self.half
        ws = self.world_side(arm)
        sw = self.kit.stop_line_width_m
        for i, d in enumerate(self.offsets):
            suffix = f"_{i}" if len(self.offsets) > 1 else ""
            n_in = f"{self.spec.name}_{ws}_{tag}{suffix}"
            n_out = f"{self.spec.name}_{tag}_{ws}{suffix}"
            end_in = _add((-end_m, ua), (d, va))
            self.add_lane(n_in, [self.line(n_in, _add((h, ua), (d, va)), end_in)], d)
            self.add_lane(
                n_out, [self.line(n_out, _add((-end_m, ua), (-d, va)), _add((h, ua), (-d, va)))], d
            )
            self.stop_line(f"{self.spec.name}_stop_{ws}{suffix}", n_in,
                           _add((-end_m + sw / 2, ua), (d, va)), d, ua, va)  # fmt: skip

    def stop_line(self, name: str, lane: str, centre: Vec2, d: float, ua: Vec2, va: Vec2) -> None:
        self.out.stop_lines.append(
            StopLine(name=name, lane=lane, centre_m=self.world(centre),
                     length_m=self.kit.lane_width_m)  # fmt: skip
        )
        kerb = self.width / 2 + self.kit.roadside_clearance_m
        self.out.kerb_of_stop_line[name] = self.world(_add((1.0, centre), (kerb - d, va)))

    def intersection_stop_lines(self, arms: tuple[str, ...]) -> None:
        kit = self.kit
        for a in arms:
            ua = _unit(SIDES.index(a))
            va = (-ua[1], ua[0])
            ws = self.world_side(a)
            straight = SIDES[(SIDES.index(a) + 2) % 4]
            for i, d in enumerate(self.offsets):
                # the stop line is on straight on if the tile has it, else on a turn
                ends = [straight] + [b for b in arms if b not in (a, straight)]
                names = {l.name for l in self.out.lanes}
                lane = next(
                    n for b in ends if (n := self.lane_name(ws, self.world_side(b), i)) in names
                )
                suffix = f"_{i}" if len(self.offsets) > 1 else ""
                at = self.box + kit.stop_line_setback_m + kit.stop_line_width_m / 2
                self.stop_line(f"{self.spec.name}_stop_{ws}{suffix}", lane,
                               _add((at, ua), (d, va)), d, ua, va)  # fmt: skip

    # --- slots ----------------------------------------------------------------------------------

    def slot(self, name: str, centre: Vec2, yaw_local_rad: float, size: Vec2) -> None:
        yaw = math.degrees(wrap(yaw_local_rad + self.rot))
        self.out.slots.append(ParkingSlot(name, self.world(centre), round(yaw, 9), size))

    def lot_slots(self) -> None:
        """Two rows of perpendicular slots either side of the aisle (which opens to the west)."""
        wdt, dep = self.kit.lot_slot_m
        h = self.half
        first = -h + self.box  # leave the entry free
        last = h - self.kit.dead_end_margin_m
        n = int((last - first) // wdt)
        y = self.width / 2 + dep / 2
        for row, sign in (("n", 1.0), ("s", -1.0)):
            for j in range(n):
                x = first + (j + 0.5) * wdt
                self.slot(f"{self.spec.name}_{row}{j}", (x, sign * y), sign * math.pi / 2,
                          (wdt, dep))  # fmt: skip

    def roadside_slots(self) -> None:
        """Parallel slots along both kerbs, facing the traffic of the lane beside them."""
        wdt, length = self.kit.roadside_slot_m
        n = int(self.size // length)
        y = self.width / 2 + wdt / 2
        for row, sign, yaw in (("s", -1.0, 0.0), ("n", 1.0, math.pi)):
            for j in range(n):
                x = -self.half + (j + 0.5) * self.size / n
                self.slot(f"{self.spec.name}_{row}{j}", (x, sign * y), yaw, (wdt, length))

    # --- the tile -------------------------------------------------------------------------------

    def build(self) -> TileContent:
        t = self.spec.type
        arms = ARMS[t]
        if t in ("straight", "curve", "roadside_parking", "tee", "cross"):
            self.through_lanes(arms)
        if t in ("tee", "cross"):
            self.intersection_stop_lines(arms)
        if t == "dead_end":
            self.stub_lanes("w", self.half - self.kit.dead_end_margin_m, "end")
        if t == "parking_lot":
            self.stub_lanes("w", self.half - self.kit.dead_end_margin_m, "lot")
            self.lot_slots()
        if t == "roadside_parking":
            self.roadside_slots()
        self.ports()
        return self.out

    def ports(self) -> None:
        """Lane ends that lie on the tile's edge: they must meet a neighbour's lane."""
        cx, cy = self.spec.centre_m
        for lane in self.out.lanes:
            first, last = lane.road.pieces[0], lane.road.pieces[-1]
            for end, (p, yaw) in (
                ("start", piece_point(first, 0.0)),
                ("end", piece_point(last, 1.0)),
            ):
                if max(abs(p[0] - cx), abs(p[1] - cy)) > self.half - 1e-9:
                    self.out.ports.append((lane.name, end, p, yaw))


def expand(kit: TileKit, spec: TileSpec) -> TileContent:
    """A tile's lanes, stop lines and slots in the world frame (spec checked by the loader)."""
    return _Builder(kit, spec).build()
