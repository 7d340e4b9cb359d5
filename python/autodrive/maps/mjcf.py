"""Writes a map's MJCF scene (maps/<map>.xml) from its description.

Angles in the file are radians: the simulator includes it in a scene with
<compiler angle="radian"/>. World geoms use contype 1 / conaffinity 6 (src/mjcf_gen.h). Terrain
patches are thin boxes on the floor; a surface's friction is the geom's first friction value, read
by the tyre model and by MuJoCo contacts alike. Markings and roads are visual-only boxes just
above the floor. Walls are planes at their inner face: plane contacts are far cheaper than box
contacts, and nothing can be behind a boundary wall. Cones and boxes are world-body geoms, not
bodies: static bodies cost MuJoCo 2.2 broadphase time every step.
"""

from __future__ import annotations

import math
from typing import Iterable, Sequence

from autodrive.maps import geometry, reftags, textures
from autodrive.core.geometry import wrap
from autodrive.maps.description import MapDescription
from autodrive.maps.model import REFERENCE_TAG_THICKNESS_M, REFERENCE_TAG_TOP_M, ParkingSlot, Vec2

NUMERIC_MAX_VALUES = 500  # MuJoCo 2.2's limit per <numeric>: longer data goes on in <name>.partK
CUSTOM_STEP_M = 0.05  # spacing of the lane and route centre lines in <custom> numerics
LAMPS = ("red", "yellow", "green")  # top to bottom
# light_level -> the look at light level 1 (MuJoCo's default headlight, the sun) scaled down
DAY_HEADLIGHT = {"ambient": 0.1, "diffuse": 0.4, "specular": 0.5}
DAY_SUN_DIFFUSE = 0.8

WORLD = 'contype="1" conaffinity="6"'
VIS = 'contype="0" conaffinity="0" mass="0"'


def num(v: float) -> str:
    """A number as MJCF text: shortest form, 10 significant digits, no '-0'."""
    return "0" if v == 0 else format(v, ".10g")


def nums(vs: Iterable[float]) -> str:
    return " ".join(num(v) for v in vs)


def _axis_yaw(yaw: float) -> float:
    """A symmetric box's yaw folded into (-pi/2, pi/2]: the same box, one way to write it."""
    y = wrap(yaw)
    if y <= -math.pi / 2 + 1e-12:
        y += math.pi
    elif y > math.pi / 2 + 1e-12:
        y -= math.pi
    return y


def _same_line(p: Vec2, yaw_p: float, q: Vec2, yaw_q: float) -> bool:
    """Same point and same line direction (either way)."""
    return math.dist(p, q) < 1e-9 and abs(_axis_yaw(yaw_p - yaw_q)) < 1e-9


class _Writer:
    def __init__(self, m: MapDescription) -> None:
        self.m, self.kit = m, m.kit
        self.lines: list[str] = []
        c = self.kit.contact
        self.contact = f"{num(c.torsional_friction_m)} {num(c.rolling_friction_m)}"

    def add(self, text: str) -> None:
        self.lines.append("    " + text)

    def friction(self, mu: float) -> str:
        return f'friction="{num(mu)} {self.contact}"'

    def mark(
        self,
        name: str,
        pos: Vec2,
        length: float,
        yaw: float,
        width: float,
        road: bool = False,
        yellow: bool = False,
    ) -> None:
        """A visual strip: a painted line (white, or yellow), or with road=True a piece of
        tarmac."""
        k = self.kit.road if road else self.kit.marking
        rgba = self.kit.marking.yellow_rgba if yellow else k.rgba
        self.add(
            f'<geom name="{name}" type="box" pos="{nums((*pos, k.height_m))}" '
            f'size="{nums((length / 2, width / 2, k.thickness_m / 2))}" '
            f'euler="0 0 {num(_axis_yaw(yaw))}" {VIS} rgba="{nums(rgba)}"/>'
        )  # fmt: skip

    def markings(self) -> None:
        """A strip per chord of each marking's strokes, lengthened by the width times the turn
        to the next chord so that a curve's strips close on its outer edge."""
        for mk in self.m.markings:
            for j, stroke in enumerate(mk.strokes):
                for q, (a, b) in enumerate(zip(stroke, stroke[1:])):
                    length = math.dist(a, b)
                    if length == 0:
                        continue
                    yaw = math.atan2(b[1] - a[1], b[0] - a[0])
                    nxt = stroke[q + 2] if q + 2 < len(stroke) else None
                    turn = abs(wrap(math.atan2(nxt[1] - b[1], nxt[0] - b[0]) - yaw)) if nxt else 0.0
                    mid = ((a[0] + b[0]) / 2, (a[1] + b[1]) / 2)
                    self.mark(f"{mk.name}_{j}_{q}", mid, length + mk.width_m * turn, yaw, mk.width_m,
                              yellow=mk.colour == "yellow")  # fmt: skip

    def header(self) -> None:
        m, eye = self.m, self.kit.eye_camera
        floor = self.kit.surfaces[m.floor_surface]
        h = m.floor_half_size_m
        level = m.options.light_level
        self.lines += [
            f'<mujoco model="{m.name}">',
            f"  <!-- generated from {m.name}.yaml and kit.yaml by tools/gen-maps; edit those -->",
        ]
        if level != 1:  # night: MuJoCo's default headlight dimmed (texture paths: see below)
            hl = " ".join(f'{k}="{nums([v * level] * 3)}"' for k, v in DAY_HEADLIGHT.items())
            self.lines.append(f"  <visual><headlight {hl}/></visual>")
        self.lines += [
            "  <asset>",
            '    <texture name="sky" type="skybox" builtin="gradient" rgb1="0.6 0.7 0.9" '
            'rgb2="0.2 0.25 0.3" width="64" height="64"/>',
        ]
        self.assets()
        self.lines += ["  </asset>", "  <worldbody>"]
        sun = nums([DAY_SUN_DIFFUSE * level] * 3)
        self.add(
            '<light name="sun" directional="true" pos="0 0 5" dir="0 0 -1" '
            f'diffuse="{sun}" castshadow="false"/>'
        )
        self.add(
            f'<camera name="eye" pos="0 0 {num(eye.height_m)}" xyaxes="1 0 0 0 1 0" '
            f'fovy="{num(eye.fovy_deg)}"/>'
        )
        for c in m.eye_cameras:  # user: the image size, which marks it for autodrive-sim --eye
            self.add(
                f'<camera name="{c.name}" pos="{nums((*c.centre_m, c.height_m))}" '
                f'xyaxes="1 0 0 0 1 0" fovy="{num(eye.fovy_deg)}" '
                f'user="{eye.width_px} {eye.height_px}"/>'
            )
        self.add(
            f'<geom name="floor" type="plane" size="{nums((h, h))} 0.1" {WORLD} '
            f'{self.friction(floor.friction)} rgba="{nums(floor.rgba)}"/>'
        )
        sp = m.spawn.pose
        self.add(
            f'<site name="spawn" pos="{nums((sp.x_m, sp.y_m))} 0" euler="0 0 {num(sp.yaw_rad)}" '
            'size="0.02"/>'
        )
        for s in m.named_spawns():
            p = s.pose
            self.add(
                f'<site name="spawn_{s.name}" pos="{nums((p.x_m, p.y_m))} 0" '
                f'euler="0 0 {num(p.yaw_rad)}" size="0.02"/>'
            )

    def assets(self) -> None:
        """Textures (files relative to the map's folder; the simulator's scene sets texturedir
        to that folder), one per tile type and sign kind used, and one material per lamp."""
        m = self.m
        for name in sorted({t.texture for t in m.tile_contents()}):
            self.lines.append(
                f'    <texture name="{name}" type="2d" file="{textures.DIR_NAME}/{name}.png"/>'
            )
            self.lines.append(f'    <material name="{name}_mat" texture="{name}"/>')
        for name in sorted({textures.sign_texture_name(s.kind, s.speed_limit_m_s)
                            for s in m.placed_signs()}):  # fmt: skip
            self.lines.append(
                f'    <texture name="{name}" type="2d" file="{textures.DIR_NAME}/{name}.png"/>'
            )
            self.lines.append(f'    <material name="{name}_mat" texture="{name}"/>')
        for t in m.reference_tags:
            n = reftags.texture_name(t.id)
            self.lines.append(
                f'    <texture name="{n}" type="2d" file="{textures.DIR_NAME}/{n}.png"/>'
            )
            self.lines.append(
                f'    <material name="{n}_mat" texture="{n}" specular="0" shininess="0" '
                'reflectance="0"/>'
            )
        tl = self.kit.traffic_light
        for light in m.lights():
            for c in LAMPS:
                self.lines.append(
                    f'    <material name="{light.name}_lamp_{c}_mat" '
                    f'rgba="{nums(tl.lamp_off_rgba[c])}" emission="0"/>'
                )

    def tiles(self) -> None:
        """One textured box per tile: its markings are in the texture."""
        tk = self.kit.tiles
        for t in self.m.tile_contents():
            h = t.size_m / 2
            self.add(
                f'<geom name="tile_{t.spec.name}" type="box" '
                f'pos="{nums((*t.spec.centre_m, tk.height_m))}" '
                f'size="{nums((h, h, tk.thickness_m / 2))}" '
                f'euler="0 0 {num(wrap(math.radians(t.spec.rotation_deg)))}" {VIS} '
                f'material="{t.texture}_mat"/>'
            )

    def reference_tags(self) -> None:
        """One plate per reference tag, its top face carrying the whole 10-cell image. MuJoCo
        lays a 2D texture on a box's top face with the image's up along the box's +y: the box
        is yawed yaw - 90 deg so that the print's top points along yaw (as the roof tags,
        sim_tags.h)."""
        t_m = REFERENCE_TAG_THICKNESS_M
        for t in self.m.reference_tags:
            half = 0.5 * t.size_m * reftags.CELLS / reftags.BLACK_CELLS
            self.add(
                f'<geom name="reftag_{t.id}" type="box" '
                f'pos="{nums((*t.centre_m, REFERENCE_TAG_TOP_M - t_m / 2))}" '
                f'size="{nums((half, half, t_m / 2))}" '
                f'euler="0 0 {num(wrap(math.radians(t.yaw_deg) - math.pi / 2))}" {VIS} '
                f'material="{reftags.texture_name(t.id)}_mat"/>'
            )

    def lights(self) -> None:
        """Per light: a pole (collidable: a LIDAR sees it), a housing and three lamps (visual),
        the lamps on the housing's face towards the approach."""
        tl = self.kit.traffic_light
        for light in self.m.lights():
            x, y = light.position_m
            c, s = math.cos(light.yaw_rad), math.sin(light.yaw_rad)
            ph = tl.pole_height_m
            self.add(
                f'<geom name="{light.name}_pole" type="cylinder" pos="{nums((x, y, ph / 2))}" '
                f'size="{nums((tl.pole_radius_m, ph / 2))}" {WORLD} '
                f'{self.friction(self.kit.obstacle.friction)} rgba="{nums(tl.pole_rgba)}"/>'
            )
            dx, dy, dz = tl.housing_size_m
            zc = ph + dz / 2
            self.add(
                f'<geom name="{light.name}_housing" type="box" pos="{nums((x, y, zc))}" '
                f'size="{nums((dx / 2, dy / 2, dz / 2))}" euler="0 0 {num(light.yaw_rad)}" '
                f'{VIS} rgba="{nums(tl.housing_rgba)}"/>'
            )
            for k, colour in enumerate(LAMPS):
                lx, ly = x + c * dx / 2, y + s * dx / 2
                lz = zc + (1 - k) * dz / 3
                self.add(
                    f'<geom name="{light.name}_lamp_{colour}" type="sphere" '
                    f'pos="{nums((lx, ly, lz))}" size="{num(tl.lamp_radius_m)}" {VIS} '
                    f'material="{light.name}_lamp_{colour}_mat"/>'
                )

    def signs(self) -> None:
        """Per sign: a post (collidable) and a face (visual) textured with its kind."""
        sk = self.kit.sign
        for sign in self.m.placed_signs():
            x, y = sign.position_m
            ph = sk.post_height_m
            self.add(
                f'<geom name="{sign.name}_post" type="cylinder" pos="{nums((x, y, ph / 2))}" '
                f'size="{nums((sk.post_radius_m, ph / 2))}" {WORLD} '
                f'{self.friction(self.kit.obstacle.friction)} rgba="{nums(sk.post_rgba)}"/>'
            )
            c, s = math.cos(sign.yaw_rad), math.sin(sign.yaw_rad)
            t = sk.face_thickness_m
            f = sk.face_size_m / 2
            z = ph + f * 0.6
            axes = f'xyaxes="{nums((round(-s, 12), round(c, 12)))} 0 0 0 1"'
            # the face box's local z is its normal (the way it points), local y is up: MuJoCo
            # paints a box's 2d texture on its +-z faces, image up = local +y; a plain plate
            # behind it hides the mirrored copy on its back
            for part, off, look in (
                ("back", sk.post_radius_m + t / 2, f'rgba="{nums(sk.post_rgba)}"'),
                ("face", sk.post_radius_m + 1.5 * t,
                 f'material="{textures.sign_texture_name(sign.kind, sign.speed_limit_m_s)}_mat"'),
            ):  # fmt: skip
                self.add(
                    f'<geom name="{sign.name}_{part}" type="box" '
                    f'pos="{nums((x + c * off, y + s * off, z))}" '
                    f'size="{nums((f, f, t / 2))}" {axes} {VIS} {look}/>'
                )

    def custom(self) -> None:
        """What C readers need, as MuJoCo custom numerics and texts (mj_name2id(mjOBJ_NUMERIC))."""
        m = self.m
        out = []
        for light in m.lights():
            p = light.program
            data = nums((p.cycle_s, p.offset_s, p.green_s, p.yellow_s))
            out.append(f'    <numeric name="{light.name}_program" data="{data}"/>')
        pairs = m.light_conflicts()
        if pairs:
            flat = [float(v) for pair in pairs for v in pair]
            out.append(f'    <numeric name="tl_conflicts" data="{nums(flat)}"/>')
        for lane in m.lanes():
            pts = [v for x, y, _ in m.centre_line(lane, CUSTOM_STEP_M) for v in (x, y)]
            out += _numeric_parts(f"lane_{lane.name}", [lane.half_width_m], pts)
        for r in m.named_routes():
            pts = [v for p in r.polyline_m for v in p]
            out += _numeric_parts(f"route_{r.name}", [1.0 if r.loop else 0.0, r.half_width_m], pts)
        for sign in m.placed_signs():
            out.append(f'    <text name="{sign.name}_kind" data="{sign.kind}"/>')
        if m.terrain_patches:  # the sim's tyres read their friction (sim/.../src/terrain.c)
            names = " ".join(p.name for p in m.terrain_patches)
            out.append(f'    <text name="terrain_patches" data="{names}"/>')
        for (
            o
        ) in m.late_obstacles:  # the simulator adds these (world geoms it moves in) at their time
            data = nums(
                (*o.centre_m, o.yaw_rad, *o.size_m, o.appear_s or 0.0, o.trigger_radius_m or 0.0)
            )
            out.append(f'    <numeric name="late_{o.name}" data="{data}"/>')
        if out:
            self.lines += ["  <custom>", *out, "  </custom>"]

    def slots(self, slots: Sequence[ParkingSlot]) -> None:
        """Each slot's two side lines and its back line; a line shared with a neighbour is drawn
        once, and back lines in one row are joined into one."""
        w = self.kit.marking.line_width_m
        sides: list[tuple[Vec2, float, float]] = []  # centre, length, yaw
        backs: list[tuple[Vec2, Vec2, float]] = []  # ends, yaw
        for s in slots:
            yaw = s.yaw_rad
            c, si = math.cos(yaw), math.sin(yaw)
            half_w, half_d = s.size_m[0] / 2, s.size_m[1] / 2
            right = (si, -c)  # unit vector to the parked car's right
            for side in (-half_w, half_w):  # left side first
                p = (s.centre_m[0] + side * right[0], s.centre_m[1] + side * right[1])
                if not any(_same_line(p, yaw, q, y) for q, _, y in sides):
                    sides.append((p, s.size_m[1], yaw))
            bc = (s.centre_m[0] + half_d * c, s.centre_m[1] + half_d * si)
            a = (bc[0] - half_w * right[0], bc[1] - half_w * right[1])  # left end
            b = (bc[0] + half_w * right[0], bc[1] + half_w * right[1])
            if backs and _same_line(backs[-1][1], backs[-1][2], a, yaw):
                backs[-1] = (backs[-1][0], b, yaw)  # the row continues to the right
            elif backs and _same_line(backs[-1][0], backs[-1][2], b, yaw):
                backs[-1] = (a, backs[-1][1], yaw)  # ... or to the left
            else:
                backs.append((a, b, yaw))
        for k, (p, length, yaw) in enumerate(sides):
            self.mark(f"slot_line_{k}", p, length, yaw, w)
        for k, (a, b, yaw) in enumerate(backs):
            mid = ((a[0] + b[0]) / 2, (a[1] + b[1]) / 2)
            self.mark(
                "slot_back" + (f"_{k}" if k else ""), mid, math.dist(a, b), yaw - math.pi / 2, w
            )

    def box(self, name: str, centre: Vec2, size: Sequence[float], yaw: float) -> None:
        ob = self.kit.obstacle
        self.add(
            f'<geom name="{name}" type="box" pos="{nums((*centre, size[2] / 2))}" '
            f'size="{nums(v / 2 for v in size)}" euler="0 0 {num(yaw)}" {WORLD} '
            f'{self.friction(ob.friction)} rgba="{nums(ob.box_rgba)}"/>'
        )

    def cone(self, name: str, p: Vec2) -> None:
        k = self.kit.cone
        self.add(
            f'<geom name="{name}" type="cylinder" pos="{nums((*p, k.height_m / 2))}" '
            f'size="{nums((k.radius_m, k.height_m / 2))}" {WORLD} '
            f'{self.friction(self.kit.obstacle.friction)} rgba="{nums(k.rgba)}"/>'
        )
        b = k.base_size_m / 2
        t = k.base_thickness_m / 2
        self.add(
            f'<geom name="{name}_base" type="box" pos="{nums((*p, t))}" size="{nums((b, b, t))}" '
            f'{VIS} rgba="{nums(k.base_rgba)}"/>'
        )

    def roads(self) -> None:
        rk, mk = self.kit.road, self.kit.marking
        dash = 0
        for r in self.m.roads:
            arcs = [p for p in r.pieces if p.arc is not None]
            lines = [p for p in r.pieces if p.line is not None]
            for p in arcs:
                assert p.arc is not None
                seg = max(1, round(abs(p.arc.sweep_deg) / 90 * rk.arc_segments_per_90deg))
                ln = geometry.piece_length_m(p) / seg * (1 + rk.arc_segment_overlap)
                for k in range(seg):
                    (x, y), yaw = geometry.piece_point(p, (k + 0.5) / seg)
                    self.mark(f"road_{p.name}_{k}", (x, y), ln, yaw, r.width_m, road=True)
                    if r.centre_marking == "dashed" and k % 2 == 0:
                        self.mark(f"mark_c{dash}", (x, y), ln, yaw, mk.centre_dash_width_m)
                        dash += 1
            for p in lines:
                (x, y), yaw = geometry.piece_point(p, 0.5)
                length = geometry.piece_length_m(p)
                self.mark(f"road_{p.name}", (x, y), length, yaw, r.width_m, road=True)
                if r.centre_marking != "dashed":
                    continue
                n = max(1, round(length / mk.centre_dash_pitch_m))
                ay = _axis_yaw(yaw)  # dashes in the same order whichever way the piece runs
                for k in range(n):
                    t = -length / 2 + (k + 0.5) * length / n
                    px, py = x + t * math.cos(ay), y + t * math.sin(ay)
                    self.mark(
                        f"mark_{p.name}{k}", (px, py), mk.centre_dash_length_m, ay,
                        mk.centre_dash_width_m,
                    )  # fmt: skip

    def write(self) -> str:
        m, kit = self.m, self.kit
        self.header()
        self.tiles()
        self.slots(m.parking_slots)  # the tiles' slots are painted in their textures
        self.roads()
        self.markings()
        for s in m.stop_lines:
            self.mark(
                s.name,
                s.centre_m,
                s.length_m,
                m.stop_line_yaw_rad(s),
                kit.marking.stop_line_width_m,
            )
        for b in m.boxes:
            self.box(b.name, b.centre_m, b.size_m, b.yaw_rad)
        for c in m.cones:
            self.cone(c.name, c.position_m)
        for p in m.parked:
            slot = m.slot(p.slot)
            self.box(f"parked_{p.slot}", slot.centre_m, kit.parked_car_size_m, slot.yaw_rad)
        self.lights()
        self.signs()
        self.reference_tags()
        t = kit.terrain_patch_thickness_m
        for patch in m.terrain_patches:
            surface = kit.surfaces[patch.surface]
            self.add(
                f'<geom name="{patch.name}" type="box" pos="{nums((*patch.centre_m, t / 2))}" '
                f'size="{nums((patch.size_m[0] / 2, patch.size_m[1] / 2, t / 2))}" {WORLD} '
                f'{self.friction(surface.friction)} rgba="{nums(surface.rgba)}"/>'
            )
        hz = kit.obstacle.wall_height_m / 2
        for w in m.walls:
            nx, ny = w.normal
            # planes size only bounds drawing and rays; the local vertical axis is x for walls
            # facing +-x and y for walls facing +-y
            hx, hy = (hz, w.length_m / 2) if nx else (w.length_m / 2, hz)
            self.add(
                f'<geom name="{w.name}" type="plane" pos="{nums((*w.face_centre_m, hz))}" '
                f'size="{nums((hx, hy))} 0.05" zaxis="{nums((nx, ny))} 0" {WORLD} '
                f'{self.friction(kit.obstacle.friction)} rgba="{nums(kit.obstacle.wall_rgba)}"/>'
            )
        self.lines.append("  </worldbody>")
        self.custom()
        self.lines += ["</mujoco>", ""]
        return "\n".join(self.lines)


def _numeric_parts(name: str, head: list[float], points: list[float]) -> list[str]:
    """<numeric> lines of head + points: the first named name, the rest name.part1, .part2 ...
    (at most NUMERIC_MAX_VALUES values each; parts hold whole x y pairs)."""
    values = head + [round(v, 6) for v in points]
    first = NUMERIC_MAX_VALUES - (NUMERIC_MAX_VALUES - len(head)) % 2
    chunks = [values[:first]]
    rest = values[first:]
    while rest:
        chunks.append(rest[:NUMERIC_MAX_VALUES])
        rest = rest[NUMERIC_MAX_VALUES:]
    return [
        f'    <numeric name="{name}{f".part{k}" if k else ""}" data="{nums(c)}"/>'
        for k, c in enumerate(chunks)
    ]


def generate(m: MapDescription) -> str:
    """The map's MJCF text."""
    return _Writer(m).write()
