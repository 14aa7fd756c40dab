"""Backends: one module per file format, imported only when that format is used; the formats'
table is backends/formats.py."""
