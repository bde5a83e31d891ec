#!/usr/bin/env python3
"""The figure of an `impinge plan` folder (plan.png): the resection's depth on the femoral head-neck clock face
(12 superior, 3 anterior; radius: distance from the head centre, mm) and, per target, the ROM limit before, after
and the target. Reads plan.json and femur_resected.ply (per-vertex resection_mm and clock_hour) or, with the pelvis
resected, pelvis_resected.ply on the acetabular clock face.

Usage: /usr/bin/python3 analysis/render_plan.py PLAN_FOLDER"""
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def read_ply(path):
    """Vertex float properties (x, y, z, resection_mm, clock_hour) of a binary PLY written by impinge."""
    data = open(path, "rb").read()
    head, body = data.split(b"end_header\n", 1)
    lines = head.decode().splitlines()
    n = int(next(line for line in lines if line.startswith("element vertex")).split()[2])
    props = [line.split()[2] for line in lines if line.startswith("property float")]
    v = np.frombuffer(body[:n * 4 * len(props)], dtype="<f4").reshape(n, len(props)).astype(float)
    return {p: v[:, k] for k, p in enumerate(props)}


def clock_panel(ax, props, centre, title):
    depth = props["resection_mm"]
    on = depth > 0.01
    if "clock_hour" not in props or not on.any():
        ax.text(0.5, 0.5, "no clock face (scan neutral)" if on.any() else "nothing resected", ha="center",
                transform=ax.transAxes)
        ax.set_axis_off()
        return
    theta = props["clock_hour"][on] / 12 * 2 * np.pi
    xyz = np.column_stack([props["x"], props["y"], props["z"]])[on]
    r = np.linalg.norm(xyz - centre, axis=1)
    sc = ax.scatter(theta, r, c=depth[on], s=6, cmap="magma_r", vmin=0)
    ax.set_theta_zero_location("N")
    ax.set_theta_direction(-1)
    ax.set_xticks(np.arange(12) / 12 * 2 * np.pi)
    ax.set_xticklabels(["12"] + [str(h) for h in range(1, 12)])
    ax.set_title(title, fontsize=9)
    plt.colorbar(sc, ax=ax, shrink=0.7, label="depth removed (mm)")


def main():
    folder = sys.argv[1]
    plan = json.load(open(os.path.join(folder, "plan.json")))
    centre = np.asarray(plan["head_centre_mm"], dtype=float)
    fig = plt.figure(figsize=(10, 4.2))
    bone = "femur" if plan["femur_resection"]["resected"] else "pelvis"
    props = read_ply(os.path.join(folder, f"{bone}_resected.ply"))
    r = plan[f"{bone}_resection"]
    ax = fig.add_subplot(1, 2, 1, projection="polar")
    clock_panel(ax, props, centre,
                f"{bone}: {r['volume_mm3']:.0f} mm$^3$, deepest {r['deepest_cut_mm']:.1f} mm, "
                f"{r['area_mm2']:.0f} mm$^2$\n(radius: distance from the head centre, mm)")
    ax = fig.add_subplot(1, 2, 2)
    targets = [t for t in plan["targets"] if t.get("target_deg") is not None]
    x = np.arange(len(targets))
    val = lambda t, k: np.nan if t.get(k) is None else t[k]  # noqa: E731
    ax.bar(x - 0.2, [val(t, "limit_before_deg") for t in targets], 0.4, label="before", color="0.6")
    ax.bar(x + 0.2, [val(t, "limit_after_deg") for t in targets], 0.4, label="after", color="tab:blue")
    ax.scatter(x, [t["target_deg"] for t in targets], marker="_", s=400, color="k", label="target", zorder=3)
    ax.set_xticks(x)
    ax.set_xticklabels([t["target"].replace("_", " ") for t in targets], rotation=20, ha="right", fontsize=8)
    ax.set_ylabel("ROM limit (deg)")
    ax.legend(fontsize=8)
    ax.set_title("checked by the ROM search on the resected bones", fontsize=9)
    fig.tight_layout(rect=(0, 0, 1, 0.95))
    # Atomically: a temporary file renamed over plan.png once it is whole.
    tmp = os.path.join(folder, ".plan.png.tmp")
    fig.savefig(tmp, dpi=130, format="png")
    os.replace(tmp, os.path.join(folder, "plan.png"))


if __name__ == "__main__":
    main()
