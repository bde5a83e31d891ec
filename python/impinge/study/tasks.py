"""Running a study's tasks: one task, or a group of tasks that share one Joint (same subject, settings and
COR), in whatever process runs them (this one, a Dask worker, a shard on a batch system).

A task writes its outputs into DIR/tasks/.tmp-<id>-<random>/ and renames that folder to DIR/tasks/<id>/
when it is complete, so a task folder either holds a whole task (task.json last) or does not exist. A task
that raises is recorded (status "error", the message) and does not stop the others."""
import collections
import hashlib
import json
import math
import os
import shutil
import socket
import time
import traceback
import uuid
import warnings

import numpy as np

import impinge

# The Joints this process has built, by group (subject, settings, COR), most recent last.
_JOINTS = collections.OrderedDict()
_NOMINAL_COR = {}  # subject (path or generated spec) -> its nominal COR: one fit for all its perturbed samples
_JOINT_CACHE_SIZE = int(os.environ.get("IMPINGE_STUDY_JOINT_CACHE", "2"))
_GENERATED = {}


def worker_name():
    """host:pid of this process (results.csv's worker column)."""
    return f"{socket.gethostname()}:{os.getpid()}"


def _generated(spec):
    key = json.dumps(spec, sort_keys=True)
    if key not in _GENERATED:
        _GENERATED[key] = impinge.generated_hip(triangles=spec["triangles"], cam_mm=spec["cam_mm"],
                                                coverage_deg=spec["coverage_deg"])
    return _GENERATED[key]


def _nominal_cor(task):
    """The COR the Joint finds by itself (input frame, mm), by the session's own policy
    (impinge.femoral_head_centre). Once per subject."""
    subject = task["subject"]
    key = json.dumps(subject, sort_keys=True)
    if key not in _NOMINAL_COR:
        if "generated" in subject:
            h = _generated(subject["generated"])
            found = impinge.femoral_head_centre(h["femur"], h["pelvis"])
        else:
            found = impinge.femoral_head_centre(subject=subject["path"])
        _NOMINAL_COR[key] = np.asarray(found["centre"], dtype=float)
    return _NOMINAL_COR[key]


def build_joint(task):
    """The Joint of a task: its subject, its Joint keywords, and its COR (the nominal one moved by the
    task's cor_offset_mm; sample 0 leaves the COR to the Joint)."""
    kw = dict(task["joint"])
    if any(task["cor_offset_mm"]):
        if "head_region" in kw:
            raise impinge.Error("perturb: a COR perturbation needs the automatic COR, not head_region")
        kw["cor"] = [float(x) for x in _nominal_cor(task) + np.asarray(task["cor_offset_mm"])]
    subject = task["subject"]
    if "generated" in subject:
        h = _generated(subject["generated"])
        kw.setdefault("neutral", "scan")  # a generated hip has no whole bones
        return impinge.Joint(h["femur"], h["pelvis"], **kw)
    return impinge.Joint(subject=subject["path"], **kw)


def joint_for(task):
    """(Joint, seconds spent building it here: 0 when this process holds it already)."""
    group = task["group"]
    if group in _JOINTS:
        _JOINTS.move_to_end(group)
        return _JOINTS[group], 0.0
    t0 = time.perf_counter()
    joint = build_joint(task)
    built = time.perf_counter() - t0
    _JOINTS[group] = joint
    while len(_JOINTS) > max(_JOINT_CACHE_SIZE, 1):
        _JOINTS.popitem(last=False)
    return joint, built


def _write_csv(path, columns):
    """columns: dict name -> 1-D array-like (equal lengths) -> a CSV with a header row."""
    names = list(columns)
    cols = [np.asarray(columns[n]) for n in names]
    with open(path, "w") as f:
        f.write(",".join(names) + "\n")
        for row in zip(*cols):
            f.write(",".join(cell(x) for x in row) + "\n")


def cell(x):
    """One CSV cell: exact floats (repr), nan, true/false, integers, text."""
    if isinstance(x, (bool, np.bool_)):
        return "true" if x else "false"
    if isinstance(x, (float, np.floating)):
        return repr(float(x)) if math.isfinite(x) else ("nan" if math.isnan(x) else repr(float(x)))
    if isinstance(x, (int, np.integer)):
        return str(int(x))
    return str(x)


def _run_rom(joint, task, folder):
    o = task["options"]
    d = joint.rom_limits(threshold_mm=o["threshold_mm"], step_deg=o["step_deg"], max_deg=o["max_deg"],
                         contacts=o["contacts"], contact_depth_mm=o["contact_depth_mm"], metric=o["metric"])
    motions = [k for k, v in d.items() if isinstance(v, dict)]
    # rom_limits.csv's columns, as the CLI writes them (not the contact point or the poses at and before the limit)
    fields = [k for k in d[motions[0]] if k not in ("contact_mm", "pose_at_limit_deg", "start_deg")]
    _write_csv(os.path.join(folder, "rom_limits.csv"),
               dict({"motion": motions}, **{k: [d[m][k] for m in motions] for k in fields}))
    figures = {}
    for m in motions:
        figures[f"limit_{m}_deg"] = float(d[m]["limit_deg"])
    for m in motions:
        figures[f"contact_class_{m}"] = d[m]["contact_class"]
    figures["excluded_vertices"] = int(d["excluded_vertices"])
    return figures


def _run_envelope(joint, task, folder):
    o = task["options"]
    ir = joint.rom_map(flexion=o["flexion"], adduction=o["adduction"], threshold_mm=o["threshold_mm"],
                       contact_depth_mm=o["contact_depth_mm"], metric=o["metric"])
    F, A = np.meshgrid(o["flexion"], o["adduction"], indexing="ij")
    _write_csv(os.path.join(folder, "rom_map.csv"), {"flexion_deg": F.ravel(), "adduction_deg": A.ravel(),
                                                     "max_internal_rotation_deg": ir.ravel()})
    finite = ir[np.isfinite(ir)]
    return {"envelope_cells": int(ir.size), "envelope_limited_cells": int(finite.size),
            "envelope_mean_ir_deg": float(finite.mean()) if finite.size else float("nan"),
            "envelope_min_ir_deg": float(finite.min()) if finite.size else float("nan"),
            "envelope_max_ir_deg": float(finite.max()) if finite.size else float("nan")}


def _run_motion(joint, task, folder):
    m = impinge.load_motion(task["item"], task["side"])
    r = joint.motion(m["angles"])
    columns = {k: v for k, v in r.items() if k not in ("detection_ms",)}
    columns["time_s"] = m["time_s"]
    _write_csv(os.path.join(folder, "frames.csv"), columns)
    gap = np.fmin(r["femur_min_gap_mm"], r["pelvis_min_gap_mm"])
    out = {"frames": int(len(gap)), "min_gap_mm": float(np.nanmin(gap)) if np.isfinite(gap).any() else float("nan")}
    out["min_gap_time_s"] = float(m["time_s"][int(np.nanargmin(gap))]) if np.isfinite(gap).any() else float("nan")
    if "femur_min_distance_mm" in r:
        dist = np.fmin(r["femur_min_distance_mm"], r["pelvis_min_distance_mm"])
        out["min_distance_mm"] = float(np.nanmin(dist)) if np.isfinite(dist).any() else float("nan")
        measure = dist
    else:
        measure = gap
    inside = measure < 0
    out["frames_penetrating"] = int(inside.sum())
    out["first_penetration_s"] = float(m["time_s"][int(np.argmax(inside))]) if inside.any() else float("nan")
    return out


def _run_distance(joint, task, folder):
    f, a, r = task["item"]
    d = joint.detect_pose(f, a, r)
    arrays = {k: v for k, v in d.items() if isinstance(v, np.ndarray)}
    np.savez_compressed(os.path.join(folder, "gaps.npz"), **arrays)
    out = {}
    for bone in ("femur", "pelvis"):
        for q in ("gap", "distance"):
            x = d.get(f"{bone}_{q}_mm")
            if x is None:
                continue
            out[f"{bone}_min_{q}_mm"] = float(np.nanmin(x)) if np.isfinite(x).any() else float("nan")
            out[f"{bone}_penetrating_vertices_{q}"] = int(np.sum(x < 0))
    return out


def _run_morphology(joint, task, folder):
    m = joint.morphology()
    with open(os.path.join(folder, "morphology.json"), "w") as f:
        json.dump(m, f, indent=1)
    out = {}
    for part in ("femur", "acetabulum"):
        for k, v in m[part].items():
            if isinstance(v, dict) and isinstance(v.get("value"), (int, float)) and not isinstance(v["value"], bool):
                out[k] = float(v["value"])
            elif isinstance(v, dict) and v.get("value") is None and "unit" in v:
                out[k] = float("nan")
    return out


def _run_plan(joint, task, folder):
    o = dict(task["options"])
    o["allow_partial"] = True  # a missed target is a result of the study, recorded in plan.json and its figures
    d = joint.plan(**o)
    for t in d["targets"]:  # a target motion named as the study file gives it, not by its absolute path
        if o.get("target_motion") and t["target"] == o["target_motion"]:
            t["target"] = task.get("given", {}).get("target_motion", t["target"])
    meshes = {k: d.pop(k) for k in list(d) if k.endswith("_resected") or k.endswith("_resection_mm")}
    with open(os.path.join(folder, "plan.json"), "w") as f:
        json.dump(d, f, indent=1)
    np.savez_compressed(os.path.join(folder, "resection.npz"),
                        **{k: np.asarray(v) for k, v in meshes.items() if k.endswith("_resection_mm")})
    out = {"all_targets_met": bool(d["all_targets_met"]), "plan_ms": float(d["timings_ms"]["total"])}
    for bone in ("femur", "pelvis"):
        r = d[f"{bone}_resection"]
        if r["resected"]:
            for k in ("volume_mm3", "area_mm2", "deepest_cut_mm", "mean_depth_mm"):
                out[f"{bone}_{k}"] = float(r[k])
    for t in d["targets"]:
        if "limit_after_deg" in t:
            out[f"limit_after_{t['target']}_deg"] = float("nan") if t["limit_after_deg"] is None else float(
                t["limit_after_deg"])
            out[f"met_{t['target']}"] = bool(t["met"])
        if "labral_limit_after_deg" in t:  # labrum = true: the labral limit, the one the plan targeted
            out[f"labral_limit_after_{t['target']}_deg"] = float("nan") if t["labral_limit_after_deg"] is None \
                else float(t["labral_limit_after_deg"])
    return out


RUNNERS = {"rom": _run_rom, "envelope": _run_envelope, "motion": _run_motion, "distance": _run_distance,
           "morphology": _run_morphology, "plan": _run_plan}


def task_record(task):
    """The parameters of a task as results.csv gives them (one flat dict)."""
    rec = {"task_id": task["id"], "kind": task["kind"], "label": task["label"], "subject": task["subject_name"],
           "side": task["side"], "sample": task["sample"], "cor_dx_mm": task["cor_offset_mm"][0],
           "cor_dy_mm": task["cor_offset_mm"][1], "cor_dz_mm": task["cor_offset_mm"][2],
           "cor_offset_mm": float(np.linalg.norm(task["cor_offset_mm"]))}
    for k, v in sorted(task["joint"].items()):
        rec[k] = json.dumps(v) if isinstance(v, list) else v
    given = task.get("given", {})  # a path option as the study file gives it
    for k, v in sorted(task["options"].items()):
        rec[k] = given[k] if k in given else json.dumps(v) if isinstance(v, list) else v
    if task["kind"] == "motion":  # its name in the study: as much of its path as keeps it apart from the others
        rec["motion"] = task.get("item_name") or os.path.basename(task["item"])
    if task["kind"] == "distance":
        rec["flexion_deg"], rec["adduction_deg"], rec["internal_rotation_deg"] = task["item"]
    return rec


def _file_records(folder):
    """{name: {bytes, sha256}} of a task folder's outputs (all but task.json), to notice damage on a rerun."""
    out = {}
    for name in sorted(os.listdir(folder)):
        path = os.path.join(folder, name)
        if name == "task.json" or not os.path.isfile(path):
            continue
        h = hashlib.sha256()
        with open(path, "rb") as f:
            for block in iter(lambda: f.read(1 << 20), b""):
                h.update(block)
        out[name] = {"bytes": os.path.getsize(path), "sha256": h.hexdigest()}
    return out


def read_done(tasks_dir, task):
    """The record of a finished task (its task.json), or None when it has not finished. A task folder whose
    task.json is unreadable, or whose outputs differ from the sizes and checksums task.json recorded (a file
    truncated, emptied or deleted since), is damaged: it is moved aside (tasks/.damaged-<id>-<random>) and the
    task counts as not finished, so that the run does it again."""
    folder = os.path.join(tasks_dir, task["id"])
    if not os.path.isdir(folder):
        return None
    try:
        with open(os.path.join(folder, "task.json")) as f:
            record = json.load(f)
        files = record["files"]
        damaged = _file_records(folder) != files
    except (OSError, ValueError, KeyError, TypeError):
        damaged = True
    if damaged:
        aside = os.path.join(tasks_dir, f".damaged-{task['id']}-{uuid.uuid4().hex[:8]}")
        try:
            os.rename(folder, aside)
        except OSError:
            pass  # moved aside or redone by another worker meanwhile
        return None
    return record


def run_task(task, tasks_dir):
    """Run one task here and write DIR/tasks/<id>/ (its outputs, then task.json) -> its record: parameters,
    figures, status ('ok' or 'error'), error, warnings (the Joint's, about its input), time_s (the task's own time, with its Joint's build when built
    here), joint_build_s, worker."""
    folder = os.path.join(tasks_dir, f".tmp-{task['id']}-{uuid.uuid4().hex[:8]}")
    os.makedirs(folder)
    record = {"parameters": task_record(task), "figures": {}, "status": "ok", "error": "", "warnings": "",
              "worker": worker_name()}
    t0 = time.perf_counter()
    built = 0.0
    try:
        impinge.set_threads(task.get("threads", 1))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # the Joint's warnings go to the record, from joint.warnings
            joint, built = joint_for(task)
        record["warnings"] = " | ".join(joint.warnings)
        record["figures"] = RUNNERS[task["kind"]](joint, task, folder)
    except Exception as e:  # noqa: BLE001 (a task's error is recorded, the study goes on)
        record["status"] = "error"
        record["error"] = f"{type(e).__name__}: {e}".replace("\n", " ")
        with open(os.path.join(folder, "traceback.txt"), "w") as f:
            f.write(traceback.format_exc())
    record["time_s"] = time.perf_counter() - t0
    record["joint_build_s"] = built
    record["task"] = task
    record["files"] = _file_records(folder)
    with open(os.path.join(folder, "task.json"), "w") as f:
        json.dump(record, f, indent=1, default=float)
    target = os.path.join(tasks_dir, task["id"])
    try:
        os.rename(folder, target)
    except OSError:  # done meanwhile by another worker (a task rescheduled after its worker was lost)
        shutil.rmtree(folder, ignore_errors=True)
        done = read_done(tasks_dir, task)
        if done is not None:
            return done
        raise
    return record


def run_group(tasks, tasks_dir, retry_errors=False):
    """Run the tasks of one group (one Joint) in order, skipping those already finished -> their records.
    The group's Joint is built once, for its first unfinished task."""
    records = []
    for task in tasks:
        done = read_done(tasks_dir, task)
        if done is not None and (done["status"] == "ok" or not retry_errors):
            done["skipped"] = True
            records.append(done)
            continue
        if done is not None:
            shutil.rmtree(os.path.join(tasks_dir, task["id"]), ignore_errors=True)
        records.append(run_task(task, tasks_dir))
    return records
