"""The serial protocol's description (PROTOCOL.md, beside the codec in the firmware core) ->
docs/reference/protocol.md: the same text as a page of the documentation site, which builds
only from docs/."""

from __future__ import annotations

from pathlib import Path

PATH = "docs/reference/protocol.md"


def source(root: Path) -> Path:
    """The protocol's description wherever the firmware core keeps its codec."""
    found = sorted((root / "firmware" / "nano").glob("**/PROTOCOL.md"))
    if len(found) != 1:
        raise FileNotFoundError(f"expected one PROTOCOL.md under firmware/nano, found {found}")
    return found[0]


def render(root: Path) -> str:
    src = source(root)
    rel = src.relative_to(root).as_posix()
    return f"<!-- Generated from {rel} by tools/gen-docs: do not edit. -->\n" + src.read_text()
