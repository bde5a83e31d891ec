"""What the Python experiment drivers share (experiment_support.hpp's counterpart): their command line
(--out DIR [--data DIR] [--quick]) and their meta.json's provenance (commit, date, machine)."""
import datetime
import json
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def arg(name, default=None):
    """The value after `name` on the command line, or default."""
    return sys.argv[sys.argv.index(name) + 1] if name in sys.argv else default


def experiment_args(name, usage):
    """(the experiment's output folder OUT/name, created; --data or None; --quick). Exits with `usage`
    without --out."""
    out_root = arg("--out")
    if out_root is None:
        sys.exit(usage)
    d = os.path.join(out_root, name)
    os.makedirs(d, exist_ok=True)
    return d, arg("--data"), "--quick" in sys.argv


def write_meta(d, experiment, *, quick, data_folder, parameters, timing, repetitions=None, versions=None):
    """d/meta.json with the fields every driver's meta.json has, in the C++ drivers' order (write_meta in
    experiment_support.cpp; tools/check-report checks they agree): experiment, git_commit (with -dirty when
    tracked files outside results/ differ from it), date (UTC), quick, repetitions (None: not repeated), timing
    (how times were taken), data_folder, parameters, versions (impinge's and the peers'), compiler and kernels
    (impinge.build_info()), cores (CPUs this process may run on) and machine (impinge.machine_info()). Written
    atomically."""
    import impinge
    commit = subprocess.run(["git", "-C", ROOT, "rev-parse", "HEAD"], capture_output=True, text=True).stdout.strip()
    # The results folder left out, as the C++ drivers' source_commit(): a reproduction rewrites it as it goes.
    dirty = subprocess.run(["git", "-C", ROOT, "status", "--porcelain", "--untracked-files=no", "--", ".",
                            ":(exclude)results"], capture_output=True, text=True).stdout.strip() != ""
    build = impinge.build_info()
    meta = {"experiment": experiment, "git_commit": (commit or "unknown") + ("-dirty" if dirty and commit else ""),
            "date": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ"),
            "quick": bool(quick), "repetitions": repetitions, "timing": timing, "data_folder": data_folder,
            "parameters": parameters, "versions": {"impinge": build["version"], **(versions or {})},
            "compiler": build["compiler"], "kernels": build["kernels"],
            "cores": str(len(os.sched_getaffinity(0))), "machine": impinge.machine_info()}
    tmp = os.path.join(d, f".meta.json.{os.getpid()}.tmp")
    with open(tmp, "w") as f:
        json.dump(meta, f, indent=2)
        f.write("\n")
    os.replace(tmp, os.path.join(d, "meta.json"))
