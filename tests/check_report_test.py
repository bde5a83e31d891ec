"""tools/check-report and analysis/claims.py: the checker reads thesis items as the manifest writes them,
finds a run from mixed or dirty commits or without one of the manifest's experiments, a thesis item without a
claim, a bad verdict and a page that runs over; and the committed run (results/) comes from one clean commit,
holds every experiment, and its claims.csv has a row for every thesis item of experiments/manifest.tsv."""
import csv
import importlib.machinery
import importlib.util
import json
import os
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TOOL = os.path.join(ROOT, "tools", "check-report")
_loader = importlib.machinery.SourceFileLoader("check_report", TOOL)
check = importlib.util.module_from_spec(importlib.util.spec_from_loader("check_report", _loader))
_loader.exec_module(check)


def test_thesis_items_are_read_one_by_one():
    assert check.thesis_items("Tables 2, 6, 7; Fig. 49 counts") == {"Table 2", "Table 6", "Table 7", "Fig. 49"}
    assert check.thesis_items("Sec. 5.2, Tables 11-13, Fig. 60-63") == (
        {"Sec. 5.2", "Table 11", "Table 12", "Table 13", "Fig. 60", "Fig. 61", "Fig. 62", "Fig. 63"})
    assert check.thesis_items("Table 5, Eq. 7-8") == {"Table 5", "Eq. 7", "Eq. 8"}
    assert check.thesis_items("Sec. 3.5.2, Fig. 46") == {"Sec. 3.5.2", "Fig. 46"}
    assert check.thesis_items("(new) the Euclidean distance beside Open3D and VTK (issue 26)") == set()


def head():
    """This checkout's HEAD commit, or None outside a git work tree."""
    r = subprocess.run(["git", "-C", ROOT, "rev-parse", "HEAD"], capture_output=True, text=True)
    return r.stdout.strip() if r.returncode == 0 else None


def write_run(d, commits, claims_rows, log="", leave_out=(), drop_field=None):
    """A run of every manifest experiment (but leave_out), the k-th from commits[k % len(commits)] ("abc" stands for
    HEAD: a run of the code as it is), every meta.json with every field but drop_field."""
    here = head() or "abc"
    for k, name in enumerate(n for n in check.manifest_items() if n not in leave_out):
        os.makedirs(os.path.join(d, name), exist_ok=True)
        meta = {field: "x" for field in check.META_FIELDS}
        meta["git_commit"] = commits[k % len(commits)].replace("abc", here)
        meta.pop(drop_field, None)
        with open(os.path.join(d, name, "meta.json"), "w") as f:
            json.dump(meta, f)
    with open(os.path.join(d, "claims.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(check.CLAIM_COLUMNS))
        w.writeheader()
        w.writerows(claims_rows)
    os.makedirs(os.path.join(d, "paper"), exist_ok=True)
    with open(os.path.join(d, "paper", "impinge.log"), "w") as f:
        f.write(log)
    write_paper(d, [(100, 700, 10, 1, False)], [("table", 1, 750, 650)])
    with open(os.path.join(d, "reproduce_times.csv"), "w") as f:
        f.write("step,driver_s,analysis_s,wall_s,share\nbuild,900,,900,0.3\n01_x,2000,100,2100,0.7\n"
                "total,,,3000,1.0\n")


def write_pdf(path, texts):
    """A one-page A4 PDF, written by hand, drawing "Table text" in Helvetica for each (x, y, font size, scale,
    turned) of `texts`: at (x, y) PDF points, the font size scaled by `scale` through the page's transformation
    (as \\resizebox does), turned a quarter when `turned`. Its printed size is font size x scale."""
    ops = []
    for x, y, size, scale, turned in texts:
        m = f"0 {scale} {-scale} 0" if turned else f"{scale} 0 0 {scale}"
        ops.append(f"q {m} {x} {y} cm BT /F1 {size} Tf 0 0 Td (Table text) Tj ET Q")
    content = "\n".join(ops).encode()
    objects = [b"<< /Type /Catalog /Pages 2 0 R >>", b"<< /Type /Pages /Kids [3 0 R] /Count 1 >>",
               b"<< /Type /Page /Parent 2 0 R /MediaBox [0 0 595 842] /Contents 4 0 R "
               b"/Resources << /Font << /F1 5 0 R >> >> >>",
               b"<< /Length %d >>\nstream\n" % len(content) + content + b"\nendstream",
               b"<< /Type /Font /Subtype /Type1 /BaseFont /Helvetica >>"]
    out, offsets = bytearray(b"%PDF-1.4\n"), []
    for k, body in enumerate(objects, start=1):
        offsets.append(len(out))
        out += b"%d 0 obj\n" % k + body + b"\nendobj\n"
    xref = len(out)
    out += b"xref\n0 %d\n0000000000 65535 f \n" % (len(objects) + 1)
    out += b"".join(b"%010d 00000 n \n" % o for o in offsets)
    out += b"trailer\n<< /Size %d /Root 1 0 R >>\nstartxref\n%d\n%%%%EOF\n" % (len(objects) + 1, xref)
    with open(path, "wb") as f:
        f.write(bytes(out))


def write_paper(d, texts, floats):
    """RESULTS d's built paper: impinge.pdf drawing `texts` (write_pdf) and the position file paper/impinge.tex
    writes, with each (kind, number, top, bottom) of `floats` (PDF points from the page's bottom) on page 1."""
    write_pdf(os.path.join(d, "paper", "impinge.pdf"), texts)
    sp = 65536 * 72.27 / 72
    with open(os.path.join(d, "paper", "impinge.pos"), "w") as f:
        for k, (kind, number, top, bottom) in enumerate(floats, start=1):
            f.write(f"begin {kind} {k} {number - 1} 0 0 {round(top * sp)}\n")
            f.write(f"end {kind} {k} {number} 0 0 {round(bottom * sp)}\n")


def every_item_row(verdict="holds"):
    items = sorted(set().union(*check.manifest_items().values()))
    return [{"thesis_item": "; ".join(items), "claim": "c", "kind": "measured", "thesis_value": "t", "our_value": "o",
             "tolerance": "1 %", "conditions": "rest pose", "same_subjects": "yes", "verdict": verdict, "reason": "r",
             "section": "s"}]


def run(d, *extra):
    return subprocess.run([sys.executable, TOOL, d, *extra], capture_output=True, text=True)


def test_a_clean_single_commit_run_covering_the_manifest_passes():
    with tempfile.TemporaryDirectory() as d:
        write_run(d, ["abc", "abc"], every_item_row())
        r = run(d)
        assert r.returncode == 0, r.stdout


def test_mixed_and_dirty_commits_are_found():
    with tempfile.TemporaryDirectory() as d:
        write_run(d, ["abc", "def"], every_item_row())
        r = run(d, "--allow-dirty")
        assert r.returncode == 1 and r.stdout.count("provenance:") == 2, r.stdout
    with tempfile.TemporaryDirectory() as d:
        write_run(d, ["abc-dirty"], every_item_row())
        assert run(d).returncode == 1
        assert run(d, "--allow-dirty").returncode == 0


def test_a_meta_json_without_every_field_is_found():
    with tempfile.TemporaryDirectory() as d:
        write_run(d, ["abc"], every_item_row(), drop_field="machine")
        r = run(d)
        assert r.returncode == 1 and "lacks machine" in r.stdout, r.stdout


def git(repo, *args):
    subprocess.run(["git", "-C", repo, "-c", "user.name=t", "-c", "user.email=t@t", *args], check=True,
                   capture_output=True)
    return subprocess.run(["git", "-C", repo, "rev-parse", "HEAD"], capture_output=True, text=True).stdout.strip()


def test_a_run_older_than_a_change_to_what_shapes_the_results_is_found():
    # A repository whose first commit holds a driver, a README and a test: a run of it is current until a later
    # commit touches the driver (changes to the README or the tests do not count).
    with tempfile.TemporaryDirectory() as repo, tempfile.TemporaryDirectory() as d:
        os.makedirs(os.path.join(repo, "experiments"))
        os.makedirs(os.path.join(repo, "python", "tests"))
        for path, text in (("experiments/01.py", "a = 1\n"), ("README.md", "r\n"), ("python/tests/t.py", "t\n")):
            with open(os.path.join(repo, path), "w") as f:
                f.write(text)
        git(repo, "init", "-q")
        git(repo, "add", "-A")
        first = git(repo, "commit", "-q", "-m", "one")
        os.makedirs(os.path.join(d, "01"))
        with open(os.path.join(d, "01", "meta.json"), "w") as f:
            json.dump({"git_commit": first}, f)
        assert check.check_current(d, repo) == []
        for path in ("README.md", "python/tests/t.py"):
            with open(os.path.join(repo, path), "a") as f:
                f.write("more\n")
        git(repo, "commit", "-q", "-am", "docs and tests")
        assert check.check_current(d, repo) == []
        with open(os.path.join(repo, "experiments", "01.py"), "a") as f:
            f.write("b = 2\n")
        git(repo, "commit", "-q", "-am", "driver")
        found = check.check_current(d, repo)
        assert len(found) == 1 and "experiments/01.py" in found[0] and "README" not in found[0], found
        # A commit the repository does not hold cannot be vouched for.
        with open(os.path.join(d, "01", "meta.json"), "w") as f:
            json.dump({"git_commit": "0" * 40}, f)
        assert "not in this repository's history" in check.check_current(d, repo)[0]


def test_an_experiment_missing_from_the_run_is_found():
    with tempfile.TemporaryDirectory() as d:
        write_run(d, ["abc"], every_item_row(), leave_out=("13_distance_peers",))
        r = run(d)
        assert r.returncode == 1 and "13_distance_peers (experiments/manifest.tsv) has no meta.json" in r.stdout, r.stdout


def test_a_thesis_item_without_a_claim_and_a_bad_verdict_are_found():
    with tempfile.TemporaryDirectory() as d:
        rows = every_item_row()
        rows[0]["thesis_item"] = rows[0]["thesis_item"].replace("Fig. 53; ", "")
        write_run(d, ["abc"], rows)
        r = run(d)
        assert r.returncode == 1 and "no row for Fig. 53" in r.stdout, r.stdout
    with tempfile.TemporaryDirectory() as d:
        write_run(d, ["abc"], every_item_row("probably"))
        r = run(d)
        assert r.returncode == 1 and "verdict 'probably'" in r.stdout, r.stdout


def test_a_claims_table_without_kind_tolerance_and_conditions_is_found():
    with tempfile.TemporaryDirectory() as d:
        rows = every_item_row()
        write_run(d, ["abc"], rows)
        with open(os.path.join(d, "claims.csv"), "w", newline="") as f:
            old = ["thesis_item", "claim", "thesis_value", "our_value", "verdict", "reason", "section"]
            w = csv.DictWriter(f, fieldnames=old, extrasaction="ignore")
            w.writeheader()
            w.writerows(rows)
        r = run(d)
        assert r.returncode == 1 and "lacks the columns kind, tolerance, conditions, same_subjects" in r.stdout, r.stdout


def test_figure_text_under_eight_points_at_its_printed_width_is_found():
    # A figure 6.5 in wide printed at half the text width shrinks its 8 pt text to about 4 pt; drawn at the printed
    # width (half the text width, in inches) it keeps 8 pt.
    with tempfile.TemporaryDirectory() as results, tempfile.TemporaryDirectory() as paper:
        os.makedirs(os.path.join(paper, "sections"))
        with open(os.path.join(paper, "sections", "01.tex"), "w") as f:
            f.write("\\includegraphics[width=0.5\\textwidth]{01_x/fig.pdf}\n")
        os.makedirs(os.path.join(results, "01_x"))
        for width, found in ((6.5, 1), (0.5 * check.TEXT_WIDTH_IN, 0)):
            with open(os.path.join(results, "01_x", "figures.json"), "w") as f:
                json.dump({"fig": {"width_in": width, "min_font_pt": 8}}, f)
            findings = check.check_figure_text(results, paper)
            assert len(findings) == found, findings
            if found:
                assert "01_x/fig prints its smallest text at 4.0 pt" in findings[0], findings


def test_the_analysis_draws_figure_text_at_eight_points_where_the_paper_prints_it():
    # analysis/common.py's save() enlarges text drawn at 6 pt on a 6.5 in figure that the paper prints at half the
    # text width, so that check_figure_text, reading the figures.json it writes, finds nothing; the two share the
    # text width and the 8 pt floor.
    sys.path.insert(0, os.path.join(ROOT, "analysis"))
    import common
    assert common.TEXT_WIDTH_IN == check.TEXT_WIDTH_IN and common.MIN_FIGURE_FONT_PT == check.MIN_FIGURE_FONT_PT
    with tempfile.TemporaryDirectory() as results, tempfile.TemporaryDirectory() as paper:
        os.makedirs(os.path.join(paper, "sections"))
        with open(os.path.join(paper, "sections", "01.tex"), "w") as f:
            f.write("\\includegraphics[width=0.5\\textwidth]{01_x/fig.pdf}\n")
        d = os.path.join(results, "01_x")
        os.makedirs(d)
        assert common.printed_width_in("01_x", "fig", os.path.join(paper, "sections")) == 0.5 * check.TEXT_WIDTH_IN
        assert common.printed_width_in("01_x", "other", os.path.join(paper, "sections")) is None
        old = common.PAPER_SECTIONS
        common.PAPER_SECTIONS = os.path.join(paper, "sections")
        try:
            fig, ax = common.plt.subplots(figsize=(6.5, 3))
            ax.plot([0, 1], [0, 1], label="a line")
            ax.legend(fontsize=6)
            ax.set_xlabel("x", fontsize=6)
            ax.tick_params(labelsize=6)
            common.save(fig, d, "fig")
        finally:
            common.PAPER_SECTIONS = old
        with open(os.path.join(d, "figures.json")) as f:
            recorded = json.load(f)["fig"]
        assert recorded["min_font_pt"] >= 8 * 6.5 / (0.5 * check.TEXT_WIDTH_IN) - 1e-9, recorded
        assert check.check_figure_text(results, paper) == []


def test_table_text_printed_under_seven_points_is_found_in_the_pdf():
    # Table 1 at 10 pt; Table 2 at 10 pt shrunk by half (5 pt, as \\resizebox prints a wide table); Table 3 at 8 pt
    # turned on its page; Figure 1 at 9 pt scaled to 0.75 (6.75 pt). Text outside every float (a 4 pt line at the
    # page's foot) is not a table's.
    with tempfile.TemporaryDirectory() as d:
        os.makedirs(os.path.join(d, "paper"))
        write_paper(d, [(100, 700, 10, 1, False), (100, 600, 10, 0.5, False), (300, 420, 8, 1, True),
                        (100, 300, 9, 0.75, False), (100, 50, 4, 1, False)],
                    [("table", 1, 750, 650), ("table", 2, 640, 560), ("table", 3, 540, 360), ("figure", 1, 340, 250)])
        sizes = check.table_text_sizes(d)
        assert set(sizes) == {"Table 1", "Table 2", "Table 3", "Figure 1"}, sizes
        for name, expected in (("Table 1", 10), ("Table 2", 5), ("Table 3", 8), ("Figure 1", 6.75)):
            assert abs(sizes[name][0] - expected) < 0.06 and abs(sizes[name][1] - expected) < 0.06, (name, sizes)
        findings = check.check_text_size(d)
        assert len(findings) == 2 and "Table 2 prints text at 5.0 pt" in findings[0] and "Figure 1" in findings[1], \
            findings


def test_a_full_run_over_an_hour_after_its_build_and_a_run_without_its_time_table_are_found():
    with tempfile.TemporaryDirectory() as d:
        write_run(d, ["abc"], every_item_row())
        metas = check.read_metas(d)
        for m in metas.values():
            m["quick"] = False
        assert check.check_run_time(d, metas) == []  # 35 min after a 15 min build
        with open(os.path.join(d, "reproduce_times.csv"), "a") as f:
            f.write("02_y,1600,,1600,0.3\n")
        findings = check.check_run_time(d, metas)
        assert len(findings) == 1 and "took 62 min after its build" in findings[0], findings
        os.remove(os.path.join(d, "reproduce_times.csv"))
        assert "reproduce_times.csv missing" in check.check_run_time(d, metas)[0]


def test_a_line_is_sized_by_its_text_not_its_superscripts():
    # Three glyphs at 7 pt and one at 5 pt on one line: a superscript; alone on its own line, 5 pt counts.
    assert check.line_sizes([(100, 7), (100.5, 7), (99.8, 7), (102, 5)]) == [7]
    assert check.line_sizes([(100, 7), (100.5, 7), (80, 5)]) == [7, 5]


def test_a_page_that_runs_over_is_found():
    with tempfile.TemporaryDirectory() as d:
        write_run(d, ["abc"], every_item_row(), "Overfull \\vbox (250.3pt too high) has occurred while \\output")
        r = run(d)
        assert r.returncode == 1 and "vbox" in r.stdout, r.stdout
    with tempfile.TemporaryDirectory() as d:
        write_run(d, ["abc"], every_item_row(), "Overfull \\hbox (3.1pt too wide) in paragraph at lines 1--2")
        assert run(d).returncode == 0


def experiments_at(commit):
    """The experiments of experiments/manifest.tsv at `commit` (None when git cannot tell)."""
    r = subprocess.run(["git", "-C", ROOT, "show", f"{commit}:experiments/manifest.tsv"], capture_output=True, text=True)
    if r.returncode != 0:
        return None
    return {line.split("\t")[0] for line in r.stdout.splitlines()[1:] if line and not line.startswith("#")}


def items_at(commit):
    """{experiment: thesis items} of experiments/manifest.tsv at `commit` (None when git cannot tell)."""
    r = subprocess.run(["git", "-C", ROOT, "show", f"{commit}:experiments/manifest.tsv"], capture_output=True, text=True)
    if r.returncode != 0:
        return None
    rows = csv.DictReader((line for line in r.stdout.splitlines() if not line.startswith("#")), delimiter="\t")
    return {row["name"]: check.thesis_items(row["thesis"]) for row in rows}


def run_predates_same_fields(commit):
    """True when the run's commit is older than the commit that gave every meta.json the same fields (META_FIELDS
    in tools/check-report): such a run cannot have them."""
    r = subprocess.run(["git", "-C", ROOT, "log", "--format=%H", "-S", "META_FIELDS", "--", "tools/check-report"],
                       capture_output=True, text=True)
    introduced = r.stdout.split()[-1] if r.returncode == 0 and r.stdout.split() else None
    if introduced is None:
        return False
    return subprocess.run(["git", "-C", ROOT, "merge-base", "--is-ancestor", commit.removesuffix("-dirty"),
                           introduced], capture_output=True).returncode == 0 and commit != introduced


def test_the_committed_run_is_one_clean_commit_of_every_experiment_and_its_claims_cover_the_manifest():
    results = os.path.join(ROOT, "results")
    # Every experiment the manifest held at the run's commit is in the run, from that one clean commit. An
    # experiment added since (experiment 15, before issue 51's reference run) is the only finding allowed.
    with open(os.path.join(results, "01_lut_memory", "meta.json")) as f:
        commit = json.load(f)["git_commit"]
    then = experiments_at(commit)
    findings = check.check_provenance(results, allow_dirty=False)
    if then is not None:
        findings = [x for x in findings if not any(f"provenance: {name} (experiments/manifest.tsv) has no meta.json"
                                                   in x for name in set(check.manifest_items()) - then)]
    if run_predates_same_fields(commit):
        findings = [x for x in findings if " lacks " not in x]
    # Not asserted here: check_current (a code commit lands before its reference run; tools/check-report on
    # results/ says so, and the reference run is redone last, issue 51).
    assert findings == []
    # Likewise the claims of an experiment added since the run (its rows come with the next reference run).
    claims = check.check_claims(results)
    if then is not None:
        claims = [x for x in claims if not any(f"(experiments/manifest.tsv: {name})" in x
                                               for name in set(check.manifest_items()) - then)]
    # And the thesis items a manifest line has named since the run (issue 82: Figs. 41, 42, 47, 48, 57 reproduced):
    # their rows come with the next reference run too.
    before = items_at(commit)
    if before is not None:
        claims = [x for x in claims if not any(x == f"claims: no row for {item} (experiments/manifest.tsv: {name})"
                                               for name, items in check.manifest_items().items()
                                               for item in items - before.get(name, set()))]
    assert claims == []
