"""vehicle/nigel.params -> autodrive_vehicle.h: one #define per figure, for C and C++.

A figure of one number becomes AUTODRIVE_VEHICLE_<KEY>; one of three numbers gets _X, _Y, _Z;
one of two or more than three gets _0, _1, ...; a word becomes a string. The envelope that
planners and scoring use (autodrive.core.vehicle) is derived here once too."""

from __future__ import annotations

from autodrive.core import vehicle
from autodrive.devtools.codegen import c_header

GUARD = "AUTODRIVE_VEHICLE_H"
PREFIX = "AUTODRIVE_VEHICLE_"


def _number(v: float) -> str:
    text = repr(float(v))
    return text if ("." in text or "e" in text) else text + ".0"


def render(car: vehicle.Vehicle, source_name: str) -> str:
    lines = []
    for key, value in car.figures.items():
        name = PREFIX + key.upper()
        if isinstance(value, str):
            lines.append(f'#define {name} "{value}"')
        elif isinstance(value, float):
            lines.append(f"#define {name} {_number(value)}")
        else:
            suffixes = (
                ("X", "Y", "Z") if len(value) == 3 else tuple(str(i) for i in range(len(value)))
            )
            lines += [f"#define {name}_{s} {_number(v)}" for s, v in zip(suffixes, value)]
    lines += [
        "",
        "/* The envelope (chassis box and wheels) in base_link: length, width, and its centre",
        " * ahead of the rear axle. */",
        f"#define {PREFIX}ENVELOPE_LENGTH_M {_number(car.envelope_length_m)}",
        f"#define {PREFIX}ENVELOPE_WIDTH_M {_number(car.envelope_width_m)}",
        f"#define {PREFIX}ENVELOPE_CENTER_AHEAD_M {_number(car.envelope_center_ahead_m)}",
    ]
    return c_header.wrap(
        GUARD,
        source_name,
        "autodrive.devtools.codegen.vehicle_header",
        "The car's figures, SI units named in each key.",
        lines,
    )
