"""impinge.study: studies of many hips, motions and parameter sweeps, on one machine or a cluster (Dask).

    /usr/bin/python3 -m impinge.study run STUDY.toml --out DIR [--workers N | --scheduler tcp://HOST:8786]
                                      [--shard I/N] [--retry-errors]
    /usr/bin/python3 -m impinge.study merge --out DIR SHARD_DIR...
    /usr/bin/python3 -m impinge.study tasks STUDY.toml         (list the expanded tasks, run nothing)

A study file (TOML) names subjects, [[task]] tables (kind rom, envelope, motion or distance, with the
parameters they sweep) and [perturb] (COR offsets drawn from a seeded normal distribution); docs/studies.md
lists every key. From Python: run(study_path, out, ...), merge(out, shard_dirs), load_study, expand."""
from .runner import merge, read_results, run  # noqa: F401
from .spec import KINDS, StudyError, expand, load_study  # noqa: F401
