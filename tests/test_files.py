"""Result files: outputs checked before any work, strict JSON, files replaced only when complete."""

import math

import pytest

from colonsim.errors import ColonsimError
from colonsim.files import atomic_paths, check_output_file, check_output_folder, write_json


def test_output_folders_and_files_are_checked_without_writing(tmp_path):
    (tmp_path / "file").write_text("x")
    (tmp_path / "folder.json").mkdir()
    assert check_output_folder(tmp_path / "new" / "deeper") == tmp_path / "new" / "deeper"
    assert check_output_file(tmp_path / "new" / "pred.csv", suffixes=(".csv",)).name == "pred.csv"
    for check, path, message in (
            (check_output_folder, tmp_path / "file", "is an existing file, not a folder"),
            (check_output_folder, tmp_path / "file" / "sub", "is a file, not a folder"),
            (check_output_file, tmp_path / "folder.json", "is a folder"),
            (check_output_file, tmp_path / "file" / "x.json", "is a file, not a folder")):
        with pytest.raises(ColonsimError, match=message):
            check(path)
    with pytest.raises(ColonsimError, match="give a file ending in .png"):
        check_output_file(tmp_path / "plot.txt", suffixes=(".png",))
    assert sorted(p.name for p in tmp_path.rglob("*")) == ["file", "folder.json"]  # the probes left nothing


@pytest.mark.skipif(not __import__("os").path.isdir("/proc/self"), reason="needs /proc")
def test_a_place_nobody_may_write_is_refused():
    with pytest.raises(ColonsimError, match="cannot write in /proc"):
        check_output_folder("/proc/colonsim-test/out")


def test_json_is_strict_and_a_refused_document_leaves_the_file(tmp_path):
    path = tmp_path / "doc.json"
    write_json(path, {"a": 1})
    before = path.read_bytes()
    with pytest.raises(ColonsimError, match=r"doc.json: b\[1\].c is nan, which JSON cannot hold"):
        write_json(path, {"a": 2, "b": [0.5, {"c": math.nan}]})
    assert path.read_bytes() == before and [p.name for p in tmp_path.iterdir()] == ["doc.json"]


def test_files_written_together_are_replaced_together(tmp_path):
    a, b = tmp_path / "a.txt", tmp_path / "b.txt"
    a.write_text("old a")
    with pytest.raises(RuntimeError):
        with atomic_paths(a, b) as (ta, tb):
            ta.write_text("new a")
            raise RuntimeError("the second file could not be made")
    assert a.read_text() == "old a" and not b.exists() and [p.name for p in tmp_path.iterdir()] == ["a.txt"]
    with atomic_paths(a, b) as (ta, tb):
        ta.write_text("new a")
        tb.write_text("new b")
    assert a.read_text() == "new a" and b.read_text() == "new b"
