"""Results that depend on the geometry, not on how a file writes it (issue 48, item 1). Invariants: a shared hip
whose pelvis or femur has its vertices and faces renumbered (and each face's corners rotated), or whose pelvis has
every vertex duplicated (each face its own three), gives the original's ROM limits within 0.05 deg and least
distances within 0.01 mm. A pelvis whose every triangle is split in four (the same surface, more vertices) gives the
same acetabulum (0.005 mm), the same equidistant translation (0.005 mm) and least distances (0.01 mm), and the same
limits within 0.1 deg where both runs call them monotone, but for one within 1 deg: the vertices the split adds are
new samples of the same surface, and where the femur's neck presses into the middle of a pelvic triangle they meet it
first (lhdl-ct's extension: 49.4 deg, 48.75 on the split pelvis; rotating about the fitted head centre instead, its
internal rotation moves 0.56 deg the same way). A contact between vertices is what a per-vertex gap cannot see, so
splitting triangles moves a limit by up to the angle over which the contact crosses a triangle. (Before the
equidistant placement stopped guarding rim contacts, it levered the femur out of the socket past the first contact,
and the split moved extension 137.9 -> 139.6 deg and abduction 54.6 -> 57.9 deg.) An OBJ file's vertices come back in
the file's order."""
import csv
import json
import os

import numpy as np
import pytest

from conftest import DATA, run

SUBJECT = os.path.join(DATA, "lhdl-ct", "subject.json")


def read_ply(path):
    """(V, F) of a binary little-endian PLY with float or double x y z and int or uint faces."""
    with open(path, "rb") as f:
        head = b""
        while not head.endswith(b"end_header\n"):
            head += f.readline()
        lines = head.decode().splitlines()
        nv = int(next(x for x in lines if x.startswith("element vertex")).split()[-1])
        nf = int(next(x for x in lines if x.startswith("element face")).split()[-1])
        props = [x.split() for x in lines if x.startswith("property") and "list" not in x]
        types = {"float": "<f4", "double": "<f8", "uchar": "u1", "int": "<i4", "uint": "<u4"}
        vdt = np.dtype([(p[2], types[p[1]]) for p in props[:len(props)]])
        V = np.frombuffer(f.read(nv * vdt.itemsize), dtype=vdt)
        listp = next(x for x in lines if "list" in x).split()
        fdt = np.dtype([("n", types[listp[2]]), ("i", types[listp[3]], (3,))])
        F = np.frombuffer(f.read(nf * fdt.itemsize), dtype=fdt)["i"]
    return np.stack([V["x"], V["y"], V["z"]], axis=1).astype(float), F.astype(np.int64)


def write_ply(path, V, F):
    with open(path, "wb") as f:
        f.write(f"ply\nformat binary_little_endian 1.0\nelement vertex {len(V)}\nproperty double x\nproperty double y\n"
                f"property double z\nelement face {len(F)}\nproperty list uchar int vertex_indices\nend_header\n"
                .encode())
        f.write(np.ascontiguousarray(V, dtype="<f8").tobytes())
        rec = np.zeros(len(F), dtype=[("n", "u1"), ("i", "<i4", (3,))])
        rec["n"], rec["i"] = 3, F
        f.write(rec.tobytes())


def variant(tmp, name, transform, bone="pelvis"):
    """A copy of the shared subject whose `bone` ("pelvis" or "femur") is transform(V, F)."""
    s = json.load(open(SUBJECT))
    base = os.path.dirname(SUBJECT)
    d = tmp / name
    d.mkdir()
    other = "femur" if bone == "pelvis" else "pelvis"
    V, F = read_ply(os.path.join(base, s[bone]))
    write_ply(d / f"{bone}.ply", *transform(V, F))
    s[bone] = str(d / f"{bone}.ply")
    s[other] = os.path.join(base, s[other])
    (d / "subject.json").write_text(json.dumps(s))
    return d / "subject.json"


def renumbered(V, F):
    rng = np.random.default_rng(7)
    p = rng.permutation(len(V))
    inv = np.empty_like(p)
    inv[p] = np.arange(len(V))
    return V[p], np.roll(inv[F][rng.permutation(len(F))], 1, axis=1)


def duplicated(V, F):
    return V[F.reshape(-1)], np.arange(3 * len(F)).reshape(-1, 3)


def split4(V, F):
    edges, W, out = {}, list(V), []

    def mid(a, b):
        k = (min(a, b), max(a, b))
        if k not in edges:
            edges[k] = len(W)
            W.append((V[a] + V[b]) / 2)
        return edges[k]
    for a, b, c in F:
        ab, bc, ca = mid(a, b), mid(b, c), mid(c, a)
        out += [(a, ab, ca), (ab, b, bc), (ca, bc, c), (ab, bc, ca)]
    return np.array(W), np.array(out)


def outcome(subject, out):
    r = run(["rom", "--subject", subject, "--precision", "0.5", "--no-map", "--out", out / "rom"])
    assert r.returncode == 0, r.stderr
    limits = {x["motion"]: float(x["limit_deg"] or "nan") for x in csv.DictReader(open(out / "rom" / "rom_limits.csv"))}
    r = run(["distance", "--subject", subject, "--precision", "0.5", "--pose", "30,5,10", "--out", out / "d"])
    assert r.returncode == 0, r.stderr
    s = json.load(open(out / "d" / "summary.json"))
    return limits, (s["femur"]["min_distance_mm"], s["pelvis"]["min_distance_mm"])


@pytest.mark.skipif(not os.path.exists(SUBJECT), reason="shared data absent")
@pytest.mark.parametrize("transform,bone", [(renumbered, "pelvis"), (duplicated, "pelvis"), (renumbered, "femur")],
                         ids=["pelvis-renumbered", "pelvis-duplicated", "femur-renumbered"])
def test_a_bone_written_another_way_gives_the_same_limits_and_distances(tmp_path, transform, bone):
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    ref_limits, ref_dist = outcome(SUBJECT, tmp_path / "a")
    limits, dist = outcome(variant(tmp_path, "v", transform, bone), tmp_path / "b")
    for k in ref_limits:
        assert abs(limits[k] - ref_limits[k]) <= 0.05 or (np.isnan(limits[k]) and np.isnan(ref_limits[k])), \
            (k, ref_limits[k], limits[k])
    assert np.allclose(dist, ref_dist, atol=0.01, rtol=0), (ref_dist, dist)


def test_an_obj_keeps_its_vertex_order(tmp_path):
    """assimp joins identical vertices unless told not to: the reader keeps the file's order and count."""
    impinge = pytest.importorskip("impinge")  # the Python module: skipped where it is not built (--sanitize)
    V = np.array([[0, 0, 0], [10, 0, 0], [0, 10, 0], [0, 0, 10], [5, 5, 5]], float)
    order = [3, 0, 4, 1, 2]
    F = np.array([[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]])
    with open(tmp_path / "m.obj", "w") as f:
        for i in order:
            f.write("v %g %g %g\n" % tuple(V[i]))
        pos = {i: k + 1 for k, i in enumerate(order)}
        for t in F:
            f.write("f %d %d %d\n" % tuple(pos[i] for i in t))
    W, _ = impinge.load_mesh(str(tmp_path / "m.obj"))
    assert W.shape == (5, 3)
    np.testing.assert_array_equal(W, V[order])


def monotone_limits(out):
    return {x["motion"]: float(x["limit_deg"]) for x in csv.DictReader(open(out / "rom" / "rom_limits.csv"))
            if x["monotone"] in ("1", "true") and x["status"] == "limited"}


@pytest.mark.skipif(not os.path.exists(SUBJECT), reason="shared data absent")
def test_a_pelvis_split_in_four_gives_the_same_acetabulum_translation_and_distances(tmp_path):
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    _, ref_dist = outcome(SUBJECT, tmp_path / "a")
    _, dist = outcome(variant(tmp_path, "v", split4, "pelvis"), tmp_path / "b")
    assert np.allclose(dist, ref_dist, atol=0.01, rtol=0), (ref_dist, dist)
    a, b = (json.load(open(tmp_path / x / "d" / "summary.json")) for x in ("a", "b"))
    assert np.allclose(a["acetabular_centre_mm"], b["acetabular_centre_mm"], atol=0.005, rtol=0)
    assert np.allclose(a["joint_translation_mm"], b["joint_translation_mm"], atol=0.005, rtol=0)
    la, lb = monotone_limits(tmp_path / "a"), monotone_limits(tmp_path / "b")
    both = set(la) & set(lb)
    assert len(both) >= 6, (la, lb)
    # All but one within 0.1 deg; the one left (lhdl-ct's extension, 0.6 deg apart at 0.5 deg maps) within 1 deg,
    # the split's earlier (its added vertices meet the femur first).
    off = {k: (la[k], lb[k]) for k in both if abs(la[k] - lb[k]) > 0.1}
    assert len(off) <= 1 and all(abs(a - b) <= 1 for a, b in off.values()), off
