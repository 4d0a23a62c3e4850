"""Write results atomically: a temporary file renamed into place, never a half-written file."""

from __future__ import annotations

import datetime as dt
import json
import os
import secrets
import tempfile
from pathlib import Path


def atomic_write_text(path: Path, text: str) -> None:
    """Write text to path via a temporary file in the same folder and an atomic rename."""
    path = Path(path)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "w") as fh:
            fh.write(text)
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def write_text(path: Path, text: str) -> None:
    """Text, written atomically."""
    atomic_write_text(path, text)


def write_csv(path: Path, frame) -> None:
    """A CSV that loads straight into pandas or a spreadsheet, written atomically."""
    atomic_write_text(path, frame.to_csv(index=False))


def write_json(path: Path, data: dict) -> None:
    """Pretty JSON, written atomically."""
    atomic_write_text(path, json.dumps(data, indent=2, sort_keys=False, default=str) + "\n")


def new_run_folder(root: Path) -> tuple[Path, Path]:
    """A (working, final) pair of folder names under root; work happens in a hidden folder."""
    stamp = dt.datetime.now().strftime("%Y%m%d-%H%M%S")
    name = f"{stamp}-{secrets.token_hex(3)}"
    root.mkdir(parents=True, exist_ok=True)
    return root / f".partial-{name}", root / name


def link_latest(root: Path, final: Path) -> None:
    """root/latest -> the newest run folder (replaced atomically)."""
    latest = root / "latest"
    if latest.is_symlink() or not latest.exists():
        tmp_link = root / f".latest-{final.name}"
        tmp_link.symlink_to(final.name)
        tmp_link.replace(latest)
