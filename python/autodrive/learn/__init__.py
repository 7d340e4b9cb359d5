"""The learning stack: multi-agent intersection traversal (marl), behavioural cloning (pilot)
and independent simulated jobs on Ray (sweep). The environments are in autodrive.gym."""
