"""Result files: outputs checked before any work, and written atomically (complete or untouched).

A command checks its output folder or file with :func:`check_output_folder` /
:func:`check_output_file` before it starts, so a bad ``--out`` costs nothing and leaves nothing.
Writers replace files only once their new content is complete (:func:`atomic_paths`), and files
that belong together (a model's JSON and arrays) are replaced together, after all are written.
"""

from __future__ import annotations

import json
import math
import os
import tempfile
from contextlib import contextmanager
from pathlib import Path

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


@contextmanager
def atomic_paths(*paths):
    """Yield a temporary path beside each of ``paths``; when the block succeeds they replace
    ``paths`` (in the order given), when it fails every temporary file is removed and nothing
    is replaced."""
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
    finally:
        for tmp in temps:
            if os.path.exists(tmp):
                os.unlink(tmp)


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
