"""Every number a user gives has a range, checked where it is parsed whether or not the run uses
it (colonsim.limits.OPTION_RANGES, colonsim.options.ranged); size limits follow from what the
program can process (a million-query file is read, colonsim.limits.QUERY_MAX_BYTES)."""

import numpy as np
import pandas as pd
import pytest

from colonsim.cli import main
from colonsim.errors import ColonsimError
from colonsim.identification.cleanup import check_decimation
from colonsim.limits import OPTION_RANGES, QUERY_MAX_BYTES
from colonsim.options import ranged
from colonsim.surrogate.table import read_query_file


def one_line_error(capsys, *words):
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and all(w in err[0] for w in words), err


@pytest.mark.parametrize("argv, words", [
    (["insert", "--segment", "straight", "--snapshot-every", "-1"], ["--snapshot-every", "-1 is outside 0.001-10"]),
    (["insert", "--segment", "straight", "--snapshot-every", "nan"], ["--snapshot-every", "not a finite number"]),
    (["calibrate", "--curve", "c.csv", "--mode", "uniaxial", "--decimate", "3"], ["--decimate", "3 is outside 5-10,000"]),
    (["calibrate", "--curve", "c.csv", "--mode", "uniaxial", "--decimate", "-1"], ["--decimate", "-1 is outside"]),
    (["calibrate", "--curve", "c.csv", "--mode", "uniaxial", "--decimate", "1e9"], ["--decimate", "not a whole number"]),
])
def test_a_number_outside_its_range_is_refused_when_parsed_even_if_unused(capsys, tmp_path, argv, words):
    assert main([*argv, "--out", str(tmp_path / "out")]) == 2
    one_line_error(capsys, *words)
    assert not (tmp_path / "out").exists() or not any((tmp_path / "out").iterdir())


def test_numbers_inside_their_ranges_pass():
    assert ranged("--snapshot-every")("0.05") == 0.05 and ranged("--decimate")("20") == 20
    for option, (low, high, _) in OPTION_RANGES.items():
        assert ranged(option)(str(low)) == low and ranged(option)(str(high)) == high


def test_decimation_never_invents_points():
    check_decimation("c", 30, 30)
    with pytest.raises(ColonsimError, match=r"--decimate 31 is more than the 30 points of c: the extra points would be "
                                            r"invented by interpolation; give at most 30"):
        check_decimation("c", 31, 30)


def test_a_million_queries_are_read_and_a_larger_file_than_the_bound_is_refused(tmp_path):
    n = 1_000_000
    rng = np.random.default_rng(0)
    path = tmp_path / "patients.csv"
    pd.DataFrame({"segment": "rsj", "scope": rng.choice(["utc", "pdc", "sdc"], n), "age": rng.integers(18, 95, n),
                  "sex": rng.choice(["male", "female"], n)}).to_csv(path, index=False)
    assert path.stat().st_size > 16 * 2**20  # refused by the documents' bound before
    assert len(read_query_file(path)) == n
    huge = tmp_path / "huge.csv"
    with open(huge, "wb") as fh:  # sparse: costs no disk
        fh.truncate(QUERY_MAX_BYTES + 1)
    with pytest.raises(ColonsimError, match=r"query file .*huge.csv holds 32 MB, more than the 32 MB an input may hold"):
        read_query_file(huge)


def test_a_stability_range_is_checked_when_parsed_even_for_a_strip_fit_that_does_not_use_it(capsys, tmp_path):
    from colonsim.data import BUNDLED_MANIFEST

    argv = ["calibrate", "--manifest", str(BUNDLED_MANIFEST), "--stability-range", "2", "4", "--out", str(tmp_path / "o")]
    assert main(argv) == 2
    one_line_error(capsys, "--stability-range", "2 4 must run from below 1 to above 1")
    assert not (tmp_path / "o").exists()
