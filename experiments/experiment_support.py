"""What the Python experiment drivers share (experiment_support.hpp's counterpart): their command line
(--out DIR [--data DIR] [--quick]) and their meta.json's provenance (commit, date, machine)."""
import datetime
import json
import os
import platform
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


def write_meta(d, experiment, fields):
    """d/meta.json: experiment, git_commit (with -dirty when tracked files outside results/ differ from it), date
    (UTC), cores, machine, then `fields`."""
    commit = subprocess.run(["git", "-C", ROOT, "rev-parse", "HEAD"], capture_output=True, text=True).stdout.strip()
    # The results folder left out, as the C++ drivers' source_commit(): a reproduction rewrites it as it goes.
    dirty = subprocess.run(["git", "-C", ROOT, "status", "--porcelain", "--untracked-files=no", "--", ".",
                            ":(exclude)results"], capture_output=True, text=True).stdout.strip() != ""
    meta = {"experiment": experiment, "git_commit": commit + ("-dirty" if dirty else ""),
            "date": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ"),
            "cores": str(os.cpu_count()), "machine": platform.processor() or platform.machine()}
    meta.update(fields)
    with open(os.path.join(d, "meta.json"), "w") as f:
        json.dump(meta, f, indent=2)
