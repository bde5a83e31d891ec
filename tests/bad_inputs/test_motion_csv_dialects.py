"""Issue 80, cases 5/7: a motion CSV as spreadsheets write it (a UTF-8 byte-order mark, quoted column names such as
"time_s", CRLF line ends, quoted numbers) was "missing column 'time_s'". It is the same motion as the plain file:
`impinge motion` writes the same frames and Python's load_motion reads the same angles. A column truly missing is
named with the columns the header has."""
import csv
import io

import pytest

from conftest import one_line_error, run

ROWS = [(0.0, 10.0, 1.5, -3.0), (0.5, 20.25, 2.0, 4.0), (1.0, 45.0, -5.0, 12.5)]
NAMES = ["time_s", "flexion_deg", "adduction_deg", "internal_rotation_deg"]


def plain_text():
    return ",".join(NAMES) + "\n" + "".join(",".join(repr(v) for v in r) + "\n" for r in ROWS)


def spreadsheet_text():
    """The same table written by Python's csv module with every cell quoted and CRLF, after a byte-order mark."""
    out = io.StringIO()
    w = csv.writer(out, quoting=csv.QUOTE_ALL, lineterminator="\r\n")
    w.writerow(NAMES + ["note, with a comma"])
    for r in ROWS:
        w.writerow([repr(v) for v in r] + ['say "hi"'])
    return "\ufeff" + out.getvalue()


def frames(path):
    """frames.csv's rows without detection_ms (a timing)."""
    rows = list(csv.DictReader(open(path)))
    return [{k: v for k, v in r.items() if k != "detection_ms"} for r in rows]


def test_a_spreadsheets_csv_is_the_plain_motion(generated, tmp_path):
    plain, sheet = tmp_path / "plain.csv", tmp_path / "sheet.csv"
    plain.write_text(plain_text())
    sheet.write_bytes(spreadsheet_text().encode("utf-8"))
    assert sheet.read_bytes().startswith(b'\xef\xbb\xbf"time_s"')
    for name in ("plain", "sheet"):
        r = run(["motion", "--subject", generated, "--motion", tmp_path / f"{name}.csv", "--precision", "2",
                 "--quiet", "--out", tmp_path / f"out_{name}"])
        assert r.returncode == 0, r.stderr
    a, b = frames(tmp_path / "out_plain" / "frames.csv"), frames(tmp_path / "out_sheet" / "frames.csv")
    assert len(a) == len(ROWS) and a == b
    impinge = pytest.importorskip("impinge")
    m = impinge.load_motion(str(sheet))
    assert m["time_s"].tolist() == [r[0] for r in ROWS]
    assert m["angles"].tolist() == [list(r[1:]) for r in ROWS]


def test_a_missing_column_is_named_with_the_columns_found(generated, tmp_path):
    m = tmp_path / "m.csv"
    m.write_bytes(("\ufeff" + '"time","flexion_deg",adduction_deg,internal_rotation_deg\r\n0,1,2,3\r\n').encode())
    one_line_error(run(["motion", "--subject", generated, "--motion", m, "--out", tmp_path / "o"]),
                   f"{m}:1: missing column 'time_s' (the header's columns: 'time', 'flexion_deg', 'adduction_deg', "
                   "'internal_rotation_deg')")
