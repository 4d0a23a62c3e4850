"""Content-hash cache of whole solves: an unchanged request is answered without solving.

The key covers everything a result depends on: the parameters, the settings and seed, the
classification tolerances, the engine and its version, and a hash of this package's code and
templates (which fix the rendered input file and the classification). Figures are not in the key:
they are drawn on demand and added to the entry. Standard library only, so a cache hit needs
neither numpy nor pandas nor Bertini.
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
from functools import cache
from pathlib import Path

from ..fs import cache_root, temp_folder
from ..resources import template_texts
from ..versions import bertini2_version

PACKAGE = Path(__file__).resolve().parent.parent


@cache
def code_hash() -> str:
    """Hash of the package's source and templates: any change to them invalidates the cache."""
    h = hashlib.sha256()
    for f in sorted(PACKAGE.rglob("*.py")):
        h.update(f.relative_to(PACKAGE).as_posix().encode())
        h.update(f.read_bytes())
    for name, text in sorted(template_texts().items()):
        h.update(name.encode())
        h.update(text.encode())
    return h.hexdigest()


def engine_identity(engine: str, bertini: str | None) -> str:
    """What solves: the bertini2 version, or a user's binary by path, size and time."""
    binary = bertini or (os.environ.get("COTM_BERTINI") if engine == "cli" else None)
    if binary:
        path = Path(shutil.which(binary) or "missing")
        stat = path.stat() if path.exists() else None
        return f"{path}:{stat.st_size if stat else 0}:{stat.st_mtime_ns if stat else 0}"
    return f"bertini2 {bertini2_version()}"


def request_key(params: dict, settings: dict, tolerances: dict) -> str:
    """The content hash of a solve request (settings: Settings.result_key())."""
    blob = json.dumps(
        {
            "params": params,
            "settings": settings,
            "tolerances": tolerances,
            "code": code_hash(),
            "engine": engine_identity(settings.get("engine", "homotopy"), settings.get("bertini")),
        },
        sort_keys=True,
        default=str,
    )
    return hashlib.sha256(blob.encode()).hexdigest()[:20]


def solves_root() -> Path:
    """Where cached solves are kept."""
    return cache_root() / "solves"


def entry(key: str) -> Path:
    """Where the run folder of a request is kept."""
    return solves_root() / key


def lookup(key: str) -> Path | None:
    """The cached run folder of `key`, if complete."""
    folder = entry(key)
    return folder if (folder / "run.json").is_file() else None


def staging_folder() -> Path:
    """A new empty folder on the cache's file system, to solve in and then `commit`."""
    root = solves_root()
    root.mkdir(parents=True, exist_ok=True)
    return temp_folder(".tmp-", root)


def commit(key: str, folder: Path) -> Path:
    """Make a finished folder the cache entry of `key` (an atomic rename); returns the entry."""
    target = entry(key)
    try:
        folder.rename(target)
    except OSError:  # another process stored the same request first: keep theirs
        shutil.rmtree(folder, ignore_errors=True)
    return target


def add_files(key: str, files: list[Path]) -> None:
    """Copy files (figures drawn later) into an existing entry, each atomically."""
    target = entry(key)
    if not target.is_dir():
        return
    for f in files:
        tmp = target / f".{f.name}.tmp"
        shutil.copy2(f, tmp)
        tmp.replace(target / f.name)
