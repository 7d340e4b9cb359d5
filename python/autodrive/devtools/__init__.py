"""Developer tools: generated headers and docs (codegen), LCM inspection, MCAP export and the
Foxglove bridge (inspect), PlatformIO offline (pio_offline)."""
