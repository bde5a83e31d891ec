"""Shaded renders of a hip: both bones as lit triangle surfaces coloured by impingement level, from
the standard views, with the acetabular clock face (matplotlib's 3-D polygons; no hand-written
rasteriser). Used by `impinge distance --render` (render_hip.py) and experiment 08.

Coordinates are the pelvic frame's (ISB: X anterior, Y superior, Z right; origin at the hip centre;
mm). Views: anterior (from +X), lateral (from the hip's side), and the medial view of the socket
that the thesis uses for Tables 12-13 (from the midline, socket region only, femur hidden)."""
import numpy as np
from matplotlib.path import Path
from mpl_toolkits.mplot3d import proj3d
from mpl_toolkits.mplot3d.art3d import Line3DCollection, Poly3DCollection

PLY_TYPES = {"float": "<f4", "float32": "<f4", "double": "<f8", "uchar": "u1", "uint8": "u1", "int": "<i4",
             "int32": "<i4", "uint": "<u4", "char": "i1", "short": "<i2", "ushort": "<u2"}


def read_gap_ply(path):
    """Read a binary little-endian PLY as written by impinge (x y z gap_mm quality level red green
    blue; triangles). Returns V (n x 3), F (m x 3), rgb (n x 3, 0-1) and gap (n, NaN untested)."""
    with open(path, "rb") as f:
        props, n, m = [], 0, 0
        elem = None
        while True:
            line = f.readline().decode("ascii").strip()
            if line == "end_header":
                break
            t = line.split()
            if t[:1] == ["format"] and t[1] != "binary_little_endian":
                raise ValueError(f"{path}: only binary little-endian PLY is read")
            if t[:1] == ["element"]:
                elem = t[1]
                if elem == "vertex":
                    n = int(t[2])
                elif elem == "face":
                    m = int(t[2])
            elif t[:1] == ["property"] and elem == "vertex":
                props.append((t[2], PLY_TYPES[t[1]]))
        vert = np.frombuffer(f.read(n * np.dtype(props).itemsize), dtype=np.dtype(props), count=n)
        face = np.frombuffer(f.read(m * 13), dtype=np.dtype([("k", "u1"), ("i", "<i4", 3)]), count=m)
    if m and (face["k"] != 3).any():
        raise ValueError(f"{path}: non-triangle faces")
    V = np.stack([vert["x"], vert["y"], vert["z"]], axis=1).astype(float)
    names = vert.dtype.names
    rgb = (np.stack([vert["red"], vert["green"], vert["blue"]], axis=1) / 255.0 if "red" in names
           else np.full((n, 3), 0.8))
    gap = vert["gap_mm"].astype(float) if "gap_mm" in names else np.full(n, np.nan)
    return V, face["i"].astype(np.int64), rgb, gap


# The one set of impingement levels of this report's figures (mm, on the gap): beyond 6 mm apart (the thesis'
# blue, sec. 5.2), 4-6 yellow, 2-4 orange, 0-2 red (the thesis' red: within 2 mm), at or below 0 purple (bone
# contact or penetration); vertices without a gap (not tested) grey.
REPORT_LEVELS_MM = (6.0, 4.0, 2.0, 0.0)
LEVEL_COLOURS = [("apart, femur", (0.40, 0.70, 0.40)), ("apart, pelvis", (0.40, 0.58, 0.85)),
                 ("4-6 mm", (0.95, 0.85, 0.20)), ("2-4 mm", (0.95, 0.55, 0.15)), ("0-2 mm", (0.85, 0.15, 0.15)),
                 ("contact", (0.55, 0.20, 0.65)), ("not tested", (0.80, 0.80, 0.80))]


def level_rgb(gap, femur):
    """Per-vertex colours (n x 3, 0-1) of gaps (mm, NaN: not tested) by REPORT_LEVELS_MM; `femur` picks the
    colour of vertices farther apart than the first level (green on the femur, blue on the pelvis)."""
    colours = dict(LEVEL_COLOURS)
    out = np.tile(colours["not tested"], (len(gap), 1))
    g = np.asarray(gap, float)
    t6, t4, t2, t0 = REPORT_LEVELS_MM
    for mask, name in ((g > t6, "apart, femur" if femur else "apart, pelvis"), ((g > t4) & (g <= t6), "4-6 mm"),
                       ((g > t2) & (g <= t4), "2-4 mm"), ((g > t0) & (g <= t2), "0-2 mm"), (g <= t0, "contact")):
        out[mask] = colours[name]
    return out


def level_key(fig, skip=()):
    """The colour key of level_rgb below the figure (one row)."""
    from matplotlib.patches import Patch
    fig.legend(handles=[Patch(color=c, label=n) for n, c in LEVEL_COLOURS if n not in skip], loc="lower center",
               ncol=7, fontsize=7, frameon=False)


def to_frame(V, origin, axes):
    """Points V (n x 3, input frame) into a frame given by its origin and axes (columns X, Y, Z)."""
    return (V - origin) @ axes


def plot_coordinates(P):
    """Points P (n x 3, pelvic frame: X anterior, Y superior, Z right; mm) in the 3-D axes' coordinates
    (Z right, X anterior, Y superior), so that matplotlib's vertical axis is superior."""
    return P[:, [2, 0, 1]]


VIEWS = {
    # name: (azimuth for a right hip, elevation, title)
    "anterior": (90, 5, "anterior"),
    "lateral": (0, 5, "lateral"),
    "acetabulum_medial": (180, 5, "acetabulum, medial view"),
}


class _Triangles3D(Poly3DCollection):
    """Poly3DCollection of triangles whose depth sort is one numpy pass: matplotlib 3.6's sorts polygon by
    polygon in Python (3.5 s a figure of 100k triangles, most of experiment 08's analysis). The same
    order (mean depth, farthest first, ties in the given order), polygons and colours, so the same image."""

    def do_3d_projection(self):
        if (not hasattr(self, "_vec") or self._A is not None or getattr(self, "_codes3d", None) is not None
                or getattr(self, "_sort_zpos", None) is not None):
            return super().do_3d_projection()
        txs, tys, tzs = proj3d._proj_transform_vec(self._vec, self.axes.M)
        n = len(txs) // 3
        if n == 0 or len(txs) != 3 * n or not self._closed:
            return super().do_3d_projection()
        x, y, z = (np.asarray(a).reshape(n, 3) for a in (txs, tys, tzs))
        order = np.argsort(-z.mean(axis=1), kind="stable")
        cface = self._facecolor3d
        cedge = self._edgecolor3d
        if len(cface) != n:
            cface = cface.repeat(n, axis=0)
        if len(cedge) != n:
            cedge = cface if len(cedge) == 0 else cedge.repeat(n, axis=0)
        self._facecolors2d, self._edgecolors2d = cface[order], cedge[order]
        # Closed triangles as PolyCollection.set_verts makes them, without its per-path checks.
        xy = np.stack([x[order], y[order]], axis=2)
        xy = np.concatenate([xy, xy[:, :1]], axis=1)
        codes = np.array([Path.MOVETO, Path.LINETO, Path.LINETO, Path.CLOSEPOLY], dtype=Path.code_type)
        make = getattr(Path, "_fast_from_codes_and_verts", Path)  # matplotlib 3.6's (Debian 12) unchecked maker
        self._paths = [make(t, codes) for t in xy]
        self.stale = True
        if len(self._edgecolor3d) != len(cface):
            self._edgecolors2d = self._edgecolor3d
        return np.min(tzs)


def _crop(V, F, centre, radius):
    keep = np.linalg.norm(V[F] - centre, axis=2).max(axis=1) <= radius
    return F[keep]


def draw(ax, bodies, view, side="right", clock=None, radius=60.0, extent=None, title=None):
    """Draw on a 3-D axes `ax`. bodies: list of (V, F, rgb) in the pelvic frame (mm); view: a key of
    VIEWS; side: "right" or "left" (lateral and medial views swap); clock: optional dict with
    centre, twelve, three (pelvic frame) and radius_mm of the acetabular clock face; radius: only
    triangles within this distance of the hip centre are drawn (mm; the socket's medial view uses
    the cup alone, as the thesis' Tables 12-13 hide the pelvis outside the socket region); extent:
    half-width of the shown cube (mm; default 0.85 x min(radius, 60)); title: default the view's name."""
    azim, elev, _ = VIEWS[view]
    if side == "left" and view != "anterior":
        azim = 180 - azim
    a, e = np.radians(azim), np.radians(elev)
    toward_eye = np.array([np.cos(e) * np.cos(a), np.cos(e) * np.sin(a), np.sin(e)])  # plot coordinates
    light = toward_eye + np.array([0.0, 0.0, 0.6])
    light /= np.linalg.norm(light)
    # All bodies in one collection, so that mplot3d depth-sorts their triangles together.
    tris, cols = [], []
    for V, F, rgb in bodies:
        F = _crop(V, F, np.zeros(3), radius)
        if len(F) == 0:
            continue
        tri = plot_coordinates(V)[F]
        nrm = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
        nrm /= np.maximum(np.linalg.norm(nrm, axis=1, keepdims=True), 1e-12)
        lam = 0.3 + 0.7 * np.abs(nrm @ light)  # two-sided Lambert
        tris.append(tri)
        cols.append(np.clip(rgb[F].mean(axis=1) * lam[:, None], 0, 1))
    if tris:
        c = np.concatenate(cols)
        poly = _Triangles3D(np.concatenate(tris), facecolors=c, edgecolors=c, linewidths=0.15, antialiased=False)
        poly.set_rasterized(True)  # PDFs embed the surface as an image: small files
        ax.add_collection3d(poly)
    if clock is not None:
        c, u, v, r = (np.asarray(clock[k], float) for k in ("centre", "twelve", "three", "radius_mm"))
        t = np.linspace(0, 2 * np.pi, 121)
        ring = c + r * (np.outer(np.cos(t), u) + np.outer(np.sin(t), v))
        ring = plot_coordinates(ring)
        ax.add_collection3d(Line3DCollection([ring], colors="k", linewidths=0.8, zorder=10))
        for h in (12, 3, 6, 9):
            ang = np.radians(30 * h)
            p = plot_coordinates((c + 1.18 * r * (np.cos(ang) * u + np.sin(ang) * v))[None])[0]
            ax.text(p[0], p[1], p[2], str(h), fontsize=7, ha="center", va="center", zorder=11,
                    color="k", fontweight="bold")
    lim = extent if extent is not None else min(radius, 60.0) * 0.85
    ax.set_xlim(-lim, lim)
    ax.set_ylim(-lim, lim)
    ax.set_zlim(-lim, lim)
    ax.set_box_aspect((1, 1, 1))
    ax.view_init(elev=elev, azim=azim)
    ax.set_axis_off()
    ax.set_title(title if title is not None else VIEWS[view][2], fontsize=8)
