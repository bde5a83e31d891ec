"""impinge morphology (clinical/morphology.hpp) on the shared hips, against independent measures:
- the head radius within 0.3 mm of an independent sphere fit (numpy least squares on the head's cap) on the CT
  hip; within 1.5 mm on the MRI hips, whose heads are not spheres;
- a mirrored hip (x negated, the other side) gives the same morphology, and a rigidly moved hip the same;
- the neck axis (Reikeras: through the head centre and the centre of the neck's narrowest cross-section) within
  0.5 deg of an own implementation of that definition (numpy slicing, the sections normal to the axis, iterated
  from impinge's axis); the neck shell's centroid that impinge took for the neck's centre before was 0.2-8.4 deg
  off it (area-weighted) and 1.8-13.0 deg (the vertex mean);
- the lateral centre-edge angle within 0.5 deg of an own ray sweep (numpy Moeller-Trumbore rays from the head centre
  in the anterior pelvic plane's coronal plane, from superior towards lateral, until one meets no bone within the head
  radius + 10 mm; the median of five planes 2 mm apart), so that the left-minus-right difference of mc22's one
  pelvis is the sweep's, -9.0 deg (the rim points' median before read mc22-left's as 10.7 deg, not 19.8: -18.0);
- Joint.morphology() is the CLI's morphology.json;
- the femur PLY carries the head's deviation from its sphere."""
import json
import os
import subprocess
import tempfile

import numpy as np
import pytest

import impinge

DATA = os.environ.get("IMPINGE_SHARED_DATA", "../shared/data/hips")
CLI = os.environ.get("IMPINGE_CLI", "build/impinge")
HIPS = ["lhdl-ct", "mc22", "mc22-left", "tlem2-mri"]

needs_data = pytest.mark.skipif(not os.path.exists(os.path.join(DATA, "lhdl-ct", "subject.json")),
                                reason="shared data absent")


def morphology(subject_or_args, out):
    args = ["--subject", subject_or_args] if isinstance(subject_or_args, str) else subject_or_args
    subprocess.run([CLI, "morphology", *args, "--out", out], check=True, capture_output=True, text=True)
    with open(os.path.join(out, "morphology.json")) as f:
        return json.load(f)


def values(m):
    """Every scalar and per-hour measure of a morphology.json, flattened: name -> float."""
    out = {}
    for part in ("femur", "acetabulum"):
        for k, v in m[part].items():
            if not isinstance(v, dict) or "value" not in v:
                continue
            x = v["value"]
            if isinstance(x, dict):
                for h, y in x.items():
                    out[f"{part}.{k}.{h}"] = np.nan if y is None else float(y)
            elif not isinstance(x, list):
                out[f"{part}.{k}"] = np.nan if x is None else float(x)
    return out


def sphere_fit(P):
    """Algebraic least-squares sphere (|p|^2 = 2 c.p + d), then Gauss-Newton on the geometric distance."""
    A = np.c_[2 * P, np.ones(len(P))]
    x = np.linalg.lstsq(A, (P ** 2).sum(1), rcond=None)[0]
    c, r = x[:3], np.sqrt(x[3] + x[:3] @ x[:3])
    for _ in range(20):
        d = P - c
        n = np.linalg.norm(d, axis=1)
        J = np.c_[-d / n[:, None], -np.ones(len(P))]
        step = np.linalg.lstsq(J, -(n - r), rcond=None)[0]
        c, r = c + step[:3], r + step[3]
    return c, r


@needs_data
@pytest.mark.parametrize("hip", HIPS)
def test_head_radius_matches_an_independent_sphere_fit(hip, tmp_path):
    m = morphology(os.path.join(DATA, hip, "subject.json"), str(tmp_path))
    subject = json.load(open(os.path.join(DATA, hip, "subject.json")))
    V, _ = impinge.load_mesh(os.path.join(DATA, hip, subject["femur"]))
    c = np.array(m["femur"]["head_centre_mm"]["value"])
    n = np.array(m["femur"]["neck_axis"]["value"])
    r = m["femur"]["head_radius_mm"]["value"]
    # The head's cap: vertices within 6 mm of the reported sphere, more than 100 deg from the neck direction.
    d = V - c
    dist = np.linalg.norm(d, axis=1)
    cap = (np.abs(dist - r) < 6) & ((d @ -n) / dist < np.cos(np.radians(100)))
    assert cap.sum() > 200
    # Own robust fit: refit on the points within 2.5 rms (at least 1 mm) of the last sphere, five times.
    P = V[cap]
    for _ in range(5):
        c_own, r_own = sphere_fit(P)
        res = np.linalg.norm(V[cap] - c_own, axis=1) - r_own
        keep = np.abs(res) < max(1.0, 2.5 * np.sqrt(np.mean(res ** 2)))
        P = V[cap][keep]
    assert len(P) > 200
    # The CT head is a sphere to 0.39 mm rms: both fits agree within 0.3 mm. The MRI heads are not (sphericity up to
    # 4.7 mm): a fit of their whole cap and impinge's fit of their most spherical part (RANSAC, then the fixed
    # point of its inliers) differ by 0.4-1.3 mm, and a cap fit's radius moves by up to 5 mm with the cap's extent.
    assert abs(r_own - r) <= (0.3 if hip == "lhdl-ct" else 1.5), (hip, r_own, r)
    # The values a reader checks first lie in anatomical ranges.
    f, a = m["femur"], m["acetabulum"]
    assert 100 < f["neck_shaft_angle_deg"]["value"] < 150
    assert -30 < f["version_posterior_condylar_deg"]["value"] < 50
    assert all(15 < v < 90 for v in f["alpha_deg_by_hour"]["value"].values() if v is not None)
    assert 30 < a["radiographic_inclination_deg"]["value"] < 70
    assert -10 < a["radiographic_anteversion_deg"]["value"] < 45
    assert 0.2 < a["head_coverage"]["value"] < 0.7


def measured_bone(hip, bone, tmp_path):
    """impinge morphology of a shared hip, its subject.json, the `bone` mesh (V, F) and the head's centre and radius."""
    m = morphology(os.path.join(DATA, hip, "subject.json"), str(tmp_path))
    subject = json.load(open(os.path.join(DATA, hip, "subject.json")))
    V, F = impinge.load_mesh(os.path.join(DATA, hip, subject[bone]))
    return m, subject, V, F, np.array(m["femur"]["head_centre_mm"]["value"]), m["femur"]["head_radius_mm"]["value"]


def section(V, F, p0, n):
    """Centroid (by length) and perimeter (mm) of the closed loop, nearest p0, of the plane (p0, n) through the mesh."""
    s = (V - p0) @ n
    sf = s[F]
    parent = {}

    def find(x):
        while parent.setdefault(x, x) != x:
            parent[x] = parent[parent[x]]
            x = parent[x]
        return x
    segments = []
    for tri in F[(sf.min(1) < 0) & (sf.max(1) >= 0)]:
        keys, pts = [], []
        for a, b in ((0, 1), (1, 2), (2, 0)):
            if (s[tri[a]] < 0) != (s[tri[b]] < 0):
                w = s[tri[a]] / (s[tri[a]] - s[tri[b]])
                keys.append((min(tri[a], tri[b]), max(tri[a], tri[b])))
                pts.append(V[tri[a]] + w * (V[tri[b]] - V[tri[a]]))
        if len(pts) == 2:
            segments.append((keys, pts))
            parent[find(keys[0])] = find(keys[1])
    loops = {}
    for keys, pts in segments:
        loops.setdefault(find(keys[0]), []).append(pts)
    best = None
    for seg in loops.values():
        S = np.array(seg)
        length = np.linalg.norm(S[:, 0] - S[:, 1], axis=1)
        g = (S.mean(1) * length[:, None]).sum(0) / length.sum()
        if best is None or np.linalg.norm(g - p0) < best[0]:
            best = (np.linalg.norm(g - p0), g, length.sum())
    return best[1], best[2]


@needs_data
@pytest.mark.parametrize("hip", HIPS)
def test_neck_axis_agrees_with_the_narrowest_section(hip, tmp_path):
    m, _, V, F, c, r = measured_bone(hip, "femur", tmp_path)
    a = impinge_axis = np.array(m["femur"]["neck_axis"]["value"])
    for _ in range(30):  # the narrowest section normal to the axis, 8 mm inside the head radius to 16 mm beyond
        g = min((section(V, F, c - d * a, a) for d in np.arange(r - 8, r + 16, 0.5)), key=lambda x: x[1])[0]
        new = (c - g) / np.linalg.norm(c - g)
        done = np.linalg.norm(new - a) < 1e-7
        a = new
        if done:
            break
    angle = np.degrees(np.arccos(np.clip(a @ impinge_axis, -1, 1)))
    assert angle <= 0.5, (hip, angle)


def first_hits(o, d, A, B, C):
    """Distance (mm) along the unit ray (o, d) to its first hit on the triangles (A, B, C), inf when none."""
    e1, e2 = B - A, C - A
    p = np.cross(d, e2)
    det = (e1 * p).sum(1)
    ok = np.abs(det) > 1e-12
    inv = np.where(ok, 1 / np.where(ok, det, 1), 0)
    s = o - A
    u = (s * p).sum(1) * inv
    q = np.cross(s, e1)
    v = (q @ d) * inv
    t = (q * e2).sum(1) * inv
    hit = ok & (u >= 0) & (v >= 0) & (u + v <= 1) & (t > 0)
    return t[hit].min() if hit.any() else np.inf


@needs_data
@pytest.mark.parametrize("hip", HIPS)
def test_lateral_centre_edge_angle_is_where_the_roof_ends(hip, tmp_path):
    m, subject, V, F, c, r = measured_bone(hip, "pelvis", tmp_path)
    L = {k: np.array(v["position_mm"]) for k, v in m["acetabulum"]["pelvic_frame"]["landmarks"].items()}
    # The anterior pelvic plane (both ASIS, the pubic tubercles' midpoint): medio-lateral and superior axes in it.
    pubis = 0.5 * (L["pubic_tubercle_left"] + L["pubic_tubercle_right"])
    right = (L["asis_right"] - L["asis_left"]) / np.linalg.norm(L["asis_right"] - L["asis_left"])
    normal = np.cross(L["asis_right"] - pubis, L["asis_left"] - pubis)
    normal /= np.linalg.norm(normal)
    up = np.cross(normal, right)
    up *= np.sign(up @ (0.5 * (L["asis_left"] + L["asis_right"]) - pubis))
    lateral = right if subject["side"] == "right" else -right
    near = np.linalg.norm(V[F].mean(1) - c, axis=1) < r + 20
    A, B, C = V[F[near, 0]], V[F[near, 1]], V[F[near, 2]]
    edges = []
    for offset in (-4, -2, 0, 2, 4):
        o, last = c + offset * normal, None
        for a in np.arange(0, 90, 0.1):
            d = np.cos(np.radians(a)) * up + np.sin(np.radians(a)) * lateral
            if first_hits(o, d, A, B, C) > r + 10:
                break
            last = a
        if last is not None:
            edges.append(last)
    own = float(np.median(edges))
    assert abs(m["acetabulum"]["lateral_centre_edge_deg"]["value"] - own) <= 0.5, (hip, own)


def write_ply(path, V, F):
    with open(path, "wb") as f:
        f.write(f"ply\nformat binary_little_endian 1.0\nelement vertex {len(V)}\nproperty double x\nproperty double y\n"
                f"property double z\nelement face {len(F)}\nproperty list uchar int vertex_indices\nend_header\n".encode())
        f.write(np.ascontiguousarray(V, dtype="<f8").tobytes())
        rec = np.zeros(len(F), dtype=[("n", "u1"), ("i", "<i4", (3,))])
        rec["n"] = 3
        rec["i"] = F
        f.write(rec.tobytes())


def moved_copy(hip, out, transform, flip_side):
    """The hip with every vertex moved by transform (x -> R x + t, LPS), side flipped when mirrored; triangles
    re-wound when the transform reverses orientation."""
    subject = json.load(open(os.path.join(DATA, hip, "subject.json")))
    R, t = transform
    for key in ("femur", "pelvis"):
        V, F = impinge.load_mesh(os.path.join(DATA, hip, subject[key]))
        if np.linalg.det(R) < 0:
            F = F[:, ::-1]
        write_ply(os.path.join(out, key + ".ply"), V @ R.T + t, F)
    s = dict(subject, femur="femur.ply", pelvis="pelvis.ply")
    if flip_side:
        s["side"] = "left" if subject["side"] == "right" else "right"
    s.pop("landmarks", None)
    json.dump(s, open(os.path.join(out, "subject.json"), "w"))
    return os.path.join(out, "subject.json")


@needs_data
def test_a_mirrored_or_moved_hip_has_the_same_morphology(tmp_path):
    base = values(morphology(os.path.join(DATA, "lhdl-ct", "subject.json"), str(tmp_path / "base")))
    mirror = (np.diag([-1.0, 1.0, 1.0]), np.zeros(3))
    a = np.radians(25)
    R = np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]]) @ \
        np.array([[1, 0, 0], [0, np.cos(0.4), -np.sin(0.4)], [0, np.sin(0.4), np.cos(0.4)]])
    moved = (R, np.array([40.0, -120.0, 300.0]))
    for name, transform, flip in (("mirrored", mirror, True), ("moved", moved, False)):
        d = tmp_path / name
        d.mkdir()
        got = values(morphology(moved_copy("lhdl-ct", str(d), transform, flip), str(d / "out")))
        for k, v in base.items():
            unit_mm = k.endswith("_mm") or "_mm." in k
            tol = 0.05 if unit_mm else 0.02 if ("coverage" in k and "deg" not in k) or "ratio" in k else 0.5
            assert np.isnan(v) == np.isnan(got[k]), (name, k, v, got[k])
            if not np.isnan(v):
                assert abs(got[k] - v) <= tol, (name, k, v, got[k])


@needs_data
def test_joint_morphology_is_the_clis_and_the_ply_shows_the_deviation(tmp_path):
    subject = os.path.join(DATA, "tlem2-mri", "subject.json")
    cli = morphology(subject, str(tmp_path))
    j = impinge.Joint(subject=subject, resolution=2.0)
    py = j.morphology()
    assert values(py) == pytest.approx(values(cli), nan_ok=True)
    ply = open(tmp_path / "femur_sphericity.ply", "rb").read(400).decode("latin-1")
    assert "property float gap_mm" in ply  # the deviation, in the gap's slot (ParaView colours it)
    assert cli["femur"]["sphericity_max_mm"]["value"] >= cli["femur"]["sphericity_rms_mm"]["value"] > 0


def test_a_generated_hip_has_its_analytic_alpha_angle_and_offset_and_a_cam_raises_it(tmp_path):
    """A generated hip (head radius 22 mm, cylindrical neck of radius 15 mm along the clock's axis): the contour leaves
    the head's radius + 0.5 mm (the tolerance at a 0 rms fit) where 15 / sin(alpha) = 22.5, at every hour; the
    anterior offset ratio is (22 - 15) / 44. A 2 mm cam at the antero-superior junction raises the alpha angle there
    past 55 deg and leaves the postero-inferior hours within 3 deg."""
    out = {}
    for cam in (0, 2):
        g = str(tmp_path / f"gen{cam}")
        subprocess.run([CLI, "generate", "--triangles", "12000", "--cam", str(cam), "--out", g], check=True,
                       capture_output=True)
        out[cam] = morphology(os.path.join(g, "subject.json"), str(tmp_path / f"m{cam}"))
    f0, f2 = out[0]["femur"], out[2]["femur"]
    assert f0["head_radius_mm"]["value"] == pytest.approx(22.0, abs=0.05)
    alpha = np.degrees(np.arcsin(15 / 22.5))
    a0 = f0["alpha_deg_by_hour"]["value"]
    assert all(abs(a0[str(h)] - alpha) <= 0.5 for h in range(1, 13)), (alpha, a0)
    assert f0["head_neck_offset_ratio"]["value"] == pytest.approx(7 / 44, abs=0.005)
    assert f0["version_posterior_condylar_deg"]["value"] is None  # no knee: no version, said in the notes
    assert any("no femoral landmarks" in n for n in out[0]["notes"])
    a2 = f2["alpha_deg_by_hour"]["value"]
    assert max(a2[str(h)] for h in (12, 1, 2)) > 55
    assert all(abs(a2[str(h)] - a0[str(h)]) <= 3 for h in (6, 7, 8)), (a0, a2)
