"""From the command line to a run file: the config schema and its checks, the scenes and their
initial states, the runner that drives the engine and writes snapshots, run folders and their
locks, resource checks, and the command line itself."""
