"""tools/check-paper-numbers: it flags numbers typed in the paper's prose and lets through the kinds
of number its documentation allows; the paper's sections pass it."""
import os
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TOOL = os.path.join(ROOT, "tools", "check-paper-numbers")


def run(text):
    with tempfile.NamedTemporaryFile("w", suffix=".tex", delete=False) as f:
        f.write(text)
    try:
        return subprocess.run([sys.executable, TOOL, f.name], capture_output=True, text=True)
    finally:
        os.unlink(f.name)


def test_typed_measurements_are_flagged():
    for text, number in [("The pelvis rasterises in 15.2~ms.", "15.2"),
                         ("a speed-up of 10--20 times", "10"),
                         ("at $0.05^\\circ$ precision", "0.05"),
                         ("it saves 19\\% of the memory", "19"),
                         ("counts 3,601 nodes", "3,601")]:
        r = run(text)
        assert r.returncode == 1, text
        assert f": {number}\t" in r.stdout, (text, r.stdout)


def test_allowed_numbers_pass():
    text = r"""\section{Map size (thesis Tables 2, 6 and~7; Fig.~49)}
\label{sec:x1}\input{01_lut_memory/macros}
Issue~4 asks for \given{5}$\times$; the thesis prints \thesis{0.497}; Audenaert et al.\ (2012) report
\cited{27.9}~deg. At \given{$0.1^\circ$} the map of $(180/p+1)\times(360/p)$ nodes, $k = 229$, AVX-512
kernels, the 95th percentile, (1)~first. \includegraphics[width=0.48\textwidth]{a1.pdf}
\begin{equation} L = 4k + 1/2 \end{equation} measured \SampCulledMs~ms (\texttt{BM\_Rasterize/1/3/2}).
% a comment with 42 ms
"""
    r = run(text)
    assert r.returncode == 0, r.stdout


def test_the_paper_passes():
    r = subprocess.run([sys.executable, TOOL], capture_output=True, text=True)
    assert r.returncode == 0, r.stdout


def run_named(name, text, tmp_path):
    path = tmp_path / name
    path.write_text(text)
    return subprocess.run([sys.executable, TOOL, str(path)], capture_output=True, text=True)


def test_summary_number_words_are_flagged(tmp_path):
    """Issue 82, item 4: in the abstract and the conclusion a number written as a word is a number."""
    for text, word in [("faster than FCL by one to two orders of\nmagnitude on the real hips", "one"),
                       ("Three findings are refuted", "Three"),
                       ("the saving of about a fifth of the nodes", "a fifth"),
                       ("samples orders of magnitude faster", "orders of magnitude"),
                       ("it is twice as fast", "twice")]:
        for name in ("99_conclusion.tex", "00_abstract.tex"):
            r = run_named(name, text, tmp_path)
            assert r.returncode == 1, (name, text)
            assert f": {word}\t" in r.stdout, (name, text, r.stdout)


def test_summary_number_words_pass_from_macros_and_elsewhere(tmp_path):
    ok = (r"\ClaimsNot{} findings do not hold; one of the hips; \thesis{two} detectors; FCL takes "
          r"\ConclFclAllLow--\ConclFclAllHigh{} times as long.")
    assert run_named("99_conclusion.tex", ok, tmp_path).returncode == 0
    # Outside the abstract and the conclusion, words are prose (digits are still checked).
    assert run_named("05_slices.tex", "Three findings, one to two orders of magnitude.", tmp_path).returncode == 0
