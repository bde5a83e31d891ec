"""Experiment 15 (issue 49): the morphology of every shared hip beside its ROM limits and the published normal
ranges, so that the paper tests, and does not assert, whether the shared hips have a cam or a pincer.

For each shared hip with a subject.json under --data: impinge.Joint (the CLI's defaults: equidistant joint centre,
distance metric) at 0.1 deg (--quick: 0.5 deg), its morphology (Joint.morphology(): clinical/morphology.hpp) and its
ROM limits in the ISB pelvic frame and in the anterior pelvic plane (pelvis_frame 'app', the frame of clinical
tools and of the published simulated ranges); and the generated hips below.

Outputs (OUT/15_morphology/):
  morphology.csv  one row per hip: head radius and sphericity, neck-shaft angle, femoral version (posterior
                  condylar and transepicondylar), alpha angle per clock hour and its largest, head-neck offset
                  ratio; acetabular radius, inclination, version (anterior pelvic plane), lateral and anterior
                  centre-edge angles, head coverage
  limits.csv      one row per hip, pelvic frame and motion: limit_deg, status, normal_deg, soft_tissue_first (the
                  generated hips also internal_rotation_map_F_flexion: the ROM map's internal rotation at F deg)
  published.csv   the published normal ranges the analysis sets beside ours (experiments/15_published.csv)
  meta.json
Always also the generated hips with a cam of 0-4 mm (12,000 triangles; scan neutral: no landmarks, so no version or
neck-shaft angle, and their limits in the input frame's axes): how the alpha angle and internal rotation at 90 deg
flexion follow the cam.

usage: exp_15_morphology --out DIR [--data DIR] [--quick]"""
import csv
import os
import shutil
import time

from experiment_support import experiment_args, write_meta

import impinge

HERE = os.path.dirname(os.path.abspath(__file__))
CAMS_MM = (0.0, 1.0, 2.0, 3.0, 4.0)
MAP_FLEXION_DEG = [0.0, 20.0, 40.0]  # generated hips (12,000 triangles, scan neutral): the cam's height
MORPH_COLUMNS = ["subject", "side", "head_radius_mm", "head_fit_rms_mm", "sphericity_rms_mm", "sphericity_max_mm",
                 "neck_shaft_angle_deg", "version_posterior_condylar_deg", "version_transepicondylar_deg",
                 "alpha_max_deg", "alpha_max_hour"] + [f"alpha_{h}h_deg" for h in range(1, 13)] + \
                ["head_neck_offset_ratio", "acetabular_radius_mm", "radiographic_inclination_deg",
                 "radiographic_anteversion_deg", "lateral_centre_edge_deg", "anterior_centre_edge_deg", "head_coverage", "ms"]


def value(part, key):
    v = part[key]["value"]
    return "nan" if v is None else v


def main():
    d, data, quick = experiment_args("15_morphology", __doc__)
    resolution = 0.5 if quick else 0.1
    hips = sorted(h for h in os.listdir(data) if os.path.exists(os.path.join(data, h, "subject.json"))) \
        if data and os.path.isdir(data) else []
    shutil.copyfile(os.path.join(HERE, "15_published.csv"), os.path.join(d, "published.csv"))
    with open(os.path.join(d, "morphology.csv"), "w", newline="") as fm, \
            open(os.path.join(d, "limits.csv"), "w", newline="") as fl:
        wm, wl = csv.writer(fm), csv.writer(fl)
        wm.writerow(MORPH_COLUMNS)
        wl.writerow(["subject", "pelvic_frame", "motion", "limit_deg", "status", "normal_deg", "soft_tissue_first"])
        runs = [(hip, lambda frame, hip=hip: impinge.Joint(subject=os.path.join(data, hip, "subject.json"),
                                                          resolution=resolution, pelvis_frame=frame))
                for hip in hips]
        for cam in CAMS_MM:
            h = impinge.generated_hip(triangles=12000, cam_mm=cam)
            runs.append((f"generated-cam{cam:g}", lambda frame, h=h: impinge.Joint(
                h["femur"], h["pelvis"], resolution=resolution, neutral="scan")))
        for hip, make in runs:
            print(f"[15_morphology] {hip}", flush=True)
            j = make("isb")
            t0 = time.perf_counter()
            m = j.morphology()
            ms = (time.perf_counter() - t0) * 1e3
            f, a = m["femur"], m["acetabulum"]
            alpha = f["alpha_deg_by_hour"]["value"]
            wm.writerow([hip, m["side"]] + [value(f, k) for k in (
                "head_radius_mm", "head_fit_rms_mm", "sphericity_rms_mm", "sphericity_max_mm", "neck_shaft_angle_deg",
                "version_posterior_condylar_deg", "version_transepicondylar_deg", "alpha_max_deg", "alpha_max_hour")] +
                [("nan" if alpha[str(h)] is None else alpha[str(h)]) for h in range(1, 13)] +
                [value(f, "head_neck_offset_ratio")] + [value(a, k) for k in (
                    "radius_mm", "radiographic_inclination_deg", "radiographic_anteversion_deg",
                    "lateral_centre_edge_deg", "anterior_centre_edge_deg", "head_coverage")] + [ms])
            if hip.startswith("generated"):
                # Its flexion stops before 90 deg (a cup about a straight neck): internal rotation over the ROM map's
                # flexions instead (NaN: in contact without rotation, or free to 150 deg).
                ir = j.rom_map(flexion=MAP_FLEXION_DEG, adduction=[0.0])
                for f, v in zip(MAP_FLEXION_DEG, ir[:, 0]):
                    wl.writerow([hip, "scan", f"internal_rotation_map_{f:g}_flexion", v,
                                 "limited" if v == v else "not_limited", "nan", 0])
            joints = [j] if hip.startswith("generated") else [j, make("app")]
            for joint in joints:
                for motion, r in joint.rom_limits().items():
                    if not isinstance(r, dict):
                        continue
                    wl.writerow([hip, r["pelvic_frame"], motion, r["limit_deg"], r["status"], r["normal_deg"],
                                 int(bool(r["soft_tissue_first"]))])
    write_meta(d, "15_morphology", quick=quick, data_folder=data if hips else None,
               timing="not timed (the morphology_ms column: one run each, not quoted)",
               parameters={"resolution_deg": resolution, "subjects": hips, "generated_cams_mm": list(CAMS_MM),
                           "generated_triangles": 12000,
                           "rom": "CLI defaults (equidistant, distance metric, contact depth 0.25 mm)"})


if __name__ == "__main__":
    main()
