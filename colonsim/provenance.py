"""Which code produced a result: the colonsim version and, in a git checkout, the commit.

Recorded in every result document (material.json, summary.json, surrogate JSON) so that a number
can be traced to the code and the assumptions it came from (README: how to cite).
"""

from __future__ import annotations

import functools
import os
import subprocess
from pathlib import Path


@functools.lru_cache(maxsize=1)
def code_version() -> dict:
    """``{"colonsim_version": ..., "git_commit": ... or None}``; "+modified" marks uncommitted changes."""
    from colonsim import __version__

    root = Path(__file__).resolve().parents[1]
    commit = None
    # `git status` refreshes the index and takes .git/index.lock to do it, which can make the user's
    # own `git commit` in that checkout fail at that moment; GIT_OPTIONAL_LOCKS=0 reads without it
    env = {**os.environ, "GIT_OPTIONAL_LOCKS": "0"}
    if (root / ".git").exists():
        try:
            commit = subprocess.run(["git", "-C", str(root), "rev-parse", "HEAD"], capture_output=True, text=True,
                                    timeout=5, check=True, env=env, stdin=subprocess.DEVNULL).stdout.strip() or None
            dirty = subprocess.run(["git", "-C", str(root), "status", "--porcelain", "--untracked-files=no"],
                                   capture_output=True, text=True, timeout=5, check=True, env=env,
                                   stdin=subprocess.DEVNULL).stdout.strip()
            if commit and dirty:
                commit += "+modified"
        except (OSError, subprocess.SubprocessError):
            commit = None
    return {"colonsim_version": __version__, "git_commit": commit}
