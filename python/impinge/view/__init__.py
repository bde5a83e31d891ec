"""impinge view: the thesis' Joint3D (section 3.4) as a page in the browser (issue 79).

A local aiohttp server around one `impinge.Joint`, set up from the same options as `impinge distance` (the option
table's rows, parsed by the library: `Joint._from_cli`). The page (three.js, bundled by esbuild at build time into
static/viewer.js; nothing is fetched from a network when it runs) shows both bones; every pose it asks for is detected
by the library (`Joint.detect_pose`: the joint-centre method, exact look-ups, Euclidean distances) and answered with
the per-vertex values the page colours.

Safety: the server listens on 127.0.0.1 unless told otherwise; every request must carry the random token printed in
the page's address (as Jupyter does), else 403. It reads only the files named on the command line.

Protocol (WebSocket /ws): the page sends {"type": "pose", "id": n, "pose": [flexion, adduction, internal_rotation]}
(degrees, ISB); the server answers the newest pose it has (an older pending one is dropped, never queued) with one
binary message: a little-endian uint32 header length, the header (JSON: id, pose, R (9, row-major, input frame), t
(3, mm), summary, ms), then float32 femur gaps, float32 pelvis gaps, float32 femur distances, float32 pelvis
distances (absent: NaN), uint8 femur levels, uint8 pelvis levels, each padded to 4 bytes. A bad message gets
{"type": "error", "message": ...} and the server keeps serving.
"""
import asyncio
import json
import math
import os
import secrets
import struct
import sys
import tempfile
import time
import webbrowser
from concurrent.futures import ThreadPoolExecutor
import weakref

import numpy as np

import impinge

STATIC = os.path.join(os.path.dirname(__file__), "static")
MAX_MESSAGE_BYTES = 4096  # a pose message is < 200 bytes; anything larger is refused


class BadMessage(ValueError):
    """A message from the page that is not a valid request (said back to the page)."""


def parse_pose_message(text):
    """A page's message -> (id, (flexion, adduction, internal_rotation)) in degrees. Raises BadMessage naming
    what is wrong (not JSON, not an object, unknown type, a pose not three finite numbers within +-360 deg)."""
    size = len(text.encode("utf-8", "surrogatepass"))
    if size > MAX_MESSAGE_BYTES:
        raise BadMessage(f"message of {size} bytes: at most {MAX_MESSAGE_BYTES}")
    try:
        m = json.loads(text)
    except (ValueError, RecursionError) as e:
        raise BadMessage(f"not JSON: {e}") from None
    if not isinstance(m, dict):
        raise BadMessage("expected an object {type, id, pose}")
    if m.get("type") != "pose":
        raise BadMessage(f"unknown message type {m.get('type')!r} (known: pose)")
    pose = m.get("pose")
    if not isinstance(pose, list) or len(pose) != 3 or not all(
            isinstance(x, (int, float)) and not isinstance(x, bool) for x in pose):
        raise BadMessage(f"pose {pose!r}: expected [flexion, adduction, internal_rotation] in degrees")
    try:
        finite = all(math.isfinite(x) and abs(x) <= 360 for x in pose)
    except OverflowError:  # an integer too large for a float
        finite = False
    if not finite:
        raise BadMessage(f"pose {pose!r}: each angle must be finite and within +-360 deg")
    ident = m.get("id", 0)
    if not isinstance(ident, int) or isinstance(ident, bool):
        raise BadMessage(f"id {ident!r}: expected an integer")
    return ident, tuple(float(x) for x in pose)


def _finite(x):
    """A number for JSON: None for NaN, inf or a missing value."""
    try:
        x = float(x)
    except (TypeError, ValueError):
        return None
    return x if math.isfinite(x) else None


def _padded(a):
    b = np.ascontiguousarray(a).tobytes()
    return b + b"\0" * (-len(b) % 4)


class Viewer:
    """One Joint and what the page needs of it: the scene (meshes, levels, palette, axes) and posed frames."""

    def __init__(self, joint, motion=None, plan=None, motion_folder=None):
        self.joint = joint
        self.motion = self._read_motion(motion) if motion else None  # read now: a bad file fails before the page
        self.motion_folder = None
        if motion_folder:
            if not os.path.isdir(motion_folder):
                raise impinge.Error(f"--motion-folder {motion_folder}: not a folder")
            self.motion_folder = os.path.realpath(motion_folder)
        self._folder_motions = {}
        self._jobs = {}
        self._pool = ThreadPoolExecutor(max_workers=1, thread_name_prefix="impinge-view-job")
        setup = joint.setup
        self.meshes = joint.meshes
        self.plan = read_plan(plan, self.meshes) if plan else None
        thresholds = list(setup["levels_thresholds_mm"])
        frames = setup.get("frames")
        axes = None
        if frames:  # anatomical neutral: the pelvic frame's axes (input frame): x anterior, y superior, z right (ISB)
            p = frames["pelvis"]
            axes = {"x": p["x_axis"], "y": p["y_axis"], "z": p["z_axis"]}
        clock = None
        if frames and "acetabulum" in frames:  # the acetabular clock face (Blankenbaker et al. 2007), input frame
            ac = frames["acetabulum"]
            clock = {"centre_mm": ac["rim_centre_mm"], "twelve": ac["clock_twelve"], "three": ac["clock_three"],
                     "radius_mm": ac["rim_radius_mm"], "convention": ac.get("convention")}
        self.scene = {
            "impinge_version": impinge.__version__,
            "femur_vertices": int(len(self.meshes["femur"][0])),
            "pelvis_vertices": int(len(self.meshes["pelvis"][0])),
            "femur_triangles": int(len(self.meshes["femur"][1])),
            "pelvis_triangles": int(len(self.meshes["pelvis"][1])),
            "levels_thresholds_mm": thresholds,
            "levels_on": setup["levels_on"],
            "distances": bool(setup["distances"]),
            "palette": impinge.level_colours(len(thresholds) + 1),
            "head_centre_mm": list(map(float, joint.cor)),
            "head_radius_mm": setup.get("head_radius_mm"),
            "side": setup["side"],
            "input_frame": setup["input_frame"],
            "neutral": setup["neutral"],
            "joint_centre": setup["joint_centre"],
            "pelvic_frame": setup.get("pelvic_frame"),
            "axes": axes,
            "clock": clock,
            "motion": None if self.motion is None else {k: self.motion[k] for k in ("name", "format")},
            "motion_folder": motion_folder is not None,
            "plan": None if self.plan is None else self.plan["summary"],
            "warnings": list(setup.get("warnings", [])),
        }

    def _read_motion(self, path):
        m = impinge.load_motion(path, self.joint.setup["side"])
        return {"name": os.path.basename(path), "format": m["format"],
                "time_s": np.asarray(m["time_s"]).tolist(), "angles": np.asarray(m["angles"]).tolist()}

    def motion_files(self):
        """The motion files (.csv, .mot, .sto) directly in --motion-folder, by name; [] without one. An entry that
        resolves outside the folder (a symbolic link out) is not listed."""
        if self.motion_folder is None:
            return []
        out = []
        for e in sorted(os.listdir(self.motion_folder)):
            p = os.path.join(self.motion_folder, e)
            if e.lower().endswith((".csv", ".mot", ".sto")) and os.path.isfile(p) and \
                    os.path.dirname(os.path.realpath(p)) == self.motion_folder:
                out.append(e)
        return out

    def motion_of(self, name):
        """The motion the page shows: --motion's (name None) or the file `name` of --motion-folder. Raises
        impinge.Error for a name that is not one of motion_files() (a path, '..', a link out: refused)."""
        if name is None:
            if self.motion is None:
                raise impinge.Error("no motion was given (impinge view --motion FILE)")
            return self.motion
        if name not in self.motion_files():
            raise impinge.Error(f"motion {name!r}: not a motion file of the motion folder "
                                f"({', '.join(self.motion_files()) or 'none'})")
        if name not in self._folder_motions:
            self._folder_motions[name] = self._read_motion(os.path.join(self.motion_folder, name))
        return self._folder_motions[name]

    def job(self, name, motion=None):
        """The state of a background job ('rom', 'morphology', 'motion' of `motion`), started at its first request:
        {"state": "running", "seconds": s} | {"state": "done", "result": ...} | {"state": "error", "message": ...}."""
        key = name if name != "motion" else f"motion:{motion}"
        name = key
        if name not in self._jobs:
            fn = {"rom": self._rom, "morphology": self._morphology}.get(name) or (lambda: self._motion_least(motion))
            self._jobs[name] = (time.perf_counter(), self._pool.submit(fn))
        t0, fut = self._jobs[name]
        if not fut.done():
            return {"state": "running", "seconds": round(time.perf_counter() - t0, 1)}
        try:
            return {"state": "done", "seconds": round(time.perf_counter() - t0, 1), "result": fut.result()}
        except impinge.Error as e:
            return {"state": "error", "message": str(e)}

    def _rom(self):
        """The standard motions' limits (Joint.rom_limits, `impinge rom`'s defaults) with the pose at each limit and
        where each motion starts; computed once."""
        if getattr(self, "_rom_rows", None) is None:
            self._rom_rows = self._rom_search()
        return self._rom_rows

    def _rom_search(self):
        limits = self.joint.rom_limits()
        out = []
        for name, row in limits.items():
            if not isinstance(row, dict):
                continue
            at = row.get("pose_at_limit_deg")
            entry = {"motion": name, "limit_deg": _finite(row.get("limit_deg")), "status": row.get("status"),
                     "limited_by": row.get("limited_by"), "contact_class": row.get("contact_class"),
                     "normal_deg": _finite(row.get("normal_deg")), "pelvic_frame": row.get("pelvic_frame"),
                     "pose_at_limit_deg": list(at) if at is not None else None,
                     "start_deg": list(row.get("start_deg") or (0, 0, 0))}
            out.append(entry)
        return out

    def _morphology(self):
        """The morphology values the page shows beside the view (Joint.morphology(): each measure's value)."""
        m = self.joint.morphology()

        def value(part, key):
            x = m[part].get(key)
            return x.get("value") if isinstance(x, dict) else x

        by_hour = value("femur", "alpha_deg_by_hour") or {}
        out = {"alpha_deg_by_hour": {h: _finite(v) for h, v in by_hour.items()}}
        for part, keys in (("femur", ("alpha_max_deg", "alpha_max_hour", "head_radius_mm", "neck_shaft_angle_deg",
                                      "version_posterior_condylar_deg")),
                           ("acetabulum", ("lateral_centre_edge_deg", "anterior_centre_edge_deg",
                                           "radiographic_anteversion_deg", "radiographic_inclination_deg"))):
            for k in keys:
                out[k] = _finite(value(part, k))
        return out

    def _motion_least(self, name=None):
        """Per frame of a motion (motion_of(name)): the least distance and the least radial gap of both bones
        (Joint.motion)."""
        r = self.joint.motion(np.asarray(self.motion_of(name)["angles"], dtype=float))
        out = {"least_gap_mm": [_finite(x) for x in np.fmin(r["femur_min_gap_mm"], r["pelvis_min_gap_mm"])]}
        if "femur_min_distance_mm" in r:
            out["least_distance_mm"] = [_finite(x) for x in
                                        np.fmin(r["femur_min_distance_mm"], r["pelvis_min_distance_mm"])]
        return out

    def plan_bytes(self, bone):
        """A bone after the plan as binary: float32 V (n x 3, input frame, mm) then float32 resection_mm (n)."""
        V, depth = self.plan["bones"][bone]
        return _padded(V) + _padded(depth)

    def mesh_bytes(self, bone):
        """A bone as binary: uint32 vertex count, uint32 triangle count, float32 V (n x 3), uint32 F (m x 3)."""
        V, F = self.meshes[bone]
        return struct.pack("<II", len(V), len(F)) + _padded(np.asarray(V, "<f4")) + _padded(np.asarray(F, "<u4"))

    def frame_bytes(self, ident, pose):
        """The binary answer to one pose (the module docstring's layout). Runs the detection (GIL released)."""
        t0 = time.perf_counter()
        r = self.joint.detect_pose(*pose)
        R, t = self.joint.femur_pose(*pose)
        ms = (time.perf_counter() - t0) * 1e3
        fs, ps = r["summary"]["femur"], r["summary"]["pelvis"]
        nan = float("nan")

        def least(a, b):
            v = [x for x in (a, b) if x is not None and math.isfinite(x)]
            return min(v) if v else None

        summary = {
            "least_gap_mm": least(fs.get("min_gap_mm"), ps.get("min_gap_mm")),
            "least_distance_mm": least(fs.get("min_distance_mm"), ps.get("min_distance_mm")),
            "contact_area_mm2": float(ps.get("area_penetrating_mm2") or 0.0),
            "contact_class": ps.get("closest_contact_class"),
            "inside_area_mm2": ps.get("area_inside_mm2"),
            "femur": {k: fs.get(k) for k in ("min_gap_mm", "min_distance_mm", "vertices_penetrating",
                                              "vertices_inside")},
            "pelvis": {k: ps.get(k) for k in ("min_gap_mm", "min_distance_mm", "vertices_penetrating",
                                               "vertices_inside")},
        }
        header = json.dumps({"id": ident, "pose": list(pose), "R": np.asarray(R).ravel().tolist(),
                             "t": np.asarray(t).ravel().tolist(), "summary": summary, "ms": ms},
                            allow_nan=False, default=lambda x: None).encode()
        nf, npv = self.scene["femur_vertices"], self.scene["pelvis_vertices"]
        fd = r.get("femur_distance_mm", np.full(nf, nan, np.float32))
        pd = r.get("pelvis_distance_mm", np.full(npv, nan, np.float32))
        parts = [struct.pack("<I", len(header)), header + b" " * (-len(header) % 4),
                 _padded(r["femur_gap_mm"].astype("<f4")), _padded(r["pelvis_gap_mm"].astype("<f4")),
                 _padded(np.asarray(fd, "<f4")), _padded(np.asarray(pd, "<f4")),
                 _padded(r["femur_level"]), _padded(r["pelvis_level"])]
        return b"".join(parts)


def read_ply_vertices(path):
    """The vertex records of a binary little-endian PLY (as impinge writes it) by the header's property names."""
    kinds = {"float": "<f4", "double": "<f8", "uchar": "u1", "int": "<i4", "uint": "<u4"}
    with open(path, "rb") as f:
        n, props, elem = 0, [], None
        while True:
            line = f.readline()
            if not line:
                raise impinge.Error(f"{path}: no end_header: not a PLY file impinge wrote")
            t = line.decode("ascii", "replace").split()
            if t[:2] == ["element", "vertex"]:
                n, elem = int(t[2]), "vertex"
            elif t[:1] == ["element"]:
                elem = t[1]
            elif t[:1] == ["property"] and elem == "vertex":
                if t[1] not in kinds:
                    raise impinge.Error(f"{path}: vertex property type {t[1]!r} not read here")
                props.append((t[2], kinds[t[1]]))
            elif t[:1] == ["format"] and t[1] != "binary_little_endian":
                raise impinge.Error(f"{path}: format {t[1]}: expected binary_little_endian (as impinge plan writes)")
            elif t == ["end_header"]:
                break
        dtype = np.dtype(props)
        data = f.read(n * dtype.itemsize)
        if len(data) < n * dtype.itemsize:
            raise impinge.Error(f"{path}: {n} vertices announced, the file ends before them")
        return np.frombuffer(data, dtype=dtype, count=n)


def read_plan(folder, meshes):
    """An `impinge plan` output folder for this hip -> {"summary": targets and per-bone figures (plan.json),
    "bones": {bone: (V float32 (n, 3) mm input frame, resection_mm float32 (n,))}}. Raises impinge.Error naming the
    file when plan.json or a resected mesh is missing or was made for another mesh (its vertex count)."""
    path = os.path.join(folder, "plan.json")
    try:
        p = impinge._json_file.load(path)  # a key given twice is an error
    except OSError as e:
        raise impinge.Error(f"--plan {folder}: cannot read {path}: {e.strerror}") from None
    except ValueError as e:
        raise impinge.Error(f"--plan {folder}: {path} is not JSON: {e}") from None
    bones = {}
    for bone in ("femur", "pelvis"):
        ply = os.path.join(folder, f"{bone}_resected.ply")
        if not os.path.exists(ply):
            continue
        v = read_ply_vertices(ply)
        n = len(meshes[bone][0])
        if len(v) != n or "resection_mm" not in v.dtype.names:
            raise impinge.Error(f"--plan: {ply} has {len(v)} vertices{'' if 'resection_mm' in v.dtype.names else ' and no resection_mm'}"
                                f"; this {bone} has {n}: a plan of another hip?")
        bones[bone] = (np.column_stack([v["x"], v["y"], v["z"]]).astype("<f4"), v["resection_mm"].astype("<f4"))
    if not bones:
        raise impinge.Error(f"--plan {folder}: no femur_resected.ply or pelvis_resected.ply")
    keep = ("target", "target_deg", "limit_before_deg", "limit_after_deg", "met", "note")
    summary = {"folder": os.path.abspath(folder), "all_targets_met": p.get("all_targets_met"),
               "targets": [{k: t.get(k) for k in keep} for t in p.get("targets", [])],
               "bones": {b: {k: (p.get(f"{b}_resection") or {}).get(k) for k in
                             ("volume_mm3", "area_mm2", "deepest_cut_mm", "mean_depth_mm")} for b in bones}}
    return {"summary": summary, "bones": bones}


def export_poses(viewer, spec):
    """The poses (degrees, ISB) an export holds and what they are: `spec` "auto" (the motion's frames when there is
    one, else "rom"), "rom" (neutral, and per standard motion with a limit the pose 2 deg before it and at it),
    "motion", or "F,A,R;F,A,R;...". Raises impinge.Error naming the option on a bad spec."""
    if spec == "auto":
        spec = "motion" if viewer.motion is not None else "rom"
    if spec == "motion":
        if viewer.motion is None:
            raise impinge.Error("--export-poses motion: no --motion was given")
        return [tuple(p) for p in viewer.motion["angles"]], "the motion's frames"
    if spec == "rom":
        poses = [(0.0, 0.0, 0.0)]
        for r in viewer._rom():
            at, start = r["pose_at_limit_deg"], r["start_deg"]
            if at is None:
                continue
            f = max(0.0, r["limit_deg"] - 2) / r["limit_deg"] if r["limit_deg"] > 0 else 0.0
            poses.append(tuple(s0 + (a0 - s0) * f for s0, a0 in zip(start, at)))
            poses.append(tuple(at))
        return poses, "neutral and, per standard motion, the poses 2 deg before and at its limit"
    poses = []
    for k, item in enumerate(spec.split(";")):
        try:
            p = tuple(float(x) for x in item.split(","))
        except ValueError:
            p = ()
        if len(p) != 3 or not all(math.isfinite(x) and abs(x) <= 360 for x in p):
            raise impinge.Error(f"--export-poses: pose {k + 1} '{item}': expected FLEXION,ADDUCTION,INTERNAL_ROTATION "
                                "in degrees (each within +-360), poses separated by ';'; or auto, rom, motion")
        poses.append(p)
    return poses, "the poses given"


def export_html(viewer, path, spec, max_mb):
    """Write `path`: one HTML file holding the page's script, the meshes, the chosen poses' values (as the server
    sends them), the ROM limits, the morphology and the motion, so that it opens from disk with no server and no
    network. Poses beyond `max_mb` (MB) are decimated evenly (first and last kept); the page says what it holds and
    that between stored poses nothing is computed. Written atomically (a temporary file, then renamed). Returns
    (poses kept, poses asked, bytes). Raises impinge.Error when even the meshes and one pose exceed max_mb."""
    import base64
    poses, what = export_poses(viewer, spec)
    b64 = lambda b: base64.b64encode(b).decode("ascii")  # noqa: E731
    with open(os.path.join(STATIC, "viewer.js"), encoding="utf-8") as f:
        script = f.read().replace("</script", "<\\/script")
    with open(os.path.join(STATIC, "index.html"), encoding="utf-8") as f:
        html = f.read()
    meshes = {f"/api/mesh/{bone}": b64(viewer.mesh_bytes(bone)) for bone in ("femur", "pelvis")}
    if viewer.plan is not None:
        meshes.update({f"/api/plan/mesh/{bone}": b64(viewer.plan_bytes(bone)) for bone in viewer.plan["bones"]})
    first = viewer.frame_bytes(0, poses[0])
    per_pose = len(b64(first)) + 120  # a pose's values and its JSON around them
    asked = len(poses)
    done = lambda result: {"state": "done", "seconds": 0, "result": result}  # noqa: E731
    # An exported page chooses no motion file (there is no server to read it) and shows --motion's, if any.
    json_parts = {"/api/scene": dict(viewer.scene, motion_folder=False), "/api/motions": {"files": []}}
    for route, fn in (("/api/rom", viewer._rom), ("/api/morphology", viewer._morphology)):
        try:
            json_parts[route] = done(fn())
        except impinge.Error as e:  # e.g. the ROM's distance metric with --distances off: said in the page
            json_parts[route] = {"state": "error", "message": str(e)}
    if viewer.motion is not None:
        json_parts["/api/motion"] = viewer.motion
        json_parts["/api/motion/least"] = done(viewer._motion_least())
    text_of = lambda x: json.dumps(x, allow_nan=False, default=lambda v: None)  # noqa: E731
    base = len(script) + len(html) + sum(len(m) for m in meshes.values()) + len(text_of(json_parts)) + 4096
    room = int((max_mb * 1e6 - base) // per_pose)
    if room < 1:
        raise impinge.Error(f"--export-max-mb {max_mb:g}: the meshes and one pose need {(base + per_pose) / 1e6:.1f} MB")
    if asked > room:
        keep = sorted({round(k * (asked - 1) / (room - 1)) for k in range(room)}) if room > 1 else [0]
        poses = [poses[k] for k in keep]
    frames = [{"pose": list(p), "data": b64(first if k == 0 else viewer.frame_bytes(k, p))}
              for k, p in enumerate(poses)]

    def build(frames):
        note = (f"Exported file: {len(frames)} stored poses ({what}"
                + (f", {asked} asked, decimated evenly to fit {max_mb:g} MB" if len(frames) < asked else "")
                + "). Nothing is computed here: a slider or the timeline shows the stored pose nearest to it.")
        data = {"json": json_parts, "buffers": meshes, "frames": frames, "note": note}
        text = text_of(data).replace("</", "<\\/")
        return html.replace('<script src="viewer.js?token=__TOKEN__"></script>',
                            f"<script>window.__IMPINGE_EXPORT__ = {text};</script>\n<script>{script}</script>")

    page = build(frames)
    while len(page.encode()) > max_mb * 1e6 and len(frames) > 1:  # the estimate was short: every other pose kept
        frames = frames[:-1:2] + frames[-1:]
        page = build(frames)
    if len(page.encode()) > max_mb * 1e6:
        raise impinge.Error(f"--export-max-mb {max_mb:g}: the meshes and one pose need {len(page.encode()) / 1e6:.1f} MB")
    folder = os.path.dirname(os.path.abspath(path))
    fd, tmp = tempfile.mkstemp(prefix=".impinge-export-", suffix=".html", dir=folder)
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(page)
            f.flush()
            os.fsync(f.fileno())
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)  # as an ordinary file of the user's (mkstemp makes it 0600)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise
    return len(frames), asked, len(page.encode())


def make_app(viewer, token):
    """The aiohttp application: the page, its script, the scene, both meshes and the pose WebSocket; every
    request must carry `token` (query `token` or header X-Impinge-Token), else 403."""
    from aiohttp import web, WSMsgType

    @web.middleware
    async def require_token(request, handler):
        given = request.query.get("token") or request.headers.get("X-Impinge-Token", "")
        if not secrets.compare_digest(given.encode("utf-8", "surrogateescape"), token.encode()):
            return web.Response(status=403, text="impinge view: a request without this server's token is refused\n")
        return await handler(request)

    async def page(request):
        with open(os.path.join(STATIC, "index.html"), encoding="utf-8") as f:
            html = f.read()
        resp = web.Response(text=html.replace("__TOKEN__", token), content_type="text/html")
        resp.headers["Cache-Control"] = "no-store"
        return resp

    async def script(request):
        return web.FileResponse(os.path.join(STATIC, "viewer.js"), headers={"Content-Type": "text/javascript"})

    async def scene(request):
        return web.json_response(viewer.scene)

    async def mesh(request):
        bone = request.match_info["bone"]
        if bone not in ("femur", "pelvis"):
            raise web.HTTPNotFound(text=f"no bone {bone!r} (femur, pelvis)")
        return web.Response(body=viewer.mesh_bytes(bone), content_type="application/octet-stream")

    async def socket(request):
        # Messages up to 1 MiB are read (one over 4 KB is answered with an error); a larger one closes the socket.
        ws = web.WebSocketResponse(max_msg_size=1 << 20)
        await ws.prepare(request)
        request.app["sockets"].add(ws)
        pending = {"req": None}
        wake = asyncio.Event()
        loop = asyncio.get_running_loop()

        async def worker():
            while not ws.closed:
                await wake.wait()
                wake.clear()
                req, pending["req"] = pending["req"], None
                if req is None:
                    continue
                try:
                    data = await loop.run_in_executor(None, viewer.frame_bytes, *req)
                except Exception as e:  # noqa: BLE001 - any failure is said to the page; the server goes on
                    if not ws.closed:
                        await ws.send_str(json.dumps({"type": "error", "id": req[0], "message": str(e)}))
                    continue
                if not ws.closed:
                    await ws.send_bytes(data)

        task = asyncio.ensure_future(worker())
        try:
            async for msg in ws:
                if msg.type == WSMsgType.TEXT:
                    try:
                        pending["req"] = parse_pose_message(msg.data)  # the newest replaces an older pending one
                        wake.set()
                    except BadMessage as e:
                        await ws.send_str(json.dumps({"type": "error", "message": str(e)}))
                    except Exception as e:  # noqa: BLE001 - never drop the page for a message
                        await ws.send_str(json.dumps({"type": "error", "message": f"bad message: {e}"}))
                elif msg.type == WSMsgType.BINARY:
                    await ws.send_str(json.dumps({"type": "error", "message": "binary messages are not accepted"}))
                elif msg.type == WSMsgType.ERROR:
                    break
        finally:
            task.cancel()
        return ws

    async def close_sockets(app):  # on Ctrl-C: the open pages are told the server has gone, not waited for
        for ws in list(app["sockets"]):
            await ws.close(code=1001, message=b"server stopped")

    async def plan_mesh(request):
        bone = request.match_info["bone"]
        if viewer.plan is None or bone not in viewer.plan["bones"]:
            raise web.HTTPNotFound(text=f"no plan of the {bone} (impinge view --plan DIR)")
        return web.Response(body=viewer.plan_bytes(bone), content_type="application/octet-stream")

    async def motion(request):
        try:
            return web.json_response(viewer.motion_of(request.query.get("file")))
        except impinge.Error as e:
            raise web.HTTPNotFound(text=str(e))

    async def motions(request):
        return web.json_response({"files": viewer.motion_files()})

    def job_route(name):
        async def handler(request):
            motion = request.query.get("file")
            if name == "motion":
                try:
                    viewer.motion_of(motion)
                except impinge.Error as e:
                    raise web.HTTPNotFound(text=str(e))
            return web.json_response(viewer.job(name, motion), dumps=lambda x: json.dumps(x, allow_nan=False))
        return handler

    app = web.Application(middlewares=[require_token], client_max_size=64 * 1024)
    app["sockets"] = weakref.WeakSet()
    app.on_shutdown.append(close_sockets)
    app.add_routes([web.get("/", page), web.get("/viewer.js", script), web.get("/api/scene", scene),
                    web.get("/api/mesh/{bone}", mesh), web.get("/ws", socket), web.get("/api/motion", motion),
                    web.get("/api/motion/least", job_route("motion")), web.get("/api/rom", job_route("rom")),
                    web.get("/api/morphology", job_route("morphology")),
                    web.get("/api/plan/mesh/{bone}", plan_mesh), web.get("/api/motions", motions)])
    return app


async def serve(viewer, host, port, open_browser, token, ready=None):
    """Serve until Ctrl-C, SIGTERM or SIGHUP (the open pages' sockets are closed first). Prints the page's address;
    opens it unless open_browser is False. `ready`: an optional callback given the address once listening."""
    import signal
    from aiohttp import web
    stop = asyncio.Event()
    loop = asyncio.get_running_loop()
    for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP):
        loop.add_signal_handler(sig, stop.set)
    runner = web.AppRunner(make_app(viewer, token), handle_signals=False)
    await runner.setup()
    site = web.TCPSite(runner, host, port)
    await site.start()
    bound = site._server.sockets[0].getsockname()[1]
    shown = f"[{host}]" if ":" in host else host
    url = f"http://{shown}:{bound}/?token={token}"
    print(f"impinge view: {url}", flush=True)
    if ready:
        ready(url)
    if open_browser:  # through a private file (0600), so the token is not on a command line other users can read
        fd, redirect = tempfile.mkstemp(prefix="impinge-view-", suffix=".html")
        with os.fdopen(fd, "w") as f:
            f.write(f'<!doctype html><meta http-equiv="refresh" content="0; url={url}"><a href="{url}">{url}</a>')
        webbrowser.open("file://" + redirect)
    try:
        await stop.wait()
    finally:
        await runner.cleanup()
    print("impinge view: stopped", file=sys.stderr)


def main(argv=None):
    """`python3 -m impinge.view --view-json JSON -- CLI_OPTIONS...`, as `impinge view` runs it: JSON holds host,
    port, open_browser (the option table's view rows, checked by the CLI); the options after `--` are `impinge
    distance`'s, parsed by the library (Joint._from_cli). Returns the exit status."""
    argv = list(sys.argv[1:] if argv is None else argv)
    if len(argv) < 2 or argv[0] != "--view-json":
        print("usage: python3 -m impinge.view --view-json JSON [-- impinge distance options]", file=sys.stderr)
        return 2
    view = json.loads(argv[1])
    rest = argv[3:] if len(argv) > 2 and argv[2] == "--" else argv[2:]
    if not os.path.exists(os.path.join(STATIC, "viewer.js")):
        print("impinge view: the page was not built (no impinge/view/static/viewer.js): run tools/install-deps "
              "(npm ci in web/) and rebuild", file=sys.stderr)
        return 2
    try:
        joint, command = impinge.Joint._from_cli(rest)
        viewer = Viewer(joint, motion=command["motion"], plan=view.get("plan") or None,
                        motion_folder=view.get("motion_folder") or None)
    except impinge.Error as e:
        print(f"impinge: error: {e}", file=sys.stderr)
        return 2
    for w in joint.warnings:
        print(f"impinge: warning: {w}", file=sys.stderr)
    if view.get("export"):
        try:
            kept, asked, size = export_html(viewer, view["export"], view.get("export_poses", "auto"),
                                            float(view.get("export_max_mb", 25)))
        except (impinge.Error, OSError) as e:
            print(f"impinge: error: {e}", file=sys.stderr)
            return 1
        print(f"impinge view: wrote {view['export']} ({kept} poses" + (f" of {asked}" if kept < asked else "") +
              f", {size / 1e6:.1f} MB)", flush=True)
        return 0
    token = view.get("token") or secrets.token_urlsafe(24)
    try:
        asyncio.run(serve(viewer, view["host"], int(view["port"]), bool(view["open_browser"]), token))
    except KeyboardInterrupt:
        print("impinge view: stopped", file=sys.stderr)
    except OSError as e:
        print(f"impinge: error: cannot listen on {view['host']}:{view['port']}: {e.strerror or e}", file=sys.stderr)
        return 2
    return 0
