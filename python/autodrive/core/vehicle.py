"""Reads the vehicle description (vehicle/nigel.params), the one place the car's figures are
written. Format: "key = value [value ...]", '#' starts a comment, SI units named in each key.

Usage: ``v = load(); v.wheelbase_m; v.chassis_size_m[0]; v.envelope_length_m``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Union

from autodrive.core.geometry import Footprint
from autodrive.core.settings import VEHICLE_FILE

Figure = Union[float, tuple[float, ...], str]


class VehicleFileError(ValueError):
    """A vehicle description that cannot be read; the message names the file and line."""


@dataclass(frozen=True)
class Vehicle:
    """The car's figures by key (units in the key names), plus the envelope derived from them."""

    source: Path
    figures: dict[str, Figure] = field(default_factory=dict)

    def __getattr__(self, key: str) -> Figure:
        figures: dict[str, Figure] = object.__getattribute__(self, "figures")
        if key in figures:
            return figures[key]
        raise AttributeError(f"{self.source}: no figure '{key}'")

    def number(self, key: str) -> float:
        """A one-number figure, e.g. number('wheelbase_m')."""
        value = self.figures.get(key)
        if not isinstance(value, float):
            raise VehicleFileError(f"{self.source}: '{key}' is not a single number ({value!r})")
        return value

    def vector(self, key: str) -> tuple[float, ...]:
        """A figure of several numbers, e.g. vector('chassis_size_m')."""
        value = self.figures.get(key)
        if not isinstance(value, tuple):
            raise VehicleFileError(f"{self.source}: '{key}' is not a list of numbers ({value!r})")
        return value

    # The envelope (chassis box and wheels) that planners, scoring and plots use.
    @property
    def envelope_length_m(self) -> float:
        return self.vector("chassis_size_m")[0]

    @property
    def envelope_width_m(self) -> float:
        return max(
            self.vector("chassis_size_m")[1],
            self.number("track_m") + self.number("wheel_width_m"),
        )

    @property
    def envelope_center_ahead_m(self) -> float:
        """Centre of the envelope ahead of the rear axle (base_link)."""
        return self.vector("chassis_offset_m")[0]

    @property
    def envelope(self) -> Footprint:
        return Footprint(
            self.envelope_length_m, self.envelope_width_m, self.envelope_center_ahead_m
        )


def _parse_value(text: str) -> Figure:
    words = text.split()
    try:
        numbers = tuple(float(w) for w in words)
    except ValueError:
        if len(words) == 1:
            return words[0]
        raise
    return numbers[0] if len(numbers) == 1 else numbers


def load(path: Path | str | None = None) -> Vehicle:
    """Reads a vehicle description; raises VehicleFileError naming the file, line and problem."""
    source = Path(path) if path is not None else VEHICLE_FILE
    try:
        lines = source.read_text().splitlines()
    except OSError as err:
        raise VehicleFileError(f"{source}: cannot read the vehicle description ({err})") from err
    figures: dict[str, Figure] = {}
    for number, raw in enumerate(lines, start=1):
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        key, sep, value = (part.strip() for part in line.partition("="))
        if not sep or not key or not value:
            raise VehicleFileError(
                f"{source}:{number}: expected 'key = value', got '{raw.strip()}'"
            )
        if key in figures:
            raise VehicleFileError(f"{source}:{number}: '{key}' is given twice")
        try:
            figures[key] = _parse_value(value)
        except ValueError:
            raise VehicleFileError(
                f"{source}:{number}: '{key}' has a bad value '{value}'"
            ) from None
    return Vehicle(source=source, figures=figures)
