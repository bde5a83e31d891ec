"""Shared fixtures of the bad-input suite: the CLI, a generated hip, and a runner that bounds every case's time."""
import os
import subprocess

import pytest

CLI = os.environ.get("IMPINGE_CLI", os.path.join(os.path.dirname(__file__), "..", "..", "build", "impinge"))
DATA = os.environ.get("IMPINGE_SHARED_DATA", os.path.join(os.path.dirname(__file__), "..", "..", "..", "shared",
                                                          "data", "hips"))
# Every case ends within this (issue 48): a hang fails, it does not stall the suite. Under the sanitizers
# (IMPINGE_SANITIZED, set by tests/CMakeLists.txt) a command runs 10 to 25 times slower, and on CI's two busy cores
# a plan of 11 s idle ran past 30 s: four times as long there.
CASE_SECONDS = 120 if os.environ.get("IMPINGE_SANITIZED") == "1" else 30


def run(args, **kw):
    """The CLI with `args` (list), its exit code, stdout and stderr; a case that runs past CASE_SECONDS fails."""
    try:
        return subprocess.run([CLI] + [str(a) for a in args], capture_output=True, text=True, timeout=CASE_SECONDS,
                              **kw)
    except subprocess.TimeoutExpired:
        pytest.fail(f"impinge {' '.join(map(str, args))}: still running after {CASE_SECONDS} s")


def one_line_error(r, *fragments):
    """The run failed with exit 2 and one line 'impinge: error: ...' holding every fragment."""
    lines = [x for x in r.stderr.splitlines() if x.startswith("impinge: error:")]
    assert r.returncode == 2 and len(lines) == 1, (r.returncode, r.stderr)
    for f in fragments:
        assert f in lines[0], (f, lines[0])
    return lines[0]


@pytest.fixture(scope="session")
def generated(tmp_path_factory):
    """A generated hip (3,000 triangles): its subject.json path."""
    d = tmp_path_factory.mktemp("generated")
    r = run(["generate", "--triangles", "3000", "--out", d / "g"])
    assert r.returncode == 0, r.stderr
    return d / "g" / "subject.json"
