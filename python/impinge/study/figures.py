"""A study's figures (matplotlib, Agg): the limits' distributions per motion, their sensitivity to the COR's
perturbation, and the least gap per motion file."""
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


NOT_SETTINGS = ("task_id", "sample", "cor_dx_mm", "cor_dy_mm", "cor_dz_mm", "cor_offset_mm", "time_s",
                "joint_build_s", "worker", "excluded_vertices", "status", "error", "warnings")


def _setting(r):
    """A rom task's subject and settings: what its perturbed samples share with its nominal one."""
    return tuple((k, str(v)) for k, v in r.items() if not k.startswith(("limit_", "contact_class_"))
                 and k not in NOT_SETTINGS)


def _ok(rows, kind):
    return [r for r in rows if r["kind"] == kind and r["status"] == "ok"]


def draw(out, rows):
    """Write out/figures/limits.png and sensitivity.png (rom tasks), motion_min_gap.png (motion tasks)."""
    folder = os.path.join(out, "figures")
    os.makedirs(folder, exist_ok=True)
    rom = _ok(rows, "rom")
    if rom:
        motions = [k[len("limit_"):-len("_deg")] for k in rom[0] if k.startswith("limit_") and k.endswith("_deg")]
        labels = sorted({(r["subject"], r["label"]) for r in rom})
        cols = 3
        nrows = (len(motions) + cols - 1) // cols
        fig, axes = plt.subplots(nrows, cols, figsize=(3.2 * cols, 2.6 * nrows), squeeze=False)
        for ax, m in zip(axes.ravel(), motions):
            data = [[r[f"limit_{m}_deg"] for r in rom if (r["subject"], r["label"]) == lab
                     and np.isfinite(r[f"limit_{m}_deg"])] for lab in labels]
            ax.boxplot([d if d else [np.nan] for d in data], vert=True, widths=0.6)
            ax.set_xticks(range(1, len(labels) + 1))
            ax.set_xticklabels([s if len({x[1] for x in labels}) == 1 else f"{s}\n{lab}" for s, lab in labels],
                               fontsize=6, rotation=30)
            ax.set_title(m.replace("_", " "), fontsize=8)
            ax.set_ylabel("limit (deg)", fontsize=7)
            ax.tick_params(labelsize=6)
        for ax in axes.ravel()[len(motions):]:
            ax.set_axis_off()
        fig.suptitle("ROM limits over the COR perturbations, per subject", fontsize=9)
        fig.tight_layout()
        fig.savefig(os.path.join(folder, "limits.png"), dpi=110)
        plt.close(fig)

        nominal = {}
        for r in rom:
            if r["sample"] == 0:
                nominal[_setting(r)] = r
        fig, ax = plt.subplots(figsize=(6, 3.6))
        for m in motions:
            x, y = [], []
            for r in rom:
                if r["sample"] == 0:
                    continue
                n = nominal.get(_setting(r))
                if n is None:
                    continue
                x.append(r["cor_offset_mm"])
                y.append(abs(r[f"limit_{m}_deg"] - n[f"limit_{m}_deg"]))
            if x:
                ax.scatter(x, y, s=8, label=m.replace("_", " "))
        ax.set_xlabel("COR offset from the nominal centre (mm)")
        ax.set_ylabel("|limit - nominal limit| (deg)")
        ax.set_title("Sensitivity of the ROM limits to the centre of rotation", fontsize=9)
        if ax.has_data():
            ax.legend(fontsize=6, ncol=2)
        fig.tight_layout()
        fig.savefig(os.path.join(folder, "sensitivity.png"), dpi=110)
        plt.close(fig)

    motion = _ok(rows, "motion")
    if motion:
        labels = sorted({(r["subject"], r["motion"]) for r in motion})
        fig, ax = plt.subplots(figsize=(max(4, 0.6 * len(labels) + 2), 3.4))
        data = [[r["min_gap_mm"] for r in motion if (r["subject"], r["motion"]) == lab
                 and np.isfinite(r["min_gap_mm"])] or [np.nan] for lab in labels]
        ax.boxplot(data, widths=0.6)
        ax.set_xticks(range(1, len(labels) + 1))
        ax.set_xticklabels([f"{s}\n{m}" for s, m in labels], fontsize=6, rotation=30)
        ax.axhline(0, color="r", lw=0.8)
        ax.set_ylabel("least gap over the motion (mm)")
        ax.set_title("Least gap per motion file over the COR perturbations", fontsize=9)
        fig.tight_layout()
        fig.savefig(os.path.join(folder, "motion_min_gap.png"), dpi=110)
        plt.close(fig)
