"""searchtrack.estimate (filled in by later issues)."""
