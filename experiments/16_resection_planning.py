"""Experiment 16 (issue 50): resection planning. How much bone `impinge plan` removes, where, and what it restores,
against cams of known size and position.

Three parts, all with the CLI's defaults (equidistant joint centre, distance metric, contact depth 0.25 mm,
clearance 0.3 mm, burr radius 2.5 mm, safety depth 30 % of the neck's least diameter) at 0.25 deg
(--quick: 0.5 deg):
  generated  generated hips (12,000 triangles) with a cam of 1-4 mm: targets = the cam-free hip's limits of the
             motions the cam limits (flexion, abduction, internal rotation); the cam's volume (the two meshes share
             their vertices: numpy's divergence theorem), the plan's volume, area, depths, the share of the removal
             on the cam, the limits after (the plan's check) and the time.
  added_cam  every shared hip's femur with a cam added at its antero-superior head-neck junction (a radial bump of
             CAM_MM, Gaussian over 12 deg about the direction CAM_FROM_NECK_DEG from the neck towards 1:30 o'clock
             of the ISB femur frame): targets = the same hip's limits without the cam where the cam lowered them by
             more than 1 deg; checked again by a separate ROM search on the resected femur (a new Joint on the
             returned mesh).
  ir90       every shared hip: internal rotation at 90 deg flexion raised by 10 deg, resecting the femur, and both
             bones: met or why not, volume, time.

Timing: the plan of the generated hip with the largest cam and lhdl-ct's femur-only ir90 plan, 5 times each
(--quick: 3), alternated: plan_times.csv.

--quick (CI's budget, issue 82 item 7): maps at 0.5 deg, 3 timing runs, and the shared hips' parts (added_cam, ir90)
on QUICK_HIPS alone (lhdl-ct, the timed hip, and tlem2-mri: a CT and an MRI hip; the mc22 pair is left out; the first
two hips when neither is there).

Outputs (OUT/16_resection_planning/): generated.csv, added_cam.csv, ir90.csv, plan_times.csv, published.csv (the published
resection volumes and ROM gains the analysis sets beside ours: experiments/16_published.csv), meta.json.

usage: exp_16_resection_planning --out DIR [--data DIR] [--quick]"""
import csv
import os
import shutil
import time

import numpy as np

from experiment_support import experiment_args, write_meta

import impinge

HERE = os.path.dirname(os.path.abspath(__file__))
CAMS_MM = (1.0, 2.0, 3.0, 4.0)
GENERATED_TARGETS = ("flexion", "abduction", "internal_rotation")
CAM_MM = 3.0
CAM_WIDTH_DEG = 12.0
TIMED_HIP = "lhdl-ct"  # the shared hip whose plan time the paper quotes
QUICK_HIPS = (TIMED_HIP, "tlem2-mri")  # --quick: the shared hips planned
CAM_FROM_NECK_DEG = 62.0  # the bump's centre: this far from the neck axis (towards the neck), at the junction


def volume(V, F):
    V = np.asarray(V, dtype=float)
    return abs(np.einsum("ij,ij->i", V[F[:, 0]], np.cross(V[F[:, 1]], V[F[:, 2]])).sum() / 6)


def vertex_areas(V, F):
    tri = 0.5 * np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]), axis=1)
    a = np.zeros(len(V))
    np.add.at(a, F.ravel(), np.repeat(tri / 3, 3))
    return a


def limits_of(joint):
    return {m: r for m, r in joint.rom_limits().items() if isinstance(r, dict)}


def in_file_order(p, bone, n):
    """A plan's per-vertex resection depth (mm) of `bone` in the file's n vertices: the vertices the reading removed
    (meshes.<bone>.vertices_removed: a speck inside the bone, a fragment) cut by 0."""
    removed = p["meshes"][bone]["vertices_removed"]
    depth = np.zeros(n)
    depth[np.setdiff1d(np.arange(n), removed)] = np.asarray(p[f"{bone}_resection_mm"])
    return depth


def on_cam_share(V_cam, V_free, F, depth):
    """The share of the removal (depth x area) on the vertices the cam moved."""
    w = vertex_areas(V_cam, F) * depth
    on = np.linalg.norm(V_cam - V_free, axis=1) > 0.05
    return float(w[on].sum() / w.sum()) if w.sum() > 0 else float("nan")


def add_cam(V, centre, radius, neck_axis, frame, height):
    """The femur with a radial bump at the antero-superior head-neck junction (input frame, mm)."""
    a = np.asarray(neck_axis, dtype=float)  # from the neck towards the head centre
    x, y = np.asarray(frame["x_axis"], dtype=float), np.asarray(frame["y_axis"], dtype=float)  # anterior, superior
    u = (x + y) - np.dot(x + y, a) * a
    u /= np.linalg.norm(u)
    t = np.radians(CAM_FROM_NECK_DEG)
    d = np.cos(t) * (-a) + np.sin(t) * u
    p = V - centre
    r = np.linalg.norm(p, axis=1)
    g = np.degrees(np.arccos(np.clip(p @ d / r, -1, 1))) / CAM_WIDTH_DEG
    near = (r > radius - 6) & (r < radius + 12)  # the head-neck junction, not the far neck or the shaft
    bump = np.where(near, height * np.exp(-g * g), 0.0)
    return V + p / r[:, None] * bump[:, None]


def main():
    d, data, quick = experiment_args("16_resection_planning", __doc__)
    precision = 0.5 if quick else 0.25
    hips = sorted(h for h in os.listdir(data) if os.path.exists(os.path.join(data, h, "subject.json"))) \
        if data and os.path.isdir(data) else []
    if quick:
        hips = [h for h in hips if h in QUICK_HIPS] or hips[:2]
    shutil.copyfile(os.path.join(HERE, "16_published.csv"), os.path.join(d, "published.csv"))
    plan_columns = ["volume_mm3", "area_mm2", "deepest_cut_mm", "mean_depth_mm", "clock_from_h", "clock_to_h"]

    timed = {}  # plans whose time the paper quotes: timed again below, with their spread

    # Generated cams.
    with open(os.path.join(d, "generated.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["cam_mm", "cam_volume_mm3"] + plan_columns + ["on_cam_share", "motion", "limit_free_deg",
                                                                 "limit_cam_deg", "limit_after_deg", "met", "plan_ms"])
        free_hip = impinge.generated_hip(triangles=12000, cam_mm=0.0)
        free = limits_of(impinge.Joint(free_hip["femur"], free_hip["pelvis"], precision=precision, neutral="scan"))
        for cam in CAMS_MM:
            print(f"[16_resection_planning] generated cam {cam:g} mm", flush=True)
            h = impinge.generated_hip(triangles=12000, cam_mm=cam)
            j = impinge.Joint(h["femur"], h["pelvis"], precision=precision, neutral="scan")
            before = limits_of(j)
            target = ",".join(f"{m}={free[m]['limit_deg']:.2f}" for m in GENERATED_TARGETS
                              if before[m]["limit_deg"] < free[m]["limit_deg"] - 0.5)
            if not target:
                for m in GENERATED_TARGETS:
                    w.writerow([cam, volume(h["femur"][0], h["femur"][1]) - volume(free_hip["femur"][0], free_hip["femur"][1])]
                               + [0.0] * 4 + ["nan", "nan", "nan", m, free[m]["limit_deg"], before[m]["limit_deg"],
                                             before[m]["limit_deg"], 1, 0.0])
                continue
            plan = lambda j=j, target=target: j.plan(target=target, allow_partial=True)  # noqa: E731
            t0 = time.perf_counter()
            p = plan()
            ms = (time.perf_counter() - t0) * 1e3
            timed["generated"] = (f"generated hip with the {cam:g} mm cam", plan)
            r = p["femur_resection"]
            cam_volume = volume(h["femur"][0], h["femur"][1]) - volume(free_hip["femur"][0], free_hip["femur"][1])
            share = on_cam_share(np.asarray(h["femur"][0]), np.asarray(free_hip["femur"][0]), np.asarray(h["femur"][1]),
                                 in_file_order(p, "femur", len(h["femur"][0])))
            after = {t["target"]: t for t in p["targets"]}
            for m in GENERATED_TARGETS:
                t = after.get(m)
                w.writerow([cam, cam_volume] + [r[k] if r[k] is not None else "nan" for k in plan_columns] +
                           [share, m, free[m]["limit_deg"], before[m]["limit_deg"],
                            t["limit_after_deg"] if t else before[m]["limit_deg"], int(t["met"]) if t else 1, ms])

    # Real femurs with an added cam, and internal rotation at 90 deg flexion + 10 deg.
    with open(os.path.join(d, "added_cam.csv"), "w", newline="") as fa, \
            open(os.path.join(d, "ir90.csv"), "w", newline="") as fi:
        wa, wi = csv.writer(fa), csv.writer(fi)
        wa.writerow(["subject", "cam_mm", "cam_volume_mm3"] + plan_columns +
                    ["on_cam_share", "motion", "limit_free_deg", "limit_cam_deg", "limit_after_deg",
                     "limit_checked_deg", "met", "plan_ms"])
        wi.writerow(["subject", "resect", "limit_before_deg", "target_deg", "limit_after_deg", "met", "note"] +
                    [f"femur_{k}" for k in plan_columns[:3]] + [f"pelvis_{k}" for k in plan_columns[:3]] + ["plan_ms"])
        for hip in hips:
            subject = os.path.join(data, hip, "subject.json")
            print(f"[16_resection_planning] {hip}", flush=True)
            j = impinge.Joint(subject=subject, precision=precision)
            free = limits_of(j)
            # IR at 90 deg flexion + 10 deg.
            ir = free["internal_rotation_90_flexion"]
            if ir["status"] == "limited":
                for resect in ("femur", "both"):
                    plan = lambda j=j, resect=resect, limit=ir["limit_deg"]: j.plan(  # noqa: E731
                        target=f"internal_rotation_90_flexion={limit + 10:.3f}", resect=resect, allow_partial=True)
                    t0 = time.perf_counter()
                    p = plan()
                    ms = (time.perf_counter() - t0) * 1e3
                    if resect == "femur" and hip == TIMED_HIP:
                        timed["shared"] = (f"{hip} internal rotation at 90 deg flexion + 10 deg, femur", plan)
                    t = p["targets"][0]
                    fr, pr = p["femur_resection"], p["pelvis_resection"]
                    wi.writerow([hip, resect, ir["limit_deg"], t["target_deg"], t["limit_after_deg"], int(t["met"]),
                                 t["note"]] + [fr[k] for k in plan_columns[:3]] +
                                [pr[k] if pr["resected"] else 0.0 for k in plan_columns[:3]] + [ms])
            # The added cam.
            m = j.morphology()["femur"]
            V, F = impinge.load_mesh(os.path.join(data, hip, impinge.subject_meshes(subject)["femur"]))
            Vc = add_cam(V, np.asarray(m["head_centre_mm"]["value"]), m["head_radius_mm"]["value"],
                         m["neck_axis"]["value"], m["frame"], CAM_MM)
            cam_volume = volume(Vc, F) - volume(V, F)
            pelvis = os.path.join(data, hip, impinge.subject_meshes(subject)["pelvis"])
            jc = impinge.Joint((Vc, F), pelvis, subject=subject, precision=precision)
            cam = limits_of(jc)
            lowered = [k for k in free if free[k]["status"] == "limited" and cam[k]["status"] == "limited"
                       and cam[k]["limit_deg"] < free[k]["limit_deg"] - 1]
            if not lowered:
                wa.writerow([hip, CAM_MM, cam_volume] + ["nan"] * 6 + ["nan", "none", "nan", "nan", "nan", "nan", 1, 0])
                continue
            t0 = time.perf_counter()
            p = jc.plan(target=",".join(f"{k}={free[k]['limit_deg']:.3f}" for k in lowered), allow_partial=True)
            ms = (time.perf_counter() - t0) * 1e3
            Vr, Fr = p["femur_resected"]
            checked = limits_of(impinge.Joint((np.asarray(Vr), np.asarray(Fr)), pelvis, subject=subject,
                                              precision=precision))
            share = on_cam_share(Vc, V, F, in_file_order(p, "femur", len(V)))
            r = p["femur_resection"]
            after = {t["target"]: t for t in p["targets"]}
            for k in lowered:
                wa.writerow([hip, CAM_MM, cam_volume] + [r[c] if r[c] is not None else "nan" for c in plan_columns] +
                            [share, k, free[k]["limit_deg"], cam[k]["limit_deg"], after[k]["limit_after_deg"],
                             checked[k]["limit_deg"], int(after[k]["met"]), ms])
    # The plan times the paper quotes, with their spread: each timed plan REPS times, the plans alternated (one
    # run of each in turn), the Joint built (its maps are the set-up, not the plan).
    reps = 3 if quick else 5
    with open(os.path.join(d, "plan_times.csv"), "w", newline="") as ft:
        wt = csv.writer(ft)
        wt.writerow(["kind", "plan", "repetition", "plan_ms"])
        for k in range(reps):
            for kind, (name, run) in sorted(timed.items()):
                t0 = time.perf_counter()
                run()
                wt.writerow([kind, name, k, (time.perf_counter() - t0) * 1e3])
    write_meta(d, "16_resection_planning", quick=quick, data_folder=data if hips else None, repetitions=reps,
               timing="plan_times.csv: wall time of Joint.plan (the ROM check included) on 2 cores, each timed plan "
                      "run REPS times, alternated; the plan_ms columns of the other CSVs: one run each",
               parameters={
                   "precision_deg": precision, "subjects": hips, "generated_cams_mm": list(CAMS_MM),
                   "generated_triangles": 12000, "added_cam_mm": CAM_MM, "added_cam_width_deg": CAM_WIDTH_DEG,
                   "added_cam_from_neck_deg": CAM_FROM_NECK_DEG, "timed_hip": TIMED_HIP,
                   "plan": "CLI defaults (clearance 0.3 mm, burr radius 2.5 mm, safety depth 0.3 x neck diameter; "
                           "equidistant joint centre, distance metric, contact depth 0.25 mm)"})


if __name__ == "__main__":
    main()
