"""experiments/manifest.tsv names every CSV each experiment's driver writes, and only those: the CSV
names a driver writes are the "/name.csv" literals of experiments/NN_name*.cpp, or the "name.csv" literals of
a Python driver experiments/NN_name*.py (inputs beside the
drivers, experiments/NN_*.csv, start with a digit and are not outputs). Also: every manifest line
names an existing driver, analysis script and paper section."""
import csv
import pathlib
import re

ROOT = pathlib.Path(__file__).resolve().parent.parent
EXP = ROOT / "experiments"


def manifest():
    with open(EXP / "manifest.tsv", newline="") as f:
        return [r for r in csv.DictReader(f, delimiter="\t") if r["name"] and not r["name"].startswith("#")]


def written_by(name):
    out = set()
    for src in EXP.glob(name + "*.cpp"):
        out |= {m for m in re.findall(r'"/([A-Za-z0-9_]+\.csv)"', src.read_text()) if not m[0].isdigit()}
    for src in EXP.glob(name + "*.py"):  # a Python driver names its outputs as plain string literals
        out |= {m for m in re.findall(r'"([A-Za-z0-9_]+\.csv)"', src.read_text()) if not m[0].isdigit()}
    return out


def test_manifest_lists_every_csv_a_driver_writes():
    rows = manifest()
    assert rows, "empty manifest"
    for r in rows:
        listed = {c.strip() for c in r["csv"].split(",") if c.strip()}
        written = written_by(r["name"])
        assert written - listed == set(), f"{r['name']}: the driver writes {sorted(written - listed)}, not in the manifest"
        assert listed - written == set(), f"{r['name']}: the manifest lists {sorted(listed - written)}, not written by the driver"


def test_every_manifest_line_names_existing_files():
    for r in manifest():
        for col in ("driver", "analysis", "paper_section"):
            assert (ROOT / r[col]).is_file(), f"{r['name']}: {col} {r[col]} does not exist"
