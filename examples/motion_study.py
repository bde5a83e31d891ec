"""A short study with impinge's Python module: load a hip, run a range-of-motion sweep, and plot the
minimum gap over time and the gap-coloured acetabulum at the closest pose.

usage: PYTHONPATH=build/python /usr/bin/python3 examples/motion_study.py OUT_DIR [DATA_DIR]
Uses the shared subject lhdl-ct (DATA_DIR, default ../shared/data/hips) when present, otherwise a
generated hip with a 2 mm cam bump. Writes OUT_DIR/min_gap.png, OUT_DIR/pelvis_gaps.png and
OUT_DIR/motion.csv. Run by ./reproduce --quick so it cannot rot."""
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import impinge  # noqa: E402


def load_hip(data_dir):
    """(ball, socket, neutral, name): a real hip in RAS when the shared data is there, else generated."""
    subject = os.path.join(data_dir, "lhdl-ct")
    if os.path.exists(os.path.join(subject, "femur_r.ply")):
        lps_to_ras = np.diag([-1.0, -1.0, 1.0])  # subject.json says LPS
        V, F = impinge.load_mesh(os.path.join(subject, "femur_r.ply"))
        P, G = impinge.load_mesh(os.path.join(subject, "pelvis.ply"))
        return (V @ lps_to_ras, F), (P @ lps_to_ras, G), "anatomical", "lhdl-ct"
    h = impinge.generated_hip(triangles=12000, cam_mm=2.0)
    return h["femur"], h["pelvis"], "scan", "generated hip (2 mm cam)"


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "example-out"
    data = sys.argv[2] if len(sys.argv) > 2 else "../shared/data/hips"
    os.makedirs(out, exist_ok=True)
    ball, socket, neutral, name = load_hip(data)
    joint = impinge.Joint(ball, socket, neutral=neutral, resolution=0.25)

    # A flexion sweep with internal rotation rising towards the end (the FADIR direction), 5 s.
    t = np.linspace(0.0, 5.0, 251)
    angles = np.column_stack([100 * t / 5, 10 * t / 5, 25 * (t / 5) ** 2])
    m = joint.motion(angles)
    gap = np.fmin(m["femur_min_gap_mm"], m["pelvis_min_gap_mm"])
    np.savetxt(os.path.join(out, "motion.csv"), np.column_stack([t, angles, gap]), delimiter=",",
               header="time_s,flexion_deg,adduction_deg,internal_rotation_deg,min_gap_mm", comments="")

    fig, ax = plt.subplots(figsize=(6, 3.2))
    ax.plot(t, gap, color="k")
    ax.axhline(0, color="r", lw=0.8)
    ax.set_xlabel("time (s): flexion 0 to 100, adduction 0 to 10, internal rotation 0 to 25 deg")
    ax.set_ylabel("minimum gap (mm)")
    ax.set_title(f"{name}: minimum gap over the motion", fontsize=9)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "min_gap.png"), dpi=120)
    plt.close(fig)

    # The acetabulum at the closest pose, coloured by gap: socket vertices within 40 mm of the COR.
    k = int(np.nanargmin(gap))
    r = joint.detect_pose(*angles[k])
    V = socket[0] - joint.cor
    near = (np.linalg.norm(V, axis=1) < 40) & np.isfinite(r["pelvis_gap_mm"])
    fig = plt.figure(figsize=(5, 4.5))
    ax = fig.add_subplot(projection="3d")
    sc = ax.scatter(V[near, 0], V[near, 1], V[near, 2], c=r["pelvis_gap_mm"][near], cmap="RdYlBu", vmin=0, vmax=6,
                    s=2)
    fig.colorbar(sc, ax=ax, shrink=0.6, label="gap (mm)")
    ax.view_init(elev=10, azim=0)
    ax.set_axis_off()
    ax.set_title(f"acetabulum at t = {t[k]:.2f} s (min gap {gap[k]:.2f} mm)", fontsize=9)
    fig.savefig(os.path.join(out, "pelvis_gaps.png"), dpi=120)
    plt.close(fig)
    print(f"motion_study: {name}, {len(t)} poses, least gap {gap[k]:.3f} mm at t = {t[k]:.2f} s; written to {out}")


if __name__ == "__main__":
    main()
