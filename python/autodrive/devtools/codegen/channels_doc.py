"""lcm_types/channels.yaml -> docs/reference/channels.md: the channel table as a person reads it."""

from __future__ import annotations

from autodrive.core import channels

PATH = "docs/reference/channels.md"


def _programs(names: tuple[str, ...]) -> str:
    return ", ".join(names) if names else "-"


def render(table: channels.ChannelTable, source_name: str) -> str:
    out = [
        f"<!-- Generated from {source_name} by tools/gen-docs: do not edit. -->",
        "# LCM channels",
        "",
        f"Every channel on the bus, from the one channel table `{source_name}`. `<VEH>` is the",
        f"vehicle name in capitals (`{table.vehicle_prefix}1`, `{table.vehicle_prefix}2`, ...: the "
        "simulator's cars), so many cars share one network; `<CAM>` is an overhead camera of the",
        "map (`EYE1`, `EYE2`, ...: the map description's `eye_cameras`). All",
        "types are in package `autodrive` (`lcm_types/autodrive/`). Units are SI unless the field",
        "name says otherwise. C and C++ spell the names through the generated",
        "`<autodrive_channels.h>` (`AUTODRIVE_CH_<ID>`, `AUTODRIVE_CH_<ID>_SUFFIX` for per-vehicle and per-camera",
        "channels), Python through `autodrive.core.channels.channel(id, vehicle)`.",
        "",
        f"Default URL: `{table.url_default}` (ttl=0: never leaves the host). Tests use their own",
        "ports so that runs in parallel do not hear each other.",
        "",
        f"Two sessions on one machine (two users): `{table.instances.variable}=N` (or a",
        "program's `--instance N`) gives a session its own bus and ports. Instance N moves every",
        f"URL on the default port to that port + {table.instances.port_step} N, the Smart City",
        f"Manager's web port {table.instances.web_port} to {table.instances.web_port} +",
        f"{table.instances.port_step} N, and the simulator's run dir (its ptys) to",
        f"`{table.instances.sim_run_dir}-N`; instance 0 (unset) keeps the defaults. So an SCM",
        "on one instance never commands another instance's lights.",
        "",
        "A *planned* channel is reserved for work in progress: no program publishes it yet. The",
        "HIL parking test records a run and checks both ways that the code and this table agree.",
        "A live channel with a condition (status `live (traffic_lights)`: only on maps with",
        "traffic lights; `live (on_demand)`: only when someone acts; `live (v2v)`: only when a",
        "runtime knows its map pose; `live (smart_city)`: only while the Smart City Manager",
        "runs; `live (eye_cameras)`: only when the simulator renders a map's several overhead",
        "cameras) is expected in a recorded",
        "run only when the audit is told the condition holds (`channel_audit --when ...`).",
        "",
        "| channel | type | rate | publishers | subscribers | status | content |",
        "|---|---|---|---|---|---|---|",
    ]
    for ch in table.channels:
        out.append(
            f"| `{ch.name}` | `{ch.type}` | {ch.rate} | {_programs(ch.publishers)} | "
            f"{_programs(ch.subscribers)} | {ch.status}{f' ({ch.when})' if ch.when else ''} | "
            f"{ch.content} |"
        )
    out.append("")
    return "\n".join(out)
