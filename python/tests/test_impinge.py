"""The Python module against the CLI and the C++ library. Invariants: gaps from Python equal the
CLI's on a generated hip, bit for bit; maps are numpy views with the documented shapes; bad
arrays (wrong shape, NaN, bad indices, wrong dtype) raise impinge.Error naming the array;
motion() equals detect_pose() frame by frame."""
import csv
import json
import os
import struct
import subprocess
import tempfile

import numpy as np
import pytest

import impinge

CLI = os.environ.get("IMPINGE_CLI", "build/impinge")
DATA = os.environ.get("IMPINGE_SHARED_DATA", "../shared/data/hips")


def read_ply_vertices(path):
    """The vertex records of a binary PLY written by impinge, by the header's property names (x y z gap_mm
    quality [distance_mm]: float; level red green blue: uchar)."""
    kinds = {"float": "<f4", "uchar": "u1"}
    with open(path, "rb") as f:
        n, props, elem = 0, [], None
        while True:
            t = f.readline().decode().split()
            if t[:2] == ["element", "vertex"]:
                n, elem = int(t[2]), "vertex"
            elif t[:1] == ["element"]:
                elem = t[1]
            elif t[:1] == ["property"] and elem == "vertex":
                props.append((t[2], kinds[t[1]]))
            elif t == ["end_header"]:
                break
        dtype = np.dtype(props)
        return np.frombuffer(f.read(n * dtype.itemsize), dtype=dtype, count=n)


def read_gaps(path):
    """gap_mm per vertex of a PLY written by impinge."""
    return read_ply_vertices(path)["gap_mm"]


@pytest.fixture(scope="module")
def generated():
    d = tempfile.mkdtemp(prefix="impinge_py_")
    subprocess.run([CLI, "generate", "--triangles", "3000", "--cam", "2", "--out", d + "/s"], check=True,
                   capture_output=True)
    return d


def test_gaps_equal_the_cli_on_a_generated_hip(generated):
    d = generated
    subprocess.run([CLI, "distance", "--subject", d + "/s/subject.json", "--precision", "1", "--pose=30,-10,5",
                    "--out", d + "/cli"], check=True, capture_output=True)
    cli_ball, cli_socket = read_gaps(d + "/cli/femur_gaps.ply"), read_gaps(d + "/cli/pelvis_gaps.ply")
    with open(d + "/cli/summary.json") as f:
        summary = json.load(f)
    cor = summary["head_centre_mm"]
    # Where the one pose's time went: the parts within the whole (set-up, pose and output in order; each body's
    # sampling and marking within the set-up, both scans within the pose), no layered maps with the direct set-up.
    t = summary["timings_ms"]
    assert summary["query_strategy"] == "direct" and t["femur_layered_sampling"] == t["pelvis_layered_sampling"] == 0
    assert 0 < t["setup_total"] + t["pose"] + t["output"] <= t["total"]
    for part in ("femur", "pelvis"):
        assert 0 < t[f"{part}_sampling"] + t[f"{part}_marking"] <= t["setup_total"]
        assert t[f"{part}_detection"] + t[f"{part}_distance"] <= t["pose"]
    ball, socket = impinge.load_mesh(d + "/s/femur_r.ply"), impinge.load_mesh(d + "/s/pelvis.ply")
    # The CLI's distance sets up for its one pose (query strategy auto: direct, no layered maps); the Joint, the same.
    j = impinge.Joint(ball, socket, cor=cor, neutral="scan", resolution=1.0, query_strategy="direct")
    r = j.detect_pose(30, -10, 5)
    assert r["femur_gap_mm"].dtype == np.float32 and r["femur_gap_mm"].shape == (len(ball[0]),)
    # With the layered maps (the Joint's default, for many poses): the same distances and first-surface gaps; the
    # hidden vertices' gaps the maps' interpolation of the exact ones, within 0.1 mm here.
    m = impinge.Joint(ball, socket, cor=cor, neutral="scan", resolution=1.0).detect_pose(30, -10, 5)
    for part in ("femur", "pelvis"):
        np.testing.assert_array_equal(m[f"{part}_distance_mm"], r[f"{part}_distance_mm"])
        first = m[f"{part}_status"] == 0
        np.testing.assert_array_equal(m[f"{part}_gap_mm"][first], r[f"{part}_gap_mm"][first])
        np.testing.assert_array_equal(m[f"{part}_status"], r[f"{part}_status"])
        np.testing.assert_allclose(m[f"{part}_gap_mm"], r[f"{part}_gap_mm"], atol=0.1)
    np.testing.assert_array_equal(r["femur_gap_mm"], cli_ball)
    np.testing.assert_array_equal(r["pelvis_gap_mm"], cli_socket)
    # The Euclidean distances beside them (issue 26): the CLI's, and never larger in size than a gap.
    np.testing.assert_array_equal(r["femur_distance_mm"], read_ply_vertices(d + "/cli/femur_gaps.ply")["distance_mm"])
    np.testing.assert_array_equal(r["pelvis_distance_mm"], read_ply_vertices(d + "/cli/pelvis_gaps.ply")["distance_mm"])
    both = np.isfinite(r["femur_gap_mm"]) & np.isfinite(r["femur_distance_mm"])
    assert np.count_nonzero(both) > 50
    assert np.all(np.abs(r["femur_distance_mm"][both]) <= np.abs(r["femur_gap_mm"][both]) + 0.05)
    assert r["summary"]["femur"]["min_distance_mm"] == pytest.approx(float(np.nanmin(r["femur_distance_mm"])))
    # Off: no distance arrays.
    assert "femur_distance_mm" not in impinge.Joint(ball, socket, cor=cor, neutral="scan", resolution=1.0,
                                                   distances=False).detect_pose(30, -10, 5)
    # The same pose as a rotation matrix.
    R = j.femur_rotation(30, -10, 5)
    np.testing.assert_array_equal(j.detect(R)["femur_gap_mm"], cli_ball)
    s = r["summary"]["femur"]
    assert s["vertices_tested"] == int(np.count_nonzero(r["femur_status"] == 0))
    assert s["min_gap_mm"] == pytest.approx(float(np.nanmin(r["femur_gap_mm"])))


def test_motion_equals_detect_pose_and_maps_are_views(generated):
    d = generated
    ball, socket = impinge.load_mesh(d + "/s/femur_r.ply"), impinge.load_mesh(d + "/s/pelvis.ply")
    j = impinge.Joint(ball, socket, neutral="scan", resolution=2.0)
    angles = np.array([[0, 0, 0], [20, 5, -5], [40, -10, 10]], dtype=float)
    m = j.motion(angles)
    for k, a in enumerate(angles):
        r = j.detect_pose(*a)
        assert m["femur_min_gap_mm"][k] == r["summary"]["femur"]["min_gap_mm"]
        assert m["pelvis_min_gap_mm"][k] == r["summary"]["pelvis"]["min_gap_mm"]
    mp = j.pelvis_map
    v = mp.values
    assert v.dtype == np.float32 and v.shape == (mp.num_nodes,) and not v.flags.writeable
    assert mp.num_nodes == (180 // 2 + 1) * (360 // 2)
    assert int(np.isfinite(v).sum()) == mp.nodes_covered
    u = mp.node_directions()
    np.testing.assert_allclose(np.linalg.norm(u, axis=1), 1.0, atol=1e-12)
    assert j.frames is None


def test_motion_set_up_chosen_by_its_frames(generated):
    """impinge motion with --query-strategy auto: a short motion builds no layered maps (direct), one of 400
    frames or more builds them (maps), as summary.json says; forcing either gives the same distances, first-surface gaps and
    levels frame by frame (only the hidden vertices' radial gaps may differ: exact against interpolated)."""
    d = generated

    def motion(frames, name, *extra):
        mot = f"{d}/{name}.mot"
        with open(mot, "w") as f:
            f.write(f"m\nversion=1\nnRows={frames}\nnColumns=4\ninDegrees=yes\nendheader\n"
                    "time\thip_flexion_r\thip_adduction_r\thip_rotation_r\n")
            for i in range(frames):
                f.write(f"{i * 0.01:.2f}\t{40 * i / frames:.4f}\t{5 * i / frames:.4f}\t{-10 * i / frames:.4f}\n")
        out = f"{d}/{name}"
        subprocess.run([CLI, "motion", "--subject", d + "/s/subject.json", "--motion", mot, "--precision", "2",
                        "--quiet", "--vtp-every", "1000000", "--out", out, *extra], check=True, capture_output=True)
        with open(out + "/summary.json") as f:
            setup = json.load(f)["query_strategy"]
        with open(out + "/frames.csv") as f:
            rows = list(csv.DictReader(f))
        return setup, rows

    short, rows = motion(5, "m5")
    forced, rows_maps = motion(5, "m5maps", "--query-strategy", "maps")
    assert (short, forced) == ("direct", "maps")
    assert motion(5, "m5setup", "--setup", "maps")[0] == "maps"  # the former name, for one release
    r = subprocess.run([CLI, "distance", "--subject", d + "/s/subject.json", "--precision", "2", "--setup", "maps",
                        "--out", d + "/setup_alias"], capture_output=True, text=True)
    assert r.returncode == 0 and "--setup is deprecated" in r.stderr and "use --query-strategy" in r.stderr
    for a, b in zip(rows, rows_maps):
        for col in ("femur_min_distance_mm", "pelvis_min_distance_mm", "pelvis_level0_area_mm2",
                    "pelvis_level2_area_mm2"):
            assert a[col] == b[col], col
    assert motion(400, "m400")[0] == "maps"
    assert motion(399, "m399")[0] == "direct"


def test_maps_saved_and_loaded_give_the_same_gaps(generated):
    d = generated
    ball, socket = impinge.load_mesh(d + "/s/femur_r.ply"), impinge.load_mesh(d + "/s/pelvis.ply")
    j = impinge.Joint(ball, socket, neutral="scan", resolution=1.0)
    j.save_maps(d + "/b.map", d + "/s.map")
    k = impinge.Joint(ball, socket, neutral="scan", resolution=1.0, maps=(d + "/b.map", d + "/s.map"))
    np.testing.assert_array_equal(k.pelvis_map.values, j.pelvis_map.values)
    np.testing.assert_array_equal(k.detect_pose(20, 5, 5)["femur_gap_mm"], j.detect_pose(20, 5, 5)["femur_gap_mm"])
    with pytest.raises(impinge.Error, match="another subject or COR"):
        impinge.Joint(ball, socket, cor=j.cor + [0.5, 0, 0], neutral="scan", resolution=1.0,
                      maps=(d + "/b.map", d + "/s.map"))
    with pytest.raises(impinge.Error, match="the joint's scheme is equiangular at 2"):
        impinge.Joint(ball, socket, neutral="scan", resolution=2.0, maps=(d + "/b.map", d + "/s.map"))
    with open(d + "/b.map", "r+b") as f:
        f.seek(100)
        byte = f.read(1)
        f.seek(100)
        f.write(bytes([byte[0] ^ 0x10]))
    with pytest.raises(impinge.Error, match="checksum mismatch"):
        impinge.Joint(ball, socket, neutral="scan", resolution=1.0, maps=(d + "/b.map", d + "/s.map"))


def test_sparse_maps_give_the_same_gaps(generated):
    d = generated
    ball, socket = impinge.load_mesh(d + "/s/femur_r.ply"), impinge.load_mesh(d + "/s/pelvis.ply")
    dense = impinge.Joint(ball, socket, neutral="scan", resolution=0.5)
    sparse = impinge.Joint(ball, socket, neutral="scan", resolution=0.5, sparse_region_mm=float("inf"))
    assert sparse.pelvis_map.sparse and not dense.pelvis_map.sparse
    assert sparse.pelvis_map.bytes < dense.pelvis_map.bytes
    np.testing.assert_array_equal(sparse.pelvis_map.values, dense.pelvis_map.values)
    for pose in ((0, 0, 0), (30, -10, 5), (90, 10, 25)):
        a, b = dense.detect_pose(*pose), sparse.detect_pose(*pose)
        np.testing.assert_array_equal(a["femur_gap_mm"], b["femur_gap_mm"])
        np.testing.assert_array_equal(a["pelvis_gap_mm"], b["pelvis_gap_mm"])
    with pytest.raises(impinge.Error, match="sparse"):
        impinge.Joint(ball, socket, neutral="scan", resolution=2.0, sparse_region_mm=-1.0)


def test_layered_maps_test_hidden_vertices_and_leave_the_others(generated):
    d = generated
    ball, socket = impinge.load_mesh(d + "/s/femur_r.ply"), impinge.load_mesh(d + "/s/pelvis.ply")
    single = impinge.Joint(ball, socket, neutral="scan", resolution=1.0, layers=0)
    layered = impinge.Joint(ball, socket, neutral="scan", resolution=1.0)  # layers=4: the default
    a, b = single.detect_pose(20, 5, 10), layered.detect_pose(20, 5, 10)
    for key in ("femur_gap_mm", "pelvis_gap_mm"):
        tested = ~np.isnan(a[key])
        np.testing.assert_array_equal(a[key][tested], b[key][tested])  # first-surface gaps unchanged
    # The cup's outer wall is hidden behind its inner surface: tested by the femur's layered map now,
    # and outside the femur (the head lies inside the cup's hollow).
    s = b["summary"]["pelvis"]
    assert s["vertices_tested_layered"] > 0 and s["min_gap_layered_mm"] > 0
    assert a["summary"]["pelvis"]["vertices_tested_layered"] == 0
    with pytest.raises(impinge.Error, match="layers"):
        impinge.Joint(ball, socket, neutral="scan", resolution=2.0, layers=99)


def test_bad_arrays_raise_clear_errors(generated):
    d = generated
    V, F = impinge.load_mesh(d + "/s/femur_r.ply")
    S = impinge.load_mesh(d + "/s/pelvis.ply")
    cases = [
        ((V[:, :2], F), "shape (n, 3)"),
        ((V.astype(np.complex128), F), "dtype complex128"),
        ((V, F.astype(np.float64)), "not an integer type"),
        ((np.where(np.arange(len(V))[:, None] == 7, np.nan, V), F), "vertex 7 has a non-finite"),
        ((V, np.where(F == F.max(), len(V) + 5, F)), "outside [0, %d)" % len(V)),
        ((V, F[:, ::-1][:, :2]), "shape (n, 3)"),
        (([1, 2, 3], F), "expected a numpy array"),
    ]
    for ball, fragment in cases:
        with pytest.raises(impinge.Error) as e:
            impinge.Joint(ball, S, neutral="scan", resolution=2.0)
        assert fragment in str(e.value), str(e.value)
    j = impinge.Joint((V, F), S, neutral="scan", resolution=2.0)
    with pytest.raises(impinge.Error, match="rotation"):
        j.detect(np.ones((3, 3)))
    with pytest.raises(impinge.Error, match=r"shape \(k, 3\)"):
        j.motion(np.zeros((4, 2)))
    with pytest.raises(impinge.Error, match="not finite"):
        j.motion(np.array([[0, np.nan, 0]]))
    with pytest.raises(impinge.Error, match="scheme: 'hexagon' is not one of equiangular"):
        impinge.Joint((V, F), S, neutral="scan", scheme="hexagon")
    with pytest.raises(impinge.Error, match="nope.ply"):
        impinge.load_mesh(d + "/nope.ply")
    # A generated hip is no whole pelvis: anatomical neutral says so.
    with pytest.raises(impinge.Error, match="not a whole femur|whole pelvis"):
        impinge.Joint((V, F), S)


def test_long_calls_release_the_gil(generated):
    """While one thread is inside motion(), another Python thread keeps running."""
    import threading
    d = generated
    j = impinge.Joint(impinge.load_mesh(d + "/s/femur_r.ply"), impinge.load_mesh(d + "/s/pelvis.ply"),
                      neutral="scan", resolution=1.0)
    angles = np.column_stack([np.linspace(0, 90, 20000), np.zeros(20000), np.zeros(20000)])
    inside, done = threading.Event(), threading.Event()

    def work():
        inside.set()
        j.motion(angles)
        done.set()

    count = 0
    th = threading.Thread(target=work)
    th.start()
    inside.wait()
    while not done.is_set():
        count += 1
    th.join()
    assert count > 1000, f"the main thread ran only {count} iterations while motion() worked"


def test_fit_sphere_recovers_an_analytic_sphere():
    rng = np.random.default_rng(5)
    u = rng.normal(size=(500, 3))
    u /= np.linalg.norm(u, axis=1)[:, None]
    u = u[u[:, 2] > 0.3]  # a cap, as a femoral head
    s = impinge.fit_sphere(np.array([10.0, -20.0, 30.0]) + 23.5 * u)
    np.testing.assert_allclose(s["centre"], [10, -20, 30], atol=1e-9)
    assert s["radius"] == pytest.approx(23.5, abs=1e-9)


@pytest.mark.skipif(not os.path.exists(os.path.join(DATA, "lhdl-ct", "subject.json")), reason="shared data absent")
def test_real_subject_anatomical_frames():
    femur = impinge.load_mesh(os.path.join(DATA, "lhdl-ct", "femur_r.ply"))
    pelvis = impinge.load_mesh(os.path.join(DATA, "lhdl-ct", "pelvis.ply"))
    lps = np.diag([-1.0, -1.0, 1.0])  # the subject is LPS: to RAS
    ball, socket = (femur[0] @ lps, femur[1]), (pelvis[0] @ lps, pelvis[1])
    j = impinge.Joint(ball, socket, resolution=0.5)
    f = j.frames
    assert {"pelvis", "femur", "scan_pose_deg", "acetabulum"} <= set(f)
    axes = np.column_stack([f["pelvis"]["x_axis"], f["pelvis"]["y_axis"], f["pelvis"]["z_axis"]])
    np.testing.assert_allclose(axes.T @ axes, np.eye(3), atol=1e-12)
    m = j.motion(np.array([[0, 0, 0], [90, 0, 0]]))
    assert np.all(np.isfinite(m["femur_min_gap_mm"]))
    # ROM from Python: a limit is where detect_pose first shows contact (the first touch: no contact depth).
    lim = j.rom_limits(contact_depth_mm=0)
    fl = lim["internal_rotation_90_flexion"]["limit_deg"]
    assert 0 < fl < 150
    assert j.detect_pose(90, 0, fl)["summary"]["pelvis"]["min_gap_mm"] <= 0 or \
        j.detect_pose(90, 0, fl)["summary"]["femur"]["min_gap_mm"] <= 0
    assert min(j.detect_pose(90, 0, fl - 0.5)["summary"]["pelvis"]["min_gap_mm"],
               j.detect_pose(90, 0, fl - 0.5)["summary"]["femur"]["min_gap_mm"]) > 0
    grid = j.rom_map(flexion=[0, 90], adduction=[0, 10], contact_depth_mm=0)
    assert grid.shape == (2, 2) and grid[1, 0] == pytest.approx(fl)
    # Each limit says what it is, the published normal range beside it, whether the soft tissue usually ends the
    # motion first (the bony limit past that range), and the pelvic frame the angles are measured in.
    row = lim["internal_rotation_90_flexion"]
    assert row["status"] == "limited" and row["pelvic_frame"] == "isb" and row["normal_deg"] == pytest.approx(37.9)
    assert bool(row["soft_tissue_first"]) == (fl > 37.9)
    app = impinge.Joint(ball, socket, resolution=0.5, pelvis_frame="app")
    in_app = app.rom_limits(contact_depth_mm=0)
    assert in_app["flexion"]["pelvic_frame"] == "app"
    # Both pelvic frames in every row: limit_deg is the session frame's; the other frame's is the motion about that
    # frame's axes on the same joint, which a Joint set up in that frame (its own maps, sampled about other axes,
    # joint surfaces and joint centre) finds too, within the 0.5 deg maps' resolution (measured: at most 0.5 deg).
    APP_TOLERANCE_DEG = 0.75
    same = lambda a, b: (np.isnan(a) and np.isnan(b)) or a == b
    close = lambda a, b: (np.isnan(a) and np.isnan(b)) or abs(a - b) <= APP_TOLERANCE_DEG
    for m, r in lim.items():
        if not isinstance(r, dict):
            continue
        a = in_app[m]
        assert same(r["limit_isb_deg"], r["limit_deg"]) and r["status_isb"] == r["status"], m
        assert same(a["limit_app_deg"], a["limit_deg"]) and a["status_app"] == a["status"], m
        assert close(r["limit_app_deg"], a["limit_app_deg"]) and close(r["limit_isb_deg"], a["limit_isb_deg"]), m
    # The tilt between the frames moves flexion: the APP and ISB flexion limits differ.
    assert abs(lim["flexion"]["limit_app_deg"] - lim["flexion"]["limit_isb_deg"]) > 1
    # Active ranges of living subjects and simulated bony ranges, each with its own source.
    assert lim["flexion"]["normal_source"].startswith("AAOS") and np.isnan(lim["flexion"]["bony_normal_deg"])
    assert lim["fadir"]["bony_normal_deg"] == pytest.approx(27.9)
    assert lim["fadir"]["bony_normal_source"].startswith("Audenaert") and np.isnan(lim["fadir"]["normal_deg"])


def test_a_joint_set_up_without_layered_maps_refuses_rom_searches(generated):
    """query_strategy='direct' leaves the layered maps out (a few poses); a ROM search needs them and says so."""
    d = generated
    ball, socket = impinge.load_mesh(d + "/s/femur_r.ply"), impinge.load_mesh(d + "/s/pelvis.ply")
    j = impinge.Joint(ball, socket, neutral="scan", resolution=2.0, query_strategy="direct")
    assert j.setup["query_strategy"] == "direct"
    with pytest.raises(impinge.Error, match="without its layered maps.*query strategy 'maps'"):
        j.rom_limits()
    assert impinge.Joint(ball, socket, neutral="scan", resolution=2.0).setup["query_strategy"] == "maps"
