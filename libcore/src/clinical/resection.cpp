#include "impinge/clinical/resection.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <optional>
#include <unordered_map>

#include "impinge/casters/exact_reference.hpp"
#include "impinge/casters/signed_distance.hpp"
#include "impinge/core/error.hpp"
#include "impinge/core/interrupt.hpp"

namespace impinge {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

/// Area-weighted outward vertex normals (unit; zero where a vertex has no face).
Vertices vertex_normals(const Vertices& V, const Faces& F) {
  Vertices N = Vertices::Zero(V.rows(), 3);
  double volume6 = 0;
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    const Eigen::Vector3d a = V.row(F(f, 0)), b = V.row(F(f, 1)), c = V.row(F(f, 2));
    const Eigen::Vector3d n = (b - a).cross(c - a);
    volume6 += a.dot(b.cross(c));
    for (int k = 0; k < 3; ++k) N.row(F(f, k)) += n.transpose();
  }
  const double sign = volume6 >= 0 ? 1.0 : -1.0;  // a mesh wound inwards has its normals turned round
  for (Eigen::Index i = 0; i < N.rows(); ++i) {
    const double len = N.row(i).norm();
    if (len > 0) N.row(i) *= sign / len;
  }
  return N;
}

/// A uniform grid over vertices (cell = `cell` mm) for the burr's neighbourhoods.
struct VertexGrid {
  double cell = 1;
  std::unordered_map<std::int64_t, std::vector<std::int64_t>> cells;
  static std::int64_t key(std::int64_t x, std::int64_t y, std::int64_t z) {
    return (x & 0x1FFFFF) | ((y & 0x1FFFFF) << 21) | ((z & 0x1FFFFF) << 42);
  }
  std::int64_t coord(double v) const { return static_cast<std::int64_t>(std::floor(v / cell)); }
  VertexGrid(const Vertices& V, const std::vector<std::uint8_t>& use, double cell_mm) : cell(cell_mm) {
    for (Eigen::Index i = 0; i < V.rows(); ++i)
      if (use[static_cast<std::size_t>(i)]) cells[key(coord(V(i, 0)), coord(V(i, 1)), coord(V(i, 2)))].push_back(i);
  }
  template <class F>
  void near(const Eigen::Vector3d& p, F&& f) const {
    const std::int64_t x = coord(p.x()), y = coord(p.y()), z = coord(p.z());
    for (std::int64_t dx = -1; dx <= 1; ++dx)
      for (std::int64_t dy = -1; dy <= 1; ++dy)
        for (std::int64_t dz = -1; dz <= 1; ++dz) {
          const auto it = cells.find(key(x + dx, y + dy, z + dz));
          if (it != cells.end())
            for (std::int64_t i : it->second) f(i);
        }
  }
};

/// One bone's working state during a plan.
struct BoneState {
  bool allowed = false;
  const Vertices* V = nullptr;  // joint frame, unposed (relative to the COR)
  const Faces* F = nullptr;
  const Eigen::VectorXd* area = nullptr;  // per vertex, mm^2 (the joint's: JointBody::vertex_area)
  Vertices normals;
  std::vector<std::uint8_t> protect;
  std::vector<double> required, depth;  // the contacts' depth (before the burr), the planned depth
  Vertices resected;
  std::vector<double> limit;       // per vertex: the deepest it may go (the safety depth, less where the bone is thin)
  std::vector<std::uint8_t> thin;  // 1: held by the bone's thickness, not the safety depth
  std::unique_ptr<VertexGrid> grid;
  std::vector<std::uint8_t> thickness_known;
  std::unique_ptr<SignedDistanceQuery> query;
  std::unique_ptr<ExactReference> original;
  bool changed = true;

  bool can_take(std::int64_t i) const {
    const auto k = static_cast<std::size_t>(i);
    return allowed && !protect[k] && depth[k] < limit[k] - 1e-9;
  }
  /// The bone's thickness under vertex i: the first hit of the ray from it along -n_i (from 0.05 mm inside, past
  /// its own faces) with the input's surface, mm; infinity when the ray meets nothing.
  double thickness(std::size_t i) const {
    const Eigen::Vector3d n = normals.row(static_cast<Eigen::Index>(i)).transpose();
    const Eigen::Vector3d from = V->row(static_cast<Eigen::Index>(i)).transpose() - 0.05 * n;
    const std::optional<double> t = original->first_hit(from, -n);
    return t ? *t + 0.05 : kInf;
  }
  void rebuild_query(const std::string& name) {
    if (!changed && query) return;
    TriangleMesh m;
    m.V = resected;
    m.F = *F;
    m.source = name + " (resected, joint frame)";
    query = std::make_unique<SignedDistanceQuery>(m);
    changed = false;
  }
  /// The burr's widening of `required` (file comment, step 3), held at each vertex's limit (the safety depth, half
  /// the bone's thickness; zero on the protected surface).
  void apply_burr(double b) {
    const std::size_t n = required.size();
    std::vector<double> d(n, 0.0);
    for (std::size_t i = 0; i < n; ++i) d[i] = required[i];
    if (b > 0 && grid) {
      const double b2 = b * b;
      for (std::size_t j = 0; j < n; ++j) {
        if (required[j] <= 0) continue;
        const Eigen::Vector3d xj = V->row(static_cast<Eigen::Index>(j)).transpose();
        const double rj = required[j];
        grid->near(xj, [&](std::int64_t i) {
          const double s2 = (V->row(i).transpose() - xj).squaredNorm();
          if (s2 >= b2) return;
          const double v = rj - (b - std::sqrt(b2 - s2));
          if (v > d[static_cast<std::size_t>(i)]) d[static_cast<std::size_t>(i)] = v;
        });
      }
    }
    for (std::size_t i = 0; i < n; ++i) {
      double v = protect[i] ? 0.0 : std::min(std::max(d[i], 0.0), limit[i]);
      if (v > 0 && !thickness_known[i]) {
        // At most half the bone's thickness here: a thin rim or trochanter is not cut through.
        thickness_known[i] = 1;
        const double half = 0.5 * thickness(i);
        if (half < limit[i]) limit[i] = half, thin[i] = 1;
        v = std::min(v, limit[i]);
      }
      if (v != depth[i]) changed = true;
      depth[i] = v;
    }
    for (std::size_t i = 0; i < n; ++i)
      resected.row(static_cast<Eigen::Index>(i)) =
          V->row(static_cast<Eigen::Index>(i)) - depth[i] * normals.row(static_cast<Eigen::Index>(i));
  }
};

/// One followed contact: a vertex of a bone at a pose.
struct Contact {
  std::int32_t pose = 0;
  bool ball = true;
  std::int64_t vertex = 0;
  std::int64_t seed = -1;  // the other bone's last closest triangle
  double deficit = 0;      // c - signed distance, this round
  std::int64_t triangle = -1;
};

enum class Blocked : std::uint8_t { no = 0, head = 1, lunate = 2, depth = 3, bone = 4 };

/// Bone b's state (0 femur, 1 pelvis) at the start: no depth, limits `cap` mm less depths removed before.
void prepare_bone(BoneState& s, int b, const Joint& joint, const ResectionOptions& o, double cap) {
  const JointBody& body = b == 0 ? joint.ball() : joint.socket();
  s.allowed = b == 0 ? o.bones != ResectBones::pelvis : o.bones != ResectBones::femur;
  s.V = &body.relative;
  s.F = &body.mesh.F;
  s.area = &body.vertex_area;
  s.normals = vertex_normals(body.relative, body.mesh.F);
  const auto n = static_cast<std::size_t>(body.relative.rows());
  s.protect.assign(n, 0);
  s.required.assign(n, 0.0);
  s.depth.assign(n, 0.0);
  s.resected = body.relative;
  s.limit.assign(n, cap);
  const std::vector<double>& removed = b == 0 ? o.femur_removed_mm : o.pelvis_removed_mm;
  require(removed.empty() || removed.size() == n, "resection: " + std::to_string(removed.size()) +
                                                      " depths removed before for " + std::to_string(n) +
                                                      " vertices of " + body.mesh.source);
  for (std::size_t i = 0; i < removed.size(); ++i) s.limit[i] = std::max(0.0, cap - removed[i]);
  s.thin.assign(n, 0);
  s.thickness_known.assign(n, 0);
  if (s.allowed) {
    TriangleMesh m;
    m.V = body.relative;
    m.F = body.mesh.F;
    m.source = body.mesh.source;
    s.original = std::make_unique<ExactReference>(m);
  }
}

/// Marks the protected surfaces (file comment, step 3) and holds them at depth 0.
void protect_surfaces(const HipJoint& hip, BoneState (&bone)[2]) {
  const auto& art = hip.articular();
  const Eigen::Vector3d hc = hip.head_centre_joint();
  const double rh = hip.head_radius_mm();
  // The labrum line: the rim plane with the femur at neutral; the head's surface inside it is protected, the
  // head-neck junction outside it (where an osteochondroplasty restores the offset) is not.
  const auto& acetabulum = hip.acetabulum();
  const FemurPose neutral = hip.femur_pose({});
  for (Eigen::Index i = 0; i < bone[0].V->rows(); ++i) {
    const auto k = static_cast<std::size_t>(i);
    if (art && acetabulum) {
      const Eigen::Vector3d w = hip.to_working(neutral.R * bone[0].V->row(i).transpose() + neutral.t);
      bone[0].protect[k] = art->femur[k] && (w - acetabulum->rim_centre).dot(acetabulum->opening) < 0;
    } else if (art)
      bone[0].protect[k] = art->femur[k];
    else
      bone[0].protect[k] = std::abs((bone[0].V->row(i).transpose() - hc).norm() - rh) <= 0.5;
  }
  for (Eigen::Index i = 0; i < bone[1].V->rows(); ++i) {
    const auto k = static_cast<std::size_t>(i);
    if (art) {
      bone[1].protect[k] = art->pelvis[k];
    } else {
      const Eigen::Vector3d u = bone[1].V->row(i).transpose();
      bone[1].protect[k] = u.norm() <= rh + 3 && bone[1].normals.row(i).dot(-u.normalized()) > 0.7;
    }
  }
  for (BoneState& s : bone)
    for (std::size_t i = 0; i < s.limit.size(); ++i)
      if (s.protect[i]) s.limit[i] = 0;
}

/// One target pose, flattened: its target, its index there, and its femur pose (set by find_contacts).
struct PoseRef {
  int target = 0;
  std::size_t index = 0;
  FemurPose pose;
};

/// Step 1, the contacts at every pose (file comment); sets each pose's FemurPose. Parallel over the poses.
std::vector<std::vector<Contact>> find_contacts(const HipJoint& hip, const std::vector<ResectionTarget>& targets,
                                                const RomBaseline& baseline, const ResectionOptions& o,
                                                const BoneState (&bone)[2], std::vector<PoseRef>& poses) {
  std::vector<std::vector<Contact>> per_pose(poses.size());
  std::string pose_error;
#pragma omp parallel
  {
    PoseResult res;
#pragma omp for schedule(dynamic, 1)
    for (std::size_t p = 0; p < poses.size(); ++p) {
      try {
        const ResectionTarget& tg = targets[static_cast<std::size_t>(poses[p].target)];
        const FemurPose P = hip.femur_pose(tg.poses[poses[p].index]);
        poses[p].pose = P;
        hip.joint().detect(P.R, P.t, res);
        for (int b = 0; b < 2; ++b) {
          const ScanGaps& g = b == 0 ? res.ball_gaps : res.socket_gaps;
          const std::vector<std::uint8_t>& skip = b == 0 ? baseline.skip_ball : baseline.skip_socket;
          for (std::size_t i = 0; i < g.gap_mm.size(); ++i) {
            if (!skip.empty() && skip[i]) continue;
            const float d = g.distance_mm.empty() ? std::nanf("") : g.distance_mm[i];
            const bool near = std::isfinite(d) ? d < o.clearance_mm + o.candidate_margin_mm : (g.gap_mm[i] < 0);
            if (!near) continue;
            if (b == 1) {  // a pelvis vertex meeting the head's joint surface (issue 81: never the neck)
              const Eigen::Vector3d u = bone[1].V->row(static_cast<Eigen::Index>(i)).transpose();
              if (baseline.meets_head(P.R.transpose() * (u - P.t))) continue;
            }
            per_pose[p].push_back({static_cast<std::int32_t>(p), b == 0, static_cast<std::int64_t>(i), -1, 0, -1});
          }
        }
      } catch (const std::exception& e) {
#pragma omp critical(resection_error)
        if (pose_error.empty()) pose_error = e.what();
      }
    }
  }
  require(pose_error.empty(), "resection: " + pose_error);
  return per_pose;
}

/// Step 3, who takes each deficit into `need` (mm per vertex), or what blocks its pose; returns the largest taken.
double share_deficits(const std::vector<Contact>& contacts, const BoneState (&bone)[2], double tolerance_mm,
                      std::vector<double> (&need)[2], std::vector<Blocked>& pose_blocked) {
  double residual = 0;
  for (const Contact& ct : contacts) {
    if (ct.deficit <= tolerance_mm) continue;
    const int a = ct.ball ? 0 : 1, b = 1 - a;
    const bool own_can = bone[a].can_take(ct.vertex);
    std::int64_t tri[3] = {-1, -1, -1};
    bool other_can = false;
    if (bone[b].allowed && ct.triangle >= 0)
      for (int m = 0; m < 3; ++m) {
        tri[m] = (*bone[b].F)(ct.triangle, m);
        other_can = other_can || bone[b].can_take(tri[m]);
      }
    if (!own_can && !other_can) {
      Blocked why = Blocked::bone;
      const bool own_protected = bone[a].allowed && bone[a].protect[static_cast<std::size_t>(ct.vertex)];
      bool other_protected = bone[b].allowed;
      for (int m = 0; m < 3 && tri[m] >= 0; ++m)
        other_protected = other_protected && bone[b].protect[static_cast<std::size_t>(tri[m])];
      if (own_protected || other_protected)
        why = (own_protected ? a : b) == 0 ? Blocked::head : Blocked::lunate;
      else if (bone[a].allowed || bone[b].allowed)
        why = Blocked::depth;
      Blocked& pb = pose_blocked[static_cast<std::size_t>(ct.pose)];
      if (pb == Blocked::no) pb = why;
      continue;
    }
    residual = std::max(residual, ct.deficit);
    const double share = own_can && other_can ? 0.5 * ct.deficit : ct.deficit;
    if (own_can)
      need[a][static_cast<std::size_t>(ct.vertex)] = std::max(need[a][static_cast<std::size_t>(ct.vertex)], share);
    if (other_can)
      for (int m = 0; m < 3; ++m)
        if (bone[b].can_take(tri[m]))
          need[b][static_cast<std::size_t>(tri[m])] = std::max(need[b][static_cast<std::size_t>(tri[m])], share);
  }
  return residual;
}

/// One round, steps 2-4 on `contacts` from the input bones (file comment); marks the poses it cannot clear.
void plan_round(ResectionPlan& plan, const ResectionOptions& o, BoneState (&bone)[2], const std::vector<PoseRef>& poses,
                std::vector<Contact>& contacts, std::vector<Blocked>& pose_blocked) {
  for (BoneState& s : bone) {
    std::fill(s.required.begin(), s.required.end(), 0.0);
    std::fill(s.depth.begin(), s.depth.end(), 0.0);
    s.resected = *s.V;
    s.changed = true;
  }
  std::fill(pose_blocked.begin(), pose_blocked.end(), Blocked::no);
  plan.residual_mm = 0;
  for (int it = 0; it < o.max_iterations; ++it) {
    interruption_point();  // a front end's stop (Ctrl-C in Python), between the iterations
    plan.iterations = it + 1;
    bone[0].rebuild_query("femur");
    bone[1].rebuild_query("pelvis");
    // 2. Each contact's signed distance to the other (resected) bone.
#pragma omp parallel for schedule(dynamic, 64)
    for (std::size_t k = 0; k < contacts.size(); ++k) {
      Contact& ct = contacts[k];
      const FemurPose& P = poses[static_cast<std::size_t>(ct.pose)].pose;
      const BoneState& own = bone[ct.ball ? 0 : 1];
      const BoneState& other = bone[ct.ball ? 1 : 0];
      const Eigen::Vector3d x = own.resected.row(static_cast<Eigen::Index>(ct.vertex)).transpose();
      const Eigen::Vector3d q = ct.ball ? Eigen::Vector3d(P.R * x + P.t) : Eigen::Vector3d(P.R.transpose() * (x - P.t));
      ClosestSurfacePoint cp;
      if (other.query->signed_distance(q, kInf, 0, cp, ct.seed)) {
        ct.seed = cp.triangle;
        ct.triangle = cp.triangle;
        ct.deficit = o.clearance_mm + o.tolerance_mm - cp.signed_mm();  // met at c (header, step 4)
      } else {
        ct.deficit = 0;
      }
    }
    std::vector<double> need[2] = {std::vector<double>(bone[0].depth.size(), 0.0),
                                   std::vector<double>(bone[1].depth.size(), 0.0)};
    plan.residual_mm = share_deficits(contacts, bone, o.tolerance_mm, need, pose_blocked);
    if (plan.residual_mm <= o.tolerance_mm || it + 1 == o.max_iterations) break;
    for (int b = 0; b < 2; ++b) {  // the burr (file comment, step 3) on the depths asked so far
      if (!bone[b].allowed) continue;
      for (std::size_t i = 0; i < need[b].size(); ++i) bone[b].required[i] += need[b][i];
      bone[b].apply_burr(o.burr_radius_mm);
    }
  }
  // Poses still asking for more after the last round are not cleared either.
  if (plan.residual_mm > o.tolerance_mm)
    for (const Contact& ct : contacts)
      if (ct.deficit > o.tolerance_mm && pose_blocked[static_cast<std::size_t>(ct.pose)] == Blocked::no)
        pose_blocked[static_cast<std::size_t>(ct.pose)] = Blocked::depth;
}

/// Drops each target's poses from its first blocked pose on (noting why); returns whether any was dropped.
bool drop_blocked_poses(ResectionPlan& plan, const std::vector<ResectionTarget>& targets,
                        const std::vector<PoseRef>& poses, const std::vector<Blocked>& pose_blocked,
                        std::vector<std::uint8_t>& pose_kept) {
  bool dropped = false;
  for (std::size_t p = 0; p < poses.size(); ++p) {
    if (!pose_kept[p] || pose_blocked[p] == Blocked::no) continue;
    const int t = poses[p].target;
    ResectionTargetResult& r = plan.targets[static_cast<std::size_t>(t)];
    r.reachable = false;
    const char* what = pose_blocked[p] == Blocked::head     ? "the femoral head's articular surface"
                       : pose_blocked[p] == Blocked::lunate ? "the acetabulum's lunate surface"
                       : pose_blocked[p] == Blocked::depth  ? "more than the safety depth or the bone's thickness"
                                                            : "a bone the plan may not resect (--resect)";
    const double theta = targets[static_cast<std::size_t>(t)].theta_deg[poses[p].index];
    r.note = "the bones meet at " +
             (std::isnan(theta) ? std::string("the way to the motion's start")
                                : std::to_string(theta).substr(0, 6) + " deg") +
             " where clearing them would take " + what;
    for (std::size_t q = p; q < poses.size() && poses[q].target == t; ++q) pose_kept[q] = 0;
    dropped = true;
  }
  return dropped;
}

/// One bone's result from its final state: depths, protection, resected mesh and sums (cap: the safety depth, mm).
void bone_result(BoneResection& out, const BoneState& s, double cap) {
  out.allowed = s.allowed;
  out.depth_mm = s.depth;
  out.protected_vertex = s.protect;
  out.resected = s.resected;
  out.normals = s.normals;
  summarize_resection(out, *s.V, *s.F, *s.area, cap);  // a further pass's sums are run_plan's, over every pass
  for (std::size_t i = 0; i < s.depth.size(); ++i)
    if (s.thin[i] && s.depth[i] > 0) ++out.thin_vertices;
}

}  // namespace

const char* to_string(ResectBones bones) {
  return enum_name(kResectBonesNames, bones);
}

ResectBones parse_resect_bones(const std::string& text, const std::string& context) {
  return parse_enum(kResectBonesNames, text, context);
}

double enclosed_volume(const Vertices& V, const Faces& F) {
  double v6 = 0;
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    const Eigen::Vector3d a = V.row(F(f, 0)), b = V.row(F(f, 1)), c = V.row(F(f, 2));
    v6 += a.dot(b.cross(c));
  }
  return std::abs(v6) / 6;
}

double neck_diameter_mm(const Vertices& femur, const Faces& faces, const Eigen::Vector3d& head_centre,
                        double head_radius_mm, const Eigen::Vector3d& neck_axis) {
  const Eigen::Vector3d a = neck_axis.normalized();
  const Vertices normals = vertex_normals(femur, faces);
  const int slabs = static_cast<int>(std::ceil(2.5 * head_radius_mm)) + 2;
  std::vector<std::vector<double>> radius(static_cast<std::size_t>(slabs));
  std::vector<unsigned> sectors(static_cast<std::size_t>(slabs), 0u);
  // Any unit vector normal to the axis, for the azimuth.
  const Eigen::Vector3d e1 =
      (std::abs(a.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY()).cross(a).normalized();
  const Eigen::Vector3d e2 = a.cross(e1);
  for (Eigen::Index i = 0; i < femur.rows(); ++i) {
    const Eigen::Vector3d p = femur.row(i).transpose() - head_centre;
    if (p.norm() <= head_radius_mm) continue;
    const double along = -p.dot(a);  // outwards from the head centre, towards the shaft
    if (along < 0) continue;
    if (std::abs(normals.row(i).dot(a)) > 0.5) continue;  // a cut end or a cap, not the neck's wall
    const Eigen::Vector3d radial = p + along * a;
    const double az = std::atan2(radial.dot(e2), radial.dot(e1));
    const int sector = std::clamp(static_cast<int>((az + M_PI) / (2 * M_PI) * 12), 0, 11);
    // slab k covers [k - 1, k + 1) mm along the axis
    for (int k = static_cast<int>(std::floor(along)); k <= static_cast<int>(std::floor(along)) + 1; ++k)
      if (k >= 0 && k < slabs) {
        radius[static_cast<std::size_t>(k)].push_back(radial.norm());
        sectors[static_cast<std::size_t>(k)] |= 1u << sector;
      }
  }
  double best = std::numeric_limits<double>::quiet_NaN();
  for (std::size_t k = 0; k < radius.size(); ++k) {
    std::vector<double>& r = radius[k];
    if (r.size() < 12 || sectors[k] != 0xFFFu || static_cast<double>(k) <= 0.5 * head_radius_mm) continue;
    std::nth_element(r.begin(), r.begin() + static_cast<std::ptrdiff_t>(r.size() / 2), r.end());
    const double d = 2 * r[r.size() / 2];
    if (!(d >= best)) best = d;
  }
  return best;
}

void summarize_resection(BoneResection& out, const Vertices& original, const Faces& F, const Eigen::VectorXd& vertex_area,
                         double cap_mm) {
  const auto n = static_cast<std::size_t>(original.rows());
  require(out.depth_mm.size() == n && static_cast<std::size_t>(out.resected.rows()) == n &&
              static_cast<std::size_t>(vertex_area.size()) == n,
          "resection summary: " + std::to_string(out.depth_mm.size()) + " depths, " +
              std::to_string(out.resected.rows()) + " resected vertices and " + std::to_string(vertex_area.size()) +
              " areas for " + std::to_string(n) + " vertices");
  out.volume_mm3 = enclosed_volume(original, F) - enclosed_volume(out.resected, F);
  out.area_mm2 = out.deepest_cut_mm = out.mean_depth_mm = 0;
  out.vertices = out.capped_vertices = 0;
  double weighted = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double d = out.depth_mm[i];
    if (d >= cap_mm - 1e-9 && d > 0) ++out.capped_vertices;
    if (d <= kResectedDepthMm) continue;
    ++out.vertices;
    out.area_mm2 += vertex_area[static_cast<Eigen::Index>(i)];
    weighted += vertex_area[static_cast<Eigen::Index>(i)] * d;
    out.deepest_cut_mm = std::max(out.deepest_cut_mm, d);
  }
  out.mean_depth_mm = out.area_mm2 > 0 ? weighted / out.area_mm2 : 0;
}

ResectionPlan plan_resection(const HipJoint& hip, const std::vector<ResectionTarget>& targets,
                             const RomBaseline& baseline, const ResectionOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  const ResectionOptions& o = options;
  check_in_range("ResectionOptions::clearance_mm", o.clearance_mm, ResectionOptions::kClearanceRange, "mm");
  require(o.safety_depth_mm > 0, "resection: safety depth " + std::to_string(o.safety_depth_mm) + " mm; valid: > 0");
  check_in_range("ResectionOptions::burr_radius_mm", o.burr_radius_mm, ResectionOptions::kBurrRadiusRange, "mm");
  require(o.tolerance_mm > 0 && o.max_iterations >= 1, "resection: tolerance must be > 0 and iterations >= 1");
  const Joint& joint = hip.joint();
  require(joint.options().distances,
          "resection: the plan needs the Euclidean distances (JointOptions::distances, --distances on)");
  require(joint.options().reach_mm() >= o.clearance_mm + o.candidate_margin_mm - 1e-9,
          "resection: the distances' reach " + std::to_string(joint.options().reach_mm()) +
              " mm is below the clearance + margin (" + std::to_string(o.clearance_mm + o.candidate_margin_mm) +
              " mm); give --distance-reach");
  ResectionPlan plan;
  plan.options = o;
  const double cap = o.safety_depth_mm;

  BoneState bone[2];  // 0 femur, 1 pelvis
  for (int b = 0; b < 2; ++b) prepare_bone(bone[b], b, joint, o, cap);
  protect_surfaces(hip, bone);
  for (BoneState& s : bone)
    if (s.allowed) {
      std::vector<std::uint8_t> use(s.protect.size());
      for (std::size_t i = 0; i < use.size(); ++i) use[i] = !s.protect[i];
      s.grid = std::make_unique<VertexGrid>(*s.V, use, std::max(o.burr_radius_mm, 0.5));
    }

  // The poses, flattened, and their targets.
  std::vector<PoseRef> poses;
  for (std::size_t t = 0; t < targets.size(); ++t) {
    require(targets[t].theta_deg.size() == targets[t].poses.size(),
            "resection: target " + targets[t].name + ": one angle per pose needed");
    for (std::size_t k = 0; k < targets[t].poses.size(); ++k) poses.push_back({static_cast<int>(t), k, {}});
  }
  plan.poses = static_cast<std::int64_t>(poses.size());

  const std::vector<std::vector<Contact>> per_pose = find_contacts(hip, targets, baseline, o, bone, poses);
  std::vector<std::uint8_t> pose_kept(poses.size(), 1);
  std::vector<Blocked> pose_blocked(poses.size(), Blocked::no);
  plan.targets.resize(targets.size());
  for (std::size_t t = 0; t < targets.size(); ++t) {
    plan.targets[t].name = targets[t].name;
    plan.targets[t].angle_deg = targets[t].angle_deg;
    plan.targets[t].poses = static_cast<std::int64_t>(targets[t].poses.size());
  }

  for (int round = 0; round < 8; ++round) {
    plan.rounds = round + 1;
    std::vector<Contact> contacts;  // the kept poses'
    for (std::size_t p = 0; p < poses.size(); ++p)
      if (pose_kept[p]) contacts.insert(contacts.end(), per_pose[p].begin(), per_pose[p].end());
    plan.contacts = static_cast<std::int64_t>(contacts.size());
    plan_round(plan, o, bone, poses, contacts, pose_blocked);
    // Drop each target's poses from its first blocked pose on, and plan again without them.
    if (!drop_blocked_poses(plan, targets, poses, pose_blocked, pose_kept)) break;
  }
  for (std::size_t p = 0; p < poses.size(); ++p) {
    ResectionTargetResult& r = plan.targets[static_cast<std::size_t>(poses[p].target)];
    if (!pose_kept[p]) continue;
    ++r.poses_cleared;
    const double theta = targets[static_cast<std::size_t>(poses[p].target)].theta_deg[poses[p].index];
    if (!std::isnan(theta) && !std::isnan(r.angle_deg)) r.reachable_deg = theta;
  }
  for (std::size_t t = 0; t < targets.size(); ++t) {
    ResectionTargetResult& r = plan.targets[t];
    if (r.reachable && !std::isnan(r.angle_deg)) r.reachable_deg = r.angle_deg;
  }
  bone_result(plan.femur, bone[0], cap);
  bone_result(plan.pelvis, bone[1], cap);
  plan.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  return plan;
}

}  // namespace impinge
