"""What every part of the package shares: the settings (where the repository's sources are), the
vehicle description, the channel table, the LCM types and wire, plane geometry, child
processes, run files, plots, signed commands and their keys."""
