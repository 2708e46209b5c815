"""Result files: outputs checked before any work, and written atomically (complete or untouched).

A command checks its output folder or file with :func:`check_output_folder` /
:func:`check_output_file` before it starts, so a bad ``--out`` costs nothing and leaves nothing.
Writers replace files only once their new content is complete (:func:`atomic_paths`), and files
that belong together (a model's JSON and arrays) are replaced together, after all are written.
A command that writes a set of files and folders writes them into a staging folder and swaps
them in only when every one is complete (:func:`output_set`): a full disk, a file-size limit or
a read-only folder leaves the earlier set byte-identical. A write that fails says why in one
line (:func:`write_failure`).
"""

from __future__ import annotations

import errno
import json
import math
import os
import shutil
import tempfile
from contextlib import contextmanager
from pathlib import Path

STAGING_PREFIX = ".colonsim-staging-"

# errno -> (what happened, what to do); the causes a user can meet and act on
_WRITE_FAILURES = {
    errno.ENOSPC: ("the disk is full", "free some space or choose --out on another disk"),
    errno.EDQUOT: ("the disk quota is used up", "free some space or choose --out on another disk"),
    errno.EFBIG: ("a file reached the file-size limit (ulimit -f)", "raise the limit (ulimit -f unlimited)"),
    errno.EROFS: ("the file system is read-only", "choose --out on a writable disk"),
    errno.EACCES: ("permission denied", "choose a folder you may write to"),
    errno.EPERM: ("operation not permitted", "choose a folder you may write to"),
    errno.EISDIR: ("a folder stands where a file goes", "move that folder away or choose another --out"),
    errno.ENOTDIR: ("a file stands where a folder goes", "move that file away or choose another --out"),
    errno.ENOTEMPTY: ("a folder stands where a file goes", "move that folder away or choose another --out"),
    errno.EIO: ("the disk reported an input/output error", "check the disk and choose another --out"),
}

from colonsim.errors import ColonsimError


def _umask() -> int:
    mask = os.umask(0o022)  # reading the umask means setting it; put it straight back
    os.umask(mask)
    return mask


def _existing_ancestor(path: Path) -> Path:
    """``path`` itself or the nearest of its parents that exists (a folder or not)."""
    path = Path(os.path.abspath(path))
    while not (path.exists() or path.is_symlink()) and path != path.parent:
        path = path.parent
    return path


def _named(option, path) -> str:
    return f"{option} {path}" if option else str(path)


def _check_writable(path: Path, option: str):
    """Refuse ``path`` (a folder to create or fill) when it lies under a file or where this user
    cannot create files. Probes by creating and removing a temporary file: permission bits
    say nothing for root, read-only file systems or /proc."""
    base = _existing_ancestor(path)
    if not base.is_dir():
        raise ColonsimError(f"{_named(option, path)}: {base} is a file, not a folder; choose a path in a folder")
    try:
        fd, probe = tempfile.mkstemp(prefix=".colonsim-probe-", dir=base)
    except OSError as exc:
        raise ColonsimError(f"{_named(option, path)}: cannot write in {base} ({exc.strerror or exc}); "
                            "choose a folder you may write to") from None
    os.close(fd)
    os.unlink(probe)


def check_output_folder(path, option="--out") -> Path:
    """``path`` as a results folder: new (created later) or an existing folder, writable.

    Raises
    ------
    ColonsimError
        An existing file, a path under a file, or a place this user may not write.
    """
    path = Path(path)
    if (path.exists() or path.is_symlink()) and not path.is_dir():
        raise ColonsimError(f"{_named(option, path)} is an existing file, not a folder; give a new folder or the "
                            "folder of an earlier run")
    _check_writable(path, option)
    return path


def check_output_file(path, option="-o", suffixes=None) -> Path:
    """``path`` as a file to write: not a folder, in a writable place, with one of ``suffixes``."""
    path = Path(path)
    if path.is_dir():
        raise ColonsimError(f"{_named(option, path)} is a folder; give a file name (in that folder, for example)")
    if suffixes and path.suffix.lower() not in suffixes:
        raise ColonsimError(f"{_named(option, path)}: give a file ending in {', '.join(suffixes)}")
    _check_writable(path.parent, option)
    return path


def write_failure(exc: OSError, target, unchanged=True) -> ColonsimError:
    """One line for a write to ``target`` that failed with ``exc``: the cause and what to do
    (``unchanged``: say that the earlier files there were left as they were)."""
    cause, fix = _WRITE_FAILURES.get(exc.errno, (exc.strerror or type(exc).__name__, "choose another --out"))
    kept = "; earlier results there are unchanged" if unchanged else ""
    shown = target if isinstance(target, str) else _final(target)
    return ColonsimError(f"cannot write {shown}: {cause}; {fix}{kept}")


def os_failure(exc: OSError) -> ColonsimError:
    """One line for an OSError that reached the command line: the cause, the file, what to do."""
    if exc.errno in _WRITE_FAILURES:
        return write_failure(exc, _final(exc.filename) if exc.filename else "a result file", unchanged=False)
    where = f" ({_final(exc.filename)})" if exc.filename else ""
    return ColonsimError(f"{exc.strerror or type(exc).__name__}{where}; check the file, the disk and the options")


def _final(path) -> Path:
    """Where a file being written into a staging folder (:func:`output_set`) will end up."""
    path = Path(path)
    return Path(*[p for p in path.parts if not p.startswith(STAGING_PREFIX)])


@contextmanager
def atomic_paths(*paths):
    """Yield a temporary path beside each of ``paths``; when the block succeeds they replace
    ``paths`` (in the order given), when it fails every temporary file is removed and nothing
    is replaced. A failed write (disk full, read-only, ...) becomes a one-line
    :class:`ColonsimError` (:func:`write_failure`)."""
    paths = [Path(p) for p in paths]
    temps = []
    try:
        for path in paths:
            path.parent.mkdir(parents=True, exist_ok=True)
            fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=path.suffix, dir=path.parent)
            os.close(fd)
            temps.append(tmp)
        yield [Path(t) for t in temps]
        mode = 0o666 & ~_umask()  # mkstemp makes 0600; give the mode a plain open() would
        for tmp in temps:
            os.chmod(tmp, mode)
        for tmp, path in zip(temps, paths):
            os.replace(tmp, path)
    except OSError as exc:
        raise write_failure(exc, " and ".join(str(_final(p)) for p in paths)) from None
    finally:
        for tmp in temps:
            if os.path.exists(tmp):
                os.unlink(tmp)


def _kind(path: Path) -> str | None:
    if path.is_symlink():
        return "link"
    return "folder" if path.is_dir() else "file" if path.exists() else None


def check_entries(folder: Path, entries: dict):
    """Refuse (before any work or swap) an entry of ``folder`` whose kind differs from what the
    set puts there: a folder where a results file goes, or the reverse."""
    for name, kind in entries.items():
        found = _kind(folder / name)
        if found is not None and found != kind:
            raise ColonsimError(f"cannot write {folder / name}: a {found} stands where the results {kind} goes; "
                                f"move it away or choose another --out")


def _swap_in(stage: Path, folder: Path):
    """Move every entry of ``stage`` into ``folder``: a file replaces its namesake in one step, a
    folder replaces its namesake as a whole (the old one is moved into ``stage`` and removed with it)."""
    entries = {p.name: "folder" if p.is_dir() else "file" for p in stage.iterdir()}
    check_entries(folder, entries)
    retired = Path(tempfile.mkdtemp(prefix=".retired-", dir=stage))
    for name, kind in sorted(entries.items(), key=lambda e: e[1] == "file"):  # folders first, files last
        target = folder / name
        if kind == "folder" and target.is_dir():
            os.rename(target, retired / name)
            try:
                os.rename(stage / name, target)
            except OSError:
                os.rename(retired / name, target)
                raise
        else:
            os.replace(stage / name, target)


@contextmanager
def output_set(folder, files=(), folders=()):
    """Yield a staging folder for the files of one command's results in ``folder``.

    The staging folder lies inside ``folder`` (so on the same disk, where a rename is one step)
    under a hidden name. When the block succeeds, each of its entries replaces its namesake in
    ``folder``: a file in one step, a folder as a whole. When the block fails (a full disk, a
    file-size limit, an error in the work itself), the staging folder is removed and ``folder``
    keeps its earlier files byte-identical; an OSError becomes one line (:func:`write_failure`).
    ``files`` and ``folders`` name the entries the set will hold, checked before the block runs
    (a folder standing where a results file goes is refused before any work).
    """
    folder = Path(folder)
    created = not folder.exists()
    stage = None
    try:
        if created:
            folder.mkdir(parents=True)
        check_entries(folder, {**{n: "file" for n in files}, **{n: "folder" for n in folders}})
        stage = Path(tempfile.mkdtemp(prefix=STAGING_PREFIX, dir=folder))
        os.chmod(stage, 0o777 & ~_umask())
        yield stage
        _swap_in(stage, folder)
    except OSError as exc:
        raise write_failure(exc, folder) from None
    finally:
        if stage is not None:
            shutil.rmtree(stage, ignore_errors=True)
        if created and folder.is_dir() and not any(folder.iterdir()):
            folder.rmdir()


@contextmanager
def atomic_path(path):
    """Yield a temporary path beside ``path``; on success it replaces ``path`` in one step."""
    with atomic_paths(path) as (tmp,):
        yield tmp


def _builtin(value):
    """JSON encoder fallback for numpy scalars and arrays."""
    import numpy as np

    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    raise TypeError(f"cannot write {type(value).__name__} to JSON")


def _non_finite(value, where="document"):
    """(where, value) of the first NaN or infinite number in a JSON-able ``value``, or None."""
    import numpy as np

    if isinstance(value, dict):
        items = ((f"{where}.{k}", v) for k, v in value.items())
    elif isinstance(value, (list, tuple, np.ndarray)):
        items = ((f"{where}[{i}]", v) for i, v in enumerate(value))
    elif isinstance(value, (float, np.floating)) and not math.isfinite(value):
        return where.removeprefix("document."), float(value)
    else:
        return None
    return next((hit for hit in (_non_finite(v, w) for w, v in items) if hit), None)


def json_text(document, name="JSON") -> str:
    """``document`` as indented strict JSON (no NaN or Infinity tokens, which standard readers refuse).

    Raises
    ------
    ColonsimError
        Naming the first non-finite value and where it is.
    """
    try:
        return json.dumps(document, indent=2, allow_nan=False, default=_builtin) + "\n"
    except ValueError:
        where, value = _non_finite(document) or ("?", math.nan)
        raise ColonsimError(f"cannot write {name}: {where} is {value}, which JSON cannot hold; nothing was "
                            "written (check the inputs that led to it)") from None


def write_json(path, document):
    """Write ``document`` as strict JSON (UTF-8) atomically; a NaN or infinity is an error."""
    text = json_text(document, Path(path).name)
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding="utf-8")


def write_csv(path, frame, **kwargs):
    """Write a pandas DataFrame as CSV atomically."""
    with atomic_path(path) as tmp:
        frame.to_csv(tmp, index=False, **kwargs)


def save_figure(fig, path, dpi=150):
    """Save a matplotlib figure atomically (figures are built with ``matplotlib.figure.Figure``,
    so no GUI backend is involved and nothing needs closing)."""
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=dpi, bbox_inches="tight")
