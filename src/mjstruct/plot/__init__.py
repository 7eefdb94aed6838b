"""Drawings and charts (matplotlib, imported lazily by each function)."""
