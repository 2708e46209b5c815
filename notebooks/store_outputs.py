"""Store the outputs the documentation site shows: run notebooks at reduced size and keep their outputs.

From the repository's root (nbclient and Pillow come with the test extra)::

    NUMBA_NUM_THREADS=1 python notebooks/store_outputs.py notebooks/0*.ipynb

Each notebook runs top to bottom in its own folder with ``COLONSIM_NOTEBOOK_SIZE=reduced`` and the
default output folder (``notebooks/output/``, git-ignored), so the paths it prints are relative and
name no machine. The cells' execution timestamps are dropped and every figure is stored as a
256-colour PNG (a third of the size of matplotlib's, the same picture), so that the committed
notebooks stay small. ``tests/test_docs_pages.py`` fails on a stored output that names a commit or
a machine's path; docs/tutorials/index.md names the machine and the date of the stored run.
"""

from __future__ import annotations

import argparse
import base64
import io
import os
import sys
import time
from pathlib import Path


def shrink_png(data: str) -> str:
    """A base64 PNG as a 256-colour PNG on white (base64), or as it was when that is not smaller."""
    from PIL import Image

    image = Image.open(io.BytesIO(base64.b64decode(data))).convert("RGBA")
    flat = Image.alpha_composite(Image.new("RGBA", image.size, "white"), image).convert("RGB")
    out = io.BytesIO()
    flat.quantize(colors=256, method=Image.Quantize.MEDIANCUT, dither=Image.Dither.NONE).save(out, "PNG", optimize=True)
    small = base64.b64encode(out.getvalue()).decode("ascii")
    return small if len(small) < len(data) else data


def tidy(notebook) -> None:
    """Drop the cells' execution timestamps and shrink every stored figure, in place."""
    for cell in notebook.cells:
        cell.metadata.pop("execution", None)
        for output in cell.get("outputs", []):
            data = output.get("data", {})
            if "image/png" in data:
                data["image/png"] = shrink_png(data["image/png"])
    notebook.metadata.pop("widgets", None)


def store(path: Path, timeout: int) -> float:
    """Run the notebook at ``path`` at reduced size and write it back with its outputs; its run time in s."""
    import nbformat
    from nbclient import NotebookClient

    notebook = nbformat.read(path, as_version=4)
    os.environ["COLONSIM_NOTEBOOK_SIZE"] = "reduced"
    os.environ.pop("COLONSIM_NOTEBOOK_OUTPUT", None)  # the default, relative to the notebook's folder
    # the kernel's "python" is this interpreter (a virtual environment's, without activating it)
    os.environ["PATH"] = str(Path(sys.executable).parent) + os.pathsep + os.environ.get("PATH", "")
    start = time.perf_counter()
    NotebookClient(notebook, timeout=timeout, kernel_name="python3",
                   resources={"metadata": {"path": str(path.parent)}}).execute()
    tidy(notebook)
    nbformat.write(notebook, path)
    return time.perf_counter() - start


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("notebooks", nargs="+", type=Path, help="the notebooks to run and store")
    parser.add_argument("--timeout", type=int, default=1800, help="seconds a cell may take (default 1800)")
    args = parser.parse_args(argv)
    missing = [str(p) for p in args.notebooks if not p.is_file()]
    if missing:
        print(f"error: no notebook {', '.join(missing)}; give paths such as notebooks/01_calibrate.ipynb",
              file=sys.stderr)
        return 2
    for path in args.notebooks:
        print(f"{path.name}: {store(path.resolve(), args.timeout):.0f} s", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
