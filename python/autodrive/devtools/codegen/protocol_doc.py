"""The serial protocol's description (PROTOCOL.md, beside the codec in the firmware core) ->
docs/reference/protocol.md: the same text as a page of the documentation site, which builds
only from docs/."""

from __future__ import annotations

from pathlib import Path

PATH = "docs/reference/protocol.md"


SOURCE = "firmware/nano/core/protocol/PROTOCOL.md"


def source(root: Path) -> Path:
    """The protocol's description, beside its codec."""
    src = root / SOURCE
    if not src.is_file():
        raise FileNotFoundError(f"the serial protocol's description {src} is missing")
    return src


def render(root: Path) -> str:
    src = source(root)
    rel = src.relative_to(root).as_posix()
    return f"<!-- Generated from {rel} by tools/gen-docs: do not edit. -->\n" + src.read_text()
