"""Hardware-in-the-loop runs on the simulator: the demo (demo), its missions (missions), the
smart-city stand-ins (city), the scoring and report of a recorded run (scoring, report) and
the parking plot (plot_parking)."""
