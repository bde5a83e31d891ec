"""Experiment 14 (issue 27): studies on Dask, measured.

1. The example cohort study (examples/hip_cohort_study.toml: every shared hip, rom + motion + distance tasks,
   COR perturbations) on the default local cluster (one worker per core), and its first 5 perturbations serially
   (no Dask); the serial run's tasks compared value for value with the same tasks (same task id) of the cluster's
   results.csv (every column but time and worker). A sample's COR offset depends on the seed, the subject and the
   sample alone, so the serial tasks are the cluster's first ones (issue 82 item 7: the whole cohort serially, 20
   perturbations, repeated the cluster's 340 tasks for about 4 of the full run's minutes).
2. Scaling: a study of ROM tasks only (every shared hip at its nominal centre and 2 COR perturbations: 12
   tasks, 6 a worker; issue 82 item 7: 44 tasks' five rounds took 11 of the full run's minutes; with 12 the
   paired two-worker/one-worker ratio read 0.615 against 44 tasks' 0.75 (not explained yet), so the ratio is this
   study's, not a constant) on one worker, on two (the 2 cores) and, as the control, as two shards in two processes without Dask,
   in 5 alternated rounds (each round runs the three in a rotated order): wall times, their ratio paired round
   by round, and the per-task overhead (scheduling, serialisation, I/O): (workers x wall - the tasks' own summed
   time) / the tasks' own time.
3. The tasks' own times, per kind, for the analysis' estimate of a 1,000-subject x 100-perturbation x
   4-method study on one machine and on a cluster.
Without shared data, the generated hips (no cam, 2 mm cam) stand in for the subjects.

Outputs (OUT/14_studies/):
  cohort_results.csv   the cohort study's results.csv (local cluster)
  cohort_summary.csv   its summary.csv
  equality.csv         serial against the local cluster: tasks, cells compared, cells that differ
  scaling.csv          round, workers (0: the control, two shards in two processes without Dask), tasks,
                       wall_s, task_s (summed), overhead, mean task s
  task_times.csv       every task of every run: run, kind, subject, time_s, joint_build_s, worker
  meta.json
--quick: the first two subjects, 1 perturbation in the cohort and 1 in the scaling study (4 tasks, 2 a worker), and 2
rounds (its figures then test the pipeline, not the 1,000-subject estimate; CI's budget, issue 82 item 7).

usage: exp_14_studies --out DIR [--data DIR] [--quick]
(build/experiments/exp_14_studies runs this file with the module on PYTHONPATH)"""
import csv
import glob
import os
import shutil
import subprocess
import sys
import tempfile
import time

from experiment_support import ROOT, experiment_args, write_meta

import impinge
from impinge import study
from impinge.study import runner, spec

EXAMPLE = os.path.join(ROOT, "examples", "hip_cohort_study.toml")
GENERATED = [{"name": "generated-cam0", "generated": {"cam_mm": 0.0, "triangles": 20000}},
             {"name": "generated-cam2", "generated": {"cam_mm": 2.0, "triangles": 20000}}]


def quiet(_):
    pass


def task_rows(run_name, out):
    rows = []
    for r in runner.read_results(os.path.join(out, runner.RESULTS_CSV)):
        rows.append({"run": run_name, "kind": r["kind"], "subject": r["subject"], "sample": r["sample"],
                     "time_s": r["time_s"], "joint_build_s": r["joint_build_s"], "worker": r["worker"]})
    return rows


def over_args(overrides):
    """--set options for the command line of impinge.study."""
    return [a for k, v in overrides.items() for a in ("--set", f"{k}={spec.toml_value(v)}")]


def require_ok(summary, folder, what):
    """Stop the experiment when a task of a study failed (a study records a failed task and goes on; timing
    or comparing failed tasks would measure nothing)."""
    if summary["errors"]:
        rows = runner.read_results(os.path.join(folder, runner.RESULTS_CSV))
        first = next((r.get("error", "") for r in rows if r["status"] != "ok"), "")
        raise SystemExit(f"14_studies: {summary['errors']} of {summary['tasks']} tasks of {what} failed; "
                         f"the first: {first}")


def write_csv(path, rows):
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]), lineterminator="\n")
        w.writeheader()
        w.writerows(rows)


def main():
    d, data, quick = experiment_args("14_studies", __doc__)
    data = os.path.abspath(data) if data else None
    real = sorted(glob.glob(os.path.join(data, "*", "subject.json"))) if data and os.path.isdir(data) else []
    subjects = real if real else GENERATED
    if quick:  # CI's budget (issue 82 item 7): the cohort and the scaling study on the first two subjects
        subjects = subjects[:2]
    # The generated hips have no anatomical landmarks: scan neutral, where the femoral-head centre (the
    # thesis') is the only joint-centre method.
    joint_centre = "equidistant" if real else "femoral-head"
    samples = 1 if quick else 20
    serial_samples = min(samples, 5)  # the serial run: the cohort's first perturbations (their tasks compared)
    # 2 perturbations (12 tasks, 6 a worker): the wall times, their ratio and the per-task overhead are measured the
    # same way as with 10 (issue 82 item 7: 44 tasks' five rounds took 11 of the full run's 65 minutes); the ratio
    # moved with the task count (the file comment).
    scaling_samples = 1 if quick else 2
    rounds = 2 if quick else 5
    work = tempfile.mkdtemp(prefix="impinge-exp14-")
    cores = os.cpu_count() or 1
    times, scaling = [], []
    try:
        # 1. The cohort study: serially, then on the local cluster; equal value for value.
        over = {"subjects": subjects, "perturb.samples": samples, "joint.joint_centre": joint_centre}
        print(f"[14_studies] cohort: {len(subjects)} subjects, {serial_samples} perturbations, serially", flush=True)
        serial = study.run(EXAMPLE, os.path.join(work, "serial"), workers=0, progress=False, log=quiet,
                           overrides=dict(over, **{"perturb.samples": serial_samples}))
        print(f"[14_studies] cohort: {len(subjects)} subjects, {samples} perturbations", flush=True)
        print(f"[14_studies] cohort on the local cluster ({cores} workers)", flush=True)
        local = study.run(EXAMPLE, os.path.join(work, "local"), workers=None, progress=False, log=quiet,
                          overrides=over)
        require_ok(serial, os.path.join(work, "serial"), "the cohort study (serial)")
        require_ok(local, os.path.join(work, "local"), "the cohort study (local cluster)")
        a = runner.read_results(os.path.join(work, "serial", runner.RESULTS_CSV))
        b = runner.read_results(os.path.join(work, "local", runner.RESULTS_CSV))
        compared = sorted((set(a[0]) | set(b[0])) - set(runner.TIMING_COLUMNS))
        # Every serial task against the cluster's task of the same id (missing there: all its cells differ).
        by_id = {y["task_id"]: y for y in b}
        differ = sum(x.get(k) != by_id.get(x["task_id"], {}).get(k) for x in a for k in compared)
        equality = [{"study": "hip-cohort", "tasks_serial": serial["tasks"], "tasks_local": local["tasks"],
                     "errors_serial": serial["errors"], "errors_local": local["errors"],
                     "workers_local": local["workers"], "columns": len(compared),
                     "tasks_compared": len(a), "cells_compared": len(a) * len(compared), "cells_differing": differ,
                     "equal": differ == 0 and len(a) == serial["tasks"]}]
        write_csv(os.path.join(d, "equality.csv"), equality)
        shutil.copy(os.path.join(work, "local", runner.RESULTS_CSV), os.path.join(d, "cohort_results.csv"))
        shutil.copy(os.path.join(work, "local", runner.SUMMARY_CSV), os.path.join(d, "cohort_summary.csv"))
        times += task_rows("cohort-serial", os.path.join(work, "serial"))
        times += task_rows("cohort-local", os.path.join(work, "local"))

        # 2. Scaling: ROM tasks only on 1 and 2 workers (local clusters, one thread per worker).
        rom = os.path.join(work, "rom_study.toml")
        with open(rom, "w") as f:
            f.write('name = "rom-scaling"\nseed = 27\nsubjects = []\n[joint]\nresolution = 0.5\n'
                    f'joint_centre = "{joint_centre}"\n[[task]]\nkind = "rom"\nmetric = "distance"\n'
                    '[perturb]\ncor_sd_mm = 1.0\nsamples = 0\n')
        over = {"subjects": subjects, "perturb.samples": scaling_samples}

        def dask_run(k, workers):
            print(f"[14_studies] scaling, round {k + 1}/{rounds}: ROM tasks on {workers} worker(s)", flush=True)
            folder = os.path.join(work, f"rom{workers}-{k}")
            s = study.run(rom, folder, workers=workers, progress=False, log=quiet, overrides=over)
            require_ok(s, folder, f"the scaling study on {workers} worker(s)")
            scaling.append({"round": k, "workers": s["workers"], "tasks": s["tasks"], "errors": s["errors"],
                            "wall_s": s["wall_s"], "setup_s": s["setup_s"], "task_s": s["task_s"],
                            "mean_task_s": s["task_s"] / s["tasks"],
                            "overhead": (s["workers"] * s["wall_s"] - s["task_s"]) / s["task_s"]})
            times.extend(task_rows(f"rom-{workers}-workers", folder))
            shutil.rmtree(folder, ignore_errors=True)

        def control_run(k):
            # The control: the same study as two shards in two processes at once, without Dask (what the 2 cores
            # give two independent processes of this work).
            print(f"[14_studies] scaling, round {k + 1}/{rounds}: two shards in two processes, without Dask",
                  flush=True)
            folder = os.path.join(work, f"shards-{k}")
            t0 = time.perf_counter()
            procs = [subprocess.Popen([sys.executable, "-m", "impinge.study", "run", rom, "--out", folder,
                                       "--workers", "0", "--shard", f"{i}/2", "--no-progress"] + over_args(over),
                                      stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
                     for i in range(2)]
            if any(p.wait() != 0 for p in procs):
                raise SystemExit("14_studies: a shard of the scaling study failed")
            wall = time.perf_counter() - t0
            records = runner.merge(folder, [], log=quiet)
            task_s = float(sum(r["time_s"] for r in records))
            scaling.append({"round": k, "workers": 0, "tasks": len(records),
                            "errors": sum(r["status"] != "ok" for r in records), "wall_s": wall, "setup_s": 0.0,
                            "task_s": task_s, "mean_task_s": task_s / len(records), "overhead": (2 * wall - task_s) / task_s})
            shutil.rmtree(folder, ignore_errors=True)

        # Alternated rounds, the order rotated each round, so that drift of the machine spreads over all three.
        runs = [lambda k: dask_run(k, 1), lambda k: dask_run(k, 2), control_run]
        for k in range(rounds):
            for j in range(len(runs)):
                runs[(j + k) % len(runs)](k)
        write_csv(os.path.join(d, "scaling.csv"), scaling)
        write_csv(os.path.join(d, "task_times.csv"), times)
    finally:
        shutil.rmtree(work, ignore_errors=True)

    import distributed
    write_meta(d, "14_studies", quick=quick, data_folder=data if real else None,
               timing="wall time of the task phase (cluster started), one OpenMP thread per task; task times measured "
                      "inside the tasks (their Joint's build included where it was built); the scaling study in "
                      f"{rounds} alternated rounds (1 worker, 2 workers, 2 shards without Dask, the order rotated)",
               repetitions=rounds,
               parameters={"cohort_study": os.path.relpath(EXAMPLE, ROOT), "cohort_perturbations": samples,
                           "cohort_serial_perturbations": serial_samples,
                           "scaling_perturbations": scaling_samples, "scaling_rounds": rounds, "scaling_resolution_deg": 0.5,
                           "subjects": [os.path.basename(os.path.dirname(s)) if isinstance(s, str) else s["name"]
                                        for s in subjects]},
               versions={"distributed": distributed.__version__})


if __name__ == "__main__":
    main()
