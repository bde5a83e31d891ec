#include "impinge/detection/detection.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "impinge/core/error.hpp"
#include "impinge/sampling/layered_sampling.hpp"
#include "core/simd_clones.hpp"
#include "core/z_order.hpp"

namespace impinge {

ScanSet make_scan_set(PointsRef P, const std::vector<std::uint8_t>& mask) {
  require(
      static_cast<Eigen::Index>(mask.size()) == P.rows(),
      "scan set: mask has " + std::to_string(mask.size()) + " entries for " + std::to_string(P.rows()) + " vertices");
  require(P.rows() < Eigen::Index(std::numeric_limits<std::int32_t>::max()), "scan set: too many vertices");
  // Order the vertices along a Z curve over their (phi, theta) direction (4096 x 8192 cells):
  // a small rotation keeps neighbours neighbours, so consecutive look-ups hit the same cache
  // lines of the other map. Results are returned in this order and mapped back by `index`.
  std::vector<std::pair<std::uint64_t, std::int32_t>> order;
  for (Eigen::Index i = 0; i < P.rows(); ++i) {
    if (!mask[static_cast<std::size_t>(i)]) continue;
    order.emplace_back(detail::direction_z_order(P(i, 0), P(i, 1), P(i, 2)), static_cast<std::int32_t>(i));
  }
  std::sort(order.begin(), order.end());
  ScanSet s;
  s.vertices = P.rows();
  for (const auto& [key, i] : order) {
    s.index.push_back(i);
    s.x.push_back(P(i, 0));
    s.y.push_back(P(i, 1));
    s.z.push_back(P(i, 2));
  }
  return s;
}

namespace {
/// R (3 x 3) row by row, then t: the 12 numbers of pose_block.
std::array<double, 12> pose_rows(const Eigen::Matrix3d& R, const Eigen::Vector3d& t) {
  return {R(0, 0), R(0, 1), R(0, 2), R(1, 0), R(1, 1), R(1, 2), R(2, 0), R(2, 1), R(2, 2), t.x(), t.y(), t.z()};
}
/// q = R p + t and |q| for a block of vertices (vectorised clones).
IMPINGE_SIMD_CLONES
void pose_block(const double* __restrict X, const double* __restrict Y, const double* __restrict Z, int m,
                const double* __restrict Rt, double* __restrict qx, double* __restrict qy, double* __restrict qz,
                double* __restrict radius) {
  for (int j = 0; j < m; ++j) {
    const double x = X[j], y = Y[j], z = Z[j];
    qx[j] = Rt[0] * x + Rt[1] * y + Rt[2] * z + Rt[9];
    qy[j] = Rt[3] * x + Rt[4] * y + Rt[5] * z + Rt[10];
    qz[j] = Rt[6] * x + Rt[7] * y + Rt[8] * z + Rt[11];
    radius[j] = std::sqrt(qx[j] * qx[j] + qy[j] * qy[j] + qz[j] * qz[j]);
  }
}
/// gap = side * (d - r) as float; NaN for no surface or r = 0.
IMPINGE_SIMD_CLONES
void gap_block(const double* __restrict d, const double* __restrict radius, double side, int m, float* __restrict gap) {
  for (int j = 0; j < m; ++j)
    gap[j] = radius[j] > 0 ? static_cast<float>(side * (d[j] - radius[j])) : std::numeric_limits<float>::quiet_NaN();
}
}  // namespace

template <typename Scalar>
void scan_gaps_compact(const ScanSet& set, const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
                       const RadialDistanceMapT<Scalar>& map, ScanSide side, float* gap_mm) {
  const double s = static_cast<double>(static_cast<int>(side));
  const std::array<double, 12> Rt = pose_rows(R, t);
  constexpr std::int64_t kBlock = 256;
  double qx[kBlock], qy[kBlock], qz[kBlock], radius[kBlock], d[kBlock];
  const std::int64_t n = set.size();
  for (std::int64_t b = 0; b < n; b += kBlock) {
    const int m = static_cast<int>(std::min(kBlock, n - b));
    pose_block(set.x.data() + b, set.y.data() + b, set.z.data() + b, m, Rt.data(), qx, qy, qz, radius);
    map.lookup_many_soa(qx, qy, qz, m, d);
    gap_block(d, radius, s, m, gap_mm + b);
  }
}

template <typename Scalar>
std::int64_t scan_gaps_compact(const ScanSet& set, const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
                               const RadialDistanceMapT<Scalar>& map, ScanSide side, float* gap_mm,
                               const FirstHitCaster* exact) {
  if (exact == nullptr) {
    scan_gaps_compact(set, R, t, map, side, gap_mm);
    return 0;
  }
  return scan_gaps_compact(set, 0, set.size(), R, t, map, side, gap_mm, exact);
}

template <typename Scalar>
std::int64_t scan_gaps_compact(const ScanSet& set, std::int64_t first, std::int64_t count, const Eigen::Matrix3d& R,
                               const Eigen::Vector3d& t, const RadialDistanceMapT<Scalar>& map, ScanSide side,
                               float* gap_mm, const FirstHitCaster* exact) {
  require(first >= 0 && count >= 0 && first + count <= set.size(), "scan: vertex range outside the set");
  const double s = static_cast<double>(static_cast<int>(side));
  const std::array<double, 12> Rt = pose_rows(R, t);
  constexpr std::int64_t kBlock = 256;
  double qx[kBlock], qy[kBlock], qz[kBlock], radius[kBlock], d[kBlock];
  const std::int64_t n = first + count;
  struct Pending {
    std::int64_t j;
    Eigen::Vector3d q;
    double radius;
  };
  thread_local std::vector<Pending> pending;  // reused: no allocation per scan once grown
  pending.clear();
  for (std::int64_t b = first; b < n; b += kBlock) {
    const int m = static_cast<int>(std::min(kBlock, n - b));
    pose_block(set.x.data() + b, set.y.data() + b, set.z.data() + b, m, Rt.data(), qx, qy, qz, radius);
    float* g = gap_mm + b;
    if (exact == nullptr) {
      map.lookup_many_soa(qx, qy, qz, m, d);
      gap_block(d, radius, s, m, g);
      continue;
    }
    map.lookup_many_soa_marked(qx, qy, qz, m, d);
    gap_block(d, radius, s, m, g);
    // Marked stencils came back as -inf, so their gaps are +-inf: noted here, resolved by the ray
    // cast after the scan, all together (the BVH stays in cache from one ray to the next).
    for (int j = 0; j < m; ++j)
      if (std::isinf(g[j])) pending.push_back({b + j, Eigen::Vector3d(qx[j], qy[j], qz[j]), radius[j]});
  }
  for (const Pending& q : pending) {
    const double h = exact->first_hit(q.q);
    gap_mm[q.j] = std::isfinite(h) && q.radius > 0 ? static_cast<float>(s * (h - q.radius))
                                                   : std::numeric_limits<float>::quiet_NaN();
  }
  return static_cast<std::int64_t>(pending.size());
}

std::int64_t scan_layered(const ScanSet& set, const Eigen::Matrix3d& R, const Eigen::Vector3d& t, const LayeredMap& map,
                          float* gap_mm, const FirstHitCaster* exact) {
  return scan_layered(set, 0, set.size(), R, t, map, gap_mm, exact);
}

std::int64_t scan_layered(const ScanSet& set, std::int64_t first, std::int64_t count, const Eigen::Matrix3d& R,
                          const Eigen::Vector3d& t, const LayeredMap& map, float* gap_mm, const FirstHitCaster* exact) {
  require(first >= 0 && count >= 0 && first + count <= set.size(), "layered scan: vertex range outside the set");
  const std::array<double, 12> Rt = pose_rows(R, t);
  constexpr std::int64_t kBlock = 256;
  double qx[kBlock], qy[kBlock], qz[kBlock], radius[kBlock], d[kBlock];
  std::uint8_t flag[kBlock];
  const std::int64_t n = first + count;
  std::int64_t refined = 0;
  for (std::int64_t b = first; b < n; b += kBlock) {
    const int m = static_cast<int>(std::min(kBlock, n - b));
    pose_block(set.x.data() + b, set.y.data() + b, set.z.data() + b, m, Rt.data(), qx, qy, qz, radius);
    map.signed_distance_many_soa(qx, qy, qz, m, d, exact != nullptr ? flag : nullptr);
    for (int j = 0; j < m; ++j) {
      double g = d[j];
      if (exact != nullptr && flag[j]) {
        g = signed_radial_distance_exact(*exact, Eigen::Vector3d(qx[j], qy[j], qz[j]));
        ++refined;
      }
      gap_mm[b + j] = std::isfinite(g) ? static_cast<float>(g) : std::numeric_limits<float>::quiet_NaN();
    }
  }
  return refined;
}

void expand_layered_scan(const ScanSet& set, const float* gap_mm, ScanGaps& out) {
  require(out.gap_mm.size() == static_cast<std::size_t>(set.vertices) && out.status.size() == out.gap_mm.size(),
          "layered scan: expand the body's first-surface scan first");
  for (std::size_t j = 0; j < set.index.size(); ++j) {
    if (gap_mm[j] == std::numeric_limits<float>::infinity()) continue;  // skipped (scan_layered_near)
    const auto i = static_cast<std::size_t>(set.index[j]);
    out.gap_mm[i] = gap_mm[j];
    out.status[i] = std::isnan(gap_mm[j]) ? ScanGaps::no_surface : ScanGaps::tested_layered;
  }
}

template <typename Scalar>
void scan_gaps(PointsRef P, const Eigen::Matrix3d& R, const std::vector<std::uint8_t>& mask,
               const RadialDistanceMapT<Scalar>& map, ScanSide side, ScanGaps& out) {
  const ScanSet set = make_scan_set(P, mask);
  std::vector<float> gaps(static_cast<std::size_t>(set.size()));
  scan_gaps_compact(set, R, Eigen::Vector3d::Zero(), map, side, gaps.data());
  expand_scan(set, gaps.data(), out);
}

void expand_scan(const ScanSet& set, const float* gap_mm, ScanGaps& out) {
  const auto n = static_cast<std::size_t>(set.vertices);
  out.gap_mm.assign(n, std::numeric_limits<float>::quiet_NaN());
  out.status.assign(n, ScanGaps::beyond_reach);
  out.refined = 0;
  for (std::size_t j = 0; j < set.index.size(); ++j) {
    const auto i = static_cast<std::size_t>(set.index[j]);
    out.gap_mm[i] = gap_mm[j];
    out.status[i] = std::isnan(gap_mm[j]) ? ScanGaps::no_surface : ScanGaps::tested;
  }
}

template <typename Scalar>
std::vector<std::uint8_t> first_surface_mask(PointsRef P, const RadialDistanceMapT<Scalar>& own_map,
                                             double tolerance_mm, double max_radius_mm) {
  std::vector<std::uint8_t> mask(static_cast<std::size_t>(P.rows()), 0);
  for (Eigen::Index i = 0; i < P.rows(); ++i) {
    const Eigen::Vector3d p = P.row(i).transpose();
    const double r = p.norm();
    if (!(r > 0) || r > max_radius_mm) continue;
    double d = own_map.lookup(p);
    if (std::isnan(d)) {
      // At the edge of the map's coverage: compare with the nearest surface among the stencil
      // nodes that have one (a rim vertex of an outer shell is still hidden by the inner one).
      // With none, the map cannot confirm the vertex is on the first surface: skip it.
      const Stencil st = own_map.scheme().interpolate(p / r);
      d = -std::numeric_limits<double>::infinity();
      for (int k = 0; k < 4; ++k)
        if (own_map.has_surface(st.nodes[k]))
          d = d == -std::numeric_limits<double>::infinity() ? double(own_map.at(st.nodes[k]))
                                                            : std::min<double>(d, own_map.at(st.nodes[k]));
    }
    if (r <= d + tolerance_mm) mask[static_cast<std::size_t>(i)] = 1;
  }
  return mask;
}

template <typename Scalar>
std::vector<std::uint8_t> first_surface_mask(PointsRef P, const RadialDistanceMapT<Scalar>& own_map,
                                             double tolerance_mm, double max_radius_mm,
                                             const FirstHitCaster& own_exact) {
  std::vector<std::uint8_t> mask(static_cast<std::size_t>(P.rows()), 0);
  const SamplingScheme& scheme = own_map.scheme();
  for (Eigen::Index i = 0; i < P.rows(); ++i) {
    const Eigen::Vector3d p = P.row(i).transpose();
    const double r = p.norm();
    if (!(r > 0) || r > max_radius_mm) continue;
    const Stencil st = scheme.interpolate(p / r);
    bool decidable = true;
    for (int k = 0; k < 4; ++k) {
      const Scalar v = own_map.at(st.nodes[k]);
      decidable = decidable && std::isfinite(v) && !has_discontinuity_mark(v);
    }
    double d;
    if (decidable) {
      d = 0;
      for (int k = 0; k < 4; ++k) d += st.weights[k] * double(own_map.at(st.nodes[k]));
    } else {
      // Only a hit nearer than r - tolerance_mm matters (the test below): the rays end just beyond it (1e-6
      // relative, so that no rounding of r - tolerance + tolerance can tell a hit there from none).
      // +inf: nothing in front of the vertex that near.
      d = own_exact.first_hit(p, r - tolerance_mm + 1e-6 * (1 + r));
    }
    if (r <= d + tolerance_mm) mask[static_cast<std::size_t>(i)] = 1;
  }
  return mask;
}

ScanSummary summarize_scan(const ScanGaps& g, const Eigen::VectorXd& area, const ImpingementLevels& levels,
                           LevelQuantity levels_on) {
  ScanSummary s;
  summarize_scan(g, area, levels, s, levels_on);
  return s;
}

const char* to_string(LevelQuantity q) { return enum_name(kLevelQuantityNames, q); }

LevelQuantity parse_level_quantity(const std::string& text, const std::string& context) {
  return parse_enum(kLevelQuantityNames, text, context);
}

std::uint8_t vertex_level(const ScanGaps& g, std::size_t i, const ImpingementLevels& levels, LevelQuantity q) {
  if (q == LevelQuantity::distance && !g.distance_mm.empty()) {
    const float d = g.distance_mm[i];
    if (!std::isnan(d)) return levels.level(d);
    const bool tested = g.status[i] == ScanGaps::tested || g.status[i] == ScanGaps::tested_layered;
    return tested ? 0 : 255;
  }
  return std::isnan(g.gap_mm[i]) ? 255 : levels.level(g.gap_mm[i]);
}

void summarize_scan(const ScanGaps& g, const Eigen::VectorXd& area, const ImpingementLevels& levels, ScanSummary& s,
                    LevelQuantity levels_on) {
  require(g.status.size() == g.gap_mm.size() && (g.distance_mm.empty() || g.distance_mm.size() == g.gap_mm.size()) &&
              area.size() == static_cast<Eigen::Index>(g.gap_mm.size()),
          "scan summary: " + std::to_string(g.gap_mm.size()) + " gaps with " + std::to_string(g.status.size()) +
              " statuses, " + std::to_string(g.distance_mm.size()) + " distances and " + std::to_string(area.size()) +
              " vertex areas");
  s.level_vertices.assign(static_cast<std::size_t>(levels.count()), 0);
  s.level_area_mm2.assign(static_cast<std::size_t>(levels.count()), 0.0);
  s.vertices_tested = s.vertices_no_surface = s.vertices_beyond_reach = s.vertices_penetrating = 0;
  s.vertices_tested_layered = 0;
  s.min_gap_layered_mm = std::numeric_limits<double>::quiet_NaN();
  double min_layered = std::numeric_limits<double>::infinity();
  s.area_penetrating_mm2 = 0;
  s.min_gap_mm = std::numeric_limits<double>::quiet_NaN();
  s.vertices = static_cast<std::int64_t>(g.gap_mm.size());
  s.vertices_refined = g.refined;
  s.levels_on = g.distance_mm.empty() ? LevelQuantity::radial_gap : levels_on;
  s.min_distance_mm = std::numeric_limits<double>::quiet_NaN();
  s.vertices_distance = s.vertices_inside = 0;
  s.area_inside_mm2 = 0;
  s.distance_winding = g.distance_winding;
  s.distance_undecided = g.distance_undecided;
  double min_gap = std::numeric_limits<double>::infinity();
  double min_distance = std::numeric_limits<double>::infinity();
  // One pass over the vertices (each sum still adds its terms in vertex order).
  const bool has_distance = !g.distance_mm.empty();
  const std::size_t n = g.gap_mm.size();
  for (std::size_t i = 0; i < n; ++i) {
    int no_surface = 0;
    if (i % 8 == 0 && i + 8 <= n && eight_without_value(g, i, no_surface)) {  // most of them: eight at once
      s.vertices_no_surface += no_surface;
      s.vertices_beyond_reach += 8 - no_surface;
      i += 7;
      continue;
    }
    if (vertex_unmeasured(g, i)) {
      ++s.vertices_beyond_reach;
      continue;
    }
    const std::uint8_t status = g.status[i];
    const float d = has_distance ? g.distance_mm[i] : std::numeric_limits<float>::quiet_NaN();
    const double a = area[static_cast<Eigen::Index>(i)];
    if (status == ScanGaps::beyond_reach) {
      ++s.vertices_beyond_reach;
    } else if (status == ScanGaps::no_surface) {
      ++s.vertices_no_surface;
    } else {
      ++s.vertices_tested;
      const double gap = g.gap_mm[i];
      if (status == ScanGaps::tested_layered) {
        ++s.vertices_tested_layered;
        min_layered = std::min(min_layered, gap);
      }
      min_gap = std::min(min_gap, gap);
      if (gap <= 0) {
        ++s.vertices_penetrating;
        s.area_penetrating_mm2 += a;
      }
    }
    const std::uint8_t lv = vertex_level(g, i, levels, s.levels_on);
    if (lv != 255) {
      ++s.level_vertices[lv];
      s.level_area_mm2[lv] += a;
    }
    if (!std::isnan(d)) {
      ++s.vertices_distance;
      min_distance = std::min(min_distance, static_cast<double>(d));
      if (d < 0) ++s.vertices_inside, s.area_inside_mm2 += a;
    }
  }
  if (s.vertices_tested > 0) s.min_gap_mm = min_gap;
  if (s.vertices_tested_layered > 0) s.min_gap_layered_mm = min_layered;
  if (s.vertices_distance > 0) s.min_distance_mm = min_distance;
}

template void scan_gaps<float>(PointsRef, const Eigen::Matrix3d&, const std::vector<std::uint8_t>&,
                               const RadialDistanceMapT<float>&, ScanSide, ScanGaps&);
template void scan_gaps<double>(PointsRef, const Eigen::Matrix3d&, const std::vector<std::uint8_t>&,
                                const RadialDistanceMapT<double>&, ScanSide, ScanGaps&);
template void scan_gaps_compact<float>(const ScanSet&, const Eigen::Matrix3d&, const Eigen::Vector3d&,
                                       const RadialDistanceMapT<float>&, ScanSide, float*);
template void scan_gaps_compact<double>(const ScanSet&, const Eigen::Matrix3d&, const Eigen::Vector3d&,
                                        const RadialDistanceMapT<double>&, ScanSide, float*);
template std::vector<std::uint8_t> first_surface_mask<float>(PointsRef, const RadialDistanceMapT<float>&, double,
                                                             double);
template std::vector<std::uint8_t> first_surface_mask<float>(PointsRef, const RadialDistanceMapT<float>&, double,
                                                             double, const FirstHitCaster&);
template std::vector<std::uint8_t> first_surface_mask<double>(PointsRef, const RadialDistanceMapT<double>&, double,
                                                              double, const FirstHitCaster&);
template std::int64_t scan_gaps_compact<float>(const ScanSet&, const Eigen::Matrix3d&, const Eigen::Vector3d&,
                                               const RadialDistanceMapT<float>&, ScanSide, float*,
                                               const FirstHitCaster*);
template std::int64_t scan_gaps_compact<double>(const ScanSet&, const Eigen::Matrix3d&, const Eigen::Vector3d&,
                                                const RadialDistanceMapT<double>&, ScanSide, float*,
                                                const FirstHitCaster*);
template std::vector<std::uint8_t> first_surface_mask<double>(PointsRef, const RadialDistanceMapT<double>&,
                                                              double, double);
template std::int64_t scan_gaps_compact<float>(const ScanSet&, std::int64_t, std::int64_t, const Eigen::Matrix3d&,
                                               const Eigen::Vector3d&, const RadialDistanceMapT<float>&, ScanSide,
                                               float*, const FirstHitCaster*);
template std::int64_t scan_gaps_compact<double>(const ScanSet&, std::int64_t, std::int64_t, const Eigen::Matrix3d&,
                                                const Eigen::Vector3d&, const RadialDistanceMapT<double>&, ScanSide,
                                                float*, const FirstHitCaster*);

}  // namespace impinge
