#include "impinge/detection.hpp"

#include <cmath>

namespace impinge {

template <typename Scalar>
void scan_gaps(const Vertices& P, const Eigen::Matrix3d& R, const std::vector<std::uint8_t>& mask,
               const RadialDistanceMapT<Scalar>& map, ScanSide side, ScanGaps& out) {
  const Eigen::Index n = P.rows();
  out.gap_mm.resize(static_cast<std::size_t>(n));
  out.status.resize(static_cast<std::size_t>(n));
  const double s = static_cast<double>(static_cast<int>(side));
  const float nan = std::numeric_limits<float>::quiet_NaN();
  // Vertices to look up are gathered in blocks: one call into the scheme per block, the
  // per-vertex stencil inlined there (no virtual dispatch per vertex).
  constexpr int kBlock = 256;
  double pts[3 * kBlock], radius[kBlock], d[kBlock];
  std::size_t index[kBlock];
  int m = 0;
  auto flush = [&] {
    map.sample_many(pts, m, d);
    for (int j = 0; j < m; ++j) {
      const std::size_t k = index[j];
      if (std::isnan(d[j])) {
        out.gap_mm[k] = nan;
        out.status[k] = ScanGaps::no_surface;
      } else {
        out.gap_mm[k] = static_cast<float>(s * (d[j] - radius[j]));
        out.status[k] = ScanGaps::tested;
      }
    }
    m = 0;
  };
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto k = static_cast<std::size_t>(i);
    if (!mask[k]) {
      out.gap_mm[k] = nan;
      out.status[k] = ScanGaps::beyond_reach;
      continue;
    }
    const Eigen::Vector3d q = R * P.row(i).transpose();
    const double r = q.norm();
    if (!(r > 0)) {
      out.gap_mm[k] = nan;
      out.status[k] = ScanGaps::no_surface;
      continue;
    }
    pts[3 * m] = q.x(), pts[3 * m + 1] = q.y(), pts[3 * m + 2] = q.z();
    radius[m] = r;
    index[m] = k;
    if (++m == kBlock) flush();
  }
  flush();
}

template <typename Scalar>
std::vector<std::uint8_t> first_surface_mask(const Vertices& P, const RadialDistanceMapT<Scalar>& own_map,
                                             double tolerance_mm, double max_radius_mm) {
  std::vector<std::uint8_t> mask(static_cast<std::size_t>(P.rows()), 0);
  for (Eigen::Index i = 0; i < P.rows(); ++i) {
    const Eigen::Vector3d p = P.row(i).transpose();
    const double r = p.norm();
    if (!(r > 0) || r > max_radius_mm) continue;
    double d = own_map.sample(p);
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

ScanSummary summarize_scan(const ScanGaps& g, const Eigen::VectorXd& area, const ImpingementLevels& levels) {
  ScanSummary s;
  s.vertices = static_cast<std::int64_t>(g.gap_mm.size());
  s.level_vertices.assign(static_cast<std::size_t>(levels.count()), 0);
  s.level_area_mm2.assign(static_cast<std::size_t>(levels.count()), 0.0);
  double min_gap = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < g.gap_mm.size(); ++i) {
    if (g.status[i] == ScanGaps::beyond_reach) {
      ++s.vertices_beyond_reach;
      continue;
    }
    if (g.status[i] == ScanGaps::no_surface) {
      ++s.vertices_no_surface;
      continue;
    }
    ++s.vertices_tested;
    const double gap = g.gap_mm[i];
    const double a = area[static_cast<Eigen::Index>(i)];
    min_gap = std::min(min_gap, gap);
    if (gap <= 0) {
      ++s.vertices_penetrating;
      s.area_penetrating_mm2 += a;
    }
    const std::uint8_t lv = levels.level(gap);
    ++s.level_vertices[lv];
    s.level_area_mm2[lv] += a;
  }
  if (s.vertices_tested > 0) s.min_gap_mm = min_gap;
  return s;
}

template void scan_gaps<float>(const Vertices&, const Eigen::Matrix3d&, const std::vector<std::uint8_t>&,
                               const RadialDistanceMapT<float>&, ScanSide, ScanGaps&);
template void scan_gaps<double>(const Vertices&, const Eigen::Matrix3d&, const std::vector<std::uint8_t>&,
                                const RadialDistanceMapT<double>&, ScanSide, ScanGaps&);
template std::vector<std::uint8_t> first_surface_mask<float>(const Vertices&, const RadialDistanceMapT<float>&, double,
                                                             double);
template std::vector<std::uint8_t> first_surface_mask<double>(const Vertices&, const RadialDistanceMapT<double>&,
                                                              double, double);

}  // namespace impinge
