#include "impinge/clinical/joint_centre.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <sstream>

#include "impinge/core/error.hpp"
#include "impinge/schemes/fibonacci_scheme.hpp"
#include "core/cpu_dispatch.hpp"
#include "core/simd_clones.hpp"

namespace impinge {

JointCentreMethod parse_joint_centre(const std::string& text, const std::string& context) {
  std::string t = text;
  std::replace(t.begin(), t.end(), '_', '-');
  for (const EnumName<JointCentreMethod>& n : kJointCentreMethodNames)
    if (t == n.name) return n.value;
  return parse_enum(kJointCentreMethodNames, text, context);  // the error, naming the text as given
}

const char* to_string(JointCentreMethod m) { return enum_name(kJointCentreMethodNames, m); }

ScanSet lunate_sample(const RadialDistanceMap& socket_map, const LunateSphere& L, int max_vertices, bool mirror_x) {
  const Eigen::Vector3d flip(mirror_x ? -1.0 : 1.0, 1.0, 1.0);  // lattice frame <-> joint frame (its own inverse)
  const double nodes = 8.0 * std::max(16, max_vertices);
  const FibonacciScheme lattice(nodes);
  const auto n = static_cast<std::int64_t>(lattice.num_nodes());
  // Each node's direction from c_a, at the sphere: where the socket's surface lies in that direction from the COR.
  std::vector<double> x(static_cast<std::size_t>(n)), y(x.size()), z(x.size()), rho(x.size());
  for (std::int64_t k = 0; k < n; ++k) {
    const Eigen::Vector3d v = L.centre + L.radius_mm * flip.cwiseProduct(lattice.node_direction(k));
    x[static_cast<std::size_t>(k)] = v.x(), y[static_cast<std::size_t>(k)] = v.y(), z[static_cast<std::size_t>(k)] = v.z();
  }
  socket_map.lookup_many_soa_marked(x.data(), y.data(), z.data(), n, rho.data());
  ScanSet set;
  set.vertices = n;
  for (std::int64_t k = 0; k < n; ++k) {
    const auto i = static_cast<std::size_t>(k);
    if (!std::isfinite(rho[i])) continue;  // no surface, or a depth discontinuity in the stencil
    const Eigen::Vector3d v(x[i], y[i], z[i]);
    const Eigen::Vector3d p = rho[i] * v.normalized();
    if (std::abs((p - L.centre).norm() - L.radius_mm) > L.band_mm) continue;                  // off the lunate sphere
    set.index.push_back(static_cast<std::int32_t>(k));
    set.x.push_back(p.x()), set.y.push_back(p.y()), set.z.push_back(p.z());
  }
  return set;
}

std::string too_few_lunate_points(const JointBody& socket, std::size_t points) {
  const SamplingScheme& scheme = socket.map.scheme();
  const double spacing_deg = scheme.max_node_spacing() * 180 / M_PI;
  std::ostringstream o;
  o << socket.mesh.source << ": " << points << " points of the lunate surface sampled, fewer than 16: ";
  if (spacing_deg > kLunateSpacingDeg * (1 + 1e-9)) {
    o << "the maps' nodes, " << spacing_deg << " deg apart (" << scheme.name() << " " << scheme.resolution_name() << " "
      << scheme.resolution() << "), are too coarse for the lunate surface; a node spacing of " << kLunateSpacingDeg
      << " deg or finer samples it (--precision " << kLunateSpacingDeg << ", or --spacing " << kLunateSpacingDeg
      << " with any scheme; the default is 0.5), or --joint-centre femoral-head needs none";
  } else {
    o << "the equidistant joint centre needs the acetabulum's joint surface (use --joint-centre femoral-head)";
  }
  return o.str();
}

JointCentre::JointCentre(JointCentreMethod method, const Joint& joint, const LunateSphere& lunate,
                         const std::vector<std::uint8_t>& guard, double head_sphere_reach_mm,
                         const EquidistantOptions& o)
    : method_(method), c_a_(lunate.centre), start_(lunate.scan_head_centre.allFinite() ? lunate.scan_head_centre : lunate.centre),
      reach_mm_(head_sphere_reach_mm), options_(o) {
  if (method == JointCentreMethod::femoral_head) return;
  require(lunate.centre.allFinite(), std::string("joint centre ") + to_string(method) +
                                         ": needs the acetabular centre (anatomical neutral), and it is not finite");
  if (method != JointCentreMethod::equidistant) return;
  require(o.max_vertices >= 16 && o.max_iterations >= 1 && o.tolerance_mm > 0,
          "joint centre equidistant: need max_vertices >= 16, max_iterations >= 1 and tolerance > 0 mm");
  require(std::isfinite(head_sphere_reach_mm) && head_sphere_reach_mm > 0,
          "joint centre equidistant: the head sphere's reach must be > 0 mm");
  require(std::isfinite(lunate.radius_mm) && lunate.radius_mm > 0 && std::isfinite(lunate.band_mm) && lunate.band_mm > 0,
          "joint centre equidistant: the lunate sphere's radius and band must be > 0 mm");
  lunate_ = lunate_sample(joint.socket().map, lunate, o.max_vertices, o.mirror_x);
  require(lunate_.size() >= 16, [&] { return too_few_lunate_points(joint.socket(), lunate_.size()); });
  const Vertices& P = joint.socket().relative;
  require(guard.empty() || guard.size() == static_cast<std::size_t>(P.rows()),
          "joint centre equidistant: the lunate flags have " + std::to_string(guard.size()) + " entries for " +
              std::to_string(P.rows()) + " pelvis vertices");
  if (!guard.empty()) guard_ = guard_points(P, joint.socket().mesh.F, guard);
}

ScanSet guard_points(const Vertices& P, const Faces& F, const std::vector<std::uint8_t>& flags) {
  ScanSet set;
  set.vertices = P.rows();
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    const std::int32_t i0 = F(f, 0), i1 = F(f, 1), i2 = F(f, 2);
    if (!(flags[static_cast<std::size_t>(i0)] && flags[static_cast<std::size_t>(i1)] && flags[static_cast<std::size_t>(i2)]))
      continue;
    const Eigen::Vector3d a = P.row(i0).transpose(), b = P.row(i1).transpose(), c = P.row(i2).transpose();
    const double longest = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
    int k = 1;
    while (k < kGuardMaxCuts && longest / k > kGuardSpacingMm) k *= 2;
    const Eigen::Vector3d u = (b - a) / k, v = (c - a) / k;
    for (int p = 0; p <= k; ++p)
      for (int q = 0; p + q <= k; ++q) {
        // The corners as given (not a + k u: the same point to the last bit wherever a corner is shared).
        const Eigen::Vector3d x = p == k ? b : q == k ? c : Eigen::Vector3d(a + p * u + q * v);
        set.index.push_back(static_cast<std::int32_t>(f));
        set.x.push_back(x.x()), set.y.push_back(x.y()), set.z.push_back(x.z());
      }
  }
  return set;
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
/// Eight lanes (j mod 8) are summed apart and then together, so that the loop vectorises: on AVX-512 as one
/// register a lane vector (normal_sums_wide), else as two halves of four lanes, each half over all the vertices
/// in turn (normal_sums_halves, AVX2 and baseline clones: the 8-lane vectors spilled to the stack there, 14 % of
/// `impinge rom`'s time on lhdl-ct). Every lane adds the same terms in the same order either way, and the lanes
/// are then added in lane order, so both give the same sums.
constexpr int kSumLanes = 8;

/// GCC vectors of kWidth doubles, floats and bytes (a dependent vector_size is not taken in a template).
template <int kWidth>
struct SumVectors;
template <>
struct SumVectors<8> {
  typedef double Lanes __attribute__((vector_size(64)));
  typedef float FloatLanes __attribute__((vector_size(32)));
  typedef std::uint8_t ByteLanes __attribute__((vector_size(8)));
};
template <>
struct SumVectors<4> {
  typedef double Lanes __attribute__((vector_size(32)));
  typedef float FloatLanes __attribute__((vector_size(16)));
  typedef std::uint8_t ByteLanes __attribute__((vector_size(4)));
};

/// Lanes [first, first + kWidth) of the eight (kSumLanes) over every vertex: lane_sum[k][first + l] (k < 14).
template <int kWidth>
inline __attribute__((always_inline)) void normal_sum_lanes(const double* X, const double* Y, const double* Z,
                                                            const float* g, const std::uint8_t* use, std::int64_t n,
                                                            const double* t, int first, double (*lane_sum)[kSumLanes]) {
  using Lanes = typename SumVectors<kWidth>::Lanes;
  using FloatLanes = typename SumVectors<kWidth>::FloatLanes;
  using ByteLanes = typename SumVectors<kWidth>::ByteLanes;
  Lanes acc[14] = {};
  const double tx = t[0], ty = t[1], tz = t[2];
  // One block of kWidth vertices; past n, the last vertex repeated and left out (use 0).
  auto block = [&](const Lanes& x, const Lanes& y, const Lanes& z, const Lanes& gap, const Lanes& used) {
    const Lanes dx = x - tx, dy = y - ty, dz = z - tz;
    const Lanes n2 = dx * dx + dy * dy + dz * dz;
    const auto finite = gap - gap == 0;  // inf - inf and NaN - NaN are NaN
    const Lanes on = finite ? used : Lanes{};
    Lanes len = n2 > 0 ? n2 : Lanes{} + 1.0;  // a vertex at t: w = 0
    for (int l = 0; l < kWidth; ++l) len[l] = std::sqrt(len[l]);
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
  const std::int64_t full = n / kSumLanes * kSumLanes;
  for (std::int64_t j0 = first; j0 < full; j0 += kSumLanes) {
    Lanes x, y, z;
    FloatLanes gf;
    ByteLanes u;
    std::memcpy(&x, X + j0, sizeof x), std::memcpy(&y, Y + j0, sizeof y), std::memcpy(&z, Z + j0, sizeof z);
    std::memcpy(&gf, g + j0, sizeof gf), std::memcpy(&u, use + j0, sizeof u);
    block(x, y, z, __builtin_convertvector(gf, Lanes), __builtin_convertvector(u != 0, Lanes) * -1.0);
  }
  if (full < n) {
    Lanes x, y, z, gap, used;
    for (int l = 0; l < kWidth; ++l) {
      const std::int64_t i = full + first + l, j = std::min(i, n - 1);
      x[l] = X[j], y[l] = Y[j], z[l] = Z[j], gap[l] = g[j], used[l] = i < n && use[j] != 0 ? 1.0 : 0.0;
    }
    block(x, y, z, gap, used);
  }
  for (int k = 0; k < 14; ++k)
    for (int l = 0; l < kWidth; ++l) lane_sum[k][first + l] = acc[k][l];
}

// The lanes' sums added in lane order into out[0..13].
void add_lanes(const double (*lane_sum)[kSumLanes], double* out) {
  for (int k = 0; k < 14; ++k) {
    double sum = 0;
    for (int l = 0; l < kSumLanes; ++l) sum += lane_sum[k][l];
    out[k] = sum;
  }
}

IMPINGE_SIMD_WIDE
void normal_sums_wide(const double* __restrict X, const double* __restrict Y, const double* __restrict Z,
                      const float* __restrict g, const std::uint8_t* __restrict use, std::int64_t n,
                      const double* __restrict t, double* __restrict out) {
  double lane_sum[14][kSumLanes];
  normal_sum_lanes<kSumLanes>(X, Y, Z, g, use, n, t, 0, lane_sum);
  add_lanes(lane_sum, out);
}

IMPINGE_SIMD_CLONES_NARROW
void normal_sums_halves(const double* __restrict X, const double* __restrict Y, const double* __restrict Z,
                        const float* __restrict g, const std::uint8_t* __restrict use, std::int64_t n,
                        const double* __restrict t, double* __restrict out) {
  double lane_sum[14][kSumLanes];
  normal_sum_lanes<kSumLanes / 2>(X, Y, Z, g, use, n, t, 0, lane_sum);
  normal_sum_lanes<kSumLanes / 2>(X, Y, Z, g, use, n, t, kSumLanes / 2, lane_sum);
  add_lanes(lane_sum, out);
}

void normal_sums(const double* X, const double* Y, const double* Z, const float* g, const std::uint8_t* use,
                 std::int64_t n, const double* t, double* out) {
  if (detail::use_wide_vectors())
    normal_sums_wide(X, Y, Z, g, use, n, t, out);
  else
    normal_sums_halves(X, Y, Z, g, use, n, t, out);
}

/// Which lunate points face the head's joint surface, with the head centre at `at` (mm; Rt: the femur's rotation
/// transposed): on_head[j] = 1 where the gap g[j] (mm) is finite and the femur's surface in q_j's direction,
/// |R^T (q_j - at)| - g[j] from the head centre, lies within reach_mm of it. Returns how many.
std::int64_t mark_on_head(const ScanSet& lunate, const float* g, const Eigen::Matrix3d& Rt, const Eigen::Vector3d& at,
                          double reach_mm, std::uint8_t* on_head) {
  std::int64_t used = 0;
  for (std::int64_t j = 0; j < lunate.size(); ++j) {
    const auto k = static_cast<std::size_t>(j);
    const double r = (Rt * (Eigen::Vector3d(lunate.x[j], lunate.y[j], lunate.z[j]) - at)).norm();
    on_head[k] = std::isfinite(g[k]) && r - g[k] <= reach_mm;
    used += on_head[k];
  }
  return used;
}

/// The equidistant normal equations A (d, m) = b at the head centre t (mm), over the lunate points with on_head[j]
/// and their gaps g (mm): gap_j(t + d) ~ gap_j(t) - w_j . d (w_j: unit direction from the head centre t to q_j; exact
/// for a spherical head). Least squares of gap_j - w_j . d - m over d and the mean joint space m: the normal
/// equations of a_j . (d, m) = gap_j, a_j = (w_j, 1).
void normal_equations(const ScanSet& lunate, const float* g, const std::uint8_t* on_head, const Eigen::Vector3d& t,
                      Eigen::Matrix4d& A, Eigen::Vector4d& b) {
  double sums[14];
  normal_sums(lunate.x.data(), lunate.y.data(), lunate.z.data(), g, on_head, lunate.size(), t.data(), sums);
  for (int i = 0, k = 0; i < 4; ++i)
    for (int c = 0; c <= i; ++c, ++k) A(i, c) = A(c, i) = sums[k];
  b = Eigen::Vector4d(sums[10], sums[11], sums[12], sums[13]);
}

/// The guard's tests at one pose of JointCentre::solve (Rt: the femur's rotation transposed; mm).
struct GuardTest {
  const Joint& joint;
  const Eigen::Matrix3d& Rt;
  double reach_mm;                                  // the head sphere's reach
  bool guard_all;                                   // every closure guarded (at neutral)
  const std::vector<std::uint8_t>& neutral_closed;  // per guard vertex: closed at neutral, guarded always
  // The gaps (mm) of set's vertices with the head centre at `at`, into `out`.
  void scan(const ScanSet& set, const Eigen::Vector3d& at, float* out) const {
    scan_gaps_compact(set, Rt, Eigen::Vector3d(-(Rt * at)), joint.ball().map, ScanSide::outside, out);
  }
  // Whether the femur's surface that set's vertex k faces, with the head centre at `at`, is the head's joint surface
  // (within the head sphere's reach, as on_head): only there is a closed joint space the head pressed into the
  // socket. A neck or a cam meeting the rim is an impingement, the ROM's to find, not the placement's to avoid
  // (guarding it levered the femur out of the socket: lhdl-ct by 6 mm at 70 deg of extension, 23-60 mm beyond).
  bool faces_head(const ScanSet& set, std::int64_t k, const Eigen::Vector3d& at, float gap) const {
    if (!std::isfinite(gap)) return false;
    const double r = (Rt * (Eigen::Vector3d(set.x[k], set.y[k], set.z[k]) - at)).norm();
    return r - gap <= reach_mm;
  }
  // Whether guard vertex `guard_k`'s closure is guarded: any closure at neutral (guard_all) and at the vertices
  // closed there (neutral_closed), elsewhere the head's (guard_at_neutral).
  bool guarded(std::int64_t guard_k, const ScanSet& set, std::int64_t k, const Eigen::Vector3d& at, float gap) const {
    if (!std::isfinite(gap)) return false;
    return guard_all || (!neutral_closed.empty() && neutral_closed[static_cast<std::size_t>(guard_k)]) ||
           faces_head(set, k, at, gap);
  }
};

/// Watches the guard points closing at t: those not yet watched whose guarded gap (guard_gap, mm) is below 0.25 mm
/// are marked in is_watched (and in closed_out, if given, where the femur's surface closing them is not the head's)
/// and appended to `watched`, their guard indices to watched_k.
void watch_closing(const ScanSet& guard, const float* guard_gap, const GuardTest& test, const Eigen::Vector3d& t,
                   std::vector<std::uint8_t>& is_watched, std::vector<std::int64_t>& watched_k, ScanSet& watched,
                   std::vector<std::uint8_t>* closed_out) {
  constexpr float kNearMm = 0.25f;
  for (std::int64_t k = 0; k < guard.size(); ++k) {
    const auto i = static_cast<std::size_t>(k);
    if (is_watched[i] || !(guard_gap[i] < kNearMm) || !test.guarded(k, guard, k, t, guard_gap[i])) continue;
    is_watched[i] = 1;
    watched_k.push_back(k);
    // Recorded as closed at neutral only where what closes it is not the head's joint surface (a head past its sphere, a
    // segmentation overlap): a closure by the head is guarded at every pose anyway, and a point recorded here is kept
    // open against anything of the femur, a neck or cam too (1,106 points of tlem2-mri's lunate surface lie within
    // 0.25 mm of its head at neutral: recording them all held its femur off a cam's contact).
    if (closed_out && !test.faces_head(guard, k, t, guard_gap[i])) (*closed_out)[i] = 1;
    watched.index.push_back(guard.index[i]);
    watched.x.push_back(guard.x[k]), watched.y.push_back(guard.y[k]), watched.z.push_back(guard.z[k]);
  }
}
}  // namespace

Eigen::Vector3d JointCentre::constrained_step(const Eigen::Matrix4d& H, const Eigen::Vector4d& b, const Eigen::Vector3d& t,
                                              const OpenPoints& open, std::vector<std::size_t>& active) {
  // Least squares of gap_j - w_j . d - m (normal equations H x = b, x = (d, m)) subject to the joint space
  // staying open at every point of `open`: c_k . x <= e_k with c_k = (w_k, 0), e_k = gap_k (w_k: the unit
  // direction from the head centre t to the point). An active set of these constraints: add the most
  // violated, solve the equality-constrained problem, drop a constraint whose multiplier turns negative. With
  // the active rows C, x = H^-1 (b - C^T l) and (C H^-1 C^T) l = C H^-1 b - e: a system as small as the
  // active set, which holds at most 3 independent rows (the constraints bind d alone).
  const Eigen::LDLT<Eigen::Matrix4d> ldlt(H);
  const Eigen::Vector4d x0 = ldlt.solve(b);
  Eigen::Vector4d x = x0;
  const std::size_t n = open.g.size();
  thread_local std::vector<double> wx, wy, wz, v;
  wx.resize(n), wy.resize(n), wz.resize(n), v.resize(n);
  for (std::size_t k = 0; k < n; ++k) {  // vectorises
    const double dx = open.x[k] - t.x(), dy = open.y[k] - t.y(), dz = open.z[k] - t.z();
    const double inv = 1.0 / std::sqrt(dx * dx + dy * dy + dz * dz);
    wx[k] = dx * inv, wy[k] = dy * inv, wz[k] = dz * inv;
  }
  auto w = [&](std::size_t k) { return Eigen::Vector3d(wx[k], wy[k], wz[k]); };
  constexpr int kMaxActive = 6;
  constexpr double kSlack = 1e-6;  // mm: a constraint violated by less is met
  // The equality-constrained solution with the active set (dropping a constraint that pulls the wrong way).
  auto solve_active = [&]() {
    while (!active.empty()) {
      const auto m = static_cast<Eigen::Index>(active.size());
      Eigen::Matrix<double, 4, Eigen::Dynamic, 0, 4, kMaxActive> Ct(4, m);  // C^T
      Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxActive, 1> e(m);
      for (Eigen::Index a = 0; a < m; ++a) {
        const std::size_t k = active[static_cast<std::size_t>(a)];
        Ct.col(a) << w(k), 0.0;
        e(a) = open.g[k];
      }
      const Eigen::Matrix<double, 4, Eigen::Dynamic, 0, 4, kMaxActive> HiCt = ldlt.solve(Ct);
      const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxActive, kMaxActive> S = Ct.transpose() * HiCt;
      const Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxActive, 1> rhs = Ct.transpose() * x0 - e;
      const Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxActive, 1> l = S.completeOrthogonalDecomposition().solve(rhs);
      x = x0 - HiCt * l;
      Eigen::Index drop = -1;
      double least = -1e-12;
      for (Eigen::Index a = 0; a < m; ++a)
        if (l(a) < least) least = l(a), drop = a;
      if (drop < 0) break;
      active.erase(active.begin() + drop);
      if (active.empty()) x = x0;
    }
  };
  // The active set starts from the last step's (the same points, in the same order: warm) and grows.
  active.erase(std::remove_if(active.begin(), active.end(), [&](std::size_t k) { return k >= n; }), active.end());
  if (active.size() > static_cast<std::size_t>(kMaxActive)) active.resize(kMaxActive);
  if (!active.empty()) solve_active();
  for (int round = 0; round < 32; ++round) {
    const double dx = x(0), dy = x(1), dz = x(2);
    for (std::size_t k = 0; k < n; ++k) v[k] = wx[k] * dx + wy[k] * dy + wz[k] * dz - open.g[k];  // vectorises
    for (std::size_t k : active) v[k] = -1;
    std::size_t worst = n;
    double most = kSlack;
    for (std::size_t k = 0; k < n; ++k)
      if (v[k] > most) most = v[k], worst = k;
    if (worst == n || static_cast<int>(active.size()) == kMaxActive) break;
    active.push_back(worst);
    solve_active();
  }
  return x.head<3>();
}

Eigen::Vector3d JointCentre::translation(const Joint& joint, const Eigen::Matrix3d& R) const {
  switch (method_) {
    case JointCentreMethod::femoral_head: return Eigen::Vector3d::Zero();
    case JointCentreMethod::acetabular: return c_a_ - R * c_a_;
    case JointCentreMethod::combined: return c_a_;
    case JointCentreMethod::equidistant: break;
  }
  return solve(joint, R, false, nullptr);
}

void JointCentre::guard_at_neutral(const Joint& joint, const Eigen::Matrix3d& R0) {
  if (method_ != JointCentreMethod::equidistant) return;
  std::vector<std::uint8_t> closed(static_cast<std::size_t>(guard_.size()), 0);
  neutral_closed_.clear();
  solve(joint, R0, true, &closed);
  neutral_closed_ = std::move(closed);
}

std::int64_t JointCentre::guarded_at_neutral() const {
  std::int64_t n = 0;
  for (std::uint8_t c : neutral_closed_) n += c;
  return n;
}

Eigen::Vector3d JointCentre::solve(const Joint& joint, const Eigen::Matrix3d& R, bool guard_all,
                                   std::vector<std::uint8_t>* closed_out) const {
  const std::int64_t n = lunate_.size();
  thread_local std::vector<float> g;
  thread_local std::vector<std::uint8_t> on_head;
  g.resize(static_cast<std::size_t>(n));
  on_head.resize(static_cast<std::size_t>(n));
  // Which lunate points face the head's joint surface: decided once per pose, with the head at the iteration's
  // start (its scan position), so that t is a function of R alone (not of where the iteration goes). The femur's
  // surface in q's direction lies |y| - gap from the head centre.
  const Eigen::Matrix3d Rt = R.transpose();
  gaps(joint, R, start_, g.data());
  const std::int64_t used = mark_on_head(lunate_, g.data(), Rt, start_, reach_mm_, on_head.data());
  require(used >= 16, "joint centre equidistant: fewer than 16 lunate vertices face the femoral head's joint surface "
                      "at this pose");
  // The guard: every lunate vertex's joint space must stay open. Those found closed at a converged t are
  // constrained from then on (watched), and the iteration goes on; most poses close none.
  const std::int64_t ng = guard_.size();
  thread_local std::vector<float> guard_gap, watched_gap;
  thread_local ScanSet watched;
  thread_local OpenPoints open;
  thread_local std::vector<std::size_t> active;  // the constraints binding at the last step (indices into open)
  active.clear();
  thread_local std::vector<std::uint8_t> is_watched;
  guard_gap.resize(static_cast<std::size_t>(ng));
  is_watched.assign(static_cast<std::size_t>(ng), 0);
  thread_local std::vector<std::int64_t> watched_k;  // each watched vertex's index into guard_
  watched_k.clear();
  watched.index.clear(), watched.x.clear(), watched.y.clear(), watched.z.clear();
  watched.vertices = guard_.vertices;
  const GuardTest test{joint, Rt, reach_mm_, guard_all, neutral_closed_};
  Eigen::Vector3d t = start_, previous = Eigen::Vector3d::Zero();
  const int max_iterations = 4 * options_.max_iterations;
  for (int it = 0, steps = 0; it < max_iterations; ++it) {
    if (it > 0) gaps(joint, R, t, g.data());  // the first step uses the selection's gaps
    Eigen::Matrix4d A;
    Eigen::Vector4d b;
    normal_equations(lunate_, g.data(), on_head.data(), t, A, b);
    open.clear();
    for (std::int64_t j = 0; j < n; ++j)
      if (on_head[static_cast<std::size_t>(j)]) open.add(lunate_.x[j], lunate_.y[j], lunate_.z[j], g[static_cast<std::size_t>(j)]);
    if (watched.size() > 0) {
      watched_gap.resize(static_cast<std::size_t>(watched.size()));
      test.scan(watched, t, watched_gap.data());
      for (std::int64_t k = 0; k < watched.size(); ++k)
        if (test.guarded(watched_k[static_cast<std::size_t>(k)], watched, k, t, watched_gap[static_cast<std::size_t>(k)]))
          open.add(watched.x[k], watched.y[k], watched.z[k], watched_gap[static_cast<std::size_t>(k)]);
    }
    Eigen::Vector3d d = constrained_step(A, b, t, open, active);
    if (d.dot(previous) < 0) d *= 0.5;  // a zig-zag between two active sets: halve the step
    previous = d;
    t += d;
    if (!t.allFinite()) throw Error("joint centre equidistant: the iteration diverged (no joint space to even out)");
    if (d.norm() >= options_.tolerance_mm && ++steps < options_.max_iterations) continue;
    // Converged (or out of steps): is the joint space open at every guard vertex not yet watched?
    test.scan(guard_, t, guard_gap.data());
    bool closed = false;
    for (std::int64_t k = 0; k < ng && !closed; ++k)
      closed = !is_watched[static_cast<std::size_t>(k)] && guard_gap[static_cast<std::size_t>(k)] < -options_.tolerance_mm &&
               test.guarded(k, guard_, k, t, guard_gap[static_cast<std::size_t>(k)]);
    if (!closed) break;
    // Closed by the head's joint surface (or, at neutral, by anything of the femur): watch it, and its guarded
    // neighbours in closing (within 0.25 mm), so that the next round does not close them in turn.
    watch_closing(guard_, guard_gap.data(), test, t, is_watched, watched_k, watched, closed_out);
    steps = 0;
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
