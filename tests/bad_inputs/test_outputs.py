"""Outputs written whole or not at all (issue 48, item 3). Invariants: a full disk (here a file-size limit,
which fails write(2) as a full device does) is a non-zero exit naming the file, and the folder is marked
incomplete; a symbolic link planted in --out is replaced, never written through; a subfolder that is a link is
refused; a run killed mid-write leaves no complete-looking folder (the INCOMPLETE marker, no summary.json)."""
import os
import signal
import subprocess
import time

from conftest import CASE_SECONDS, CLI, one_line_error, run

# The per-vertex search (a contact depth): the exact first-contact map of `impinge rom` takes over 30 s under the
# sanitizers, and the files are what is tested here.
FAST = ["--precision", "2", "--contact-depth", "0.25"]


def test_a_full_device_is_an_error_naming_the_file(generated, tmp_path):
    out = tmp_path / "o"
    r = subprocess.run(["bash", "-c", f"trap '' XFSZ; ulimit -f 4; exec {CLI} rom --subject {generated} "
                        f"{' '.join(FAST)} --out {out}"], capture_output=True, text=True, timeout=CASE_SECONDS)
    line = one_line_error(r, "rom_map.csv", "File too large")
    assert "summary.json" not in line
    assert (out / "INCOMPLETE").exists() and not (out / "summary.json").exists()
    assert not [p for p in os.listdir(out) if ".tmp-" in p], os.listdir(out)  # no temporary left behind


def test_a_planted_symlink_is_replaced_not_followed(generated, tmp_path):
    victim = tmp_path / "victim.txt"
    victim.write_text("precious\n")
    out = tmp_path / "o"
    out.mkdir()
    for name in ("rom_limits.csv", "summary.json", "rom_map.csv"):
        os.symlink(victim, out / name)
    r = run(["rom", "--subject", generated, "--out", out] + FAST)
    assert r.returncode == 0, r.stderr
    assert victim.read_text() == "precious\n"
    for name in ("rom_limits.csv", "summary.json", "rom_map.csv"):
        assert not os.path.islink(out / name) and (out / name).stat().st_size > 100
    assert not (out / "INCOMPLETE").exists()


def test_a_subfolder_that_is_a_link_is_refused(generated, tmp_path):
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    out = tmp_path / "o"
    out.mkdir()
    os.symlink(elsewhere, out / "gaps")
    motion = tmp_path / "m.csv"
    motion.write_text("time_s,flexion_deg,adduction_deg,internal_rotation_deg\n0,0,0,0\n")
    r = run(["motion", "--subject", generated, "--precision", "2", "--motion", motion, "--out", out])
    one_line_error(r, "gaps", "symbolic link")
    assert os.listdir(elsewhere) == []


def start_long_motion(generated, tmp_path, out):
    """`impinge motion` of 200,000 frames into `out`, started in the background (long enough to be caught running)."""
    motion = tmp_path / "m.csv"
    with open(motion, "w") as f:
        f.write("time_s,flexion_deg,adduction_deg,internal_rotation_deg\n")
        for k in range(200000):
            f.write(f"{k * 0.01},{(k % 90)},{(k % 20) - 10},{(k % 30) - 15}\n")
    return subprocess.Popen([CLI, "motion", "--subject", str(generated), "--precision", "1", "--motion", str(motion),
                             "--vtp-every", "1000", "--quiet", "--out", str(out)], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE)


def test_a_killed_run_leaves_no_complete_looking_folder(generated, tmp_path):
    out = tmp_path / "o"
    # A finished run first: its summary.json must not survive beside the killed run's files.
    assert run(["rom", "--subject", generated, "--precision", "2", "--no-map", "--out", out]).returncode == 0
    assert (out / "summary.json").exists()
    p = start_long_motion(generated, tmp_path, out)
    deadline = time.time() + 25
    while time.time() < deadline and not (out / "gaps").exists():
        time.sleep(0.02)
    time.sleep(0.3)
    p.send_signal(signal.SIGKILL)
    p.wait(timeout=10)
    assert p.returncode == -signal.SIGKILL, "the motion ended before it was killed: make it longer"
    assert (out / "INCOMPLETE").exists()
    assert not (out / "summary.json").exists()


def test_two_runs_on_one_out_the_second_refuses_and_a_killed_runs_lock_is_taken_over(generated, tmp_path):
    """Issue 80: a run owns its --out. While one runs, another on the same folder is refused naming it (command and
    pid); once the first is killed (its lock left behind), the next run takes the folder over and leaves no lock."""
    out = tmp_path / "o"
    p = start_long_motion(generated, tmp_path, out)
    deadline = time.time() + 25
    while time.time() < deadline and not (out / ".impinge.lock").exists():
        time.sleep(0.02)
    r = run(["rom", "--subject", generated, "--precision", "2", "--no-map", "--out", out])
    one_line_error(r, str(out), f"in use by impinge motion (pid {p.pid}", "give another --out")
    p.send_signal(signal.SIGKILL)
    p.wait(timeout=10)
    assert (out / ".impinge.lock").exists()  # left behind by the killed run
    r = run(["rom", "--subject", generated, "--precision", "2", "--no-map", "--out", out])
    assert r.returncode == 0, r.stderr
    assert not (out / ".impinge.lock").exists() and (out / "summary.json").exists()


def test_a_reused_out_holds_only_the_new_runs_files(generated, tmp_path):
    """Issue 80: `impinge rom` with its map, then with --no-map, on one folder: the second leaves no rom_map.csv of the
    first beside its summary; a file of the user's stays."""
    out = tmp_path / "o"
    fast = FAST
    assert run(["rom", "--subject", generated, "--out", out] + fast).returncode == 0
    assert (out / "rom_map.csv").exists()
    (out / "notes.txt").write_text("mine\n")
    assert run(["rom", "--subject", generated, "--no-map", "--out", out] + fast).returncode == 0
    assert not (out / "rom_map.csv").exists() and (out / "rom_limits.csv").exists() and (out / "notes.txt").exists()
