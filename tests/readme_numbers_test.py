"""tools/readme-numbers (issue 81, item 7): the README's marked numbers against the run's macros, on a synthetic
README and macros.tex files: a value that matches its macro (after the LaTeX is turned into plain text) passes, a
mismatch fails naming the README line and the macro, a macro no macros.tex defines fails, and --write rewrites the
values from the macros by renaming a whole new file into place; tools/check-report reports the findings of a full run
and leaves a quick run's alone."""
import importlib.machinery
import importlib.util
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TOOL = os.path.join(ROOT, "tools", "readme-numbers")
_loader = importlib.machinery.SourceFileLoader("check_report", os.path.join(ROOT, "tools", "check-report"))
check_report = importlib.util.module_from_spec(importlib.util.spec_from_loader("check_report", _loader))
_loader.exec_module(check_report)

MACROS = {"01_a": "\\newcommand{\\Median}{0.31}\n\\newcommand{\\Worst}{$\\infty$}\n",
          "02_b": "\\newcommand{\\Range}{44--60}\n\\newcommand{\\Tiny}{5\\times 10^{-5}}\n"
                  "\\newcommand{\\Where}{\\texttt{mc22-left} at 20\\,deg}\n"}


def results_dir(tmp_path):
    for name, text in MACROS.items():
        (tmp_path / "results" / name).mkdir(parents=True)
        (tmp_path / "results" / name / "macros.tex").write_text(text)
    return tmp_path / "results"


def readme_text(median="0.31", extra=""):
    return ("# A README\n\nText without numbers.\n"
            f"A median <!--m:Median-->{median}<!--/m--> deg, up to <!--m:Worst-->∞<!--/m--> deg.\n"
            "Ranges <!--m:Range-->44-60<!--/m-->, within <!--m:Tiny-->5e-5<!--/m--> mm, at "
            f"<!--m:Where-->mc22-left at 20deg<!--/m-->.\n{extra}")


def readme(tmp_path, median="0.31", extra=""):
    path = tmp_path / "README.md"
    path.write_text(readme_text(median, extra), encoding="utf-8")
    return path


def run(results, path, mode="--check"):
    return subprocess.run([sys.executable, TOOL, mode, "--results", str(results), "--readme", str(path)],
                          capture_output=True, text=True)


def test_values_that_match_their_macros_pass(tmp_path):
    r = run(results_dir(tmp_path), readme(tmp_path))
    assert r.returncode == 0, r.stdout + r.stderr
    assert "5 marked numbers" in r.stdout


def test_a_mismatch_fails_naming_the_line_macro_and_both_values(tmp_path):
    r = run(results_dir(tmp_path), readme(tmp_path, median="0.28"))
    assert r.returncode == 1
    assert r.stdout.splitlines() == ["README.md:4: \\Median: typed '0.28', macro '0.31' (01_a/macros.tex)"]


def test_a_macro_no_macros_tex_defines_fails(tmp_path):
    r = run(results_dir(tmp_path), readme(tmp_path, extra="New <!--m:Absent-->3<!--/m-->.\n"))
    assert r.returncode == 1
    assert r.stdout.splitlines() == ["README.md:6: \\Absent: typed '3', but no macros.tex defines \\Absent"]


def test_a_marker_left_open_and_a_results_folder_without_macros_fail(tmp_path):
    r = run(results_dir(tmp_path), readme(tmp_path, extra="Open <!--m:Median-->0.31 and on.\n"))
    assert r.returncode == 1 and "README.md:6: a marker" in r.stdout
    (tmp_path / "empty").mkdir()
    r = run(tmp_path / "empty", readme(tmp_path))
    assert r.returncode != 0 and "no macros.tex" in r.stderr


def test_write_rewrites_the_values_atomically(tmp_path):
    results = results_dir(tmp_path)
    path = readme(tmp_path, median="0.28")
    inode = os.stat(path).st_ino
    r = run(results, path, "--write")
    assert r.returncode == 0, r.stdout + r.stderr
    assert path.read_text(encoding="utf-8") == readme_text(median="0.31")
    assert os.stat(path).st_ino != inode  # a new file renamed into place, not the old one rewritten
    assert [p.name for p in tmp_path.iterdir() if p.name.endswith(".tmp")] == []
    assert run(results, path).returncode == 0


def test_write_leaves_an_unknown_macro_and_fails(tmp_path):
    path = readme(tmp_path, median="0.28", extra="New <!--m:Absent-->3<!--/m-->.\n")
    r = run(results_dir(tmp_path), path, "--write")
    assert r.returncode == 1 and "\\Absent" in r.stdout and "\\Median" not in r.stdout
    assert "<!--m:Median-->0.31<!--/m-->" in path.read_text() and "<!--m:Absent-->3<!--/m-->" in path.read_text()


def test_check_report_reports_a_full_run_and_leaves_a_quick_one(tmp_path):
    results = results_dir(tmp_path)
    path = readme(tmp_path, median="0.28")
    assert check_report.check_readme(str(results), {"01_a/meta.json": {"quick": False}}, str(path)) == [
        "readme: README.md:4: \\Median: typed '0.28', macro '0.31' (01_a/macros.tex)"]
    assert check_report.check_readme(str(results), {"01_a/meta.json": {"quick": True}}, str(path)) == []
    readme(tmp_path)
    assert check_report.check_readme(str(results), {"01_a/meta.json": {"quick": False}}, str(path)) == []
