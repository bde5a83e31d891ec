"""Running a whole study: here (serially), on a local Dask cluster (the default), on any Dask cluster
(`scheduler`), or one shard of it (`shard`); then gathering results.csv, summary.csv and the figures.

The unit of scheduling is a group: the tasks of one subject with one Joint setting and one COR, which share
one Joint. A group is one Dask task, so the worker that builds a Joint (maps, frames) runs every task that
needs it; the scheduler spreads the groups over the workers, and reschedules a group whose worker died (its
finished tasks are not run again: they are on disk)."""
import csv
import json
import os
import shutil
import sys
import time

import numpy as np

import impinge

from . import spec, tasks as task_mod
from .lock import OutLock

RESULTS_CSV = "results.csv"  # what a run writes in its folder
SUMMARY_CSV = "summary.csv"
TIMING_COLUMNS = ("time_s", "joint_build_s", "worker")  # what differs between two runs of the same tasks
STATUS_COLUMNS = ("status", "error", "warnings")
BASE_COLUMNS = ("task_id", "kind", "label", "subject", "side", "sample", "cor_dx_mm", "cor_dy_mm", "cor_dz_mm",
                "cor_offset_mm")


class Progress:
    """A one-line progress bar on a terminal (stderr); silent elsewhere unless `always`."""

    def __init__(self, total, enabled):
        self.total, self.done, self.errors, self.enabled = total, 0, 0, enabled
        self.t0 = time.monotonic()

    def add(self, records):
        self.done += len(records)
        self.errors += sum(r["status"] != "ok" for r in records)
        if not self.enabled:
            return
        width = 30
        filled = int(width * self.done / max(self.total, 1))
        elapsed = time.monotonic() - self.t0
        eta = elapsed / self.done * (self.total - self.done) if self.done else float("nan")
        sys.stderr.write(f"\r[{'#' * filled}{'.' * (width - filled)}] {self.done}/{self.total} tasks, "
                         f"{self.errors} errors, {elapsed:.0f} s, {eta:.0f} s to go ")
        sys.stderr.flush()

    def close(self):
        if self.enabled:
            sys.stderr.write("\n")


def parse_shard(text):
    """'I/N' -> (I, N), 0 <= I < N. Raises StudyError."""
    try:
        i, n = (int(x) for x in text.split("/"))
    except ValueError:
        raise spec.StudyError(f"--shard {text}: expected I/N, e.g. 0/4 (I from 0 to N - 1)") from None
    if not (n >= 1 and 0 <= i < n):
        raise spec.StudyError(f"--shard {text}: I must be 0 to N - 1 and N >= 1")
    return i, n


def groups_of(task_list):
    """{group: [tasks]} in the study's order (a group first appears with its first task)."""
    groups = {}
    for t in task_list:
        groups.setdefault(t["group"], []).append(t)
    return groups


def shard_groups(groups, shard):
    """The groups of shard (I, N): every N-th group from the I-th (a group's tasks stay together)."""
    if shard is None:
        return groups
    i, n = shard
    return {g: ts for k, (g, ts) in enumerate(groups.items()) if k % n == i}


def _write_atomic(path, text):
    tmp = f"{path}.tmp-{os.getpid()}"
    with open(tmp, "w") as f:
        f.write(text)
    os.replace(tmp, path)


def _package_path():
    """The folder that holds the impinge package (workers started here import it from there)."""
    return os.path.dirname(os.path.dirname(os.path.abspath(impinge.__file__)))


def _dask_client(workers, scheduler, threads):
    """A Dask client: on `scheduler` (tcp://HOST:PORT, or the path of a scheduler file that `dask scheduler
    --scheduler-file` writes: waited for up to 120 s, with at least one worker) or on a new local cluster of
    `workers` processes with one thread each (the default: one per core)."""
    try:
        from distributed import Client, LocalCluster
    except ImportError:
        raise spec.StudyError("Dask's distributed is missing: apt-get install python3-distributed "
                              "(tools/install-deps build), or run with --workers 0") from None
    if scheduler and "://" not in scheduler:  # a scheduler file: the batch job starts it beside this run
        deadline = time.monotonic() + 120
        while not os.path.isfile(scheduler) and time.monotonic() < deadline:
            time.sleep(0.2)
        if not os.path.isfile(scheduler):
            raise spec.StudyError(f"--scheduler {scheduler}: no such scheduler file after 120 s")
        client = Client(scheduler_file=scheduler, timeout="30s")
        client.wait_for_workers(1, timeout=120)
        return client, None
    if scheduler:
        try:
            client = Client(scheduler, timeout="10s")
        except (OSError, TimeoutError) as e:  # one line, not Dask's traceback
            raise spec.StudyError(f"--scheduler {scheduler}: cannot reach a Dask scheduler there within 10 s "
                                  f"({type(e).__name__}: {str(e).splitlines()[0] if str(e) else 'no answer'})") from None
        try:
            client.wait_for_workers(1, timeout=120)
        except (OSError, TimeoutError):
            client.close()
            raise spec.StudyError(f"--scheduler {scheduler}: no worker joined within 120 s") from None
        return client, None
    # Workers are new processes: they find the package where this one did, with `threads` OpenMP threads each.
    path = os.environ.get("PYTHONPATH", "")
    if _package_path() not in path.split(os.pathsep):
        os.environ["PYTHONPATH"] = _package_path() + (os.pathsep + path if path else "")
    os.environ["OMP_NUM_THREADS"] = str(threads)
    import logging

    cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None,
                           silence_logs=logging.ERROR)
    return Client(cluster), cluster


def run(study_path, out, workers=None, scheduler=None, shard=None, retry_errors=False, progress=None, log=None,
        on_start=None, overrides=None):
    """Run a study into folder `out` and gather its results.

    study_path: the study file (TOML). workers: local worker processes (None: one per core; 0: run here,
    serially, without Dask). scheduler: a Dask scheduler's address (then `workers` is not used). shard: (I, N):
    run only shard I of N (results-I-of-N.csv; `merge` joins the shards). retry_errors: run again the tasks
    that raised last time (else they count as finished). progress: show the progress bar (None: when stderr is
    a terminal). log: a function taking one line (None: print to stderr). on_start: called with the Dask client
    once the workers run (tests kill a worker through it). overrides: {dotted key: value} over the file's keys.
    Writes out/study.toml, out/study.json (the expanded tasks), out/tasks/<id>/, and, for a whole study,
    out/results.csv, out/summary.csv and out/figures/. -> dict(tasks, ran, skipped, errors, wall_s, setup_s,
    task_s (the tasks' own time, summed), workers). Raises StudyError (one line) before any task runs on a bad
    study (every key, value and file checked: spec.load_study), an `out` that cannot be created or written, a
    folder another runner holds (lock.py), or a scheduler file whose folder does not exist."""
    log = log or (lambda line: print(line, file=sys.stderr))
    if scheduler and "://" not in scheduler:
        check_scheduler_file(scheduler)
    study = spec.load_study(study_path, overrides)
    task_list = spec.expand(study)
    out = os.fspath(out)
    tasks_dir = os.path.join(out, "tasks")
    make_folder(out, "the study folder")
    with OutLock(out, shard):
        make_folder(tasks_dir, "the study's task folder")
        return _run_locked(study, task_list, out, tasks_dir, workers, scheduler, shard, retry_errors, progress, log,
                           on_start, overrides)


def make_folder(folder, what):
    """Create `folder` (and its parents) unless it is there -> None; StudyError of one line when it cannot be (a
    file in its place, a read-only parent)."""
    if os.path.isdir(folder):
        return
    if os.path.lexists(folder):
        raise spec.StudyError(f"{folder}: not a folder ({what} must be one: give --out a new folder or one a study "
                              "wrote)")
    try:
        os.makedirs(folder, exist_ok=True)
    except OSError as e:
        raise spec.StudyError(f"{folder}: cannot create {what} ({e.strerror})") from None


def check_scheduler_file(path):
    """A scheduler file's folder must be there (the scheduler writes the file into it, maybe later): else a
    StudyError at once, naming the path, instead of waiting for a file that cannot come."""
    folder = os.path.dirname(os.path.abspath(path))
    if os.path.isdir(path):
        raise spec.StudyError(f"--scheduler {path}: a folder, not a scheduler file (tcp://HOST:PORT, or the file "
                              "`dask scheduler --scheduler-file FILE` writes)")
    if not os.path.isdir(folder):
        raise spec.StudyError(f"--scheduler {path}: no such folder {folder} (the scheduler file's folder must exist: "
                              "`dask scheduler --scheduler-file FILE` writes the file into it)")


def _run_locked(study, task_list, out, tasks_dir, workers, scheduler, shard, retry_errors, progress, log, on_start,
                overrides):
    os.makedirs(os.path.join(out, "shards"), exist_ok=True)
    _write_atomic(os.path.join(out, "study.json"), json.dumps(
        {"name": study["name"], "study_file": study["path"], "version": impinge.__version__, "seed": study["seed"],
         "overrides": overrides or {}, "tasks": task_list}, indent=1))
    with open(study["path"]) as f:
        _write_atomic(os.path.join(out, "study.toml"), f.read())
    groups = shard_groups(groups_of(task_list), shard)
    mine = [t for t in task_list if t["group"] in groups]  # the study's order
    ids = {t["id"] for t in mine}
    for name in os.listdir(tasks_dir):  # what an interrupted run left half-written
        if name.startswith(".tmp-") and name[5:].rsplit("-", 1)[0] in ids:
            shutil.rmtree(os.path.join(tasks_dir, name), ignore_errors=True)

    def finished(t):
        done = task_mod.read_done(tasks_dir, t)
        return done is not None and (done["status"] == "ok" or not retry_errors)

    done_before = {t["id"] for t in mine if finished(t)}
    todo = {g: ts for g, ts in groups.items() if not all(t["id"] in done_before for t in ts)}
    before = len(done_before)
    where = "here, serially" if workers == 0 and not scheduler else (f"on {scheduler}" if scheduler else "local cluster")
    log(f"impinge.study: {study['name']}: {len(mine)} tasks in {len(groups)} groups"
        + (f" (shard {shard[0]}/{shard[1]} of {len(task_list)} tasks)" if shard else "")
        + f"; {before} finished before, {len(mine) - before} to run ({where})")
    bar = Progress(len(mine), sys.stderr.isatty() if progress is None else progress)
    bar.add([{"status": "ok"}] * before)
    t_setup = time.perf_counter()
    ran = []
    n_workers = 0
    client = cluster = None
    try:
        if todo and (workers != 0 or scheduler):
            client, cluster = _dask_client(workers if workers else (os.cpu_count() or 1), scheduler, study["threads"])
            n_workers = len(client.scheduler_info()["workers"])
            if on_start:
                on_start(client)
        setup_s = time.perf_counter() - t_setup
        t0 = time.perf_counter()
        if client is None:
            n_workers = 1 if todo else 0
            for ts in todo.values():
                records = task_mod.run_group(ts, tasks_dir, retry_errors)
                ran += [r for r in records if not r.get("skipped")]
                bar.add([r for r in records if not r.get("skipped")])
        else:
            from distributed import as_completed

            futures = [client.submit(task_mod.run_group, ts, tasks_dir, retry_errors, key=f"impinge-group-{g}",
                                     pure=False) for g, ts in todo.items()]
            for fut in as_completed(futures):
                records = fut.result()
                fresh = [r for r in records if not r.get("skipped")]
                ran += fresh
                bar.add(fresh)
        wall_s = time.perf_counter() - t0
    finally:
        bar.close()
        if client is not None:
            client.close()
        if cluster is not None:
            cluster.close()
    records = [task_mod.read_done(tasks_dir, t) for t in mine]
    missing = [t for t, r in zip(mine, records) if r is None]
    if missing:
        raise spec.StudyError(f"{out}: {len(missing)} tasks did not finish (first: {missing[0]['id']})")
    for t, r in zip(mine, records):  # as this study names them (a motion's name depends on the study's others)
        r["parameters"] = task_mod.task_record(t)
    if shard:
        write_results(records, os.path.join(out, "shards", f"results-{shard[0]}-of-{shard[1]}.csv"))
    else:
        gather(out, records)
    errors = sum(r["status"] != "ok" for r in records)
    summary = {"tasks": len(mine), "ran": len(ran), "skipped": len(mine) - len(ran), "errors": errors,
               "wall_s": wall_s, "setup_s": setup_s, "task_s": float(sum(r["time_s"] for r in ran)),
               "workers": n_workers}
    log(f"impinge.study: {summary['ran']} tasks run, {summary['skipped']} already done, {errors} errors; "
        f"{wall_s:.1f} s on {n_workers} worker(s)" + ("" if shard else f"; results in {out}/results.csv"))
    return summary


def rows_of(records):
    """Flat rows (parameters, figures, status, error, timing) of task records."""
    rows = []
    for r in records:
        row = dict(r["parameters"])
        row.update(r["figures"])
        row.update({"status": r["status"], "error": r["error"], "warnings": r.get("warnings", ""),
                    "time_s": r["time_s"], "joint_build_s": r["joint_build_s"], "worker": r["worker"]})
        rows.append(row)
    return rows


def columns_of(rows):
    """Column order: the base parameters, the other parameters and figures in order of first appearance, then
    status and timing."""
    cols = list(BASE_COLUMNS)
    for row in rows:
        for k in row:
            if k not in cols and k not in STATUS_COLUMNS + TIMING_COLUMNS:
                cols.append(k)
    return cols + list(STATUS_COLUMNS + TIMING_COLUMNS)


def write_results(records, path):
    """results.csv: one row per task (parameters, key figures, status, error, time_s, joint_build_s, worker);
    floats written exactly (repr), NaN as nan, a figure a task does not have left empty."""
    rows = rows_of(records)
    cols = columns_of(rows)
    tmp = f"{path}.tmp-{os.getpid()}"
    with open(tmp, "w", newline="") as f:
        w = csv.writer(f, lineterminator="\n")
        w.writerow(cols)
        for row in rows:
            w.writerow([task_mod.cell(row[c]) if c in row else "" for c in cols])
    os.replace(tmp, path)


def read_results(path):
    """results.csv -> list of dicts of strings."""
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def _varying(records, kind):
    """The parameters (besides the base columns: subject, sample, COR offset...) that vary among a kind's tasks."""
    same = [r["parameters"] for r in records if r["parameters"]["kind"] == kind]
    keys = [k for k in columns_of(same) if k not in BASE_COLUMNS + STATUS_COLUMNS + TIMING_COLUMNS]
    return [k for k in keys if all(k in p for p in same) and len({json.dumps(p.get(k)) for p in same}) > 1]


def summarise(records):
    """summary.csv's rows: per kind, label, subject, setting (the varying parameters) and numeric figure,
    statistics over the perturbation samples of the tasks that ran: n, nominal (sample 0), mean, sd, min, p05,
    p25, median, p75, p95, max (NaN results left out of the statistics, counted in n_nan)."""
    out = []
    by = {}
    varying = {kind: _varying(records, kind) for kind in {r["parameters"]["kind"] for r in records}}
    for r in records:
        p = r["parameters"]
        setting = ";".join(f"{k}={p.get(k)}" for k in varying[p["kind"]])
        by.setdefault((p["kind"], p["label"], p["subject"], setting), []).append(r)
    for (kind, label, subject, setting), group in by.items():
        ok = [r for r in group if r["status"] == "ok"]
        for fig in columns_of([r["figures"] for r in ok]):
            if fig in BASE_COLUMNS + STATUS_COLUMNS + TIMING_COLUMNS:
                continue
            values = [r["figures"].get(fig) for r in ok]
            if not values or not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in values):
                continue
            x = np.asarray(values, dtype=float)
            finite = x[np.isfinite(x)]
            nominal = [r["figures"].get(fig) for r in ok if r["parameters"]["sample"] == 0]
            stats = {"kind": kind, "label": label, "subject": subject, "setting": setting, "figure": fig,
                     "n": int(finite.size), "n_nan": int(x.size - finite.size), "errors": len(group) - len(ok),
                     "nominal": float(nominal[0]) if nominal else float("nan")}
            if finite.size:
                q = np.percentile(finite, [5, 25, 50, 75, 95])
                stats.update(mean=float(finite.mean()), sd=float(finite.std(ddof=1)) if finite.size > 1 else 0.0,
                             min=float(finite.min()), p05=q[0], p25=q[1], median=q[2], p75=q[3], p95=q[4],
                             max=float(finite.max()))
            else:
                stats.update({k: float("nan") for k in ("mean", "sd", "min", "p05", "p25", "median", "p75", "p95",
                                                         "max")})
            out.append(stats)
    return out


def gather(out, records):
    """results.csv, summary.csv and figures/ of a whole study's records."""
    write_results(records, os.path.join(out, RESULTS_CSV))
    stats = summarise(records)
    cols = ["kind", "label", "subject", "setting", "figure", "n", "n_nan", "errors", "nominal", "mean", "sd", "min",
            "p05", "p25", "median", "p75", "p95", "max"]
    with open(os.path.join(out, SUMMARY_CSV), "w", newline="") as f:
        w = csv.writer(f, lineterminator="\n")
        w.writerow(cols)
        for s in stats:
            w.writerow([task_mod.cell(s[c]) for c in cols])
    try:
        from . import figures
    except ImportError:  # pragma: no cover (matplotlib missing: the tables are the results)
        return
    figures.draw(out, rows_of(records))


def merge(out, shard_dirs, log=None):
    """Join the shards of one study (each run with --shard I/N, into `shard_dirs` or one shared folder) into
    `out`: every task's folder, then results.csv, summary.csv and figures as one run would give them.
    Raises StudyError when the shards come from different studies or a task is missing (naming it)."""
    log = log or (lambda line: print(line, file=sys.stderr))
    shard_dirs = list(shard_dirs) or [out]
    plans = []
    for d in shard_dirs:
        try:
            with open(os.path.join(d, "study.json")) as f:
                plans.append(json.load(f))
        except (OSError, ValueError) as e:
            raise spec.StudyError(f"{d}: no study.json ({e}); give folders that `run --shard` wrote") from None
    ids = [t["id"] for t in plans[0]["tasks"]]
    for d, p in zip(shard_dirs, plans):
        if [t["id"] for t in p["tasks"]] != ids:
            raise spec.StudyError(f"{d}: its study.json lists other tasks than {shard_dirs[0]}'s (another study?)")
    tasks_dir = os.path.join(out, "tasks")
    make_folder(out, "the merged study's folder")
    make_folder(tasks_dir, "the study's task folder")
    records = []
    for t in plans[0]["tasks"]:
        found = None
        for d in shard_dirs:
            r = task_mod.read_done(os.path.join(d, "tasks"), t)
            if r is not None:
                found = (d, r)
                break
        if found is None:
            raise spec.StudyError(f"merge: task {t['id']} ({t['kind']} on {t['subject_name']}, sample {t['sample']}) "
                                  f"is in none of {', '.join(shard_dirs)}: run its shard")
        d, r = found
        r["parameters"] = task_mod.task_record(t)
        src = os.path.join(d, "tasks", t["id"])
        dst = os.path.join(tasks_dir, t["id"])
        if os.path.realpath(src) != os.path.realpath(dst) and not os.path.exists(dst):
            shutil.copytree(src, dst + ".tmp-merge")
            os.rename(dst + ".tmp-merge", dst)
        records.append(r)
    if os.path.realpath(shard_dirs[0]) != os.path.realpath(out):
        for name in ("study.json", "study.toml"):
            shutil.copy(os.path.join(shard_dirs[0], name), os.path.join(out, name))
    gather(out, records)
    log(f"impinge.study merge: {len(records)} tasks from {len(shard_dirs)} folder(s); results in {out}/results.csv")
    return records


def nan_equal_rows(a, b, ignore=TIMING_COLUMNS):
    """True when two results.csv (lists of dicts) hold the same values, column for column, leaving out timing."""
    if len(a) != len(b):
        return False
    for x, y in zip(a, b):
        keys = (set(x) | set(y)) - set(ignore)
        if any(x.get(k) != y.get(k) for k in keys):
            return False
    return True


__all__ = ["run", "merge", "gather", "write_results", "read_results", "summarise", "parse_shard"]
