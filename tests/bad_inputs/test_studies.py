"""Studies that notice damage (issue 48, item 4) and keep their inputs and folder straight (issue 80, items 4 and
7). Invariants: a finished task whose outputs were truncated, emptied or deleted, or whose task.json is not JSON, is
moved aside and redone, and the rerun's results.csv equals the first run's (but for time and worker); a second
runner on the same folder refuses while the first holds it (naming it, as the CLI's output-folder lock does) and
takes over a dead one's or an empty lock; a study's paths are its folder's, wherever it runs from; a task's id
hashes every file it reads, so editing one reruns exactly the tasks that read it; two motion files with one
basename stay apart; a bad setting, an --out that cannot be written and a scheduler that cannot come are one line
(exit 2) before any task runs."""
import csv
import json
import os
import socket
import subprocess
import sys
import time

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


def run_study(path, out, *extra, **kw):
    return subprocess.run([PY, "-m", "impinge.study", "run", str(path), "--out", str(out), "--workers", "0",
                           "--no-progress", *extra], env=ENV, capture_output=True, text=True, timeout=60, **kw)


def results(out, ignore=TIMING):
    rows = list(csv.DictReader(open(os.path.join(out, "results.csv"))))
    return [{k: v for k, v in r.items() if k not in ignore} for r in rows]


def one_line(r, *fragments):
    """The study failed with exit 2 and one line on stderr, 'impinge.study: ...' holding every fragment."""
    lines = r.stderr.splitlines()
    assert r.returncode == 2 and len(lines) == 1 and lines[0].startswith("impinge.study: "), (r.returncode, r.stderr)
    for f in fragments:
        assert f in lines[0], (f, lines[0])
    return lines[0]


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


def dead_pid():
    """The pid of a process of this host that has ended."""
    p = subprocess.Popen(["true"])
    p.wait()
    return p.pid


@pytest.mark.parametrize("left", ["empty", "dead", "dead, an earlier runner's lock"])
def test_an_empty_lock_or_a_dead_runners_is_taken_over(study, left):
    """A lock with no pid (the disk was full when it was written) or whose process has ended is taken over, as the
    CLI's output-folder lock is: the run goes on (and, with a task to do, does it)."""
    path, out, first = study
    os.remove(os.path.join(task_folder(out, "rom"), "rom_limits.csv"))  # a task to do
    lock = os.path.join(out, ".lock")
    host = socket.gethostname()
    with open(lock, "w") as f:
        f.write({"empty": "", "dead": f"{dead_pid()} {host} impinge.study run 2020-01-01T00:00:00Z\n",
                 "dead, an earlier runner's lock": f"{host} {dead_pid()}\n"}[left])
    r = run_study(path, out)
    assert r.returncode == 0 and "1 tasks run, 1 already done" in r.stderr, r.stderr
    assert results(out) == first and not os.path.exists(lock)


@pytest.mark.parametrize("where", ["this host", "another host"])
def test_a_live_runners_lock_is_refused_naming_it(study, where):
    """A runner of this host that still runs (this test's process), or one of another host (whether it runs cannot
    be told from here), holds the folder: one line naming it, nothing run, the lock left as it was."""
    path, out, _ = study
    os.remove(os.path.join(task_folder(out, "rom"), "rom_limits.csv"))
    lock = os.path.join(out, ".lock")
    host = socket.gethostname() if where == "this host" else "elsewhere.example"
    text = f"{os.getpid()} {host} impinge.study run 2020-01-01T00:00:00Z\n"
    with open(lock, "w") as f:
        f.write(text)
    r = run_study(path, out)
    if where == "this host":
        one_line(r, f"{out}: in use by impinge.study run (pid {os.getpid()}, since 2020-01-01T00:00:00Z): wait for "
                    "it to end, or give another --out")
    else:
        one_line(r, f"{out}: in use by impinge.study run on elsewhere.example (pid {os.getpid()}, since "
                    f"2020-01-01T00:00:00Z); if that run has ended, remove {lock}")
    assert open(lock).read() == text and not os.path.exists(os.path.join(task_folder(out, "rom"), "rom_limits.csv"))


def test_a_lock_that_cannot_be_written_is_removed(tmp_path, monkeypatch):
    """A full disk while the lock is written: a one-line error, and no empty lock left behind to refuse the runs
    after it."""
    from impinge.study import lock as lock_mod
    from impinge.study.spec import StudyError

    def full(fd, data):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(lock_mod.os, "write", full)
    with pytest.raises(StudyError, match="cannot write the study folder's lock \\(is the disk full\\?\\)"):
        with lock_mod.OutLock(str(tmp_path)):
            pass
    assert os.listdir(tmp_path) == []


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
    with open(out / ".lock-0-of-2", "w") as f:  # a live shard runner: this process
        f.write(f"{os.getpid()} {socket.gethostname()} impinge.study run --shard 0/2 2020-01-01T00:00:00Z\n")
    r = run_study(path, out)
    one_line(r, f"in use by impinge.study run --shard 0/2 (pid {os.getpid()}, since 2020-01-01T00:00:00Z)")


def write_motion(path, frames, flexion_to=90.0):
    """A CSV motion of `frames` frames: flexion 0..flexion_to deg with adduction and internal rotation rising (a
    FADIR sweep) -> its frame count."""
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w") as f:
        f.write("time_s,flexion_deg,adduction_deg,internal_rotation_deg\n")
        for k in range(frames):
            x = k / max(frames - 1, 1)
            f.write(f"{0.05 * k:.4f},{flexion_to * x:.4f},{15 * x:.4f},{35 * x:.4f}\n")
    return frames


def plan_targets(out, given):
    """plan.json's targets of the plan task whose target_motion is `given`."""
    for row in results(out):
        if row["kind"] == "plan" and row["target_motion"] == given:
            return json.load(open(os.path.join(out, "tasks", row["task_id"], "plan.json")))["targets"]
    raise AssertionError(given)


PLANS = """
subjects = [{name = "g", generated = {cam_mm = 1.0, triangles = 3000}}]
[joint]
resolution = 2.0
[[task]]
kind = "plan"
target_motion = "motions/a.csv"
[[task]]
kind = "plan"
target_motion = "motions/b.csv"
[[task]]
kind = "motion"
motion = "motions/a.csv"
"""


def test_a_study_reads_its_own_folders_files_wherever_it_runs(tmp_path):
    """Paths in a study file are relative to its folder: run from another folder that holds other files under the
    same names, the study reads its own (the plan's target and the motion task have the study's frame counts) and
    gives the same results."""
    home, elsewhere = tmp_path / "study", tmp_path / "elsewhere"
    n_a = write_motion(str(home / "motions" / "a.csv"), 31)
    write_motion(str(home / "motions" / "b.csv"), 12, flexion_to=40)
    write_motion(str(elsewhere / "motions" / "a.csv"), 7, flexion_to=20)  # same names, other motions
    write_motion(str(elsewhere / "motions" / "b.csv"), 5, flexion_to=10)
    (home / "study.toml").write_text(PLANS)
    runs = {}
    for cwd in (home, elsewhere):
        out = tmp_path / f"out-{cwd.name}"
        r = run_study(home / "study.toml", out, cwd=cwd)
        assert r.returncode == 0, r.stderr
        runs[cwd.name] = out
    plan_ms = TIMING | {"plan_ms"}
    assert results(runs["study"], plan_ms) == results(runs["elsewhere"], plan_ms)
    for out in runs.values():
        target = plan_targets(out, "motions/a.csv")
        assert len(target) == 1 and target[0]["target"] == "motions/a.csv" and target[0]["poses"] == n_a
        assert [row["frames"] for row in results(out) if row["kind"] == "motion"] == [str(n_a)]


def test_editing_a_target_motion_reruns_exactly_the_tasks_that_read_it(tmp_path):
    """A task's id hashes every file it reads: after editing motions/b.csv (only the second plan reads it), a rerun
    runs that one task again, on the new file, and leaves the plan and the motion task that read a.csv alone."""
    write_motion(str(tmp_path / "motions" / "a.csv"), 31)
    write_motion(str(tmp_path / "motions" / "b.csv"), 12, flexion_to=40)
    (tmp_path / "study.toml").write_text(PLANS)
    out = tmp_path / "out"
    assert run_study(tmp_path / "study.toml", out).returncode == 0
    before = {(r["kind"], r["target_motion"]): r["task_id"] for r in results(out)}
    n_b = write_motion(str(tmp_path / "motions" / "b.csv"), 9, flexion_to=50)
    r = run_study(tmp_path / "study.toml", out)
    assert r.returncode == 0 and "1 tasks run, 2 already done" in r.stderr, r.stderr
    after = {(r["kind"], r["target_motion"]): r["task_id"] for r in results(out)}
    changed = {k for k in before if before[k] != after[k]}
    assert changed == {("plan", "motions/b.csv")}, (before, after)
    assert plan_targets(out, "motions/b.csv")[0]["poses"] == n_b


def test_two_motion_files_with_one_basename_stay_apart(tmp_path):
    """left/walk.csv and right/walk.csv are two motions: results.csv names them by as much of their path as keeps
    them apart (a file whose basename is its own keeps it), each with its own frames, and summary.csv does not
    pool them."""
    frames = {"left/walk.csv": write_motion(str(tmp_path / "left" / "walk.csv"), 11),
              "right/walk.csv": write_motion(str(tmp_path / "right" / "walk.csv"), 17, flexion_to=60),
              "run.csv": write_motion(str(tmp_path / "right" / "run.csv"), 6, flexion_to=30)}
    (tmp_path / "study.toml").write_text(STUDY.split("[[task]]")[0] + '[[task]]\nkind = "motion"\nmotion = '
                                         '["left/walk.csv", "right/walk.csv", "right/run.csv"]\n')
    out = tmp_path / "out"
    r = run_study(tmp_path / "study.toml", out)
    assert r.returncode == 0, r.stderr
    assert {row["motion"]: int(row["frames"]) for row in results(out)} == frames
    summary = [row for row in csv.DictReader(open(out / "summary.csv")) if row["figure"] == "frames"]
    assert sorted(float(row["nominal"]) for row in summary) == sorted(frames.values())
    assert all(row["n"] == "1" for row in summary)


@pytest.mark.parametrize("body, fragments", [
    ("[joint]\nresolution = -1.0\n", ["joint.resolution: -1 is outside the valid range"]),
    ("[joint]\nresolution = 7.0\n", ["joint.resolution = 7.0: ",
                                     "precision 7 deg: must be in (0, 90] and divide 180"]),
    ("[[task]]\nkind = 'rom'\nresolution = [2.0, 7.0]\n", ["task[0].resolution[1] = 7.0: "]),
    ("[[task]]\nkind = 'rom'\nscheme = 'healpix'\nresolution = 2.5\n",
     ["task[0].resolution = 2.5, task[0].scheme = \"healpix\": ", "nside 2.5 must be a whole number"]),
    ("[[task]]\nkind = 'rom'\njoint_centre = ['femoral-head', 'nearest']\n",
     ["task[0].joint_centre[1]: 'nearest' is not one of"]),
    ("[[task]]\nkind = 'rom'\nstep_deg = 0\n", ["task[0].step_deg: 0 deg is outside the valid range"]),
    ("[[task]]\nkind = 'plan'\ntarget = 'flexion=500'\n", ["task[0].target = \"flexion=500\": ",
                                                          "the angle must lie in (0, 150] deg"]),
    ("[[task]]\nkind = 'plan'\n", ["plan: no target"]),
    ("[joint]\npreset = 'thesis'\n[[task]]\nkind = 'envelope'\n",
     ["task[0].metric: 'distance' (the default) needs the Joint's distances"]),
    ("[[task]]\nkind = 'motion'\nmotion = 'bad.csv'\n", ["task[0].motion: ", "bad.csv"]),
])
def test_a_bad_setting_is_one_error_before_any_task_runs(tmp_path, body, fragments):
    """Every key's value (each value a sweep gives, and the Joint's settings together) is checked by the option
    table's own checks, and every motion file read, before anything is written: one line naming the key."""
    (tmp_path / "bad.csv").write_text("time_s,flexion_deg,adduction_deg,internal_rotation_deg\n0,10,0\n")
    subjects = 'subjects = [{name = "g", generated = {cam_mm = 1.0, triangles = 3000}}]\n'
    tail = "" if "[[task]]" in body else "[[task]]\nkind = 'rom'\n"
    (tmp_path / "study.toml").write_text(subjects + body + tail)
    out = tmp_path / "out"
    one_line(run_study(tmp_path / "study.toml", out), f"{tmp_path / 'study.toml'}: ", *fragments)
    assert not os.path.exists(out)  # no task ran: nothing was written


def drop_root_override():
    """In the child, as root: give up overriding file permissions (CAP_DAC_OVERRIDE, CAP_DAC_READ_SEARCH), so that
    a read-only folder is read-only to it too."""
    import ctypes
    libc = ctypes.CDLL(None, use_errno=True)
    for cap in (1, 2):  # PR_CAPBSET_DROP: root's capabilities after exec are the bounding set's
        if libc.prctl(24, cap, 0, 0, 0) != 0:
            os._exit(99)


@pytest.mark.parametrize("case", ["a file", "read-only", "in a read-only folder"])
def test_an_out_that_cannot_be_written_is_one_line(study, tmp_path, case):
    path, _, _ = study
    target = tmp_path / "target"
    if case == "a file":
        target.write_text("not a folder")
        out = target
    else:
        target.mkdir()
        out = target if case == "read-only" else target / "out"
        os.chmod(target, 0o555)
    try:
        r = run_study(path, out, preexec_fn=drop_root_override if os.geteuid() == 0 else None)
    finally:
        os.chmod(target, 0o755)
    assert r.returncode != 99, "cannot drop root's permission override here"
    assert "Traceback" not in r.stderr
    one_line(r, str(out), {"a file": "not a folder (the study folder must be one", "read-only": "Permission denied",
                           "in a read-only folder": "cannot create the study folder (Permission denied)"}[case])


def test_a_scheduler_file_in_a_missing_folder_fails_at_once(study, tmp_path):
    """The scheduler file of a folder that does not exist cannot come: an error at once naming it, not a wait of
    120 s."""
    path, out, _ = study
    os.remove(os.path.join(task_folder(out, "rom"), "rom_limits.csv"))  # so that there is a task to run
    sched = tmp_path / "nowhere" / "scheduler.json"
    t0 = time.monotonic()
    r = run_study(path, out, "--scheduler", str(sched))
    one_line(r, f"--scheduler {sched}: no such folder {tmp_path / 'nowhere'}")
    assert time.monotonic() - t0 < 20
