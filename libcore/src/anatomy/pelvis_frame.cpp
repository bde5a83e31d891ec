#include "impinge/anatomy/pelvis_frame.hpp"

#include <cmath>
#include <limits>

#include "impinge/anatomy/convex_hull.hpp"
#include "impinge/core/error.hpp"

namespace impinge {

Landmarks PelvisLandmarks::as_map() const {
  return {{"asis_right", asis_right},
          {"asis_left", asis_left},
          {"psis_right", psis_right},
          {"psis_left", psis_left},
          {"pubic_tubercle_right", pubic_tubercle_right},
          {"pubic_tubercle_left", pubic_tubercle_left}};
}

namespace {

double plane_distance(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                      const Eigen::Vector3d& p) {
  const Eigen::Vector3d n = (b - a).cross(c - a);
  const double nn = n.norm();
  return nn > 0 ? std::abs(n.dot(p - a)) / nn : 0.0;
}

bool all_given(const Landmarks& given) {
  for (const char* name : kPelvisLandmarkNames)
    if (!given.count(name)) return false;
  return true;
}

// 1. The anterior pelvic plane's hull face: the hull triangle of V with the largest area x longest edge; a1, a2: the
//    ends of that edge (the two ASIS), pub: its third corner (the pubis).
void find_app_face(const Vertices& V, const ConvexHull& hull, const std::string& ctx, Eigen::Vector3d& a1,
                   Eigen::Vector3d& a2, Eigen::Vector3d& pub) {
  double best = -1;
  Eigen::Index best_f = -1;
  int best_edge = 0;
  for (Eigen::Index f = 0; f < hull.triangles.rows(); ++f) {
    const Eigen::Vector3d p[3] = {V.row(hull.triangles(f, 0)).transpose(), V.row(hull.triangles(f, 1)).transpose(),
                                  V.row(hull.triangles(f, 2)).transpose()};
    const double area = 0.5 * (p[1] - p[0]).cross(p[2] - p[0]).norm();
    int e = 0;
    double longest = 0;
    for (int k = 0; k < 3; ++k) {
      const double len = (p[(k + 1) % 3] - p[k]).norm();
      if (len > longest) longest = len, e = k;
    }
    if (area * longest > best) best = area * longest, best_f = f, best_edge = e;
  }
  require(best_f >= 0, ctx + ": empty convex hull");
  a1 = V.row(hull.triangles(best_f, best_edge)).transpose();
  a2 = V.row(hull.triangles(best_f, (best_edge + 1) % 3)).transpose();
  pub = V.row(hull.triangles(best_f, (best_edge + 2) % 3)).transpose();
}

// 3. Pubic tubercles and 4. PSIS, per side of the midline (mid: the ASIS' midpoint; X, Y, Z: the APP's axes), from
//    the hull vertices, into `found`: below the hip centre the one least far behind the ASIS plane as seen from mid
//    (the largest angle atan2(d.X, -d.Y), d from mid), above it the most posterior (the least d.X).
void find_tubercles_and_psis(const Vertices& V, const ConvexHull& hull, const Eigen::Vector3d& hip_centre,
                             const Eigen::Vector3d& mid, const Eigen::Vector3d& pub, const Eigen::Vector3d& X,
                             const Eigen::Vector3d& Y, const Eigen::Vector3d& Z, const std::string& ctx,
                             Landmarks& found) {
  double best_pt[2] = {-std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()};
  double best_ps[2] = {std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
  Eigen::Vector3d pt[2] = {pub, pub}, ps[2] = {mid, mid};
  bool have_ps[2] = {false, false};
  for (Eigen::Index i : hull.vertices) {
    const Eigen::Vector3d v = V.row(i).transpose();
    const Eigen::Vector3d d = v - mid;
    const int s = d.dot(Z) > 0 ? 0 : 1;  // 0: right of the midline, 1: left
    const double h = (v - hip_centre).dot(Y);
    if (h < 0) {
      const double psi = std::atan2(d.dot(X), -d.dot(Y));  // angle behind the ASIS plane, <= 0
      if (psi > best_pt[s]) best_pt[s] = psi, pt[s] = v;
    } else if (d.dot(X) < best_ps[s]) {
      best_ps[s] = d.dot(X), ps[s] = v, have_ps[s] = true;
    }
  }
  require(have_ps[0] && have_ps[1], ctx + ": no posterior iliac crest above the hip centre on one side");
  found["pubic_tubercle_right"] = pt[0];
  found["pubic_tubercle_left"] = pt[1];
  found["psis_right"] = ps[0];
  found["psis_left"] = ps[1];
}

}  // namespace

PelvisLandmarks find_pelvis_landmarks(const TriangleMesh& pelvis, const Eigen::Vector3d& hip_centre, Side side,
                                      const Landmarks& given) {
  require(hip_centre.allFinite(), pelvis.source + ": hip centre is not finite");
  PelvisLandmarks L;
  Landmarks found;
  if (!all_given(given)) {
    validate_mesh(pelvis);
    const std::string ctx = pelvis.source + ": automatic pelvic landmarks";
    require(have_convex_hull(), ctx + " need CGAL; give all six landmarks in subject.json instead");
    const Vertices& V = pelvis.V;
    const ConvexHull hull = convex_hull(V);
    const Eigen::Vector3d centroid = V.colwise().mean().transpose();
    // 1. The anterior pelvic plane's hull face.
    Eigen::Vector3d a1, a2, pub;
    find_app_face(V, hull, ctx, a1, a2, pub);
    // 2. Sides: the ASIS nearer the hip centre is on the hip's side.
    const bool a1_near = (a1 - hip_centre).norm() < (a2 - hip_centre).norm();
    const Eigen::Vector3d near = a1_near ? a1 : a2, far = a1_near ? a2 : a1;
    found["asis_right"] = side == Side::right ? near : far;
    found["asis_left"] = side == Side::right ? far : near;
    const Eigen::Vector3d mid = 0.5 * (found["asis_right"] + found["asis_left"]);
    Eigen::Vector3d n = (a2 - a1).cross(pub - a1);
    if (n.dot(mid - centroid) < 0) n = -n;  // outward: the hull face's normal points away from the bone
    const Eigen::Matrix3d A = orthonormal_axes(found["asis_right"] - found["asis_left"], 2, n, 0, ctx);
    const Eigen::Vector3d X = A.col(0), Y = A.col(1), Z = A.col(2);
    require((mid - pub).dot(Y) > 0 && (mid - hip_centre).dot(Y) > 0 && (hip_centre - pub).dot(Y) > 0,
            ctx + ": the convex hull's largest face does not look like the anterior pelvic plane (both ASIS above "
                  "the hip centre, the pubis below); is this a whole pelvis? Give the landmarks in subject.json");
    // 3. Pubic tubercles and 4. PSIS.
    find_tubercles_and_psis(V, hull, hip_centre, mid, pub, X, Y, Z, ctx, found);
  }
  auto pick = [&](const char* name, Eigen::Vector3d& out) {
    const auto g = given.find(name);
    require(g == given.end() || g->second.allFinite(), pelvis.source + ": given landmark " + name + " is not finite");
    out = g != given.end() ? g->second : found.at(name);
    L.source[name] = g != given.end() ? "given" : "found";
  };
  pick("asis_right", L.asis_right);
  pick("asis_left", L.asis_left);
  pick("psis_right", L.psis_right);
  pick("psis_left", L.psis_left);
  pick("pubic_tubercle_right", L.pubic_tubercle_right);
  pick("pubic_tubercle_left", L.pubic_tubercle_left);
  L.app_out_of_plane_mm = plane_distance(L.asis_right, L.asis_left, L.pubic_tubercle_right, L.pubic_tubercle_left);
  return L;
}

AnatomicalFrame pelvis_frame(const PelvisLandmarks& L, const Eigen::Vector3d& hip_centre, PelvisFrameKind kind) {
  AnatomicalFrame F;
  F.origin = hip_centre;
  const Eigen::Vector3d z = L.asis_right - L.asis_left;
  const Eigen::Vector3d mid_asis = 0.5 * (L.asis_right + L.asis_left);
  if (kind == PelvisFrameKind::isb) {
    const Eigen::Vector3d mid_psis = 0.5 * (L.psis_right + L.psis_left);
    F.axes = orthonormal_axes(z, 2, mid_asis - mid_psis, 0, "ISB pelvic frame");
    F.definition = "ISB pelvis (Wu et al. 2002): Z through both ASIS (right), X in the plane of both ASIS and "
                   "the PSIS midpoint (anterior), Y superior; origin at the hip centre";
  } else {
    const Eigen::Vector3d mid_pt = 0.5 * (L.pubic_tubercle_right + L.pubic_tubercle_left);
    F.axes = orthonormal_axes(z, 2, mid_asis - mid_pt, 1, "anterior pelvic plane frame");
    F.definition = "anterior pelvic plane (Tannast et al. 2007): Z through both ASIS (right), X normal to the "
                   "plane of both ASIS and the pubic tubercles (anterior), Y superior; origin at the hip centre";
  }
  F.landmarks = L.as_map();
  F.landmark_source = L.source;
  F.quality_mm = L.app_out_of_plane_mm;
  return F;
}

PelvisFrameKind parse_pelvis_frame_kind(const std::string& text, const std::string& context) {
  return parse_enum(kPelvisFrameKindNames, text, context);
}

}  // namespace impinge
