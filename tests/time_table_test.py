"""tools/time-table (issue 82 item 7): the run's time table from ./reproduce's timed steps: every step's wall time
(driver plus analysis) and its share of the total, the total row, the appendix's table (longest first) and macros;
a malformed steps line is refused with one line naming it."""
import csv
import json
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TOOL = os.path.join(ROOT, "tools", "time-table")


def run(results, steps, *extra):
    return subprocess.run([sys.executable, TOOL, str(results), str(steps), *extra], capture_output=True, text=True)


def test_shares_add_up_and_the_longest_step_leads_the_table(tmp_path):
    steps = tmp_path / "steps.tsv"
    # 30 + (100 + 20) + 50 = 200 s: shares 0.15, 0.6, 0.25.
    steps.write_text("build\t30\t\n10_x\t100\t20\nclaims\t50\t\n")
    r = run(tmp_path, steps, "--mode", "quick")
    assert r.returncode == 0, r.stderr
    with open(tmp_path / "reproduce_times.csv") as f:
        rows = list(csv.DictReader(f))
    assert [x["step"] for x in rows] == ["build", "10_x", "claims", "total"]
    assert [float(x["share"]) for x in rows] == [0.15, 0.6, 0.25, 1.0]
    assert float(rows[1]["wall_s"]) == 120 and float(rows[-1]["wall_s"]) == 200 and rows[0]["analysis_s"] == ""
    table = (tmp_path / "reproduce" / "table_times.tex").read_text()
    assert table.index("10\\_x") < table.index("claims") < table.index("build")
    assert "60.0\\%" in table
    macros = (tmp_path / "reproduce" / "macros.tex").read_text()
    assert "\\newcommand{\\RunMode}{quick}" in macros and "\\newcommand{\\RunLongestShare}{60}" in macros
    assert "\\newcommand{\\RunTopology}{not recorded}" in macros  # no meta.json in this run
    assert "(3.3 min, quick run)" in r.stdout


def test_the_topology_comes_from_the_runs_meta_json(tmp_path):
    os.makedirs(tmp_path / "01_x")
    machine = {"logical_cpus": "2", "physical_cores": "1", "sockets": "1", "smt": "yes", "thread_siblings": "0-1"}
    (tmp_path / "01_x" / "meta.json").write_text(json.dumps({"machine": machine}))
    steps = tmp_path / "steps.tsv"
    steps.write_text("build\t1\t\n")
    assert run(tmp_path, steps).returncode == 0
    macros = (tmp_path / "reproduce" / "macros.tex").read_text()
    assert "2 logical CPUs on 1 physical cores" in macros and "SMT: some cores run two logical CPUs" in macros


def test_a_malformed_line_is_refused_with_one_line(tmp_path):
    steps = tmp_path / "steps.tsv"
    steps.write_text("build\t1\t\n10_x\tlong\t\n")
    r = run(tmp_path, steps)
    assert r.returncode == 2 and r.stderr.strip().count("\n") == 0, (r.returncode, r.stderr)
    assert "steps.tsv:2" in r.stderr and "'10_x\\tlong'" in r.stderr
    assert not (tmp_path / "reproduce_times.csv").exists()
