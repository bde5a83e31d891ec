#include "impinge/clinical/joint_centre.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <tuple>

#include "impinge/core/error.hpp"
#include "impinge/schemes/fibonacci_scheme.hpp"
#include "core/simd_clones.hpp"

namespace impinge {

JointCentreMethod parse_joint_centre(const std::string& text, const std::string& context) {
  std::string t = text;
  std::replace(t.begin(), t.end(), '_', '-');
  if (t == "femoral-head") return JointCentreMethod::femoral_head;
  if (t == "acetabular") return JointCentreMethod::acetabular;
  if (t == "combined") return JointCentreMethod::combined;
  if (t == "equidistant") return JointCentreMethod::equidistant;
  throw Error(context + " '" + text + "': expected femoral-head, acetabular, combined or equidistant");
}

const char* to_string(JointCentreMethod m) {
  switch (m) {
    case JointCentreMethod::acetabular: return "acetabular";
    case JointCentreMethod::combined: return "combined";
    case JointCentreMethod::equidistant: return "equidistant";
    case JointCentreMethod::femoral_head: break;
  }
  return "femoral-head";
}

ScanSet lunate_sample(PointsRef P, const std::vector<std::uint8_t>& lunate, const Eigen::Vector3d& c_a,
                      int max_vertices, bool mirror_x) {
  const Eigen::Vector3d flip(mirror_x ? -1.0 : 1.0, 1.0, 1.0);  // lattice frame <-> joint frame (its own inverse)
  std::vector<std::int32_t> flagged;
  for (std::size_t i = 0; i < lunate.size(); ++i)
    if (lunate[i]) flagged.push_back(static_cast<std::int32_t>(i));
  std::vector<Eigen::Vector3d> u(flagged.size());  // directions from c_a
  for (std::size_t k = 0; k < flagged.size(); ++k) u[k] = (P.row(flagged[k]).transpose() - c_a).normalized();
  // Cells of a Fibonacci lattice about c_a, coarse enough (8 max_vertices nodes over the sphere: 4.5 deg apart
  // for 256) that every cell over the lunate surface holds a vertex however finely it is tessellated.
  const double nodes = 8.0 * std::max(16, max_vertices);
  const FibonacciScheme lattice(nodes);
  std::vector<std::int64_t> cell(u.size());
  for (std::size_t k = 0; k < u.size(); ++k)
    cell[k] = u[k].allFinite() ? lattice.node(Eigen::Vector3d(flip.cwiseProduct(u[k]))) : -1;
  // In each cell the vertex nearest its node's direction; ties (duplicated vertices) by position.
  std::vector<std::size_t> order(flagged.size());
  for (std::size_t k = 0; k < order.size(); ++k) order[k] = k;
  auto key = [&](std::size_t k) {
    const Eigen::Vector3d p = P.row(flagged[k]).transpose();
    return std::make_tuple(cell[k], -u[k].dot(flip.cwiseProduct(lattice.node_direction(std::max<std::int64_t>(cell[k], 0)))),
                           flip.x() * p.x(), p.y(), p.z());
  };
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return key(a) < key(b); });
  ScanSet set;
  set.vertices = P.rows();
  for (std::size_t j = 0; j < order.size(); ++j) {
    const std::size_t k = order[j];
    if (cell[k] < 0 || (j > 0 && cell[order[j - 1]] == cell[k])) continue;  // one per cell
    const Eigen::Vector3d p = P.row(flagged[k]).transpose();
    set.index.push_back(flagged[k]);
    set.x.push_back(p.x()), set.y.push_back(p.y()), set.z.push_back(p.z());
  }
  return set;
}

JointCentre::JointCentre(JointCentreMethod method, const Joint& joint, const Eigen::Vector3d& c_a,
                         const std::vector<std::uint8_t>& lunate, double head_sphere_reach_mm,
                         const EquidistantOptions& o)
    : method_(method), c_a_(c_a), reach_mm_(head_sphere_reach_mm), options_(o) {
  if (method == JointCentreMethod::femoral_head) return;
  require(c_a.allFinite(), std::string("joint centre ") + to_string(method) +
                               ": needs the acetabular centre (anatomical neutral), and it is not finite");
  if (method != JointCentreMethod::equidistant) return;
  require(o.max_vertices >= 16 && o.max_iterations >= 1 && o.tolerance_mm > 0,
          "joint centre equidistant: need max_vertices >= 16, max_iterations >= 1 and tolerance > 0 mm");
  require(std::isfinite(head_sphere_reach_mm) && head_sphere_reach_mm > 0,
          "joint centre equidistant: the head sphere's reach must be > 0 mm");
  const Vertices& P = joint.socket().relative;
  require(lunate.size() == static_cast<std::size_t>(P.rows()),
          "joint centre equidistant: the lunate flags have " + std::to_string(lunate.size()) + " entries for " +
              std::to_string(P.rows()) + " pelvis vertices");
  const auto flagged = static_cast<std::int64_t>(std::count(lunate.begin(), lunate.end(), std::uint8_t(1)));
  require(flagged >= 16, joint.socket().mesh.source + ": " + std::to_string(flagged) +
                             " vertices on the lunate surface, fewer than 16: the equidistant joint centre needs "
                             "the acetabulum's joint surface (use --joint-centre femoral-head)");
  lunate_ = lunate_sample(P, lunate, c_a, o.max_vertices, o.mirror_x);
}

void JointCentre::gaps(const Joint& joint, const Eigen::Matrix3d& R, const Eigen::Vector3d& t, float* out) const {
  // A pelvis vertex q in the femur's frame: R^T (q - t); gap = |.| - ball map (outside the head: > 0).
  scan_gaps_compact(lunate_, R.transpose(), Eigen::Vector3d(-(R.transpose() * t)), joint.ball().map, ScanSide::outside,
                    out);
}

namespace {
/// The equidistant normal equations' sums over n lunate vertices (X, Y, Z: n each, joint frame, mm) at the
/// head centre t (3, mm): with a_j = (w_j, 1), w_j the unit direction from t to vertex j, the lower
/// triangle of sum a_j a_j^T row by row (out[0..9]: 00, 10, 11, 20, 21, 22, 30, 31, 32, 33) and
/// sum a_j g_j (out[10..13]), leaving out the vertices with use[j] == 0 or a non-finite gap g[j] (mm).
/// Eight lanes (j mod 8) are summed apart and then together, so that the loop vectorises (clones).
IMPINGE_SIMD_CLONES
void normal_sums(const double* __restrict X, const double* __restrict Y, const double* __restrict Z,
                 const float* __restrict g, const std::uint8_t* __restrict use, std::int64_t n,
                 const double* __restrict t, double* __restrict out) {
  constexpr int kLanes = 8;
  typedef double Lanes __attribute__((vector_size(8 * kLanes)));
  typedef float FloatLanes __attribute__((vector_size(4 * kLanes)));
  typedef std::uint8_t ByteLanes __attribute__((vector_size(kLanes)));
  Lanes acc[14] = {};
  const double tx = t[0], ty = t[1], tz = t[2];
  // One block of kLanes vertices; past n, the last vertex repeated and left out (use 0).
  auto block = [&](const Lanes& x, const Lanes& y, const Lanes& z, const Lanes& gap, const Lanes& used) {
    const Lanes dx = x - tx, dy = y - ty, dz = z - tz;
    const Lanes n2 = dx * dx + dy * dy + dz * dz;
    const auto finite = gap - gap == 0;  // inf - inf and NaN - NaN are NaN
    const Lanes on = finite ? used : Lanes{};
    Lanes len = n2 > 0 ? n2 : Lanes{} + 1.0;  // a vertex at t: w = 0
    for (int l = 0; l < kLanes; ++l) len[l] = std::sqrt(len[l]);
    const Lanes a0 = dx / len * on, a1 = dy / len * on, a2 = dz / len * on, a3 = on;
    const Lanes gg = finite ? gap * on : Lanes{};
    acc[0] += a0 * a0;
    acc[1] += a1 * a0;
    acc[2] += a1 * a1;
    acc[3] += a2 * a0;
    acc[4] += a2 * a1;
    acc[5] += a2 * a2;
    acc[6] += a3 * a0;
    acc[7] += a3 * a1;
    acc[8] += a3 * a2;
    acc[9] += a3 * a3;
    acc[10] += a0 * gg;
    acc[11] += a1 * gg;
    acc[12] += a2 * gg;
    acc[13] += a3 * gg;
  };
  const std::int64_t full = n / kLanes * kLanes;
  for (std::int64_t j0 = 0; j0 < full; j0 += kLanes) {
    Lanes x, y, z;
    FloatLanes gf;
    ByteLanes u;
    std::memcpy(&x, X + j0, sizeof x), std::memcpy(&y, Y + j0, sizeof y), std::memcpy(&z, Z + j0, sizeof z);
    std::memcpy(&gf, g + j0, sizeof gf), std::memcpy(&u, use + j0, sizeof u);
    block(x, y, z, __builtin_convertvector(gf, Lanes), __builtin_convertvector(u != 0, Lanes) * -1.0);
  }
  if (full < n) {
    Lanes x, y, z, gap, used;
    for (int l = 0; l < kLanes; ++l) {
      const std::int64_t j = std::min(full + l, n - 1);
      x[l] = X[j], y[l] = Y[j], z[l] = Z[j], gap[l] = g[j], used[l] = full + l < n && use[j] != 0 ? 1.0 : 0.0;
    }
    block(x, y, z, gap, used);
  }
  for (int k = 0; k < 14; ++k) {
    double sum = 0;
    for (int l = 0; l < kLanes; ++l) sum += acc[k][l];
    out[k] = sum;
  }
}
}  // namespace

Eigen::Vector3d JointCentre::translation(const Joint& joint, const Eigen::Matrix3d& R) const {
  switch (method_) {
    case JointCentreMethod::femoral_head: return Eigen::Vector3d::Zero();
    case JointCentreMethod::acetabular: return c_a_ - R * c_a_;
    case JointCentreMethod::combined: return c_a_;
    case JointCentreMethod::equidistant: break;
  }
  const std::int64_t n = lunate_.size();
  thread_local std::vector<float> g;
  thread_local std::vector<std::uint8_t> on_head;
  g.resize(static_cast<std::size_t>(n));
  on_head.resize(static_cast<std::size_t>(n));
  // Which lunate vertices face the head's joint surface: decided once per pose, with the head on the
  // acetabular centre (the combined method's t), so that t is a function of R alone (not of where
  // the iteration starts). The femur's surface in q's direction lies |y| - gap from the head centre.
  const Eigen::Matrix3d Rt = R.transpose();
  gaps(joint, R, c_a_, g.data());
  std::int64_t used = 0;
  for (std::int64_t j = 0; j < n; ++j) {
    const auto k = static_cast<std::size_t>(j);
    const double r = (Rt * (Eigen::Vector3d(lunate_.x[j], lunate_.y[j], lunate_.z[j]) - c_a_)).norm();
    on_head[k] = std::isfinite(g[k]) && r - g[k] <= reach_mm_;
    used += on_head[k];
  }
  require(used >= 16, "joint centre equidistant: fewer than 16 lunate vertices face the femoral head's joint surface "
                      "at this pose");
  Eigen::Vector3d t = c_a_;
  for (int it = 0; it < options_.max_iterations; ++it) {
    if (it > 0) gaps(joint, R, t, g.data());  // the first step uses the selection's gaps
    // gap_j(t + d) ~ gap_j(t) - w_j . d (w_j: unit direction from the head centre t to q_j; exact
    // for a spherical head). Least squares of gap_j - w_j . d - m over d and the mean joint space m:
    // the normal equations of a_j . (d, m) = gap_j, a_j = (w_j, 1).
    double sums[14];
    normal_sums(lunate_.x.data(), lunate_.y.data(), lunate_.z.data(), g.data(), on_head.data(), n, t.data(), sums);
    Eigen::Matrix4d A;
    for (int i = 0, k = 0; i < 4; ++i)
      for (int c = 0; c <= i; ++c, ++k) A(i, c) = A(c, i) = sums[k];
    const Eigen::Vector4d b(sums[10], sums[11], sums[12], sums[13]);
    const Eigen::Vector3d d = A.ldlt().solve(b).head<3>();
    t += d;
    if (!t.allFinite()) throw Error("joint centre equidistant: the iteration diverged (no joint space to even out)");
    if (d.norm() < options_.tolerance_mm) break;
  }
  return t;
}

double JointCentre::joint_space_sd_mm(const Joint& joint, const Eigen::Matrix3d& R, const Eigen::Vector3d& t) const {
  const std::int64_t n = lunate_.size();
  if (n == 0) return std::nan("");
  std::vector<float> g(static_cast<std::size_t>(n));
  gaps(joint, R, t, g.data());
  double s = 0, s2 = 0;
  std::int64_t k = 0;
  for (float v : g)
    if (std::isfinite(v)) s += v, s2 += double(v) * v, ++k;
  if (k < 2) return std::nan("");
  const double mean = s / double(k);
  return std::sqrt(std::max(0.0, (s2 - double(k) * mean * mean) / double(k - 1)));
}

}  // namespace impinge
