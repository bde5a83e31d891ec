"""Studies that notice damage (issue 48, item 4). Invariants: a finished task whose outputs were truncated,
emptied or deleted, or whose task.json is not JSON, is moved aside and redone, and the rerun's results.csv equals
the first run's (but for time and worker); a second runner on the same folder refuses while the first holds it and
takes over a dead one's; an unreachable scheduler is a one-line error."""
import csv
import os
import subprocess
import sys

import pytest

impinge = pytest.importorskip("impinge")

PY = "/usr/bin/python3" if os.path.exists("/usr/bin/python3") else sys.executable
ENV = dict(os.environ, PYTHONPATH=os.path.dirname(os.path.dirname(impinge.__file__)))
STUDY = """
subjects = [{name = "g", generated = {cam_mm = 1.0, triangles = 3000}}]
[joint]
resolution = 2.0
[[task]]
kind = "rom"
[[task]]
kind = "distance"
poses = [[30, 5, 10]]
"""
TIMING = {"time_s", "joint_build_s", "worker"}


def run_study(path, out, *extra):
    return subprocess.run([PY, "-m", "impinge.study", "run", str(path), "--out", str(out), "--workers", "0",
                           "--no-progress", *extra], env=ENV, capture_output=True, text=True, timeout=60)


def results(out):
    rows = list(csv.DictReader(open(os.path.join(out, "results.csv"))))
    return [{k: v for k, v in r.items() if k not in TIMING} for r in rows]


@pytest.fixture()
def study(tmp_path):
    path = tmp_path / "study.toml"
    path.write_text(STUDY)
    out = tmp_path / "out"
    r = run_study(path, out)
    assert r.returncode == 0, r.stderr
    return path, out, results(out)


def task_folder(out, kind):
    for name in os.listdir(os.path.join(out, "tasks")):
        f = os.path.join(out, "tasks", name)
        if not name.startswith(".") and os.path.exists(os.path.join(f, "task.json")) and \
                f'"kind": "{kind}"' in open(os.path.join(f, "task.json")).read():
            return f
    raise AssertionError(kind)


@pytest.mark.parametrize("damage", ["truncate", "empty", "delete", "task_json"])
def test_a_damaged_task_is_redone(study, damage):
    path, out, first = study
    rom = task_folder(out, "rom")
    if damage == "truncate":
        with open(os.path.join(rom, "rom_limits.csv"), "r+") as f:
            f.truncate(40)
    elif damage == "empty":
        open(os.path.join(rom, "rom_limits.csv"), "w").close()
    elif damage == "delete":
        os.remove(os.path.join(task_folder(out, "distance"), "gaps.npz"))
    else:
        with open(os.path.join(rom, "task.json"), "w") as f:
            f.write("{not json")
    r = run_study(path, out)
    assert r.returncode == 0, r.stderr
    assert "1 tasks run, 1 already done" in r.stderr, r.stderr
    assert results(out) == first
    assert any(n.startswith(".damaged-") for n in os.listdir(os.path.join(out, "tasks")))


def test_a_second_runner_refuses_and_a_dead_ones_lock_is_taken_over(study):
    path, out, first = study
    lock = os.path.join(out, ".lock")
    import socket
    with open(lock, "w") as f:  # a live runner: this test's own process
        f.write(f"{socket.gethostname()} {os.getpid()}\n")
    r = run_study(path, out)
    assert r.returncode == 2 and "another runner" in r.stderr and str(os.getpid()) in r.stderr, r.stderr
    with open(lock, "w") as f:  # a dead one
        f.write(f"{socket.gethostname()} 999999999\n")
    r = run_study(path, out)
    assert r.returncode == 0, r.stderr
    assert not os.path.exists(lock)


def test_an_unreachable_scheduler_is_one_line(study):
    path, out, _ = study
    os.remove(os.path.join(task_folder(out, "rom"), "rom_limits.csv"))  # so that there is a task to run
    r = subprocess.run([PY, "-m", "impinge.study", "run", str(path), "--out", str(out), "--scheduler",
                        "tcp://127.0.0.1:9", "--no-progress"], env=ENV, capture_output=True, text=True, timeout=60)
    lines = [x for x in r.stderr.splitlines() if x.startswith("impinge.study: --scheduler")]
    assert r.returncode == 2 and len(lines) == 1 and "Traceback" not in r.stderr, r.stderr


def test_shards_share_a_folder_but_a_whole_run_waits_for_them(study, tmp_path):
    path, _, first = study
    out = tmp_path / "shared"
    procs = [subprocess.Popen([PY, "-m", "impinge.study", "run", str(path), "--out", str(out), "--workers", "0",
                               "--no-progress", "--shard", f"{i}/2"], env=ENV, stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, text=True) for i in (0, 1)]
    for p in procs:
        _, err = p.communicate(timeout=60)
        assert p.returncode == 0, err
    import socket
    with open(out / ".lock-0-of-2", "w") as f:  # a live shard runner: this process
        f.write(f"{socket.gethostname()} {os.getpid()}\n")
    r = run_study(path, out)
    assert r.returncode == 2 and "another runner" in r.stderr, r.stderr
