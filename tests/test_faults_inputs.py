"""Fault corpus, inputs: FIFOs, devices, folders, oversized files and other encodings given where a
file is read. Every case: exit code 2, one line naming what the path is and what to give, within
seconds (a FIFO must never be opened for reading: that blocks until a writer comes), nothing
written. The CLI runs in-process under an alarm, so a hang fails the case instead of the suite.
"""

import codecs
import json
import os
import signal
import time
from pathlib import Path

import pytest

from colonsim.cli import main
from colonsim.data import TENSILE_DIR
from colonsim.errors import ColonsimError
from colonsim.inputs import check_input, decode_text, read_input
from colonsim.insertion.engine.material import REFERENCE_MATERIAL_PATH
from colonsim.limits import DOCUMENT_MAX_BYTES, TEXT_FILE_MAX_BYTES

CURVE = TENSILE_DIR / "specimen_01.csv"
ANATOMY = Path(__file__).resolve().parents[1] / "data" / "anatomy" / "sigmoid_loop.csv"
SWEEP = '[sweep]\nname = "enc"\n[[grid]]\nsegment = "straight"\nscope = ["utc", "sdc"]\n'
needs_dev = pytest.mark.skipif(not Path("/dev/zero").exists(), reason="needs /dev/zero")


class Hang(Exception):
    pass


@pytest.fixture
def alarm():
    """Fail a case that blocks for more than 15 s (the issue's bound) instead of hanging the suite."""
    def ring(signum, frame):
        raise Hang("blocked for 15 s")

    previous = signal.signal(signal.SIGALRM, ring)
    signal.alarm(15)
    yield
    signal.alarm(0)
    signal.signal(signal.SIGALRM, previous)


@pytest.fixture(scope="module")
def ws(tmp_path_factory):
    ws = tmp_path_factory.mktemp("inputs")
    os.mkfifo(ws / "fifo")
    (ws / "folder").mkdir()
    (ws / "sweep_fifo.toml").write_text(SWEEP.replace('segment = "straight"', 'segment = "patient"')
                                        + f'centerline = "{ws / "fifo"}"\n')
    (ws / "sweep_zero.toml").write_text(SWEEP.replace('segment = "straight"', 'segment = "patient"')
                                        + 'centerline = "/dev/zero"\n')
    (ws / "sweep_utf16.toml").write_bytes(SWEEP.encode("utf-16"))  # a byte-order mark declares it
    (ws / "sweep_utf16_nobom.toml").write_bytes(SWEEP.encode("utf-16-le"))
    (ws / "sweep_bom.toml").write_bytes(codecs.BOM_UTF8 + SWEEP.encode())
    (ws / "sweep_latin1.toml").write_bytes(SWEEP.replace('name = "enc"\n', 'name = "enc"\ndescription = "M\u00fcller"\n')
                                           .encode("latin-1"))
    with open(ws / "huge.csv", "wb") as fh:  # sparse: costs no disk
        fh.truncate(TEXT_FILE_MAX_BYTES + 1)
    with open(ws / "huge.toml", "wb") as fh:
        fh.truncate(DOCUMENT_MAX_BYTES + 1)
    (ws / "manifest_fifo.csv").write_text("specimen,file,length_mm,width_mm,thickness_mm\n"
                                          f"s1,{ws / 'fifo'},100,25,2\n")
    (ws / "manifest_twice.csv").write_text("specimen,file,length_mm,width_mm,thickness_mm\n"
                                           f"s1,{CURVE},100,25,2\ns1,{CURVE},100,25,2\n")
    (ws / "manifest_slash.csv").write_text("specimen,file,length_mm,width_mm,thickness_mm\n"
                                           f"../s1,{CURVE},100,25,2\n")
    lines = ANATOMY.read_text().splitlines()
    header = [i for i, ln in enumerate(lines) if ln and not ln.startswith("#")][0]
    cols = lines[header].split(",")
    metres = [lines[header]]
    for ln in lines[header + 1:]:
        cells = ln.split(",")
        if len(cells) == len(cols) and not ln.startswith("#"):
            for c in ("x_mm", "y_mm", "z_mm"):
                cells[cols.index(c)] = f"{float(cells[cols.index(c)]) / 1000:.6f}"
            if "diameter_mm" in cols and cells[cols.index("diameter_mm")]:
                cells[cols.index("diameter_mm")] = cells[cols.index("diameter_mm")]
        metres.append(",".join(cells))
    (ws / "metres.csv").write_text("\n".join(metres) + "\n")
    return ws


def snapshot(ws):
    return sorted((str(p.relative_to(ws)), p.stat().st_mtime_ns if p.is_file() else 0) for p in ws.rglob("*")
                  if not p.is_fifo())


FIFO_CASES = {
    "centerline FIFO": (["insert", "--centerline", "{ws}/fifo", "--out", "{ws}/o"], "is a FIFO (named pipe)"),
    "presets FIFO": (["recommend", "{ws}/model", "--segment", "rsj", "--presets", "{ws}/fifo"], "is a FIFO"),
    "sweep file FIFO": (["sweep", "{ws}/fifo", "--dry-run", "--out", "{ws}/o"], "sweep file {ws}/fifo is a FIFO"),
    "sweep centerline FIFO": (["sweep", "{ws}/sweep_fifo.toml", "--dry-run", "--out", "{ws}/o"], "is a FIFO"),
    "curve FIFO": (["calibrate", "--curve", "{ws}/fifo", "--length", "100", "--width", "25", "--thickness", "2",
                    "--out", "{ws}/o"], "is a FIFO"),
    "manifest FIFO": (["calibrate", "--manifest", "{ws}/fifo", "--out", "{ws}/o"], "manifest {ws}/fifo is a FIFO"),
    "manifest's curve FIFO": (["calibrate", "--manifest", "{ws}/manifest_fifo.csv", "--out", "{ws}/o"], "is a FIFO"),
    "material FIFO": (["insert", "--material", "{ws}/fifo", "--out", "{ws}/o"], "material file {ws}/fifo is a FIFO"),
    "query FIFO": (["predict", "{ws}/model", "--csv", "{ws}/fifo"], "query file {ws}/fifo is a FIFO"),
    "results table FIFO": (["surrogate", "fit", "{ws}/fifo", "-o", "{ws}/m"], "results table {ws}/fifo is a FIFO"),
    "model FIFO": (["predict", "{ws}/fifo.json"], "surrogate file {ws}/fifo.json is a FIFO"),
    "centerline device": (["insert", "--centerline", "/dev/zero", "--out", "{ws}/o"], "/dev/zero is a character device"),
    "sweep centerline device": (["sweep", "{ws}/sweep_zero.toml", "--dry-run", "--out", "{ws}/o"],
                                "is a character device"),
    "curve device": (["calibrate", "--curve", "/dev/urandom", "--length", "100", "--width", "25", "--thickness",
                      "2", "--out", "{ws}/o"], "/dev/urandom is a character device"),
    "material device": (["insert", "--material", "/dev/zero", "--out", "{ws}/o"], "is a character device"),
    "centerline folder": (["insert", "--centerline", "{ws}/folder", "--out", "{ws}/o"], "is a folder, not a file"),
    "sweep file folder": (["sweep", "{ws}/folder", "--dry-run", "--out", "{ws}/o"], "is a folder"),
    "curve over the cap": (["calibrate", "--curve", "{ws}/huge.csv", "--length", "100", "--width", "25",
                            "--thickness", "2", "--out", "{ws}/o"], "more than the 64 MB an input may hold"),
    "centerline over the cap": (["insert", "--centerline", "{ws}/huge.csv", "--out", "{ws}/o"], "more than the 64 MB"),
    "sweep file over the cap": (["sweep", "{ws}/huge.toml", "--dry-run", "--out", "{ws}/o"], "more than the 16 MB"),
    "sweep file in Latin-1": (["sweep", "{ws}/sweep_latin1.toml", "--dry-run", "--out", "{ws}/o"],
                              "is not UTF-8 text (byte 0xfc on line 3"),
    "specimen named twice": (["calibrate", "--manifest", "{ws}/manifest_twice.csv", "--per-specimen", "--out",
                              "{ws}/o"], "specimen 's1' is listed twice"),
    "specimen name with a slash": (["calibrate", "--manifest", "{ws}/manifest_slash.csv", "--per-specimen", "--out",
                                    "{ws}/o"], "cannot name a results folder"),
    "centerline in metres": (["insert", "--centerline", "{ws}/metres.csv", "--out", "{ws}/o"],
                             "coordinates in metres? multiply them by 1000"),
}


@pytest.fixture(scope="module")
def model(ws):
    """A small fitted surrogate (the query, presets and model cases need one)."""
    from colonsim.surrogate.synthetic import synthetic_sweep

    synthetic_sweep(design="grid", noise_cm=0.02, seed=1).to_parquet(ws / "results.parquet")
    assert main(["surrogate", "fit", str(ws / "results.parquet"), "-o", str(ws / "model"), "--restarts", "0",
                 "--targets", "final_deformation_cm"]) == 0
    os.mkfifo(ws / "fifo.json")
    return ws / "model"


@pytest.mark.parametrize("name", list(FIFO_CASES))
def test_special_files_are_refused_in_one_line_without_blocking(ws, model, name, alarm, capsys):
    argv, message = FIFO_CASES[name]
    before = snapshot(ws)
    if any("/dev/" in a for a in argv) and not Path("/dev/zero").exists():
        pytest.skip("needs /dev/zero")
    t0 = time.monotonic()
    code = main([a.replace("{ws}", str(ws)) for a in argv])
    elapsed = time.monotonic() - t0
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2, err
    assert len(err) == 1 and err[0].startswith("colonsim: error: "), err
    assert message.replace("{ws}", str(ws)) in err[0], err[0]
    assert "not found" not in err[0]  # the audit's misleading line
    assert elapsed < 15
    assert snapshot(ws) == before


@pytest.mark.parametrize("variant", ["sweep_utf16.toml", "sweep_utf16_nobom.toml", "sweep_bom.toml"])
def test_a_sweep_file_in_utf16_or_with_a_bom_is_read(ws, variant, capsys):
    assert main(["sweep", str(ws / variant), "--dry-run", "--out", str(ws / "o")]) == 0
    assert "sweep enc: 2 runs" in capsys.readouterr().out


def test_a_centerline_in_windows_1252_is_read(tmp_path):
    from colonsim.insertion.anatomy.centerline_file import read_centerline_points

    text = ANATOMY.read_text()
    (tmp_path / "c.csv").write_bytes(("# Patient M\u00fcller, CT colonography\n" + text).encode("cp1252"))
    read = read_centerline_points(tmp_path / "c.csv")
    assert (read.points_mm == read_centerline_points(ANATOMY).points_mm).all()


@needs_dev
def test_read_input_never_reads_a_device_or_a_fifo(tmp_path, alarm):
    os.mkfifo(tmp_path / "p")
    for path, kind in ((tmp_path / "p", "FIFO"), (Path("/dev/zero"), "character device"), (tmp_path, "folder")):
        with pytest.raises(ColonsimError, match=kind):
            read_input(path, "test input")
    with pytest.raises(ColonsimError, match="not found; check the path"):
        check_input(tmp_path / "missing", "test input")


def test_the_size_cap_holds_on_the_bytes_read(tmp_path):
    path = tmp_path / "a.txt"
    path.write_bytes(b"x" * 1000)
    assert len(read_input(path, "test input", max_bytes=1000)) == 1000
    with pytest.raises(ColonsimError, match="1,000 bytes, more than the 999 bytes"):
        read_input(path, "test input", max_bytes=999)


@pytest.mark.parametrize("raw,expected", [
    (b"a = 1\n", "a = 1\n"), (codecs.BOM_UTF8 + b"a = 1\n", "a = 1\n"), ("a = \u00e9\n".encode("utf-16"), "a = \u00e9\n"),
    ("a = 1\n".encode("utf-16-be"), "a = 1\n"), ("a = 1\n".encode("utf-32"), "a = 1\n")])
def test_declared_and_detectable_encodings_decode(raw, expected):
    assert decode_text(raw, "f", "test input")[0] == expected


def test_undecodable_or_binary_text_is_refused_naming_the_byte():
    with pytest.raises(ColonsimError, match=r"not UTF-8 text \(byte 0xe9 on line 2"):
        decode_text(b"a = 1\nb = \xe9\n", "f", "test input")
    assert decode_text(b"b = \xe9\n", "f", "test input", fallbacks=("cp1252",))[0] == "b = \u00e9\n"
    with pytest.raises(ColonsimError, match="holds binary bytes"):
        decode_text(b"a\x00\x00\x01\x02b", "f", "test input")


def test_a_material_file_in_utf16_is_refused_or_read_never_a_traceback(tmp_path, capsys):
    doc = json.loads(REFERENCE_MATERIAL_PATH.read_text())
    (tmp_path / "m.json").write_bytes(json.dumps(doc).encode("utf-16"))
    code = main(["insert", "--material", str(tmp_path / "m.json"), "--segment", "straight", "--element-size", "200",
                 "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and err[0].startswith("colonsim: error: "), err
