"""lcm_types/channels.yaml -> <autodrive_channels.h>: the channel names for C and C++.

A per-vehicle channel "<VEH>_ODOM" becomes AUTODRIVE_CH_ODOM_SUFFIX "_ODOM" (appended to the
vehicle name: `vehicle + AUTODRIVE_CH_ODOM_SUFFIX`, or "%s" AUTODRIVE_CH_ODOM_SUFFIX in C), and a
per-camera one "<CAM>_IMAGE" likewise AUTODRIVE_CH_IMAGE_SUFFIX "_IMAGE"; a
global one becomes AUTODRIVE_CH_<ID> with its whole name. Planned channels are generated too,
marked as such, so that work in progress spells them from the table as well."""

from __future__ import annotations

from autodrive.core import channels
from autodrive.devtools.codegen import c_header

GUARD = "AUTODRIVE_CHANNELS_H"


def render(table: channels.ChannelTable, source_name: str) -> str:
    lines = [
        f'#define AUTODRIVE_LCM_URL_DEFAULT "{table.url_default}"',
        "/* the simulator's cars are <prefix><i>; one-car programs default to car 1 */",
        f'#define AUTODRIVE_VEHICLE_PREFIX "{table.vehicle_prefix}"',
        f'#define AUTODRIVE_VEHICLE_DEFAULT "{table.vehicle_prefix}1"',
        "",
    ]
    for ch in table.channels:
        note = f"/* {ch.type}, {ch.rate}" + (", planned */" if ch.status == "planned" else " */")
        if ch.placeholder:
            suffix = ch.name[len(ch.placeholder) :]
            lines.append(f'#define AUTODRIVE_CH_{ch.id}_SUFFIX "{suffix}" {note}')
        else:
            lines.append(f'#define AUTODRIVE_CH_{ch.id} "{ch.name}" {note}')
        if ch.signed_by:  # the roles v2x_role_mask takes; NAMED: the signer must be `vehicle`
            lines.append(f'#define AUTODRIVE_CH_{ch.id}_SIGNED_BY "{",".join(ch.signed_by)}"')
            lines.append(
                f"#define AUTODRIVE_CH_{ch.id}_SIGNER_IS_VEHICLE {int(ch.signer_is_vehicle)}"
            )
    return c_header.wrap(
        GUARD,
        source_name,
        "autodrive.devtools.codegen.channels_header",
        "LCM channel names; docs/reference/channels.md describes each.",
        lines,
    )


INSTANCE_GUARD = "AUTODRIVE_INSTANCE_RULE_H"


def render_instance(table: channels.ChannelTable, source_name: str) -> str:
    """<autodrive_instance_rule.h>: the table's `instances` rule (its own header, so that a
    change of it rebuilds only the code of sessions, not every user of a channel name)."""
    rule = table.instances
    lines = [
        f'#define AUTODRIVE_INSTANCE_VARIABLE "{rule.variable}"',
        f"#define AUTODRIVE_INSTANCE_MAX {rule.max}",
        "/* instance N adds N * this to the default LCM port and to the web port */",
        f"#define AUTODRIVE_INSTANCE_PORT_STEP {rule.port_step}",
        f"#define AUTODRIVE_WEB_PORT_DEFAULT {rule.web_port}",
        "/* instance N > 0 runs the simulator in <this>-N */",
        f'#define AUTODRIVE_SIM_RUN_DIR_DEFAULT "{rule.sim_run_dir}"',
    ]
    return c_header.wrap(
        INSTANCE_GUARD,
        source_name,
        "autodrive.devtools.codegen.channels_header",
        "Sessions side by side (AUTODRIVE_INSTANCE); docs/reference/channels.md describes them.",
        lines,
    )
