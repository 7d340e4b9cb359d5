"""vehicle/nigel.params -> docs/reference/vehicle.md: the car's figures as a table a person reads, with the
description's own section headings and comments, so that no document restates a figure by hand."""

from __future__ import annotations

import re

from autodrive.core import vehicle
from autodrive.devtools.codegen import firmware_header

PATH = "docs/reference/vehicle.md"
_SECTION = re.compile(r"^#\s*-+\s*(.*?)\s*-+\s*$")


def _value_text(value: vehicle.Figure) -> str:
    if isinstance(value, str):
        return f"`{value}`"
    if isinstance(value, float):
        return f"{value:g}"
    return "(" + ", ".join(f"{v:g}" for v in value) + ")"


def render(car: vehicle.Vehicle, source_name: str) -> str:
    out = [
        "<!-- Generated from " + source_name + " by tools/gen-docs: do not edit. -->",
        "# The car: Nigel's figures",
        "",
        f"Every figure of the car is written once, in `{source_name}`; C and C++ code include the",
        "generated `<autodrive_vehicle.h>` (macros `AUTODRIVE_VEHICLE_<KEY>`), Python reads it",
        "through `autodrive.core.vehicle`, the firmware's servo figures are generated into",
        f"`{firmware_header.PATH}`, and the simulator builds the car's MJCF from it.",
        "Units are in each key. Frame: `base_link` is the rear-axle centre on the ground, x",
        "forward, y left, z up.",
        "",
        "Derived envelope (chassis box and wheels) that planners, scoring and plots use: "
        f"{car.envelope_length_m:g} m long, {car.envelope_width_m:g} m wide, its centre "
        f"{car.envelope_center_ahead_m:g} m ahead of the rear axle.",
    ]
    header = ["", "| key | value | note |", "|---|---|---|"]
    pending_header = True
    for raw in car.source.read_text().splitlines():
        line = raw.strip()
        section = _SECTION.match(line)
        if section:
            out += ["", f"## {section.group(1)}"]
            pending_header = True
            continue
        body, _, comment = raw.partition("#")
        key, sep, _value = body.partition("=")
        key = key.strip()
        if not sep or key not in car.figures:
            continue
        if pending_header:
            out += header
            pending_header = False
        out.append(f"| `{key}` | {_value_text(car.figures[key])} | {comment.strip()} |")
    out.append("")
    return "\n".join(out)
