"""Which code produced a result: the colonsim version and, in a git checkout, the commit.

Recorded in every result document (material.json, summary.json, surrogate JSON) so that a number
can be traced to the code and the assumptions it came from (README: how to cite).
"""

from __future__ import annotations

import functools
import subprocess
from pathlib import Path


@functools.lru_cache(maxsize=1)
def code_version() -> dict:
    """``{"colonsim_version": ..., "git_commit": ... or None}``; "+modified" marks uncommitted changes."""
    from colonsim import __version__

    root = Path(__file__).resolve().parents[1]
    commit = None
    if (root / ".git").exists():
        try:
            commit = subprocess.run(["git", "-C", str(root), "rev-parse", "HEAD"], capture_output=True, text=True,
                                    timeout=5, check=True).stdout.strip() or None
            dirty = subprocess.run(["git", "-C", str(root), "status", "--porcelain", "--untracked-files=no"],
                                   capture_output=True, text=True, timeout=5, check=True).stdout.strip()
            if commit and dirty:
                commit += "+modified"
        except (OSError, subprocess.SubprocessError):
            commit = None
    return {"colonsim_version": __version__, "git_commit": commit}
