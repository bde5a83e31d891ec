"""impinge.study against its own serial run, which is the oracle: a study's results do not depend on where
or in how many pieces its tasks ran.

Invariants: the local Dask cluster's results.csv equals the serial one value for value (all but time and
worker); a worker killed mid-study changes nothing; an interrupted run, run again, redoes only the unfinished
tasks and leaves the finished ones untouched; four shards merged equal one run; a task that raises is
recorded and the others finish; a task's id changes with its inputs' contents; bad study files fail with one
line naming the key; the Slurm script's commands run a study on loopback; VTK meshes give the PLY's gaps."""
import csv
import os
import shutil
import signal
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

import impinge
from impinge import study
from impinge.study import runner, spec
from impinge.vtk_meshes import polydata as vtk_polydata

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, "..", ".."))
MOTIONS = os.path.join(ROOT, "examples", "motions")
PY = "/usr/bin/python3" if os.path.exists("/usr/bin/python3") else sys.executable
ENV = dict(os.environ, PYTHONPATH=os.path.dirname(os.path.dirname(impinge.__file__)))


def write_study(folder, body, name="study.toml"):
    path = os.path.join(folder, name)
    with open(path, "w") as f:
        f.write(body)
    return path


# Two generated hips (no cam, 2 mm cam), every task kind, 3 COR perturbations: 8 groups, 40 tasks.
GENERATED = f"""
seed = 11
subjects = [{{name = "cam0", generated = {{cam_mm = 0.0, triangles = 4000}}}},
            {{name = "cam2", generated = {{cam_mm = 2.0, triangles = 4000}}}}]
[joint]
resolution = 1.0
[[task]]
kind = "rom"
[[task]]
kind = "envelope"
flexion = [0, 45, 90]
adduction = [-10, 0, 10]
[[task]]
kind = "motion"
motion = ["{MOTIONS}/fadir_sweep.csv"]
[[task]]
kind = "distance"
poses = [[0, 0, 0], [90, 0, 20]]
[perturb]
cor_sd_mm = 1.0
samples = 3
"""


@pytest.fixture(scope="module")
def serial(tmp_path_factory):
    """The generated study run here, serially, without Dask: the reference."""
    folder = tmp_path_factory.mktemp("serial")
    path = write_study(str(folder), GENERATED)
    s = study.run(path, str(folder / "out"), workers=0, progress=False, log=lambda _: None)
    return path, str(folder / "out"), s


def read(out, name="results.csv"):
    return runner.read_results(os.path.join(out, name))


def test_serial_study_writes_every_task_and_its_figures(serial):
    path, out, s = serial
    rows = read(out)
    # 2 subjects x 4 COR samples (8 groups) x (rom, envelope, motion, 2 distance poses)
    assert s["tasks"] == len(rows) == 40 and all(r["status"] == "ok" for r in rows)
    for r in rows:  # each task's own outputs, complete
        files = set(os.listdir(os.path.join(out, "tasks", r["task_id"])))
        assert "task.json" in files
        assert {"rom": "rom_limits.csv", "envelope": "rom_map.csv", "motion": "frames.csv",
                "distance": "gaps.npz"}[r["kind"]] in files
    # sample 0 is the nominal COR; the others move it, the same offset in every task of a subject and sample
    offsets = {}
    for r in rows:
        d = (r["cor_dx_mm"], r["cor_dy_mm"], r["cor_dz_mm"])
        assert (r["sample"] == "0") == (d == ("0.0", "0.0", "0.0"))
        offsets.setdefault((r["subject"], r["sample"]), set()).add(d)
    assert all(len(v) == 1 for v in offsets.values())
    # the nominal rom task equals Joint.rom_limits on the same hip (an independent call of the module)
    h = impinge.generated_hip(triangles=4000, cam_mm=2.0)
    j = impinge.Joint(h["femur"], h["pelvis"], neutral="scan", resolution=1.0)
    lim = j.rom_limits()
    nominal = next(r for r in rows if r["kind"] == "rom" and r["subject"] == "cam2" and r["sample"] == "0")
    for m in ("flexion", "internal_rotation", "abduction"):
        assert float(nominal[f"limit_{m}_deg"]) == lim[m]["limit_deg"]
    # summary: per subject and figure, the statistics of the 4 samples
    summary = read(out, "summary.csv")
    flex = next(x for x in summary if x["subject"] == "cam2" and x["figure"] == "limit_flexion_deg")
    values = [float(r["limit_flexion_deg"]) for r in rows if r["kind"] == "rom" and r["subject"] == "cam2"]
    assert int(flex["n"]) == 4 and float(flex["mean"]) == pytest.approx(np.mean(values))
    assert float(flex["nominal"]) == float(nominal["limit_flexion_deg"])
    assert {"limits.png", "sensitivity.png", "motion_min_gap.png"} <= set(os.listdir(os.path.join(out, "figures")))


def test_local_cluster_with_a_worker_killed_equals_the_serial_run(serial, tmp_path):
    path, ref, _ = serial
    out = str(tmp_path / "dask")
    killed = {}

    def kill_one_worker(client):
        pids = client.run(os.getpid)  # worker address -> pid

        def killer():
            tasks = os.path.join(out, "tasks")
            while not [n for n in os.listdir(tasks) if not n.startswith(".")]:
                time.sleep(0.05)
            killed["finished_then"] = len([n for n in os.listdir(tasks) if not n.startswith(".")])
            os.kill(sorted(pids.values())[0], signal.SIGKILL)

        threading.Thread(target=killer, daemon=True).start()

    s = study.run(path, out, workers=2, progress=False, log=lambda _: None, on_start=kill_one_worker)
    assert 0 < killed["finished_then"] < 40  # the kill came mid-study
    assert s["workers"] == 2 and s["errors"] == 0
    assert runner.nan_equal_rows(read(ref), read(out))


def test_an_interrupted_run_redoes_only_its_unfinished_tasks(serial, tmp_path):
    path, ref, _ = serial
    out = str(tmp_path / "interrupted")
    p = subprocess.Popen([PY, "-m", "impinge.study", "run", path, "--out", out, "--workers", "0", "--no-progress"],
                         env=ENV, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
    tasks = os.path.join(out, "tasks")
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and p.poll() is None:
        if os.path.isdir(tasks) and len([n for n in os.listdir(tasks) if not n.startswith(".")]) >= 10:
            break
        time.sleep(0.02)
    os.killpg(p.pid, signal.SIGKILL)
    p.wait()
    finished = {n: os.stat(os.path.join(tasks, n, "task.json")) for n in os.listdir(tasks) if not n.startswith(".")}
    assert 10 <= len(finished) < 40
    s = study.run(path, out, workers=0, progress=False, log=lambda _: None)
    assert s["skipped"] == len(finished) and s["ran"] == 40 - len(finished)
    for n, st in finished.items():  # the finished tasks were not touched
        now = os.stat(os.path.join(tasks, n, "task.json"))
        assert (now.st_ino, now.st_mtime_ns) == (st.st_ino, st.st_mtime_ns)
    assert not [n for n in os.listdir(tasks) if n.startswith(".tmp-")]
    assert runner.nan_equal_rows(read(ref), read(out))


def test_four_shards_merged_equal_one_run(serial, tmp_path):
    path, ref, _ = serial
    shards = []
    for i in range(4):
        d = str(tmp_path / f"shard{i}")
        r = subprocess.run([PY, "-m", "impinge.study", "run", path, "--out", d, "--workers", "0", "--shard",
                            f"{i}/4", "--no-progress"], env=ENV, capture_output=True, text=True)
        assert r.returncode == 0, r.stderr
        assert not os.path.exists(os.path.join(d, "results.csv"))  # a shard has only its slice
        assert os.path.exists(os.path.join(d, "shards", f"results-{i}-of-4.csv"))
        shards.append(d)
    sizes = [len(read(d, f"shards/results-{i}-of-4.csv")) for i, d in enumerate(shards)]
    assert sum(sizes) == 40 and min(sizes) > 0
    merged = str(tmp_path / "merged")
    with pytest.raises(spec.StudyError, match="is in none of"):
        study.merge(merged, shards[:3], log=lambda _: None)
    r = subprocess.run([PY, "-m", "impinge.study", "merge", "--out", merged] + shards, env=ENV,
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert runner.nan_equal_rows(read(ref), read(merged))
    with open(os.path.join(ref, "summary.csv")) as a, open(os.path.join(merged, "summary.csv")) as b:
        assert a.read() == b.read()


def test_a_task_that_raises_is_recorded_and_the_others_finish(tmp_path):
    """A setting the table accepts but the hip cannot serve (anatomical neutral needs a whole pelvis; a generated
    hip has only its cup) fails its task when it runs; a bad value fails the whole study before any task runs
    (tests/bad_inputs/test_studies.py)."""
    path = write_study(str(tmp_path), """
subjects = [{name = "g", generated = {triangles = 3000}}]
[joint]
resolution = 2.0
[[task]]
kind = "rom"
neutral = ["scan", "anatomical"]
""")
    r = subprocess.run([PY, "-m", "impinge.study", "run", path, "--out", str(tmp_path / "o"), "--workers", "0",
                        "--no-progress"], env=ENV, capture_output=True, text=True)
    assert r.returncode == 1, r.stderr  # the study finished, with an error to report
    rows = read(str(tmp_path / "o"))
    assert [x["status"] for x in rows] == ["ok", "error"]
    assert "anatomical neutral needs a whole femur and pelvis" in rows[1]["error"]
    assert rows[1]["limit_flexion_deg"] == ""
    assert float(rows[0]["limit_flexion_deg"]) > 0


def test_a_task_id_is_its_inputs_contents(tmp_path):
    h = impinge.generated_hip(triangles=3000)
    folder = tmp_path / "subj"
    folder.mkdir()
    for name, (V, F) in (("femur_r.ply", h["femur"]), ("pelvis.ply", h["pelvis"])):
        write_ply(str(folder / name), V, F)
    (folder / "subject.json").write_text('{"side": "right", "frame": "RAS", "units": "mm", "femur": "femur_r.ply", '
                                         '"pelvis": "pelvis.ply", "neutral": "scan"}')
    body = 'subjects = ["subj"]\n[[task]]\nkind = "distance"\nresolution = [1.0, 2.0]\nposes = [[0, 0, 0]]\n'
    path = write_study(str(tmp_path), body)
    ids = [t["id"] for t in spec.expand(spec.load_study(path))]
    assert len(ids) == 2 and len(set(ids)) == 2  # parameters enter the id
    assert [t["id"] for t in spec.expand(spec.load_study(path))] == ids  # and nothing else that varies
    V, F = h["pelvis"]
    write_ply(str(folder / "pelvis.ply"), V + np.array([0.0, 0.0, 1e-3]), F)  # a mesh's contents change
    assert not set(ids) & {t["id"] for t in spec.expand(spec.load_study(path))}


def write_ply(path, V, F):
    with open(path, "wb") as f:
        f.write(f"ply\nformat binary_little_endian 1.0\nelement vertex {len(V)}\nproperty double x\n"
                f"property double y\nproperty double z\nelement face {len(F)}\nproperty list uchar int "
                f"vertex_indices\nend_header\n".encode())
        f.write(np.asarray(V, dtype="<f8").tobytes())
        faces = np.zeros(len(F), dtype=[("n", "u1"), ("i", "<i4", 3)])
        faces["n"] = 3
        faces["i"] = F
        f.write(faces.tobytes())


@pytest.mark.parametrize("body, key", [
    ("subjects = []\n[[task]]\nkind = 'rom'\n", "subjects"),
    ("seed = 1\n[[task]]\nkind = 'rom'\n", "subjects"),
    ("subjects = ['nowhere/*/subject.json']\n[[task]]\nkind = 'rom'\n", "subjects[0]"),
    ("subjects = [{generated = {}}]\n", "task"),
    ("subjects = [{generated = {}}]\n[[task]]\nkind = 'walk'\n", "task[0].kind"),
    ("subjects = [{generated = {}}]\n[[task]]\nkind = 'rom'\nthreshold = 1\n", "task[0].threshold"),
    ("subjects = [{generated = {}}]\n[[task]]\nkind = 'rom'\nresolution = 'fine'\n", "task[0].resolution"),
    ("subjects = [{generated = {}}]\n[[task]]\nkind = 'motion'\n", "task[0].motion"),
    ("subjects = [{generated = {}}]\n[[task]]\nkind = 'motion'\nmotion = 'none.mot'\n", "task[0].motion"),
    ("subjects = [{generated = {}}]\n[[task]]\nkind = 'distance'\nposes = [[1, 2]]\n", "task[0].poses[0]"),
    ("subjects = [{generated = {}}]\n[[task]]\nkind = 'rom'\n[perturb]\nsamples = -1\n", "perturb.samples"),
    ("subjects = [{generated = {}}]\n[[task]]\nkind = 'rom'\n[perturb]\ncor_sd = 1\n", "perturb.cor_sd"),
    ("subjects = [{generated = {}}]\n[[task]]\nkind = 'rom'\n[joint]\nresolutoin = 1\n", "joint.resolutoin"),
    ("subjects = [{generated = {}}]\nworkers = 2\n[[task]]\nkind = 'rom'\n", "workers"),
    ("subjects = [{generated = {}}\n", None),  # not TOML
])
def test_bad_study_files_fail_with_one_line_naming_the_key(tmp_path, body, key):
    path = write_study(str(tmp_path), body)
    with pytest.raises(spec.StudyError) as e:
        spec.expand(spec.load_study(path))
    msg = str(e.value)
    assert "\n" not in msg and msg.startswith(path)
    assert (f": {key}:" in msg) if key else "not TOML" in msg
    r = subprocess.run([PY, "-m", "impinge.study", "run", path, "--out", str(tmp_path / "o")], env=ENV,
                       capture_output=True, text=True)
    assert r.returncode == 2 and r.stderr.count("\n") == 1 and path in r.stderr


def test_the_slurm_script_runs_a_study_on_loopback(serial, tmp_path):
    path, ref, _ = serial
    out = str(tmp_path / "slurm")
    env = dict(ENV, SRUN="", SCHEDULER_HOST="127.0.0.1", DASK_WORKERS="2", IMPINGE_PYTHON=PY)
    r = subprocess.run([os.path.join(ROOT, "docs", "slurm", "impinge-study.sbatch"), path, out], env=env,
                       capture_output=True, text=True, timeout=400)
    assert r.returncode == 0, r.stderr[-2000:]
    rows = read(out)
    assert len({x["worker"] for x in rows}) == 2  # both of the script's workers ran tasks
    assert runner.nan_equal_rows(read(ref), rows)


def test_vtk_meshes_give_the_ply_gaps(tmp_path):
    from vtkmodules.vtkIOLegacy import vtkPolyDataWriter
    from vtkmodules.vtkIOXML import vtkXMLPolyDataWriter

    h = impinge.generated_hip(triangles=3000, cam_mm=2.0)
    folder = tmp_path / "vtk_subject"
    folder.mkdir()
    w = vtkXMLPolyDataWriter()  # OpenSim's geometry: XML PolyData
    w.SetFileName(str(folder / "femur_r.vtp"))
    w.SetInputData(vtk_polydata(*h["femur"]))
    w.Write()
    w = vtkPolyDataWriter()  # the legacy format (binary: ASCII would round the coordinates)
    w.SetFileTypeToBinary()
    w.SetFileName(str(folder / "pelvis.vtk"))
    w.SetInputData(vtk_polydata(*h["pelvis"]))
    w.Write()
    V, F = impinge.load_mesh(str(folder / "femur_r.vtp"))
    assert np.array_equal(V, h["femur"][0]) and np.array_equal(F, h["femur"][1])
    V, F = impinge.load_mesh(str(folder / "pelvis.vtk"))
    assert np.array_equal(V, h["pelvis"][0]) and np.array_equal(F, h["pelvis"][1])
    (folder / "vtk.json").write_text('{"side": "right", "frame": "RAS", "units": "mm", "femur": "femur_r.vtp", '
                                     '"pelvis": "pelvis.vtk", "neutral": "scan"}')
    # the reference: the same vertices handed over as arrays (a PLY through assimp would round them to float32)
    a = impinge.Joint(h["femur"], h["pelvis"], neutral="scan", resolution=1.0).detect_pose(60, 0, 10)
    b = impinge.Joint(subject=str(folder / "vtk.json"), resolution=1.0).detect_pose(60, 0, 10)
    c = impinge.Joint(str(folder / "femur_r.vtp"), str(folder / "pelvis.vtk"), neutral="scan",
                      resolution=1.0).detect_pose(60, 0, 10)
    for k in ("femur_gap_mm", "pelvis_gap_mm", "femur_distance_mm", "pelvis_distance_mm"):
        np.testing.assert_array_equal(a[k], b[k])
        np.testing.assert_array_equal(a[k], c[k])
    (folder / "broken.vtp").write_text("<VTKFile>not a mesh")
    with pytest.raises(impinge.Error, match="broken.vtp: VTK cannot read it"):
        impinge.load_mesh(str(folder / "broken.vtp"))
    with pytest.raises(impinge.Error, match="missing.vtk: no such file"):
        impinge.Joint(str(folder / "missing.vtk"), str(folder / "pelvis.vtk"))


def test_motion_files_read_as_the_cli_reads_them():
    m = impinge.load_motion(os.path.join(MOTIONS, "deep_squat.mot"), "left")
    assert m["format"] == "opensim" and m["angles"].shape == (81, 3)
    assert m["angles"][:, 0].max() == pytest.approx(110.0, abs=0.01) and m["time_s"][-1] == 4.0
    with pytest.raises(impinge.Error, match="deep_squat.mot.*hip_flexion_x|side"):
        impinge.load_motion(os.path.join(MOTIONS, "deep_squat.mot"), "middle")


@pytest.mark.skipif(not os.path.exists(os.path.join(os.environ.get("IMPINGE_SHARED_DATA", "../shared/data/hips"),
                                                    "lhdl-ct", "subject.json")), reason="shared data absent")
def test_a_morphology_task_records_the_joints_morphology(tmp_path):
    data = os.environ.get("IMPINGE_SHARED_DATA", "../shared/data/hips")
    subject = os.path.abspath(os.path.join(data, "lhdl-ct", "subject.json"))
    path = write_study(str(tmp_path), f"""name = "shape"
subjects = ["{subject}"]
[joint]
resolution = 2.0
[[task]]
kind = "morphology"
""")
    out = str(tmp_path / "out")
    study.run(path, out, workers=0, progress=False, log=lambda _: None)
    rows = read(out)
    assert len(rows) == 1 and rows[0]["status"] == "ok", rows
    expected = impinge.Joint(subject=subject, resolution=2.0).morphology()
    assert float(rows[0]["alpha_max_deg"]) == pytest.approx(expected["femur"]["alpha_max_deg"]["value"])
    assert float(rows[0]["lateral_centre_edge_deg"]) == pytest.approx(
        expected["acetabulum"]["lateral_centre_edge_deg"]["value"])
    assert os.path.exists(os.path.join(out, "tasks", rows[0]["task_id"], "morphology.json"))


def test_a_plan_task_records_the_joints_plan(tmp_path):
    """A study's plan task gives Joint.plan's figures (generated hip with a 3 mm cam: flexion back to 50 deg)."""
    path = write_study(str(tmp_path), """name = "plans"
subjects = [{name = "cam3", generated = {cam_mm = 3.0, triangles = 6000}}]
[joint]
precision = 1.0
neutral = "scan"
[[task]]
kind = "plan"
target = "flexion=50"
""")
    out = str(tmp_path / "out")
    study.run(path, out, workers=0, progress=False, log=lambda _: None)
    rows = read(out)
    assert len(rows) == 1 and rows[0]["status"] == "ok", rows
    h = impinge.generated_hip(triangles=6000, cam_mm=3.0)
    expected = impinge.Joint(h["femur"], h["pelvis"], precision=1.0, neutral="scan").plan(target="flexion=50")
    assert float(rows[0]["femur_volume_mm3"]) == pytest.approx(expected["femur_resection"]["volume_mm3"])
    assert rows[0]["met_flexion"] == "true" and float(rows[0]["limit_after_flexion_deg"]) >= 50 - 0.1
    folder = os.path.join(out, "tasks", rows[0]["task_id"])
    assert os.path.exists(os.path.join(folder, "plan.json")) and os.path.exists(os.path.join(folder, "resection.npz"))


def test_a_plan_task_with_the_labrum_records_the_labral_limit(tmp_path):
    """labrum = true in a plan task (issue 81): the plan targets the labral limit; results.csv gives it after the plan,
    as a separate Joint.rom_limits(labrum=True) on the written resected femur measures it (the generated hip's cup
    covering 80 deg: abduction's labral limit 35 deg, its bony 50 deg)."""
    path = write_study(str(tmp_path), """name = "labral plans"
subjects = [{name = "cup80", generated = {cam_mm = 0.0, triangles = 6000, coverage_deg = 80.0}}]
[joint]
precision = 1.0
neutral = "scan"
[[task]]
kind = "plan"
target = "abduction=40"
labrum = true
""")
    out = str(tmp_path / "out")
    study.run(path, out, workers=0, progress=False, log=lambda _: None)
    rows = read(out)
    assert len(rows) == 1 and rows[0]["status"] == "ok", rows
    assert rows[0]["met_abduction"] == "true" and float(rows[0]["femur_volume_mm3"]) > 0
    assert float(rows[0]["labral_limit_after_abduction_deg"]) >= 40 - 0.1
    assert float(rows[0]["limit_after_abduction_deg"]) > float(rows[0]["labral_limit_after_abduction_deg"])
