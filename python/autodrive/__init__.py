"""The AutoDRIVE Nigel stack's Python tools as one typed package.

The thin entry points in tools/ call into it; nothing here spells a car figure, a map fact or a
channel name: those are read from their one source (the vehicle description, the map
descriptions, lcm_types/channels.yaml).
"""
