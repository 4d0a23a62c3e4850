"""Content-hash cache of whole solves: an unchanged request is answered without solving.

The key covers everything the result depends on: the parameters, the solver settings and seed,
the engine and its version, whether figures were asked for, and a hash of this package's code and
templates (which determine the rendered input file and the classification). Standard library only,
so a cache hit needs neither numpy nor pandas nor Bertini.
"""

from __future__ import annotations

import hashlib
import importlib.metadata as md
import json
import os
import shutil
import tempfile
from functools import cache
from pathlib import Path

PACKAGE = Path(__file__).resolve().parent
TEMPLATES = PACKAGE.parent / "templates"


def cache_root() -> Path:
    """$COTM_CACHE or ~/.cache/cotm-bertini (shared with the generic solution sets)."""
    root = os.environ.get("COTM_CACHE") or Path.home() / ".cache" / "cotm-bertini"
    return Path(root)


@cache
def code_hash() -> str:
    """Hash of the package's source and templates: any change to them invalidates the cache."""
    h = hashlib.sha256()
    files = sorted(PACKAGE.glob("*.py")) + sorted(TEMPLATES.glob("*.j2"))
    for f in files:
        h.update(f.name.encode())
        h.update(f.read_bytes())
    return h.hexdigest()


def engine_identity(engine: str, bertini: str | None) -> str:
    """What solves: the bertini2 version, or a user's binary by path, size and time."""
    if bertini or (engine == "cli" and os.environ.get("COTM_BERTINI")):
        path = Path(shutil.which(bertini or os.environ["COTM_BERTINI"]) or "missing")
        stat = path.stat() if path.exists() else None
        return f"{path}:{stat.st_size if stat else 0}:{stat.st_mtime_ns if stat else 0}"
    return f"bertini2 {md.version('bertini2')}"


def request_key(params: dict, settings: dict, plots: bool) -> str:
    """The content hash of a solve request."""
    relevant = {k: v for k, v in settings.items() if k not in ("timeout", "threads")}
    blob = json.dumps(
        {
            "params": params,
            "settings": relevant,
            "plots": plots,
            "code": code_hash(),
            "engine": engine_identity(settings.get("engine", "homotopy"), settings.get("bertini")),
        },
        sort_keys=True,
        default=str,
    )
    return hashlib.sha256(blob.encode()).hexdigest()[:20]


def entry(key: str) -> Path:
    """Where the run folder of a request is kept."""
    return cache_root() / "solves" / key


def lookup(key: str) -> Path | None:
    """The cached run folder of `key`, if complete."""
    folder = entry(key)
    return folder if (folder / "run.json").is_file() else None


def store(key: str, run_folder: Path) -> None:
    """Copy a finished run folder into the cache (atomically: copy, then rename)."""
    target = entry(key)
    if target.exists():
        return
    target.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(dir=target.parent, prefix=".tmp-"))
    try:
        shutil.copytree(run_folder, tmp, dirs_exist_ok=True, symlinks=True)
        tmp.rename(target)
    except OSError:
        shutil.rmtree(tmp, ignore_errors=True)  # another process stored it first: fine


def replay(key: str, cached: Path, work: Path, final: Path, record_update: dict) -> dict:
    """A new run folder from a cached one: same files, run.json saying where they came from."""
    shutil.copytree(cached, work, symlinks=True)
    record = json.loads((cached / "run.json").read_text())
    solved = record.get("created")
    record.update(record_update)
    record["cache"] = {"hit": True, "key": key, "solved": solved}
    tmp = work / ".run.json.tmp"
    tmp.write_text(json.dumps(record, indent=2, default=str) + "\n")
    tmp.replace(work / "run.json")
    work.rename(final)
    return record
