"""A study's checks before any task runs: every setting of every combination its sweeps make, by the option
table's own checks (impinge.check_options), and every file its tasks will read, read as they will read it. A bad one
is a StudyError of one line naming the study file and the key (spec.load_study calls them)."""
import json

import impinge

from . import spec


def _indexed(choices):
    """Every combination of {key: (where, [values])} as (values {key: value}, names {key: where the value is in
    the file: the key's path, with its index when it sweeps})."""
    combos = [({}, {})]
    for k in sorted(choices):
        where, values = choices[k]
        combos = [(dict(c, **{k: v}), dict(n, **{k: f"{where}[{j}]" if len(values) > 1 else where}))
                  for c, n in combos for j, v in enumerate(values)]
    return combos


def _checked(path, use, combo, names, cache):
    """impinge.check_options(use, **combo): the values as that call takes them. Its error becomes a StudyError
    naming the key its message names (the table's rows start with the key), else every key of the combination."""
    memo = json.dumps([use, combo], sort_keys=True)
    if memo not in cache:
        try:
            cache[memo] = impinge.check_options(use, **combo)
        except impinge.Error as e:
            msg = str(e)
            for k in sorted(combo, key=len, reverse=True):
                if msg.startswith(f"{k}: "):
                    spec._fail(path, names[k], msg[len(k) + 2:])
            given = ", ".join(f"{names[k]} = {spec.toml_value(combo[k])}" for k in sorted(combo))
            raise spec.StudyError(f"{path}: {given or use}: {msg}") from None
    return cache[memo]


def check_settings(path, study):
    """Every task's settings checked before any task runs, each combination its sweeps make, by the option
    table's own checks (impinge.check_options: a value's type, range and choice; the Joint's settings together, as
    the maps' scheme and resolution; a plan's targets), and what the tasks would refuse: the distance metric
    without the Joint's distances, head_region with a COR perturbation. Raises StudyError naming the key."""
    cache = {}
    perturbed = study["perturb"]["samples"] > 0 and study["perturb"]["cor_sd_mm"] > 0
    for i, t in enumerate(study["tasks"]):
        joint = {k: ("joint." + k, v) for k, v in study["joint"].items()}
        joint.update({k: (f"task[{i}].{k}", v) for k, v in t["joint"].items()})
        options = {k: (f"task[{i}].{k}", v) for k, v in t["options"].items() if k not in ("motion", "poses")}
        for jc, jn in _indexed(joint):
            resolved = _checked(path, "study", jc, jn, cache)
            if perturbed and jc.get("head_region") is not None:
                spec._fail(path, jn["head_region"], "a COR perturbation (perturb.samples) needs the automatic COR, "
                           "not head_region")
            if t["kind"] not in spec.KIND_USES:
                continue
            for oc, on in _indexed(options):
                if t["kind"] == "plan" and spec._is_file_value(oc.get("target_motion")):
                    # the file is read for each subject's side (check_files); a target motion is a target
                    oc = dict(oc, target_motion=None, target=oc.get("target") or "normal")
                opts = _checked(path, spec.KIND_USES[t["kind"]], oc, on, cache)
                if t["kind"] != "plan" and opts["metric"] == "distance" and not resolved["distances"]:
                    spec._fail(path, on.get("metric", f"task[{i}].metric"),
                               "'distance'" + ("" if "metric" in on else " (the default)") + " needs the Joint's "
                               "distances, off here" + (f" ({', '.join(jn.values())})" if jn else "") +
                               ": give metric = \"radial\" (the thesis' radial gap) or distances = true")


def check_files(path, study):
    """Every motion file and path option (target_motion) read as its tasks will read it, for each side of the
    study's subjects, before any task runs: a bad file is a StudyError naming the key, the file, its line."""
    sides = sorted({s.get("side", "right") for s in study["subjects"]})
    for i, t in enumerate(study["tasks"]):
        named = [(f"task[{i}].motion", f) for f in t["options"].get("motion", [])]
        named += [(f"task[{i}].{k}", v["file"]) for k, vs in t["options"].items() if k in spec.PATH_KEYS
                  for v in vs if spec._is_file_value(v)]
        for key, f in named:
            for side in sides:
                try:
                    impinge.load_motion(f, side)
                except impinge.Error as e:
                    spec._fail(path, key, str(e))
