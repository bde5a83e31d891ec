"""Experiment 18 (issue 81): how much the acetabular labrum lowers each ROM limit of every shared hip, beside the
published lowering of simulated internal rotation by a labrum segmented from CT arthrograms.

For each shared hip with a subject.json under --data: impinge.Joint (the CLI's defaults: equidistant joint centre,
distance metric; the anterior pelvic plane frame, as clinical tools and the published simulations) at 0.1 deg
(--quick: 0.5 deg), and its ROM limits with labrum=True (the labrum of labrum.hpp at its default width and height):
each motion's bony limit and its labral limit (the first of the bony limit and the femur's first contact with the
labrum), side by side.

Outputs (OUT/18_labrum/):
  labrum.csv     one row per hip and motion: bony_limit_deg, bony_status, labral_limit_deg, labral_status,
                 labral_contact_class, labrum_contact_deg, lowering_deg (bony less labral; NaN unless both limited)
  published.csv  the published lowering the analysis sets beside ours
  meta.json

usage: exp_18_labrum --out DIR [--data DIR] [--quick]"""
import csv
import os

from experiment_support import experiment_args, write_meta

import impinge

# PMC7754612 (abstract): 19 CT arthrograms, femur, hemipelvis and labrum; internal rotation between 70 and 110 deg
# flexion and 0-20 deg adduction lowered by the labrum by a median 18 deg (interquartile range 15-25).
PUBLISHED = [("internal_rotation_in_flexion", 18, 15, 25, 19,
              "PMC7754612: 19 CT arthrograms, flexion 70-110 deg x adduction 0-20 deg, median [IQR]")]


def main():
    d, data, quick = experiment_args("18_labrum", __doc__)
    resolution = 0.5 if quick else 0.1
    hips = sorted(h for h in os.listdir(data) if os.path.exists(os.path.join(data, h, "subject.json"))) \
        if data and os.path.isdir(data) else []
    with open(os.path.join(d, "published.csv"), "w", newline="") as fp:
        w = csv.writer(fp)
        w.writerow(["quantity", "median_deg", "q1_deg", "q3_deg", "hips", "source"])
        w.writerows(PUBLISHED)
    with open(os.path.join(d, "labrum.csv"), "w", newline="") as fl:
        w = csv.writer(fl)
        w.writerow(["subject", "motion", "bony_limit_deg", "bony_status", "labral_limit_deg", "labral_status",
                    "labral_contact_class", "labrum_contact_deg", "lowering_deg"])
        for hip in hips:
            print(f"[18_labrum] {hip}", flush=True)
            j = impinge.Joint(subject=os.path.join(data, hip, "subject.json"), resolution=resolution,
                              pelvis_frame="app")
            for motion, r in j.rom_limits(labrum=True).items():
                if not isinstance(r, dict):
                    continue
                w.writerow([hip, motion, r["limit_deg"], r["status"], r["labral_limit_deg"], r["labral_status"],
                            r["labral_contact_class"], r["labrum_contact_deg"], r["labral_lowering_deg"]])
    defaults = {o["name"]: o["default"] for o in impinge.options()}
    width, height = defaults["labrum-width"], defaults["labrum-height"]
    write_meta(d, "18_labrum", quick=quick, data_folder=data if hips else None,
               timing="not timed",
               parameters={"resolution_deg": resolution, "subjects": hips, "pelvis_frame": "app",
                           "labrum_width_mm": width, "labrum_height_mm": height,
                           "rom": "CLI defaults (equidistant, distance metric) with labrum=True"})


if __name__ == "__main__":
    main()
