"""Write results atomically: a temporary file renamed into place, never a half-written file."""

from __future__ import annotations

import json
import os
import tempfile
from pathlib import Path

import pandas as pd


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


def write_csv(path: Path, frame: pd.DataFrame) -> None:
    """A CSV that loads straight into pandas or a spreadsheet, written atomically."""
    atomic_write_text(path, frame.to_csv(index=False))


def write_json(path: Path, data: dict) -> None:
    """Pretty JSON, written atomically."""
    atomic_write_text(path, json.dumps(data, indent=2, sort_keys=False, default=str) + "\n")
