"""Every code block of the README and the how-to guides runs, as scikit-fem runs its examples.

A ``bash`` block's commands run in a fresh folder per document (``colonsim ...`` through the
command line's ``main``, exit code 0 required), a ``python`` block is executed there. A block
preceded by ``<!-- check: options -->`` is one whose run is expensive (an insertion at the default
mesh, a full calibration, a sweep, the demo, a cluster): each of its ``colonsim`` commands is
parsed by the real parser instead (every option must exist and every value parse), a
``python FILE`` must name a file of the repository, a ``python -m validation.NAME`` a tool whose
``--help`` lists every option given, ``pip install`` extras must exist in
pyproject.toml, and its Python is compiled. Blocks without a language (printed output, file
contents) are not code. The folder holds what the commands name: the bundled data under
``data/``, a force-displacement ``test.csv``, and a SYNTHETIC sweep table where a sweep's
``results.parquet`` is named (regression machinery, not physics).
"""

import re
import shlex
import shutil
import sys
from pathlib import Path

import pytest

from colonsim.cli import build_parser, main

ROOT = Path(__file__).resolve().parents[1]
DOCUMENTS = [ROOT / "README.md", *sorted(p for p in (ROOT / "docs" / "how-to").glob("*.md") if p.name != "index.md")]
OPTIONS_ONLY = "<!-- check: options -->"
FENCE = re.compile(r"^(?P<marker><!-- check: options -->\n)?```(?P<lang>[a-z]*)[^\n]*\n(?P<code>.*?)^```$", re.M | re.S)
SYNTHETIC_TABLES = ("colonsim_results/sweep_thesis/results.parquet",)

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib


def code_blocks(path):
    """(language, code, options_only) of every fenced block of ``path`` with a language."""
    return [(m["lang"], m["code"], bool(m["marker"])) for m in FENCE.finditer(path.read_text(encoding="utf-8"))
            if m["lang"]]


def commands(code):
    """The shell commands of a block: continuation lines joined, comments dropped, split at &&."""
    joined = code.replace("\\\n", " ")
    out = []
    for line in joined.splitlines():
        words = shlex.split(line, comments=True)
        while words:
            if "&&" in words:
                k = words.index("&&")
                out.append(words[:k])
                words = words[k + 1:]
            else:
                out.append(words)
                words = []
    return out


def _extras():
    return set(tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["optional-dependencies"])


def check_pip(words):
    for word in words[2:]:
        extras = re.fullmatch(r"\.?(?:\[(.*)\])?", word.strip("\"'"))
        if word.startswith("-"):
            continue
        assert extras, f"pip installs {word!r}: the docs install colonsim from the checkout (. or .[extra])"
        unknown = set(filter(None, (extras[1] or "").split(","))) - _extras()
        assert not unknown, f"pip install names extras pyproject.toml does not define: {unknown}"


def check_tool_options(module, args):
    """``python -m validation.NAME ARGS``: the module exists and its help names every ``--option`` given."""
    import contextlib
    import importlib
    import io

    assert module.startswith("validation.") and (ROOT / (module.replace(".", "/") + ".py")).is_file(), \
        f"python -m {module}: not a tool of the repository (validation/)"
    sys.path.insert(0, str(ROOT))
    try:
        tool = importlib.import_module(module)
    finally:
        sys.path.remove(str(ROOT))
    text = io.StringIO()
    with contextlib.redirect_stdout(text), pytest.raises(SystemExit):
        tool.main(["--help"])
    unknown = [a.split("=")[0] for a in args if a.startswith("--") and a.split("=")[0] not in text.getvalue()]
    assert not unknown, f"python -m {module}: options its --help does not list: {unknown}"


def run_command(words, options_only):
    program = words[0]
    if program == "colonsim":
        if options_only:
            try:
                build_parser().parse_args(words[1:])
            except SystemExit as exit_:  # --help or a usage error
                raise AssertionError(f"{shlex.join(words)}: the parser exits ({exit_.code})")
        else:
            assert main(words[1:]) == 0, shlex.join(words)
    elif program == "pip":
        check_pip(words)
    elif program == "python" and words[1:3] == ["-m", "pytest"]:
        pass  # the test command: it is what runs this file
    elif program == "python" and words[1:2] == ["-m"]:
        assert options_only, f"{shlex.join(words)}: a tool of the repository in a block that runs; mark it options-only"
        check_tool_options(words[2], words[3:])
    elif program == "python":
        assert options_only, f"{shlex.join(words)}: a benchmark or script in a block that runs; mark it options-only"
        assert (ROOT / words[1]).is_file(), f"{words[1]} does not exist"
    elif program == "dask":
        assert options_only, "a Dask cluster cannot start in a test; mark the block options-only"
    else:
        raise AssertionError(f"{shlex.join(words)}: a command this test does not know; add a rule for it")


@pytest.fixture
def workspace(tmp_path, monkeypatch):
    from colonsim.data import BUNDLED_MANIFEST
    from colonsim.surrogate.synthetic import synthetic_sweep

    (tmp_path / "data").symlink_to(ROOT / "data", target_is_directory=True)
    shutil.copy(BUNDLED_MANIFEST.parent / "specimen_01.csv", tmp_path / "test.csv")
    for name in SYNTHETIC_TABLES:
        (tmp_path / name).parent.mkdir(parents=True)
        synthetic_sweep(design="grid", repeats=2).to_parquet(tmp_path / name)
    monkeypatch.chdir(tmp_path)
    return tmp_path


def test_the_documents_have_code():
    assert all(code_blocks(path) for path in DOCUMENTS), "a how-to guide without a code block"
    assert any(not options for path in DOCUMENTS for _, _, options in code_blocks(path)), "no block runs"


@pytest.mark.parametrize("document", DOCUMENTS, ids=lambda p: str(p.relative_to(ROOT)))
def test_code_blocks_run(document, workspace, capsys):
    for lang, code, options_only in code_blocks(document):
        if lang in ("bash", "sh", "shell"):
            for words in commands(code):
                run_command(words, options_only)
        elif lang == "python":
            compiled = compile(code, f"{document.name} block", "exec")
            if not options_only:
                exec(compiled, {"__name__": "__doc_block__"})
        elif lang not in ("console", "toml", "json", "csv", "text"):
            raise AssertionError(f"{document.name}: a ```{lang} block this test does not know how to check")
    capsys.readouterr()


def test_an_unknown_option_in_a_block_fails():
    """The options-only check can fail: a misspelt option is caught, as is a missing script."""
    with pytest.raises(Exception):
        run_command(shlex.split("colonsim insert --segment rsj --scoop sdc"), options_only=True)
    with pytest.raises(AssertionError):
        run_command(shlex.split("python benchmarks/no_such_benchmark.py"), options_only=True)
    with pytest.raises(AssertionError):
        check_pip(shlex.split('pip install -e ".[no_such_extra]"'))
    with pytest.raises(AssertionError, match="--no-such-option"):
        run_command(shlex.split("python -m validation.report --sweep S --no-such-option"), options_only=True)
    run_command(shlex.split("python -m validation.report --sweep S --markdown-only"), options_only=True)
    run_command(shlex.split("colonsim insert --segment rsj --scope sdc"), options_only=True)
