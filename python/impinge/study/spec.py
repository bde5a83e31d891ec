"""Study files: read a study (TOML, Python's tomllib), check every key, and expand it into tasks.

A study names subjects, tasks with the parameters they sweep, and perturbations of the centre of rotation
(COR). Expanded, it is a list of Task records, each one independent computation on one hip with one set of
settings; a task's id is a hash of its inputs' contents, its parameters and impinge's version, so a study
run again on the same folder finds the tasks it has already done. Every path the study names (subjects, motion
files, a plan's target_motion) is relative to the study file's folder, wherever the study runs from. The file's
keys are documented in docs/studies.md; every bad key or value (checks.py: all of them, before any task runs) gets
a StudyError of one line naming the file and the key."""
import glob
import hashlib
import json
import math
import os
import tomllib
import warnings
import zlib

import numpy as np

import impinge
from impinge import _json_file

from . import checks

KINDS = ("rom", "envelope", "motion", "distance", "morphology", "plan")

# Every key below comes from the option table (the session layer's, impinge.options()): a study cannot expose an
# option, a default or a type that the CLI and Python do not share.
_PY_TYPES = {"number": float, "integer": int, "flag": bool, "on_off": bool, "text": str, "choice": str, "path": str,
             "numbers": list, "region": list, "point": list}


def _table(use):
    return [o for o in impinge.options() if use in o["uses"]]


# The Joint keywords a study may set (in [joint] or in a [[task]]): the map, frame and joint-centre settings (the
# table's rows with "study" in their uses). Left out: the inputs (ball, socket, subject, side, frame, landmarks: the
# subject gives them), the COR (the perturbation sets it) and maps (saved maps belong to one COR).
JOINT_KEYS = {o["key"]: _PY_TYPES[o["type"]] for o in _table("study")}
# Each kind's own options (with their defaults): those of the Joint method the kind calls.
KIND_KEYS = {
    "rom": {o["key"]: o["default"] for o in _table("rom_limits")},
    "envelope": {o["key"]: o["default"] for o in _table("rom_map")},
    "motion": {"motion": None},
    "distance": {"poses": None},
    "morphology": {},
    "plan": {o["key"]: o["default"] for o in _table("joint_plan")},
}
KIND_TYPES = dict({o["key"]: _PY_TYPES[o["type"]] for o in _table("rom_limits") + _table("rom_map") + _table("joint_plan")},
                  motion=str, poses=list)
# The Python call whose options a kind's keys are (impinge.check_options checks them as that call does).
KIND_USES = {"rom": "rom_limits", "envelope": "rom_map", "plan": "joint_plan"}
# Keys whose value is a file (the table's path rows a study may set, e.g. a plan's target_motion): read relative to
# the study file's folder, like subjects and motions, and hashed into the ids of the tasks that read them.
PATH_KEYS = {o["key"] for o in _table("rom_limits") + _table("rom_map") + _table("joint_plan") + _table("study")
             if o["type"] == "path"}
# Keys whose value is itself a list: a list of such lists sweeps them (not a plain list).
LIST_VALUED = {o["key"] for o in impinge.options() if o["type"] in ("numbers", "region", "point")}
# Former keys still accepted for one release (a warning names the key that replaces each).
OLD_KEYS = {old: o["key"] for o in impinge.options() for old in o["old_keys"]}
TOP_KEYS = {"name", "seed", "subjects", "joint", "task", "perturb", "threads"}
PERTURB_KEYS = {"cor_sd_mm": float, "samples": int}


class StudyError(ValueError):
    """A bad study file or study folder: one line naming the file and the key."""


def _fail(path, key, message):
    raise StudyError(f"{path}: {key}: {message}")


def _current(path, where, table, k):
    """The key `k` of `table` as the option table names it now: a former key is renamed, with a
    FutureWarning (shown by default: a study file is the user's data, not code) naming the file and the key; giving
    both is an error."""
    if k not in OLD_KEYS:
        return k
    new = OLD_KEYS[k]
    if new in table:
        _fail(path, f"{where}.{k}", f"give {new} or {k} (its former name), not both")
    warnings.warn(f"{path}: {where}.{k}: '{k}' is deprecated and will be removed in the next release: use '{new}'",
                  FutureWarning, stacklevel=3)
    return new


def _typed(path, key, value, kind):
    """value checked against kind (float accepts int; list stays a list)."""
    if kind is float:
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            _fail(path, key, f"expected a finite number, got {value!r}")
        return float(value)
    if kind is int:
        if isinstance(value, bool) or not isinstance(value, int):
            _fail(path, key, f"expected an integer, got {value!r}")
        return value
    if kind is bool:
        if not isinstance(value, bool):
            _fail(path, key, f"expected true or false, got {value!r}")
        return value
    if kind is str:
        if not isinstance(value, str):
            _fail(path, key, f"expected a string, got {value!r}")
        return value
    if kind is list:
        if not isinstance(value, list) or not value:
            _fail(path, key, f"expected a non-empty list, got {value!r}")
        return value
    raise AssertionError(kind)


def _values(path, key, value, kind):
    """The values a key sweeps: a list of values (a list of lists for list-valued keys), else the one value.
    key: the key's path in the file (its last part names the option)."""
    name = key.rsplit(".", 1)[-1]
    swept = isinstance(value, list) and (name not in LIST_VALUED or (value and isinstance(value[0], list)))
    items = value if swept else [value]
    if swept and not items:
        _fail(path, key, "an empty list sweeps nothing")
    out = []
    for k, v in enumerate(items):
        v = _typed(path, f"{key}[{k}]" if swept else key, v, kind)
        if kind is list and name in LIST_VALUED:
            v = [_typed(path, f"{key}[{i}]", x, float) for i, x in enumerate(v)]
            if name == "head_region" and len(v) != 4:
                _fail(path, key, f"expected [x, y, z, r] mm, got {len(v)} numbers")
        out.append(v)
    return out


def _subject_entries(path, entries):
    """subjects = [...]: paths, globs or folders of subject.json (relative to the study file), or tables
    {name = "...", generated = {cam_mm = 2.0, triangles = 6000, coverage_deg = 100.0}} (a generated hip)."""
    if not isinstance(entries, list) or not entries:
        _fail(path, "subjects", "expected a non-empty list of subject.json paths, globs or folders")
    base = os.path.dirname(os.path.abspath(path))
    subjects = []
    for k, e in enumerate(entries):
        key = f"subjects[{k}]"
        if isinstance(e, dict):
            unknown = set(e) - {"name", "generated"}
            if unknown:
                _fail(path, f"{key}.{sorted(unknown)[0]}", "unknown key (known: name, generated)")
            g = e.get("generated")
            if not isinstance(g, dict):
                _fail(path, f"{key}.generated", "expected a table {cam_mm, triangles, coverage_deg}")
            spec = {"cam_mm": 0.0, "triangles": 6000, "coverage_deg": 100.0}
            for gk, gv in g.items():
                if gk not in spec:
                    _fail(path, f"{key}.generated.{gk}", "unknown key (known: cam_mm, triangles, coverage_deg)")
                spec[gk] = _typed(path, f"{key}.generated.{gk}", gv, int if gk == "triangles" else float)
            name = _typed(path, f"{key}.name", e.get("name", f"generated-{k}"), str)
            subjects.append({"name": name, "generated": spec})
            continue
        if not isinstance(e, str):
            _fail(path, key, f"expected a path, glob or table, got {e!r}")
        pattern = os.path.join(base, os.path.expanduser(os.path.expandvars(e)))
        if any(c in e for c in "*?["):
            found = sorted(glob.glob(pattern))
            if not found:
                _fail(path, key, f"'{e}' matches no file")
        else:
            found = [pattern]
        for f in found:
            if os.path.isdir(f):
                f = os.path.join(f, "subject.json")
            if not os.path.isfile(f):
                _fail(path, key, f"'{f}' is not a subject.json file")
            f = os.path.normpath(f)
            try:
                info = _json_file.load(f)  # a key given twice is an error, as the extension says it
            except ValueError as err:
                _fail(path, key, f"{f}: not JSON ({err})")
            name = os.path.basename(os.path.dirname(f))
            subjects.append({"name": name, "path": f, "side": info.get("side", "right") if isinstance(info, dict)
                             else "right"})
    names = [s["name"] for s in subjects]
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        _fail(path, "subjects", f"two subjects named '{dup[0]}' (a subject is named by its folder)")
    return subjects


def parse_override(text):
    """'KEY=VALUE' (KEY dotted, e.g. perturb.samples; VALUE in TOML, e.g. 3 or ["a/*/subject.json"]) ->
    (KEY, value). Raises StudyError."""
    key, sep, value = text.partition("=")
    if not sep or not key.strip():
        raise StudyError(f"--set {text}: expected KEY=VALUE (e.g. perturb.samples=3)")
    try:
        return key.strip(), tomllib.loads(f"v = {value}")["v"]
    except tomllib.TOMLDecodeError:
        return key.strip(), value  # a bare string


def toml_value(v):
    """A value as TOML writes it inline (for --set): tables {k = v}, arrays, strings, numbers, booleans."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, dict):
        return "{" + ", ".join(f"{k} = {toml_value(x)}" for k, x in v.items()) + "}"
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(toml_value(x) for x in v) + "]"
    if isinstance(v, str):
        return json.dumps(v)
    return repr(v)


def _apply(doc, overrides, path):
    for key, value in (overrides or {}).items():
        parts = key.split(".")
        node = doc
        for p in parts[:-1]:
            node = node.setdefault(p, {})
            if not isinstance(node, dict):
                _fail(path, key, "cannot set a key inside a value that is not a table")
        node[parts[-1]] = value


def load_study(path, overrides=None):
    """Read and check a study file -> dict(path, name, seed, threads, subjects, tasks (the [[task]] tables,
    checked, with their swept values as lists), joint, perturb). overrides: {dotted key: value} set over the
    file's (e.g. {"perturb.samples": 3}; checked as the file's keys are). Raises StudyError naming the file and
    key."""
    path = os.fspath(path)
    try:
        with open(path, "rb") as f:
            doc = tomllib.load(f)
    except OSError as e:
        raise StudyError(f"{path}: cannot read it ({e.strerror})") from None
    except tomllib.TOMLDecodeError as e:
        raise StudyError(f"{path}: not TOML ({e})") from None
    _apply(doc, overrides, path)
    unknown = set(doc) - TOP_KEYS
    if unknown:
        _fail(path, sorted(unknown)[0], f"unknown key (known: {', '.join(sorted(TOP_KEYS))})")
    study = {"path": os.path.abspath(path), "name": _typed(path, "name", doc.get("name", os.path.splitext(
        os.path.basename(path))[0]), str), "seed": _typed(path, "seed", doc.get("seed", 0), int),
             "threads": _typed(path, "threads", doc.get("threads", 1), int)}
    if study["threads"] < 1:
        _fail(path, "threads", "must be >= 1 (OpenMP threads per task)")
    if "subjects" not in doc:
        _fail(path, "subjects", "missing (a list of subject.json paths, globs or folders)")
    study["subjects"] = _subject_entries(path, doc["subjects"])
    joint = doc.get("joint", {})
    if not isinstance(joint, dict):
        _fail(path, "joint", "expected a table of Joint options")
    study["joint"] = {}
    for k, v in joint.items():
        k = _current(path, "joint", joint, k)
        if k not in JOINT_KEYS:
            _fail(path, f"joint.{k}", f"unknown Joint option (known: {', '.join(sorted(JOINT_KEYS))})")
        study["joint"][k] = _values(path, f"joint.{k}", v, JOINT_KEYS[k])
    perturb = doc.get("perturb", {})
    if not isinstance(perturb, dict):
        _fail(path, "perturb", "expected a table {cor_sd_mm, samples}")
    for k in perturb:
        if k not in PERTURB_KEYS:
            _fail(path, f"perturb.{k}", f"unknown key (known: {', '.join(sorted(PERTURB_KEYS))})")
    study["perturb"] = {"cor_sd_mm": _typed(path, "perturb.cor_sd_mm", perturb.get("cor_sd_mm", 0.0), float),
                        "samples": _typed(path, "perturb.samples", perturb.get("samples", 0), int)}
    if study["perturb"]["cor_sd_mm"] < 0:
        _fail(path, "perturb.cor_sd_mm", "must be >= 0 mm")
    if study["perturb"]["samples"] < 0:
        _fail(path, "perturb.samples", "must be >= 0 (0: no perturbation)")
    tasks = doc.get("task")
    if not isinstance(tasks, list) or not tasks or not all(isinstance(t, dict) for t in tasks):
        _fail(path, "task", "missing: give one [[task]] table per task, with kind = rom, envelope, motion or distance")
    base = os.path.dirname(os.path.abspath(path))
    study["tasks"] = [_task_entry(path, base, i, t) for i, t in enumerate(tasks)]
    checks.check_settings(path, study)
    checks.check_files(path, study)
    return study


def _resolve(base, given):
    """A path as the study file gives it, made absolute: relative to the study file's folder `base` (~ and $VARS
    expanded; an absolute path stays as it is)."""
    return os.path.normpath(os.path.join(base, os.path.expanduser(os.path.expandvars(given))))


def _file_value(path, base, key, given):
    """A path option's value (e.g. target_motion): {"file": the absolute path, "given": the text as given}."""
    f = _resolve(base, given)
    if not os.path.isfile(f):
        _fail(path, key, f"'{given}': no such file ({f}; paths are relative to the study file's folder)")
    return {"file": f, "given": given}


def _is_file_value(v):
    return isinstance(v, dict) and set(v) == {"file", "given"}


def _task_entry(path, base, i, t):
    """[[task]] table i, checked: dict(kind, label, joint {key: [values]}, options {key: [values]}); motion files
    and path options resolved against the study file's folder `base`."""
    key = f"task[{i}]"
    kind = t.get("kind")
    if kind not in KINDS:
        _fail(path, f"{key}.kind", f"expected one of {', '.join(KINDS)}, got {kind!r}")
    entry = {"kind": kind, "label": _typed(path, f"{key}.label", t.get("label", kind), str), "joint": {},
             "options": {}}
    for k, v in t.items():
        if k in ("kind", "label"):
            continue
        k = _current(path, key, t, k)
        if k in JOINT_KEYS:
            entry["joint"][k] = _values(path, f"{key}.{k}", v, JOINT_KEYS[k])
        elif k == "poses":
            entry["options"][k] = v  # a list of poses, not a sweep: checked below
        elif k in KIND_KEYS[kind]:
            values = _values(path, f"{key}.{k}", v, KIND_TYPES[k])
            if k in PATH_KEYS:
                values = [_file_value(path, base, f"{key}.{k}" + (f"[{j}]" if len(values) > 1 else ""), x)
                          for j, x in enumerate(values)]
            entry["options"][k] = values
        else:
            _fail(path, f"{key}.{k}", f"unknown option of a {kind} task (known: "
                  f"{', '.join(sorted(set(KIND_KEYS[kind]) | set(JOINT_KEYS) | {'label'}))})")
    if kind == "motion":
        if "motion" not in entry["options"]:
            _fail(path, f"{key}.motion", "missing: a motion file (CSV or OpenSim .mot/.sto) or a list of them")
        files = []
        for m in entry["options"]["motion"]:
            f = _resolve(base, m)
            if not os.path.isfile(f):
                _fail(path, f"{key}.motion", f"'{m}': no such file ({f}; paths are relative to the study file's "
                      "folder)")
            files.append(f)
        entry["options"]["motion"] = files
    if kind == "distance":
        if "poses" not in entry["options"]:
            _fail(path, f"{key}.poses", "missing: [[flexion, adduction, internal_rotation], ...] degrees")
        poses = entry["options"]["poses"]
        if not isinstance(poses, list) or not poses:
            _fail(path, f"{key}.poses", "expected [[flexion, adduction, internal_rotation], ...] degrees")
        checked = []
        for p, pose in enumerate(poses):
            if not isinstance(pose, list) or len(pose) != 3:
                _fail(path, f"{key}.poses[{p}]", "expected [flexion, adduction, internal_rotation] degrees")
            checked.append([_typed(path, f"{key}.poses[{p}][{c}]", x, float) for c, x in enumerate(pose)])
        entry["options"]["poses"] = checked
    return entry


_digests = {}


def file_digest(path):
    """sha256 of a file's bytes (cached per path and modification time)."""
    st = os.stat(path)
    key = (path, st.st_mtime_ns, st.st_size)
    if key not in _digests:
        h = hashlib.sha256()
        with open(path, "rb") as f:
            for block in iter(lambda: f.read(1 << 20), b""):
                h.update(block)
        _digests[key] = h.hexdigest()
    return _digests[key]


def subject_digest(subject):
    """A subject's inputs as a hash: subject.json and both mesh files' contents, or the generated model's spec."""
    if "generated" in subject:
        return hashlib.sha256(json.dumps(subject["generated"], sort_keys=True).encode()).hexdigest()
    parts = [file_digest(subject["path"])]
    for key, mesh in sorted(impinge.subject_meshes(subject["path"]).items()):
        if not os.path.isfile(mesh):
            raise StudyError(f"{subject['path']}: {key}: '{mesh}': no such file")
        parts.append(file_digest(mesh))
    return hashlib.sha256("|".join(parts).encode()).hexdigest()


def cor_offset(seed, subject_name, sample, sd_mm):
    """The COR offset (3,) mm of perturbation `sample` of a subject: 0 for sample 0 (the nominal COR), else
    drawn from N(0, sd_mm^2) per axis by numpy's PCG64 seeded with (seed, crc32(subject name), sample), so a
    sample's offset is the same in every task, method and shard of the subject (paired comparisons)."""
    if sample == 0 or sd_mm == 0:
        return [0.0, 0.0, 0.0]
    rng = np.random.default_rng([seed, zlib.crc32(subject_name.encode()), sample])
    return [float(x) for x in rng.normal(0.0, sd_mm, 3)]


def _product(choices):
    """Every combination of {key: [values]} as dicts, in the keys' sorted order (the last key fastest)."""
    combos = [{}]
    for k in sorted(choices):
        combos = [dict(c, **{k: v}) for c in combos for v in choices[k]]
    return combos


def short_names(files):
    """{file: name}: each file named by its last path parts, as few as keep different files apart (its basename
    when no other file has it), so that outputs named after files never pool two of them."""
    files = sorted(set(files))
    parts = {f: f.split(os.sep) for f in files}
    names = {}
    for f in files:
        n = 1
        while n < len(parts[f]) and any(g != f and parts[g][-n:] == parts[f][-n:] for g in files):
            n += 1
        names[f] = "/".join(parts[f][-n:])
    return names


def _task_options(options):
    """A task's options three ways: as its method takes them (a path option: the absolute path), as its id hashes
    them (a path option: the text given and the file's sha256, so that editing the file changes the id) and the
    text given for each path option (results.csv's, plan.json's target name)."""
    run = {k: v["file"] if _is_file_value(v) else v for k, v in options.items()}
    ident = {k: {"given": v["given"], "sha256": file_digest(v["file"])} if _is_file_value(v) else v
             for k, v in options.items()}
    return run, ident, {k: v["given"] for k, v in options.items() if _is_file_value(v)}


def expand(study):
    """The study's tasks, in a fixed order (subject, task table, swept values, motion or pose, sample):
    a list of dicts with id, kind, label, subject (the entry), subject_name, side, sample, cor_offset_mm,
    joint (Joint keywords), options (the kind's method's keywords; a file's absolute path), given (the text a
    path option was given as), item (motion file or pose), item_name (a motion file's name in the results:
    short_names') and group (the tasks that share one Joint: same subject, settings and COR). A task's id hashes
    the contents of every file it reads (subject.json, both meshes, the motion file, a target motion), its
    settings and impinge's version."""
    version = impinge.__version__
    samples = study["perturb"]["samples"]
    sd = study["perturb"]["cor_sd_mm"]
    item_names = short_names([m for t in study["tasks"] for m in t["options"].get("motion", [])])
    tasks = []
    for subject in study["subjects"]:
        sdigest = subject_digest(subject)
        for t in study["tasks"]:
            joint_choices = dict(study["joint"], **t["joint"])
            option_choices = {k: v for k, v in t["options"].items() if k not in ("motion", "poses")}
            items = t["options"].get("motion") or t["options"].get("poses") or [None]
            item_digests = {m: file_digest(m) for m in t["options"].get("motion", [])}
            for joint in _product(joint_choices):
                for options in _product(option_choices):
                    options, ident, given = _task_options(dict({k: v for k, v in KIND_KEYS[t["kind"]].items()
                                                                if k not in ("motion", "poses")}, **options))
                    for item in items:
                        for sample in range(samples + 1):
                            offset = cor_offset(study["seed"], subject["name"], sample, sd)
                            group_key = json.dumps([sdigest, joint, offset], sort_keys=True)
                            identity = json.dumps({"subject": sdigest, "kind": t["kind"], "joint": joint,
                                                   "options": ident, "cor_offset_mm": offset,
                                                   "item": item_digests[item] if isinstance(item, str) else item,
                                                   "version": version},
                                                  sort_keys=True)
                            tasks.append({
                                "id": hashlib.sha256(identity.encode()).hexdigest()[:20], "kind": t["kind"],
                                "label": t["label"], "subject": subject, "subject_name": subject["name"],
                                "side": subject.get("side", "right"), "sample": sample, "cor_offset_mm": offset,
                                "joint": joint, "options": options, "given": given, "item": item,
                                "item_name": item_names.get(item) if isinstance(item, str) else None,
                                "group": hashlib.sha256(group_key.encode()).hexdigest()[:16],
                                "threads": study["threads"]})
    _refuse_duplicates(study, tasks)
    return tasks


def _refuse_duplicates(study, tasks):
    """Two tasks with one id are one computation listed twice: a StudyError naming them."""
    first = {}
    for t in tasks:
        if t["id"] not in first:
            first[t["id"]] = t
            continue
        a = first[t["id"]]
        if t["kind"] == "motion" and a["item"] != t["item"]:
            raise StudyError(f"{study['path']}: task: motion files '{a['item']}' and '{t['item']}' have the same "
                             "contents (one motion listed twice); give it once")
        raise StudyError(f"{study['path']}: task: two tasks are the same computation ({t['kind']} on "
                         f"{t['subject_name']}, sample {t['sample']}); give each [[task]] different settings")
