#include "impinge/casters/signed_distance.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>
#include <mutex>
#include <string>
#include <utility>

#include "casters/signed_distance_impl.hpp"
#include "core/box_order.hpp"
#include "core/cpu_dispatch.hpp"
#include "impinge/core/error.hpp"

namespace impinge {

using detail::kBoxMarginMm;
using detail::kBoxReachMm;
using detail::kNearbySlackMm;

namespace {

// A winding number within this of 1/2 cannot tell inside from outside (signed_distance.hpp, rule 3).
constexpr double kUndecidedBand = 0.25;

#ifdef IMPINGE_HAVE_EMBREE
using detail::kGroup;

/// GCC vectors of kWidth floats (a dependent vector_size is not taken in a template).
template <int kWidth>
struct BoundLanes;
template <>
struct BoundLanes<16> {
  typedef float Lanes __attribute__((vector_size(64)));
};
template <>
struct BoundLanes<8> {
  typedef float Lanes __attribute__((vector_size(32)));
};

/// group_lower_bounds (below) over kWidth lanes at a time (kGroup a multiple of it), each row read as it is needed.
template <int kWidth>
inline __attribute__((always_inline)) std::uint32_t lower_bound_lanes(const float (*v)[kGroup], float x, float y,
                                                                      float z, float limit2, float* lb2) {
  static_assert(kGroup % kWidth == 0, "the group's lanes in whole vectors");
  using Lanes = typename BoundLanes<kWidth>::Lanes;
  std::uint32_t bits = 0;
  for (int o = 0; o < kGroup; o += kWidth) {
    Lanes a, b, c, d, h, s0, s1, s2;
    // Rows r .. r + 3 (a plane: its normal and offset) at q, lanes o .. o + kWidth - 1, into out.
    const auto plane = [&](int r, Lanes& out) {
      std::memcpy(&a, v[r] + o, sizeof(Lanes)), std::memcpy(&b, v[r + 1] + o, sizeof(Lanes));
      std::memcpy(&c, v[r + 2] + o, sizeof(Lanes)), std::memcpy(&d, v[r + 3] + o, sizeof(Lanes));
      out = a * x + b * y + c * z - d;
    };
    plane(0, h), plane(4, s0), plane(8, s1), plane(12, s2);
    Lanes s = s0 > s1 ? s0 : s1;
    s = s > s2 ? s : s2;
    s = s > 0 ? s : Lanes{};
    const Lanes out = h * h + s * s;
    std::memcpy(lb2 + o, &out, sizeof(Lanes));
    const auto within = out <= limit2;  // -1 where within, lane by lane
    for (int l = 0; l < kWidth; ++l) bits |= static_cast<std::uint32_t>(within[l] & 1) << (o + l);
  }
  return bits;
}

IMPINGE_SIMD_WIDE
std::uint32_t group_lower_bounds_wide(const float (*v)[kGroup], float x, float y, float z, float limit2, float* lb2) {
  return lower_bound_lanes<16>(v, x, y, z, limit2, lb2);
}

IMPINGE_SIMD_CLONES_NARROW
std::uint32_t group_lower_bounds_narrow(const float (*v)[kGroup], float x, float y, float z, float limit2, float* lb2) {
  return lower_bound_lanes<8>(v, x, y, z, limit2, lb2);
}

/// The squared lower bounds of the distance from q = (x, y, z) (float, mm, about the query's shift) to the
/// triangles of a group (Impl::Group's rows v: plane, then the three edges' lines), lane by lane: h^2 + max(0,
/// s_0, s_1, s_2)^2, with h the distance to the triangle's plane and s_e the distance of q's foot point in that
/// plane beyond edge e's line (negative inside). The in-plane distance to the triangle is at least the largest
/// s_e (the triangle is the intersection of the three half-planes), and equal to it where the closest point
/// lies on the face or an edge; below it only in a corner's region. kGroup lanes into lb2 (mm^2); returns the
/// lanes whose bound is at most limit2 (mm^2; bit l: lane l). Throws nothing. Two forms with the same
/// arithmetic lane by lane, `wide` choosing (detail::use_wide_vectors, decided once a search):
/// - AVX-512: the sixteen lanes as one register a row (group_lower_bounds_wide);
/// - AVX2 and the baseline (clones): eight lanes at a time (group_lower_bounds_narrow). The sixteen-lane form
///   spilled every row to the stack in the AVX2 clone (some 300 instructions a call): lhdl-ct's 1,000-frame
///   motion took 1.8x the CPU time of this form on a CPU without AVX-512 (measured with
///   -DIMPINGE_SIMD_NO_AVX512, core/simd_clones.hpp).
std::uint32_t group_lower_bounds(bool wide, const float (*v)[kGroup], float x, float y, float z, float limit2,
                                 float* lb2) {
  return wide ? group_lower_bounds_wide(v, x, y, z, limit2, lb2) : group_lower_bounds_narrow(v, x, y, z, limit2, lb2);
}

#endif

}  // namespace

bool SignedDistanceQuery::available() {
#if defined(IMPINGE_HAVE_EMBREE) || defined(IMPINGE_HAVE_CGAL)
  return true;
#else
  return false;
#endif
}

SignedDistanceQuery::~SignedDistanceQuery() = default;
SignedDistanceQuery::SignedDistanceQuery(SignedDistanceQuery&&) noexcept = default;
SignedDistanceQuery& SignedDistanceQuery::operator=(SignedDistanceQuery&&) noexcept = default;

std::int64_t SignedDistanceQuery::triangles() const { return static_cast<std::int64_t>(impl_->a.size()); }

std::uint64_t SignedDistanceQuery::id() const { return impl_->serial; }

bool SignedDistanceQuery::cropped() const { return impl_->crop != nullptr; }

std::int64_t SignedDistanceQuery::cropped_fallbacks() const { return impl_->crop ? impl_->crop->fallbacks.load() : 0; }

const SignedDistanceQuery* SignedDistanceQuery::Impl::whole_query() {
  if (!crop) return nullptr;
  Crop& g = *crop;
  std::call_once(g.whole_built, [&g] { g.whole = std::make_unique<SignedDistanceQuery>(g.whole_mesh); });
  g.fallbacks.fetch_add(1, std::memory_order_relaxed);
  return g.whole.get();
}

const SignedDistanceQuery* SignedDistanceQuery::Impl::fallback(const Eigen::Vector3d& q, double radius) {
  if (!crop || crop->covers(q, radius)) return nullptr;
  return whole_query();
}

namespace {
struct Search {
  const SignedDistanceQuery::Impl* m;
  Eigen::Vector3d q;
  double best;             // mm; the radius until something is found
  std::int64_t kept = -1;  // kept triangle
  Eigen::Vector3d point;
  int feature = 0;
  bool any_only = false;
  bool wide = detail::use_wide_vectors();  // the lower bounds' form (decided once a search, not once a group)
  double margin = kBoxMarginMm;            // mm: the float lower bounds' rounding at q, and more (run sets it)
  NearbyTriangles* collect = nullptr;      // filling: every group the walk reaches (the radius stays put)
};

// Whether kept triangle t at distance d replaces the best so far: nearer, or as near with a lower index
// (ties: at a shared edge or corner; the answer then does not depend on the order of the tests). With
// nothing found yet, anything within the radius.
bool better(const Search& s, double d, std::int64_t t) {
  return d < s.best || (d == s.best && (s.kept < 0 || t < s.kept));
}

#ifdef IMPINGE_HAVE_EMBREE
// The distance from (x, y, z) to box b (lower x, y, z, upper x, y, z), float, mm.
float box_distance(const std::array<float, 6>& b, float x, float y, float z) {
  const float dx = std::max(std::max(b[0] - x, x - b[3]), 0.f);
  const float dy = std::max(std::max(b[1] - y, y - b[4]), 0.f);
  const float dz = std::max(std::max(b[2] - z, z - b[5]), 0.f);
  return std::sqrt(dx * dx + dy * dy + dz * dz);
}

// A group whose box the query's ball reaches (q = (x, y, z), float, about the shift): the triangles whose
// lower bound (group_lower_bounds, widened by the search's margin for float rounding) is within the best
// distance so far get the exact test. Whether one of them became the best.
bool visit_group(Search* s, std::uint32_t group, float x, float y, float z) {
  const SignedDistanceQuery::Impl::Group& g = s->m->groups[group];
  float lb2[kGroup];
  const float first = static_cast<float>(s->best + s->margin);
  std::uint32_t bits = group_lower_bounds(s->wide, g.v, x, y, z, first * first, lb2);
  bool closer = false;
  for (; bits != 0; bits &= bits - 1) {  // the lanes within the first limit, in order; the limit shrinks
    const int l = __builtin_ctz(bits);
    const float limit = static_cast<float>(s->best + s->margin);
    if (!(lb2[l] <= limit * limit) || g.triangle[l] < 0) continue;
    const auto t = static_cast<std::size_t>(g.triangle[l]);
    if (static_cast<std::int64_t>(t) == s->kept) continue;  // the best so far (a seed): tested already
    Eigen::Vector3d point;
    int feature = 0;
    const double d = s->m->distance_to(t, s->q, point, feature);
    if (!better(*s, d, static_cast<std::int64_t>(t))) continue;
    s->best = d, s->kept = static_cast<std::int64_t>(t), s->point = point, s->feature = feature;
    closer = true;
    if (s->any_only) break;
  }
  return closer;
}

// Embree's callback for a group the walk reaches (visit_group); a walk that fills a NearbyTriangles also
// lists the group, and keeps its radius.
bool visit(RTCPointQueryFunctionArguments* args) {
  auto* s = static_cast<Search*>(args->userPtr);
  if (s->collect != nullptr) {  // filling: list the group; the walk's radius stays that of the list's ball
    NearbyTriangles& n = *s->collect;
    const float d = box_distance(s->m->group_box[args->primID], args->query->x, args->query->y, args->query->z);
    if (n.count < NearbyTriangles::kMax) {  // in order of the box's distance from the centre (insertion)
      int i = n.count;
      for (; i > 0 && n.box_distance[i - 1] > d; --i)
        n.group[i] = n.group[i - 1], n.box_distance[i] = n.box_distance[i - 1];
      n.group[i] = static_cast<std::int32_t>(args->primID), n.box_distance[i] = d;
    }
    ++n.count;
    // Its triangles only where its box comes within the best distance so far (as a walk that shrinks).
    if (static_cast<double>(d) <= s->best + kBoxReachMm)
      visit_group(s, args->primID, args->query->x, args->query->y, args->query->z);
    return false;
  }
  const bool closer = visit_group(s, args->primID, args->query->x, args->query->y, args->query->z);
  if (closer) args->query->radius = s->any_only ? 0.f : static_cast<float>(s->best + kBoxMarginMm);
  return closer;
}
#endif

bool run(const SignedDistanceQuery::Impl& m, Search& s, double radius, std::int64_t seed = -1,
         NearbyTriangles* nearby = nullptr) {
  require(radius > 0, "signed distance: the query radius must be > 0 mm");
  s.best = radius;
  if (seed >= 0 && seed < static_cast<std::int64_t>(m.kept.size()) && m.kept[static_cast<std::size_t>(seed)] >= 0) {
    const auto t = static_cast<std::size_t>(m.kept[static_cast<std::size_t>(seed)]);
    Eigen::Vector3d point;
    int feature = 0;
    const double d = m.distance_to(t, s.q, point, feature);
    if (better(s, d, static_cast<std::int64_t>(t)))
      s.best = d, s.kept = static_cast<std::int64_t>(t), s.point = point, s.feature = feature;
  }
#ifdef IMPINGE_HAVE_EMBREE
  s.margin = kBoxMarginMm + 1e-6 * (m.extent + (s.q - m.shift).cwiseAbs().maxCoeff());
  RTCPointQuery query;
  query.x = static_cast<float>(s.q.x() - m.shift.x());
  query.y = static_cast<float>(s.q.y() - m.shift.y());
  query.z = static_cast<float>(s.q.z() - m.shift.z());
  query.time = 0.f;
  query.radius =
      std::isfinite(s.best) ? static_cast<float>(s.best + kBoxMarginMm) : std::numeric_limits<float>::infinity();
  double listed = 0;  // mm: the ball of a NearbyTriangles this walk refills
  if (nearby != nullptr && std::isfinite(s.best)) {
    const Eigen::Vector3d q(query.x, query.y, query.z);  // about the shift, as the groups' boxes
    const Eigen::Vector3d c(nearby->centre[0], nearby->centre[1], nearby->centre[2]);
    const double off = (q - c).norm();
    if (nearby->query == m.serial && nearby->radius > 0 &&
        off + s.best + kBoxReachMm <= static_cast<double>(nearby->radius)) {
      // This search's ball (and the boxes' margin) lies inside the listed ball: every group it would
      // reach is listed. A group's box lies at least its distance from the centre less `off` from q, so
      // the groups are visited nearest first until that exceeds the best distance so far.
      for (std::int32_t i = 0; i < nearby->count; ++i) {
        if (static_cast<double>(nearby->box_distance[i]) - off > s.best + kBoxReachMm) break;
        visit_group(&s, static_cast<std::uint32_t>(nearby->group[i]), query.x, query.y, query.z);
      }
      return s.kept >= 0;
    }
    // Refill about q: the walk keeps the radius of the list's ball (a little more than this search's own).
    nearby->query = 0, nearby->radius = -1.f, nearby->count = 0;
    listed = s.best + kNearbySlackMm;
    query.radius = static_cast<float>(listed + kBoxMarginMm);
    s.collect = nearby;
  }
  RTCPointQueryContext context;
  rtcInitPointQueryContext(&context);
  rtcPointQuery(m.scene, &query, &context, visit, &s);
  if (s.collect != nullptr) {
    s.collect = nullptr;
    if (nearby->count <= NearbyTriangles::kMax) {
      nearby->query = m.serial;
      nearby->centre[0] = query.x, nearby->centre[1] = query.y, nearby->centre[2] = query.z;
      nearby->radius = static_cast<float>(listed) * (1.f - 0x1p-20f);  // rounded down, below the ball walked
    } else {
      nearby->count = 0;
    }
  }
#elif defined(IMPINGE_HAVE_CGAL)
  if (m.triangles.empty()) return false;  // a crop that kept no triangle
  using K = SignedDistanceQuery::Impl::K;
  const auto hit = m.tree.closest_point_and_primitive(K::Point_3(s.q.x(), s.q.y(), s.q.z()));
  const auto t = static_cast<std::size_t>(hit.second - m.triangles.begin());
  Eigen::Vector3d point;
  int feature = 0;
  const double d = m.distance_to(t, s.q, point, feature);
  if (better(s, d, static_cast<std::int64_t>(t)))
    s.best = d, s.kept = static_cast<std::int64_t>(t), s.point = point, s.feature = feature;
#endif
  return s.kept >= 0;
}
}  // namespace

bool SignedDistanceQuery::closest(const Eigen::Vector3d& q, double radius_mm, ClosestSurfacePoint& out) const {
  if (const SignedDistanceQuery* whole = impl_->fallback(q, radius_mm)) return whole->closest(q, radius_mm, out);
  Search s{impl_.get(), q, 0, -1, {}, 0, false};
  if (!run(*impl_, s, radius_mm)) return false;
  out.distance_mm = s.best;
  out.sign = 1;
  out.triangle = impl_->face[static_cast<std::size_t>(s.kept)];
  out.point = s.point;
  out.rule = SignRule::pseudo_normal;
  return true;
}

bool SignedDistanceQuery::any_within(const Eigen::Vector3d& q, double radius_mm) const {
  if (const SignedDistanceQuery* whole = impl_->fallback(q, radius_mm)) return whole->any_within(q, radius_mm);
  Search s{impl_.get(), q, 0, -1, {}, 0, true};
  return run(*impl_, s, radius_mm);
}

bool SignedDistanceQuery::signed_distance(const Eigen::Vector3d& q, double radius_mm, int hint,
                                          ClosestSurfacePoint& out, std::int64_t seed, NearbyTriangles* nearby) const {
  if (const SignedDistanceQuery* whole = impl_->fallback(q, radius_mm))
    return whole->signed_distance(q, radius_mm, hint, out, seed, nearby);
  Search s{impl_.get(), q, 0, -1, {}, 0, false};
  if (!run(*impl_, s, radius_mm, seed, nearby)) return false;
  const Impl& m = *impl_;
  const auto t = static_cast<std::size_t>(s.kept);
  bool trusted = true;
  Eigen::Vector3d n;
  if (s.feature == 0) {
    n = m.face_normal[t];
  } else if (s.feature <= 3) {
    // The sum of the two faces' normals (addition commutes: the same bits from either face), zero on an
    // irregular edge.
    const std::int32_t twin = m.edge_twin[3 * t + static_cast<std::size_t>(s.feature - 1)];
    trusted = twin >= 0;
    n = trusted ? Eigen::Vector3d(m.face_normal[t] + m.face_normal[static_cast<std::size_t>(twin)])
                : Eigen::Vector3d::Zero();
  } else {
    const auto v = static_cast<std::size_t>(m.corner[t][s.feature - 4]);
    n = m.vertex_normal[v];
    trusted = !m.vertex_irregular[v];
  }
  const Eigen::Vector3d w = q - s.point;
  const double along = w.dot(n), scale = w.norm() * n.norm();
  int sign = along >= 0 ? 1 : -1;
  if (s.best > 1e-6 && !(std::abs(along) >= 1e-3 * scale)) trusted = false;  // q in the tangent plane
  const bool local = trusted;  // the pseudo-normal is sound here (a regular feature, q off its tangent plane)
  if (hint != 0 && s.best > 1e-6 && hint != sign) trusted = false;
  out.rule = SignRule::pseudo_normal;
  if (!trusted && s.best > 1e-6) {
    // The winding number where the pseudo-normal cannot be trusted; where it cannot tell either (the file
    // comment, rule 3), the pseudo-normal if it is sound, else undecided.
    const double wn = winding_number_decided(q);
    if (std::abs(wn - 0.5) >= kUndecidedBand) {
      sign = wn >= 0.5 ? -1 : 1;
      out.rule = SignRule::winding_number;
    } else if (!local) {
      sign = 1;
      out.rule = SignRule::undecided;
    }
  }
  out.distance_mm = s.best;
  out.sign = sign;
  out.triangle = m.face[t];
  out.point = s.point;
  return true;
}

}  // namespace impinge
