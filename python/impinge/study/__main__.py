"""The command line of impinge.study: run, merge, tasks (see `python3 -m impinge.study --help`)."""
import argparse
import sys

import impinge

from . import runner, spec


def main(argv=None):
    p = argparse.ArgumentParser(prog="python3 -m impinge.study",
                                description="Studies of many hips, motions and parameter sweeps on Dask: every task "
                                "of a study file (TOML; docs/studies.md), results.csv, summary.csv and figures.")
    sub = p.add_subparsers(dest="command", required=True)
    r = sub.add_parser("run", help="run a study (skipping the tasks DIR holds already)")
    r.add_argument("study", help="the study file (TOML)")
    r.add_argument("--out", required=True, help="the study's folder (DIR/tasks/<id>/, results.csv, summary.csv, "
                   "figures/); run again on it to finish an interrupted study")
    r.add_argument("--workers", type=int, default=None,
                   help="worker processes of the local Dask cluster (default: one per core; 0: here, serially, "
                   "without Dask)")
    r.add_argument("--scheduler", default=None, help="a running Dask scheduler: tcp://HOST:8786, or the scheduler "
                   "file `dask scheduler --scheduler-file` writes (waited for); its workers must see DIR and the "
                   "subjects at the same paths")
    r.add_argument("--shard", default=None, help="I/N: run only the I-th of N slices of the tasks (I from 0); "
                   "`merge` joins them")
    r.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                   help="set a study key over the file's (dotted, the value in TOML): --set perturb.samples=3 "
                   "--set 'subjects=[\"data/*/subject.json\"]'")
    r.add_argument("--retry-errors", action="store_true", help="run the tasks that raised last time again")
    r.add_argument("--no-progress", action="store_true", help="no progress bar")
    m = sub.add_parser("merge", help="join the shards of a study into one results.csv")
    m.add_argument("shards", nargs="*", help="the folders the shards wrote (default: --out itself)")
    m.add_argument("--out", required=True, help="the merged study's folder")
    t = sub.add_parser("tasks", help="list the expanded tasks of a study file, one per line (id, kind, subject, "
                       "sample, group)")
    t.add_argument("study")
    t.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", help="as run's")
    a = p.parse_args(argv)
    try:
        if a.command == "run":
            if a.workers is not None and a.workers < 0:
                raise spec.StudyError(f"--workers {a.workers}: must be >= 0")
            shard = runner.parse_shard(a.shard) if a.shard else None
            s = runner.run(a.study, a.out, workers=a.workers, scheduler=a.scheduler, shard=shard,
                           retry_errors=a.retry_errors, progress=False if a.no_progress else None,
                           overrides=dict(spec.parse_override(x) for x in a.set))
            return 1 if s["errors"] else 0
        if a.command == "merge":
            runner.merge(a.out, a.shards)
            return 0
        for task in spec.expand(spec.load_study(a.study, dict(spec.parse_override(x) for x in a.set))):
            print(task["id"], task["kind"], task["label"], task["subject_name"], task["sample"], task["group"])
        return 0
    except (spec.StudyError, impinge.Error) as e:  # a user's error: one line, no traceback
        print(f"impinge.study: {e}", file=sys.stderr)
        return 2
    except OSError as e:  # the file system refused (a read-only or full disk, a file where a folder should be)
        where = f"{e.filename}: " if e.filename is not None else ""
        print(f"impinge.study: {where}{e.strerror or e}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
