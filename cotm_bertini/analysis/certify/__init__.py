"""Certificates in ball arithmetic (python-flint): each solution proved, completeness where it
can be."""
