"""searchtrack.sim (filled in by later issues)."""
