#include "impinge/detection/surface_distance.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "core/z_order.hpp"
#include "impinge/core/error.hpp"
#include "impinge/sampling/layered_sampling.hpp"

namespace impinge {

namespace {
constexpr double kBoundMarginMm = 0.5;  // above the maps' interpolation error (experiment 10: < 0.04 mm)
constexpr double kHintMm = 0.1;         // a gap whose sign is a hint
}  // namespace

DistanceScanSet make_distance_scan_set(PointsRef P, double max_radius_mm, int cluster_size) {
  require(cluster_size >= 1, "distance scan: the cluster size must be >= 1");
  require(max_radius_mm > 0, "distance scan: the region radius must be > 0 mm");
  require(P.rows() < std::numeric_limits<std::int32_t>::max(), "distance scan: too many vertices");
  DistanceScanSet s;
  s.vertices = P.rows();
  std::vector<std::int32_t> keep;
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (Eigen::Index i = 0; i < P.rows(); ++i) {
    const Eigen::Vector3d p = P.row(i).transpose();
    if (!(p.norm() <= max_radius_mm)) continue;
    keep.push_back(static_cast<std::int32_t>(i));
    lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  }
  if (keep.empty()) {
    s.cluster_begin.push_back(0);
    return s;
  }
  const double cell = std::max((hi - lo).maxCoeff() / 2097151.0, 1e-9);
  std::vector<std::pair<std::uint64_t, std::int32_t>> keyed;
  keyed.reserve(keep.size());
  for (const std::int32_t i : keep) {
    const Eigen::Vector3d g = (P.row(i).transpose() - lo) / cell;
    keyed.emplace_back(detail::position_z_order(g.x(), g.y(), g.z()), i);
  }
  std::sort(keyed.begin(), keyed.end());
  for (std::size_t j = 0; j < keyed.size(); j += static_cast<std::size_t>(cluster_size)) {
    const std::size_t end = std::min(keyed.size(), j + static_cast<std::size_t>(cluster_size));
    s.cluster_begin.push_back(static_cast<std::int32_t>(j));
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (std::size_t k = j; k < end; ++k) {
      const Eigen::Vector3d p = P.row(keyed[k].second).transpose();
      s.index.push_back(keyed[k].second);
      s.position.push_back(p);
      c += p;
    }
    c /= static_cast<double>(end - j);
    double r = 0;
    for (std::size_t k = j; k < end; ++k) r = std::max(r, (s.position[k] - c).norm());
    s.centre.push_back(c);
    s.radius.push_back(r);
  }
  s.cluster_begin.push_back(static_cast<std::int32_t>(keyed.size()));
  return s;
}

DistanceScanStats scan_distances(const DistanceScanSet& set, const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
                                 const Eigen::Vector3d& cor, const SignedDistanceQuery& other, double reach_mm,
                                 const std::vector<float>& gap_mm, std::vector<float>& distance_mm) {
  require(reach_mm > 0 && std::isfinite(reach_mm), "distance scan: the reach must be > 0 mm and finite");
  require(gap_mm.empty() || static_cast<std::int64_t>(gap_mm.size()) == set.vertices,
          "distance scan: " + std::to_string(gap_mm.size()) + " gaps for " + std::to_string(set.vertices) +
              " vertices");
  DistanceScanStats st;
  distance_mm.assign(static_cast<std::size_t>(set.vertices), std::numeric_limits<float>::quiet_NaN());
  const Eigen::Vector3d shift = cor + t;
  ClosestSurfacePoint cp;
  for (std::int64_t c = 0; c < set.clusters(); ++c) {
    const auto b = static_cast<std::size_t>(set.cluster_begin[static_cast<std::size_t>(c)]);
    const auto e = static_cast<std::size_t>(set.cluster_begin[static_cast<std::size_t>(c) + 1]);
    double deepest = 0;  // the most negative gap of the cluster below -reach
    if (!gap_mm.empty())
      for (std::size_t k = b; k < e; ++k) {
        const float g = gap_mm[static_cast<std::size_t>(set.index[k])];
        if (g < -reach_mm) deepest = std::min(deepest, static_cast<double>(g));
      }
    const Eigen::Vector3d centre = R * set.centre[static_cast<std::size_t>(c)] + shift;
    if (deepest == 0 && !other.any_within(centre, set.radius[static_cast<std::size_t>(c)] + reach_mm)) {
      ++st.clusters_pruned;
      continue;
    }
    std::int64_t seed = -1;  // the previous vertex's closest triangle: neighbours share them
    for (std::size_t k = b; k < e; ++k) {
      const auto i = static_cast<std::size_t>(set.index[k]);
      const Eigen::Vector3d q = R * set.position[k] + shift;
      const double g = gap_mm.empty() ? std::numeric_limits<double>::quiet_NaN() : gap_mm[i];
      const int hint = g > kHintMm ? 1 : (g < -kHintMm ? -1 : 0);
      double radius = reach_mm;
      if (std::isfinite(g)) radius = g < -reach_mm ? -g + kBoundMarginMm : std::min(reach_mm, std::abs(g) + kBoundMarginMm);
      bool found = other.signed_distance(q, radius, hint, cp, seed);
      if (!found && radius < reach_mm) found = other.signed_distance(q, reach_mm, hint, cp, seed);
      if (!found) continue;
      seed = cp.triangle;
      distance_mm[i] = static_cast<float>(cp.signed_mm());
      ++st.measured;
      st.winding += cp.rule == SignRule::winding_number;
    }
  }
  return st;
}

ScanClusters cluster_scan_set(const ScanSet& set, int cluster_size) {
  require(cluster_size >= 1, "scan clusters: the cluster size must be >= 1");
  ScanClusters c;
  const std::int64_t n = set.size();
  if (n == 0) {
    c.cluster_begin.push_back(0);
    return c;
  }
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (std::int64_t j = 0; j < n; ++j) {
    const Eigen::Vector3d p(set.x[static_cast<std::size_t>(j)], set.y[static_cast<std::size_t>(j)],
                            set.z[static_cast<std::size_t>(j)]);
    lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  }
  const double cell = std::max((hi - lo).maxCoeff() / 2097151.0, 1e-9);
  std::vector<std::pair<std::uint64_t, std::int32_t>> keyed;
  keyed.reserve(static_cast<std::size_t>(n));
  for (std::int64_t j = 0; j < n; ++j) {
    const auto u = static_cast<std::size_t>(j);
    keyed.emplace_back(detail::position_z_order((set.x[u] - lo.x()) / cell, (set.y[u] - lo.y()) / cell,
                                                (set.z[u] - lo.z()) / cell),
                       static_cast<std::int32_t>(j));
  }
  std::sort(keyed.begin(), keyed.end());
  for (std::size_t b = 0; b < keyed.size(); b += static_cast<std::size_t>(cluster_size)) {
    const std::size_t e = std::min(keyed.size(), b + static_cast<std::size_t>(cluster_size));
    c.cluster_begin.push_back(static_cast<std::int32_t>(b));
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    for (std::size_t k = b; k < e; ++k) {
      const auto j = static_cast<std::size_t>(keyed[k].second);
      c.member.push_back(keyed[k].second);
      centre += Eigen::Vector3d(set.x[j], set.y[j], set.z[j]);
    }
    centre /= static_cast<double>(e - b);
    double r = 0;
    for (std::size_t k = b; k < e; ++k) {
      const auto j = static_cast<std::size_t>(keyed[k].second);
      r = std::max(r, (Eigen::Vector3d(set.x[j], set.y[j], set.z[j]) - centre).norm());
    }
    c.centre.push_back(centre);
    c.radius.push_back(r);
  }
  c.cluster_begin.push_back(static_cast<std::int32_t>(keyed.size()));
  return c;
}

LayeredNearStats scan_layered_near(const ScanSet& set, const ScanClusters& clusters, const Eigen::Matrix3d& R,
                                   const Eigen::Vector3d& t, const LayeredMap& map, const Eigen::Vector3d& cor,
                                   const SignedDistanceQuery& other, double reach_mm, float* gap_mm,
                                   const FirstHitCaster* exact) {
  require(reach_mm > 0 && std::isfinite(reach_mm), "layered scan: the reach must be > 0 mm and finite");
  require(static_cast<std::int64_t>(clusters.member.size()) == set.size(),
          "layered scan: the clusters hold " + std::to_string(clusters.member.size()) + " vertices, the set " +
              std::to_string(set.size()));
  LayeredNearStats st;
  constexpr int kMax = 64;
  double qx[kMax], qy[kMax], qz[kMax], d[kMax];
  std::uint8_t flag[kMax];
  const double inf = std::numeric_limits<double>::infinity();
  for (std::int64_t c = 0; c < clusters.clusters(); ++c) {
    const auto b = static_cast<std::size_t>(clusters.cluster_begin[static_cast<std::size_t>(c)]);
    const auto e = static_cast<std::size_t>(clusters.cluster_begin[static_cast<std::size_t>(c) + 1]);
    const Eigen::Vector3d qc = R * clusters.centre[static_cast<std::size_t>(c)] + t;
    if (!other.any_within(qc + cor, clusters.radius[static_cast<std::size_t>(c)] + reach_mm)) {
      double centre_gap = 0;
      std::uint8_t centre_flag = 1;
      map.signed_distance_many_soa(&qc.x(), &qc.y(), &qc.z(), 1, &centre_gap, &centre_flag);
      if (centre_gap > 0 && centre_flag == 0) {  // outside (+inf: the bone is nowhere along the ray)
        for (std::size_t k = b; k < e; ++k) gap_mm[clusters.member[k]] = static_cast<float>(inf);
        ++st.clusters_skipped;
        continue;
      }
    }
    for (std::size_t k0 = b; k0 < e; k0 += kMax) {
      const int m = static_cast<int>(std::min<std::size_t>(kMax, e - k0));
      for (int i = 0; i < m; ++i) {
        const auto j = static_cast<std::size_t>(clusters.member[k0 + static_cast<std::size_t>(i)]);
        const Eigen::Vector3d q = R * Eigen::Vector3d(set.x[j], set.y[j], set.z[j]) + t;
        qx[i] = q.x(), qy[i] = q.y(), qz[i] = q.z();
      }
      map.signed_distance_many_soa(qx, qy, qz, m, d, exact != nullptr ? flag : nullptr);
      for (int i = 0; i < m; ++i) {
        double g = d[i];
        if (exact != nullptr && flag[i]) {
          g = signed_radial_distance_exact(*exact, Eigen::Vector3d(qx[i], qy[i], qz[i]));
          ++st.refined;
        }
        gap_mm[clusters.member[k0 + static_cast<std::size_t>(i)]] =
            std::isfinite(g) ? static_cast<float>(g) : std::numeric_limits<float>::quiet_NaN();
      }
      st.vertices_scanned += m;
    }
  }
  return st;
}

}  // namespace impinge
