"""The frame every generated C header shares: who made it from what, and the include guard."""

from __future__ import annotations


def wrap(guard: str, source_name: str, generator: str, what: str, body: list[str]) -> str:
    """A complete header: a do-not-edit comment naming source_name and generator, what it
    holds, and body inside an include guard."""
    return "\n".join(
        [
            f"/* Generated from {source_name} by {generator}: do not edit.",
            f" * {what} */",
            f"#ifndef {guard}",
            f"#define {guard}",
            "",
            *body,
            "",
            f"#endif /* {guard} */",
            "",
        ]
    )
