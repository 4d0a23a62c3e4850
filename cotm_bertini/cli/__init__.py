"""The `cotm-bertini` command: a thin shell over the library's public API."""

from .main import main

__all__ = ["main"]
