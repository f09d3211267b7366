"""`pendulum bench` (command.py): its phases, each a fresh process (process.py); the simulation phase against
numpy and numba (sim.py, peers.py) and the machine's peak rate (peak.py); the report (report.py)."""
