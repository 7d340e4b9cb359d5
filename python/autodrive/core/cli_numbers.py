"""Comma-separated numbers of a command-line option (`--goal X,Y,YAW`, `--light-rgb R,G,B`)."""

from __future__ import annotations


def comma_floats(text: str, n: int, what: str, flag: str) -> tuple[float, ...]:
    """The n numbers of text; ValueError naming the option, its value and the expected form."""
    try:
        v = tuple(float(x) for x in text.split(","))
    except ValueError:
        v = ()
    if len(v) != n:
        raise ValueError(f"{flag} '{text}': want {what}")
    return v
