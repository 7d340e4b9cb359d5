"""The AutoDRIVE Nigel stack's one Python distribution (`pip install -e python/`).

Subpackages: core (settings, vehicle, channels, LCM types and wire, geometry, processes),
maps (the map kit), gym (registered Gymnasium and PettingZoo environments), learn (marl, pilot,
sweep), scm (the Smart City Manager), hil (the demo and its missions), bench, devtools.

Nothing here spells a car figure, a map fact or a channel name: those are read from their one
source (the vehicle description, the map descriptions, lcm_types/channels.yaml), found through
autodrive.core.settings.
"""
