"""The durable store of a sweep's points: one append-only file, one framed record per point.

Each solved point is appended to `points.bin` as one record (a header with its length and CRC,
then the point's columns: numeric ones as raw numpy bytes, text ones as JSON), in a single
write, as soon as the parent process receives it. A `kill -9` cannot undo a completed write (it
is in the page cache), so a killed sweep loses at most the points in flight; a record cut short
by a crash fails its length or CRC check and is dropped, with everything after it, when the file
is read, and the file is truncated there before the next append. The file is flushed to disk
(fsync) in batches, at most every `SYNC_SECONDS`, and when the sweep's points are all stored.
A point stored twice (two processes on one folder) is read once: the first record wins.

Sweep folders of earlier versions kept one `points/NNNNN.csv` per point: those are read too.
"""

from __future__ import annotations

import json
import os
import struct
import time
import zlib
from pathlib import Path

import numpy as np

STORE_FILE = "points.bin"
LEGACY_FOLDER = "points"  # one CSV per point, written by earlier versions
SYNC_SECONDS = 2.0
_MAGIC = b"CTP1"
_FRAME = struct.Struct("<4sQI")  # magic, payload length, CRC-32 of the payload
_HEAD = struct.Struct("<I")  # length of the payload's JSON header


def encode(index: int, columns: dict[str, np.ndarray]) -> bytes:
    """One framed record: a point's index and its columns."""
    rows = len(next(iter(columns.values()))) if columns else 0
    spec, text, blobs = [], {}, []
    for name, values in columns.items():
        arr = np.asarray(values)
        if arr.dtype.kind in "biuf":
            arr = np.ascontiguousarray(arr, dtype=arr.dtype.newbyteorder("<"))
            spec.append([name, arr.dtype.str])
            blobs.append(arr.tobytes())
        else:
            spec.append([name, "text"])
            text[name] = [v if type(v) is str else _jsonable(v) for v in arr.tolist()]
    head = json.dumps({"index": int(index), "rows": rows, "columns": spec, "text": text}).encode()
    payload = b"".join([_HEAD.pack(len(head)), head, *blobs])
    return _FRAME.pack(_MAGIC, len(payload), zlib.crc32(payload)) + payload


def _jsonable(value):
    if value is None or isinstance(value, str | bool | int):
        return value
    if isinstance(value, float):
        return None if value != value else value
    return str(value)


def decode(payload: bytes) -> tuple[int, dict[str, np.ndarray]]:
    """The index and columns of one record's payload (the inverse of `encode`)."""
    (size,) = _HEAD.unpack_from(payload)
    head = json.loads(payload[_HEAD.size : _HEAD.size + size])
    rows, offset = head["rows"], _HEAD.size + size
    columns: dict[str, np.ndarray] = {}
    for name, kind in head["columns"]:
        if kind == "text":
            columns[name] = np.array(head["text"][name] + [None], dtype=object)[:-1]
            continue
        dtype = np.dtype(kind)
        columns[name] = np.frombuffer(payload, dtype, rows, offset).astype(dtype.newbyteorder("="))
        offset += rows * dtype.itemsize
    return head["index"], columns


def read_records(path: Path) -> tuple[dict[int, dict[str, np.ndarray]], int]:
    """Every complete record of the file at `path` (first one per index) and the byte offset
    where the complete records end (a torn or damaged tail starts there)."""
    try:
        data = Path(path).read_bytes()
    except FileNotFoundError:
        return {}, 0
    points: dict[int, dict[str, np.ndarray]] = {}
    offset = 0
    while offset + _FRAME.size <= len(data):
        magic, length, crc = _FRAME.unpack_from(data, offset)
        start = offset + _FRAME.size
        payload = data[start : start + length]
        if magic != _MAGIC or len(payload) != length or zlib.crc32(payload) != crc:
            break
        index, columns = decode(payload)
        points.setdefault(index, columns)
        offset = start + length
    return points, offset


class PointStore:
    """The points of one sweep folder: on disk (append-only) and in memory."""

    def __init__(self, folder: Path):
        self.folder = Path(folder)
        self.path = self.folder / STORE_FILE
        self.points, end = read_records(self.path)
        if self.path.is_file() and self.path.stat().st_size > end:
            os.truncate(self.path, end)  # a torn last record: dropped, the next append follows
        self.texts: dict[int, str] = {}  # points' sweep.csv lines, when the solver wrote them
        self._fd: int | None = None
        self._synced = time.monotonic()
        for index, columns in _legacy_points(self.folder, set(self.points)).items():
            self.append(index, columns)

    def __contains__(self, index: int) -> bool:
        return index in self.points

    def __len__(self) -> int:
        return len(self.points)

    def append(self, index: int, columns: dict[str, np.ndarray], text: str | None = None) -> None:
        """Store one point durably (one write) and keep it in memory (with its sweep.csv lines
        `text`, if given: those are not stored on disk)."""
        if self._fd is None:
            self.folder.mkdir(parents=True, exist_ok=True)
            self._fd = os.open(self.path, os.O_WRONLY | os.O_APPEND | os.O_CREAT, 0o666)
        record = memoryview(encode(index, columns))
        while record:
            record = record[os.write(self._fd, record) :]
        if index not in self.points:
            self.points[index] = columns
            if text is not None:
                self.texts[index] = text
        if time.monotonic() - self._synced > SYNC_SECONDS:
            self.sync()

    def sync(self) -> None:
        """Flush what was appended to the disk."""
        if self._fd is not None:
            os.fsync(self._fd)
        self._synced = time.monotonic()

    def close(self) -> None:
        """Flush and close the file (the points stay in memory)."""
        if self._fd is not None:
            self.sync()
            os.close(self._fd)
            self._fd = None

    def __enter__(self) -> PointStore:
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def stored_indices(folder: Path) -> set[int]:
    """The indices of the points stored in a sweep folder (read-only: safe while it grows)."""
    points, _ = read_records(Path(folder) / STORE_FILE)
    return set(points) | set(_legacy_files(Path(folder)))


def _legacy_files(folder: Path) -> dict[int, Path]:
    old = folder / LEGACY_FOLDER
    if not old.is_dir():
        return {}
    return {int(p.stem): p for p in old.glob("*.csv") if p.stem.isdigit()}


def _legacy_points(folder: Path, skip: set[int]) -> dict[int, dict[str, np.ndarray]]:
    """The points of an earlier version's sweep folder (one CSV each) not in `skip`."""
    files = {i: p for i, p in _legacy_files(folder).items() if i not in skip}
    if not files:
        return {}
    from ..analysis.classify import read_table

    out = {}
    for index, path in sorted(files.items()):
        table = read_table(path)
        columns = {c: table[c].to_numpy() for c in table.columns}
        if "lost_paths" in columns:
            columns["lost_paths"] = table["lost_paths"].to_numpy(float, na_value=np.nan)
        out[index] = columns
    return out
