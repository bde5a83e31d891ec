"""Issue 80, case 5: `--triangles 20` was refused as below 50 while the help said it took 20 and up. The help now
states the range the option is checked against (from the one table): both ends are accepted, the values beside them
refused naming that range, by the CLI and by Python alike."""
import re

import pytest

from conftest import one_line_error, run


def test_help_and_the_check_state_the_same_range(tmp_path):
    h = run(["generate", "--help"])
    assert h.returncode == 0, h.stderr
    line = next(x for x in h.stdout.splitlines() if "--triangles" in x)
    low, high = (int(x) for x in re.search(r"\[(\d+), (\d+)\]", line).groups())
    for bad in (low - 1, high + 1, 20):
        one_line_error(run(["generate", "--triangles", bad, "--out", tmp_path / f"g{bad}"]),
                       f"--triangles: {bad} is outside the valid range [{low}, {high}]")
    r = run(["generate", "--triangles", low, "--out", tmp_path / "low"])
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "low" / "subject.json").exists()
    impinge = pytest.importorskip("impinge")
    with pytest.raises(impinge.Error, match=re.escape(f"triangles: {low - 1} is outside the valid range [{low}, "
                                                      f"{high}]")):
        impinge.generated_hip(triangles=low - 1)
    option = next(o for o in impinge.options() if o["key"] == "triangles")
    assert (option["min"], option["max"]) == (low, high)
    assert f"[{low}, {high}]" in option["help"]
