"""searchtrack.models (filled in by later issues)."""
