"""Structural quantities of chains with multiple joints (graph-centred core)."""
