"""Cam mechanisms designed from a linkage's cycle (placeholder, filled below)."""
