"""Figures (matplotlib is loaded only when one of these modules is imported)."""
