"""Shipped example mechanisms and generated catalogs (data only)."""
