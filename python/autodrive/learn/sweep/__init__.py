"""tools/sweep: the HIL parking sweep (parking), Gymnasium episodes as jobs (episodes), the
jobs on Ray (jobs) and the command line (cli)."""
