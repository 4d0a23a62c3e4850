"""Files and folders: the cache folder, atomic writes, run folders (standard library only)."""

from __future__ import annotations

import datetime as dt
import json
import os
import secrets
import shutil
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from .errors import ParameterError


def files_hash(paths) -> str:
    """A short content hash of files (the code a cached derivation depends on)."""
    import hashlib

    h = hashlib.sha256()
    for path in paths:
        h.update(Path(path).read_bytes())
    return h.hexdigest()[:16]


def cache_root() -> Path:
    """$COTM_CACHE or ~/.cache/cotm-bertini: derived equations, generic sets, solves, sweeps."""
    root = os.environ.get("COTM_CACHE") or Path.home() / ".cache" / "cotm-bertini"
    return Path(root)


def umask() -> int:
    """The process's file-creation mask, read without changing it where Linux allows."""
    try:
        for line in Path("/proc/self/status").read_text().splitlines():
            if line.startswith("Umask:"):
                return int(line.split()[1], 8)
    except (OSError, ValueError, IndexError):
        pass
    mask = os.umask(0o022)  # elsewhere: set and restore at once
    os.umask(mask)
    return mask


def file_mode() -> int:
    """The mode an ordinary new file gets: 0666 less the umask (tempfile's files are 0600)."""
    return 0o666 & ~umask()


def folder_mode() -> int:
    """The mode an ordinary new folder gets: 0777 less the umask (tempfile's are 0700)."""
    return 0o777 & ~umask()


def temp_folder(prefix: str, parent: Path | None = None) -> Path:
    """A new empty folder with a unique name (tempfile.mkdtemp), with the umask's mode: its
    files may end up in a run folder, which must be as shareable as any other folder."""
    folder = Path(tempfile.mkdtemp(prefix=prefix, dir=parent))
    folder.chmod(folder_mode())
    return folder


def atomic_write_text(path: Path, text: str) -> None:
    """Write text to path via a temporary file in the same folder and an atomic rename."""
    atomic_write_bytes(path, text.encode())


def atomic_write_bytes(path: Path, data: bytes) -> None:
    """Write bytes to path via a temporary file in the same folder and an atomic rename."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        os.fchmod(fd, file_mode())  # as an ordinary file: mkstemp's 0600 hides it from a group
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def write_csv(path: Path, frame) -> None:
    """A CSV that loads straight into pandas or a spreadsheet, written atomically."""
    atomic_write_text(path, frame.to_csv(index=False))


def _cell(value) -> str:
    # As pandas writes them: shortest round-trip floats, NaN empty, True/False.
    if isinstance(value, float):
        return "" if value != value else repr(value)
    return str(value)


def columns_csv(columns: dict) -> str:
    """CSV text of a table given as columns (sequences of equal length), as pandas writes it."""
    import csv
    import io

    names = list(columns)
    lists = [columns[n].tolist() if hasattr(columns[n], "tolist") else columns[n] for n in names]
    rows = zip(*lists, strict=True)
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(names)
    writer.writerows([_cell(v) for v in row] for row in rows)
    return out.getvalue()


def write_json(path: Path, data: dict) -> None:
    """Pretty JSON, written atomically."""
    atomic_write_text(path, json.dumps(data, indent=2, sort_keys=False, default=str) + "\n")


def timestamp() -> str:
    """Local time with zone, to the second, for run records."""
    return dt.datetime.now().astimezone().isoformat(timespec="seconds")


def output_root(path: str | Path, option: str = "--out") -> Path:
    """A folder to write under: refuse a path that exists and is not a directory."""
    path = Path(path)
    if path.exists() and not path.is_dir():
        raise ParameterError(f"{option} {str(path)!r}: exists and is not a directory")
    for parent in path.parents:
        if parent.exists() and not parent.is_dir():
            raise ParameterError(f"{option} {str(path)!r}: {str(parent)!r} is not a directory")
    return path


def new_run_folder(root: Path) -> Path:
    """A new, not yet existing folder name under root: <YYYYmmdd-HHMMSS>-<random>."""
    stamp = dt.datetime.now().strftime("%Y%m%d-%H%M%S")
    root = output_root(root)
    root.mkdir(parents=True, exist_ok=True)
    return root / f"{stamp}-{secrets.token_hex(3)}"


def partial_name(final: Path) -> Path:
    """The hidden working name of a folder that is renamed to `final` when complete."""
    return final.with_name(f".partial-{final.name}")


@contextmanager
def new_folder(dest: str | Path) -> Iterator[Path]:
    """Build the new folder `dest` under its hidden partial name; renamed to `dest` only when
    the block ends without error, so a failure never leaves a half-written `dest`."""
    dest = Path(dest)
    if dest.exists():
        raise FileExistsError(f"{dest} exists: results are written to a new folder")
    work = partial_name(dest)
    shutil.rmtree(work, ignore_errors=True)
    work.mkdir(parents=True)
    yield work
    work.rename(dest)


def link_tree(source: Path, dest: Path) -> None:
    """Put a copy of the folder `source` at `dest` (which must not exist): each file hard-linked
    (no space used; the files stay if `source` is deleted), copied where linking fails."""

    def link(src: str, dst: str) -> None:
        try:
            os.link(src, dst)
        except OSError:  # another file system, or links not allowed
            shutil.copy2(src, dst)

    shutil.copytree(source, dest, copy_function=link, ignore=shutil.ignore_patterns(".*"))


def link_latest(root: Path, final: Path) -> None:
    """root/latest -> the newest run folder (replaced atomically; a real file is left alone)."""
    latest = root / "latest"
    if latest.is_symlink() or not latest.exists():
        tmp_link = root / f".latest-{final.name}"
        tmp_link.symlink_to(final.name)
        tmp_link.replace(latest)
