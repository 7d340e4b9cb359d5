"""Checks lcm_types/CHANNELS.md against lcm_types/autodrive/*.lcm: every listed channel has an
existing type and a unique name, and every type starts with int64_t utime."""
import pathlib
import re
import sys

root = pathlib.Path(sys.argv[1])
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

channels = {}
rows = 0
for ln in (root / "lcm_types" / "CHANNELS.md").read_text().splitlines():
    cells = [c.strip() for c in ln.strip().strip("|").split("|")]
    if len(cells) < 4 or not cells[0].startswith("`"):
        continue
    rows += 1
    name, typ = cells[0].strip("`"), cells[1].strip("`")
    if not re.fullmatch(r"(<VEH>_)?[A-Z0-9_]+", name):
        errors.append(f"channel {name}: not UPPER_CASE (with optional <VEH>_ prefix)")
    if name in channels:
        errors.append(f"channel {name}: listed twice")
    channels[name] = typ
    if typ.split(".")[-1] not in types:
        errors.append(
            f"channel {name}: type {typ} has no lcm_types/autodrive/{typ.split('.')[-1]}.lcm"
        )
    if not cells[2] or not cells[3]:
        errors.append(f"channel {name}: rate and publisher must be given")

unused = set(types) - {t.split(".")[-1] for t in channels.values()}
if unused:
    errors.append(f"types no channel uses: {sorted(unused)}")
if rows == 0:
    errors.append("CHANNELS.md lists no channels")
for e in errors:
    print("ERROR:", e)
print(f"{rows} channels, {len(types)} types, {len(errors)} errors")
sys.exit(1 if errors else 0)
