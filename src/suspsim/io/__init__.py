"""Input/output helpers: atomic writes, provenance."""
