"""Renderers: turn results into tables, CSV and JSON. They read records, never recompute."""
