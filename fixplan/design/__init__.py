"""Design: layout search and parameter sweeps, built on the planner."""
