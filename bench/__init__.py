"""Measuring harnesses of relrl's source tree (not installed with the package)."""
