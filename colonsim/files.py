"""Atomic file writes: a result file is either complete or untouched, never half written."""

from __future__ import annotations

import json
import os
import tempfile
from contextlib import contextmanager
from pathlib import Path


def _umask() -> int:
    mask = os.umask(0o022)  # reading the umask means setting it; put it straight back
    os.umask(mask)
    return mask


@contextmanager
def atomic_path(path):
    """Yield a temporary path beside ``path``; on success it replaces ``path`` in one step."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=path.suffix, dir=path.parent)
    os.close(fd)
    try:
        yield Path(tmp)
        os.chmod(tmp, 0o666 & ~_umask())  # mkstemp makes 0600; give the mode a plain open() would
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


def _builtin(value):
    """JSON encoder fallback for numpy scalars and arrays."""
    import numpy as np

    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    raise TypeError(f"cannot write {type(value).__name__} to JSON")


def write_json(path, document):
    """Write ``document`` as indented JSON (UTF-8) atomically; NaN/inf are refused."""
    with atomic_path(path) as tmp:
        tmp.write_text(json.dumps(document, indent=2, allow_nan=False, default=_builtin) + "\n", encoding="utf-8")


def write_csv(path, frame, **kwargs):
    """Write a pandas DataFrame as CSV atomically."""
    with atomic_path(path) as tmp:
        frame.to_csv(tmp, index=False, **kwargs)


def save_figure(fig, path, dpi=150):
    """Save a matplotlib figure atomically (figures are built with ``matplotlib.figure.Figure``,
    so no GUI backend is involved and nothing needs closing)."""
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=dpi, bbox_inches="tight")


def check_output_folder(path, option="--out"):
    """Refuse, before any work, an output folder that cannot be one: an existing regular file, a
    path through a file, or a place without write permission."""
    from colonsim.errors import ColonsimError

    path = Path(path)
    if path.exists() and not path.is_dir():
        raise ColonsimError(f"{option} {path} is an existing file, not a folder; choose a folder path")
    existing = path
    while not existing.exists():
        existing = existing.parent
    if not existing.is_dir():
        raise ColonsimError(f"{option} {path}: {existing} is a file, so no folder can be made under it; "
                            "choose another path")
    if not os.access(existing, os.W_OK | os.X_OK):
        raise ColonsimError(f"{option} {path}: no permission to write in {existing}; choose another path")
