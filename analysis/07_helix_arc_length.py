"""07_helix_arc_length: Eq. 10 against the exact helix arc length; index errors it causes.

Reads RESULTS/07_helix_arc_length/{arc_length,index_errors,self_consistent,helix_nodes,helix_locate}.csv; writes
error.pdf/png, steps.pdf/png, table.tex, macros.tex, and the thesis' Figs. 47-48 drawn from the scheme's own nodes:
fig47.pdf/png (the k = 10, 20, 40 helices on the unit sphere) and fig48.pdf/png (one direction's look-up on the
k = 10 helix: global view, local view, the traveled distance)."""
import matplotlib.pyplot as plt
import numpy as np

from common import experiment_dir, read_csv, save, write_macros, write_table

d = experiment_dir("07_helix_arc_length")
arc = read_csv(d, "arc_length.csv")
idx = read_csv(d, "index_errors.csv")

fig, axes = plt.subplots(1, 2, figsize=(5.2, 3.1))
for k, g in arc.groupby("turns"):
    axes[0].plot(g.phi_deg, g.abs_error, label=f"k={int(k)}")
    axes[1].semilogy(g.phi_deg, np.abs(g.rel_error), label=f"k={int(k)}")
axes[0].set_ylabel("Eq. 10 T - exact s (unit sphere)")
axes[1].set_ylabel("|relative error|")
for ax in axes:
    ax.set_xlabel("polar angle phi (deg)")
    ax.grid(True, alpha=0.3)
fig.legend(*axes[0].get_legend_handles_labels(), loc="lower center", ncol=6, frameon=False, handlelength=1,
           columnspacing=0.8)
save(fig, d, "error", rect=(0, 0.1, 1, 1))

fig, ax = plt.subplots(figsize=(3.3, 3.1))
for k, g in arc.groupby("turns"):
    ax.plot(g.phi_deg, g.index_error_steps, label=f"k={int(k)}")
ax.set_xlabel("polar angle phi (deg)")
ax.set_ylabel("index error (node steps)")
ax.grid(True, alpha=0.3)
save(fig, d, "steps")

write_table(d, "table", ["$k$", "nodes", "exact $L$", "Eq. 10 $L$", "max index error (steps)",
                         "stencils differing", "nearest node differing", "max node diff",
                         "ns/locate exact", "ns/locate Eq. 10"],
            [[f"{int(r.turns)}", f"{int(r.nodes):,}", f"{r.total_length_exact:.6f}", f"{r.total_length_eq10:.1f}",
              f"{r.max_abs_index_error_steps:.3f}", f"{100 * r.fraction_differing:.2f}%",
              f"{100 * r.fraction_nearest_differing:.2f}%", f"{int(r.max_node_index_difference)}",
              f"{r.exact_ns_per_locate:.0f} ({r.exact_ns_q25:.0f}-{r.exact_ns_q75:.0f})",
              f"{r.eq10_ns_per_locate:.0f} ({r.eq10_ns_q25:.0f}-{r.eq10_ns_q75:.0f})"] for r in idx.itertuples()])


def sphere(ax, elev=20, azim=-60):
    """A unit sphere's outline (its meridians and parallels, faint) in a 3D axis, seen from (elev, azim)."""
    u = np.linspace(0, 2 * np.pi, 73)
    for lat in np.radians(np.arange(-60, 61, 30)):
        ax.plot(np.cos(lat) * np.cos(u), np.cos(lat) * np.sin(u), np.full_like(u, np.sin(lat)), color="0.85", lw=0.4)
    for lon in np.radians(np.arange(0, 180, 30)):
        ax.plot(np.cos(u) * np.cos(lon), np.cos(u) * np.sin(lon), np.sin(u), color="0.85", lw=0.4)
    ax.set_box_aspect((1, 1, 1))
    ax.view_init(elev=elev, azim=azim)
    ax.set_xlim(-0.8, 0.8), ax.set_ylim(-0.8, 0.8), ax.set_zlim(-0.8, 0.8)
    ax.axis("off")


def curve(k, phi_to=np.pi, n=4000):
    """The helix of Eq. 9 (theta = 2 k phi) from the north pole to phi_to, as x, y, z (the scheme's convention)."""
    phi = np.linspace(0, phi_to, n)
    th = 2 * k * phi
    return np.sin(phi) * np.cos(th), np.sin(phi) * np.sin(th), np.cos(phi)


def front(x, y, z, elev, azim):
    """Which points face the viewer (the far side of the sphere is drawn faint)."""
    e, a = np.radians(elev), np.radians(azim)
    return x * np.cos(e) * np.cos(a) + y * np.cos(e) * np.sin(a) + z * np.sin(e) >= 0


nodes = read_csv(d, "helix_nodes.csv")
ELEV, AZIM = 20, -60
fig = plt.figure(figsize=(6.6, 2.5))
for j, (k, g) in enumerate(nodes.groupby("turns")):
    ax = fig.add_subplot(1, 3, j + 1, projection="3d")
    sphere(ax, ELEV, AZIM)
    x, y, z = curve(k)
    f = front(x, y, z, ELEV, AZIM)
    ax.plot(np.where(f, x, np.nan), np.where(f, y, np.nan), np.where(f, z, np.nan), color="C0", lw=0.5)
    fn = front(g.x, g.y, g.z, ELEV, AZIM)
    ax.scatter(g.x[fn], g.y[fn], g.z[fn], s=3 if k < 40 else 1, color="C3", depthshade=False)
    ax.set_title(f"{'abc'[j]}) k = {int(k)}, w = {len(g):,}", fontsize=8, y=0.96)
fig.subplots_adjust(left=0, right=1, bottom=0, top=0.92, wspace=0)
save(fig, d, "fig47", rect=(0, 0, 1, 1))

loc = read_csv(d, "helix_locate.csv")
k10 = nodes[nodes.turns == 10]
pt = loc.set_index("point")
v, pa, pb = pt.loc["v"], pt.loc["P_a"], pt.loc["P_b"]
ex, eq10 = loc[loc.locator == "exact"], loc[loc.locator == "eq10"]
fig = plt.figure(figsize=(7.0, 3.0))
ax = fig.add_subplot(1, 3, 1, projection="3d")
el, az = 15, float(v.theta_deg)  # looking at v
sphere(ax, el, az)
x, y, z = curve(10)
f = front(x, y, z, el, az)
ax.plot(np.where(f, x, np.nan), np.where(f, y, np.nan), np.where(f, z, np.nan), color="C0", lw=0.6)
fn = front(k10.x, k10.y, k10.z, el, az)
ax.scatter(k10.x[fn], k10.y[fn], k10.z[fn], s=4, color="C3", depthshade=False)
ax.scatter([v.x], [v.y], [v.z], s=18, color="blue", depthshade=False)
ax.set_title("a) k = 10, v in blue", fontsize=11, y=0.96)
# b) the local view in (theta, phi): the two turns bracketing v, P_a and P_b, the stencil of each locator.
ax = fig.add_subplot(1, 3, 2)
phi = np.linspace(np.radians(pa.phi_deg) - 0.08, np.radians(pb.phi_deg) + 0.08, 2000)
th = np.degrees(2 * 10 * phi) % 360
near = np.abs(((th - v.theta_deg + 180) % 360) - 180) < 25
ax.plot(np.where(near, th, np.nan), np.where(near, np.degrees(phi), np.nan), color="C0", lw=0.8, label="helix")
nn = k10[(np.abs(((k10.theta_deg - v.theta_deg + 180) % 360) - 180) < 25) & (k10.phi_deg > pa.phi_deg - 9)
          & (k10.phi_deg < pb.phi_deg + 9)]
ax.scatter(nn.theta_deg, nn.phi_deg, s=10, color="C3", zorder=3, label="nodes")
ax.scatter(ex.theta_deg, ex.phi_deg, s=60, facecolors="none", edgecolors="k", zorder=4, label="stencil (exact)")
ax.scatter(eq10.theta_deg, eq10.phi_deg, s=22, marker="x", color="C2", zorder=4, label="stencil (Eq. 10)")
ax.axvline(v.theta_deg, color="0.6", lw=0.6, ls="--")
ax.scatter([v.theta_deg], [v.phi_deg], s=22, color="blue", zorder=5, label="v")
for name, p_ in (("P_a", pa), ("P_b", pb)):
    ax.scatter([p_.theta_deg], [p_.phi_deg], s=14, marker="s", color="0.3", zorder=4)
    ax.annotate(f"$P_{name[-1]}$", (p_.theta_deg, p_.phi_deg), xytext=(3, -13), textcoords="offset points",
                fontsize=11)  # its subscript at 0.7 of that: 7.2 pt printed at the text width
for r in ex.itertuples():
    ax.annotate(f"$P_{r.point[-1]}$", (r.theta_deg, r.phi_deg), xytext=(-4, 8), textcoords="offset points",
                fontsize=11)
ax.set_xlim(v.theta_deg - 25, v.theta_deg + 25)
ax.set_ylim(pb.phi_deg + 9, pa.phi_deg - 9)  # north up
ax.set_xlabel("theta (deg)")
ax.set_ylabel("phi (deg)")
ax.set_title("b) local view", fontsize=11)
ax.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.22), ncol=3, handlelength=1, borderpad=0.3,
          labelspacing=0.2, columnspacing=0.6)
# c) the traveled distance of P_b: the curve from the start (the north pole) to P_b, in black.
ax = fig.add_subplot(1, 3, 3, projection="3d")
sphere(ax, el, az)
x, y, z = curve(10)
f = front(x, y, z, el, az)
ax.plot(np.where(f, x, np.nan), np.where(f, y, np.nan), np.where(f, z, np.nan), color="C0", lw=0.4, alpha=0.5)
x, y, z = curve(10, np.radians(pb.phi_deg))
f = front(x, y, z, el, az)
ax.plot(np.where(f, x, np.nan), np.where(f, y, np.nan), np.where(f, z, np.nan), color="k", lw=1.0)
ax.scatter([pb.x], [pb.y], [pb.z], s=14, marker="s", color="0.3", depthshade=False)
ax.set_title(f"c) $P_b$'s traveled distance:\n{pb.steps:.2f} node steps", fontsize=11, y=0.96)
fig.subplots_adjust(left=0.0, right=0.99, bottom=0.3, top=0.88, wspace=0.25)
save(fig, d, "fig48", rect=(0, 0, 1, 1))

# Fig. 48's stencil: two nodes on the turn above v, two on the turn below, each pair around P_a's (P_b's) traveled
# distance (what the thesis' three steps find).
ex_sorted = ex.sort_values("steps")
above, below = ex_sorted.iloc[:2], ex_sorted.iloc[2:]
brackets = bool(above.steps.min() <= pa.steps <= above.steps.max() and below.steps.min() <= pb.steps <= below.steps.max())
big = idx.iloc[-1]
# The self-consistent Eq. 10 helix (nodes placed by Eq. 10 too): its node spacing against the exact helix's.
selfc = read_csv(d, "self_consistent.csv")
fine = selfc[selfc.turns >= 229]
write_macros(d, "macros", {
    "HAselfMaxRatio": f"{selfc.max_spacing_ratio.max():.2f}",
    "HAselfShareMin": f"{100 * fine.share_within_10pct.min():.3f}",
    "HAselfKmin": f"{int(fine.turns.min())}",
    "HAfigNodes": ", ".join(f"{len(g):,}" for _, g in nodes.groupby("turns")),
    "HAfigVphi": f"{v.phi_deg:.0f}", "HAfigVtheta": f"{v.theta_deg:.0f}",
    "HAfigPa": f"{pa.steps:.2f}", "HAfigPb": f"{pb.steps:.2f}",
    "HAfigExact": ", ".join(str(int(x)) for x in ex.node), "HAfigEqTen": ", ".join(str(int(x)) for x in eq10.node),
    "HAfigBrackets": "yes" if brackets else "no",
    "HAkBig": f"{int(big.turns)}", "HAstepsBig": f"{big.max_abs_index_error_steps:.2f}",
    "HAdifferBig": f"{100 * big.fraction_differing:.1f}", "HAnearestBig": f"{100 * big.fraction_nearest_differing:.1f}",
})
