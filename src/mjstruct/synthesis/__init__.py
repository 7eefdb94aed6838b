"""Structural synthesis: cells, atlases of chains, catalog lookup."""
