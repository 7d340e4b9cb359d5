"""Checks the channel table lcm_types/channels.yaml against lcm_types/autodrive/*.lcm: every
channel has an existing type, a unique name and id, and every type starts with int64_t utime.
(docs/reference/channels.md is generated from the table; foundation.single_source checks it is fresh.)"""
import pathlib
import re
import sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[2] / "python"))
from autodrive.core import channels as channel_table  # noqa: E402


def test_channel_table_matches_types(root: pathlib.Path) -> None:
    types_dir = root / "lcm_types" / "autodrive"
    errors = []

    types = {}
    for f in sorted(types_dir.glob("*_t.lcm")):
        text = f.read_text()
        m = re.search(r"struct\s+(\w+)\s*\{(.*?)\}", text, re.S)
        if not m:
            errors.append(f"{f.name}: no struct")
            continue
        if m.group(1) != f.stem:
            errors.append(f"{f.name}: struct is named {m.group(1)}, expected {f.stem}")
        fields = [ln.split("//")[0].strip() for ln in m.group(2).splitlines()]
        fields = [x for x in fields if x and not x.startswith("const")]
        if not fields or not re.match(r"int64_t\s+utime\s*;", fields[0]):
            errors.append(f"{f.name}: first field must be 'int64_t utime;', found {fields[:1]}")
        types[f.stem] = f

    table = channel_table.load(root / "lcm_types" / "channels.yaml")
    channels = {}
    ids = set()
    rows = 0
    for ch in table.channels:
        rows += 1
        name, typ = ch.name, ch.type
        if not re.fullmatch(r"(<VEH>_|<CAM>_)?[A-Z0-9_]+", name):
            errors.append(f"channel {name}: not UPPER_CASE (with optional <VEH>_ or <CAM>_ prefix)")
        if name in channels:
            errors.append(f"channel {name}: listed twice")
        if ch.id in ids:
            errors.append(f"channel {name}: id {ch.id} used twice")
        if name.replace("<VEH>_", "").replace("<CAM>_", "") != ch.id:
            errors.append(f"channel {name}: id {ch.id} does not match the name")
        ids.add(ch.id)
        channels[name] = typ
        if typ not in types:
            errors.append(f"channel {name}: type {typ} has no lcm_types/autodrive/{typ}.lcm")
        if not ch.rate or (ch.status == "live" and not ch.publishers):
            errors.append(f"channel {name}: rate and (when live) a publisher must be given")

    unused = set(types) - {t.split(".")[-1] for t in channels.values()}
    if unused:
        errors.append(f"types no channel uses: {sorted(unused)}")
    if rows == 0:
        errors.append("channels.yaml lists no channels")
    for e in errors:
        print("ERROR:", e)
    print(f"{rows} channels, {len(types)} types, {len(errors)} errors")
    assert not errors, "\n".join(errors)
