#include "impinge/detection/surface_distance.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "core/box_order.hpp"
#include "core/z_order.hpp"
#include "impinge/core/error.hpp"
#include "impinge/sampling/layered_sampling.hpp"

namespace impinge {

namespace {
constexpr double kBoundMarginMm = 0.5;  // above the maps' interpolation error (experiment 10: < 0.04 mm)
constexpr double kHintMm = 0.1;         // a gap whose sign is a hint

// The order of the points p along a Z curve over their positions: neighbours in space are mostly
// neighbours in this order (the distance scan's clusters, the hidden vertices' order).
std::vector<std::int32_t> position_order(const std::vector<Eigen::Vector3d>& p) {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const Eigen::Vector3d& x : p) lo = lo.cwiseMin(x), hi = hi.cwiseMax(x);
  const double cell = p.empty() ? 1.0 : std::max((hi - lo).maxCoeff() / 2097151.0, 1e-9);
  std::vector<std::pair<std::uint64_t, std::int32_t>> keyed;
  keyed.reserve(p.size());
  for (std::size_t k = 0; k < p.size(); ++k) {
    const Eigen::Vector3d g = (p[k] - lo) / cell;
    keyed.emplace_back(detail::position_z_order(g.x(), g.y(), g.z()), static_cast<std::int32_t>(k));
  }
  std::sort(keyed.begin(), keyed.end());
  std::vector<std::int32_t> order;
  order.reserve(p.size());
  for (const auto& [key, k] : keyed) order.push_back(k);
  return order;
}

// The ball about the centroid of p[0..n) (n > 0) that holds them all: centre, radius (mm).
std::pair<Eigen::Vector3d, double> bounding_ball(const Eigen::Vector3d* p, std::size_t n) {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < n; ++k) c += p[k];
  c /= static_cast<double>(n);
  double r = 0;
  for (std::size_t k = 0; k < n; ++k) r = std::max(r, (p[k] - c).norm());
  return {c, r};
}

// The positions of a scan set's vertices.
std::vector<Eigen::Vector3d> positions_of(const ScanSet& set) {
  std::vector<Eigen::Vector3d> p;
  p.reserve(set.x.size());
  for (std::size_t j = 0; j < set.x.size(); ++j) p.emplace_back(set.x[j], set.y[j], set.z[j]);
  return p;
}
}  // namespace

DistanceScanSet make_distance_scan_set(PointsRef P, double max_radius_mm, int cluster_size) {
  require(cluster_size >= 1, "distance scan: the cluster size must be >= 1");
  require(max_radius_mm > 0, "distance scan: the region radius must be > 0 mm");
  require(P.rows() < std::numeric_limits<std::int32_t>::max(), "distance scan: too many vertices");
  DistanceScanSet s;
  s.vertices = P.rows();
  std::vector<std::int32_t> keep;
  std::vector<Eigen::Vector3d> kept;
  keep.reserve(static_cast<std::size_t>(P.rows()));
  kept.reserve(static_cast<std::size_t>(P.rows()));
  for (Eigen::Index i = 0; i < P.rows(); ++i) {
    const Eigen::Vector3d p = P.row(i).transpose();
    if (!(p.norm() <= max_radius_mm)) continue;
    keep.push_back(static_cast<std::int32_t>(i));
    kept.push_back(p);
  }
  s.index.reserve(kept.size());
  s.position.reserve(kept.size());
  // In boxes of cluster_size (as order_in_boxes): compact clusters, whose balls prune far more than runs of
  // a Z curve (lhdl-ct: mean radius 5 to 7 mm against 11 to 13, the largest 28 mm against 140).
  for (const std::int32_t k :
       detail::box_order(kept.size(), {static_cast<std::int64_t>(cluster_size)},
                         [&](std::int32_t j, int axis) { return kept[static_cast<std::size_t>(j)][axis]; })) {
    s.index.push_back(keep[static_cast<std::size_t>(k)]);
    s.position.push_back(kept[static_cast<std::size_t>(k)]);
  }
  for (std::size_t j = 0; j < s.position.size(); j += static_cast<std::size_t>(cluster_size)) {
    const std::size_t n = std::min(s.position.size() - j, static_cast<std::size_t>(cluster_size));
    s.cluster_begin.push_back(static_cast<std::int32_t>(j));
    const auto [centre, radius] = bounding_ball(s.position.data() + j, n);
    s.centre.push_back(centre);
    s.radius.push_back(radius);
  }
  s.cluster_begin.push_back(static_cast<std::int32_t>(s.position.size()));
  return s;
}

namespace {
constexpr double kEmptySlackMm = 2;         // a vertex's search beyond the reach looks this much farther
constexpr double kClusterEmptySlackMm = 4;  // a cluster's test likewise
constexpr double kFloatMarginMm = 1e-3;     // an empty ball kept in float: its centre and radius rounded

// Whether the ball (q, radius_mm) lies inside the remembered empty ball (centre, empty), so that no point
// of the surface lies within radius_mm of q. The float centre and radius were rounded from double by at
// most 2^-24 of their size each: the margin covers that at any coordinates, and more.
bool inside_empty(const Eigen::Vector3d& q, double radius_mm, const Eigen::Vector3f& centre, float empty) {
  if (!(empty > 0)) return false;
  const Eigen::Vector3d c = centre.cast<double>();
  const double margin = kFloatMarginMm + 0x1p-20 * (c.cwiseAbs().maxCoeff() + static_cast<double>(empty));
  return (q - c).norm() + radius_mm < static_cast<double>(empty) - margin;
}

// Forgets what `memory` knew when it is about another surface (query: that surface's id) or sized for another set
// (k_all vertices, c_all clusters): no seeds, empty balls, nearby triangles or last centres (NaN) any more.
void fit_memory(DistanceScanMemory& memory, std::uint64_t query, std::size_t k_all, std::size_t c_all) {
  if (memory.query != query || memory.seed.size() != k_all || memory.empty_radius.size() != k_all ||
      memory.empty_centre.size() != k_all || memory.cluster_empty_radius.size() != c_all ||
      memory.cluster_empty_centre.size() != c_all || memory.nearby_slot.size() != k_all ||
      memory.cluster_last_centre.size() != c_all) {
    memory.query = query;
    memory.seed.assign(k_all, -1);
    memory.empty_centre.assign(k_all, Eigen::Vector3f::Zero());
    memory.empty_radius.assign(k_all, 0.f);
    memory.cluster_empty_centre.assign(c_all, Eigen::Vector3f::Zero());
    memory.cluster_empty_radius.assign(c_all, 0.f);
    memory.nearby_slot.assign(k_all, -1);
    memory.nearby.clear();
    memory.cluster_last_centre.assign(c_all, Eigen::Vector3f::Constant(std::numeric_limits<float>::quiet_NaN()));
  }
}

// What the steps of one scan_distances call share: the set, its pose (q = R p + shift, mm, shift = cor + t),
// the other surface, the reach (mm), the radial gaps (n, mm; or empty), the distances written (n, mm), the memory
// (or null), the counts and the closest point's scratch.
struct DistanceScan {
  const DistanceScanSet& set;
  const Eigen::Matrix3d& R;
  const Eigen::Vector3d& shift;
  const SignedDistanceQuery& other;
  double reach_mm;
  const std::vector<float>& gap_mm;
  std::vector<float>& distance_mm;
  DistanceScanMemory* memory;
  DistanceScanStats& st;
  ClosestSurfacePoint& cp;
  std::vector<std::uint8_t>* undecided;  // per vertex, or null
};

// The most negative radial gap (mm) of the set's vertices [b, e) below -reach, or 0 when none is (or no gaps).
double deepest_gap(const DistanceScan& s, std::size_t b, std::size_t e) {
  double deepest = 0;  // the most negative gap of the cluster below -reach
  if (!s.gap_mm.empty())
    for (std::size_t k = b; k < e; ++k) {
      const float g = s.gap_mm[static_cast<std::size_t>(s.set.index[k])];
      if (g < -s.reach_mm) deepest = std::min(deepest, static_cast<double>(g));
    }
  return deepest;
}

// How far cluster cs's posed centre (mm) moved since the last scan (NaN at the first, or without memory); the
// memory keeps the new centre (float).
double cluster_moved(const DistanceScan& s, std::size_t cs, const Eigen::Vector3d& centre) {
  double moved = std::numeric_limits<double>::quiet_NaN();
  if (s.memory != nullptr) {
    const Eigen::Vector3f now = centre.cast<float>();
    moved = static_cast<double>((now - s.memory->cluster_last_centre[cs]).norm());
    s.memory->cluster_last_centre[cs] = now;
  }
  return moved;
}

// Whether no point of the other surface lies within `grown` (mm: the cluster's ball grown by the reach) of
// cluster cs's posed centre (mm): recalled from the memory's empty ball (counted in st.clusters_recalled), or
// tested; when learn_cluster, tested first with kClusterEmptySlackMm more, an empty ball then remembered.
bool cluster_beyond_reach(DistanceScan& s, std::size_t cs, const Eigen::Vector3d& centre, double grown,
                          bool learn_cluster) {
  DistanceScanMemory* memory = s.memory;
  bool apart = false;
  if (memory == nullptr) {
    apart = !s.other.any_within(centre, grown);
  } else if (inside_empty(centre, grown, memory->cluster_empty_centre[cs], memory->cluster_empty_radius[cs])) {
    apart = true;
    ++s.st.clusters_recalled;
  } else if (!learn_cluster) {
    apart = !s.other.any_within(centre, grown);
  } else if (!s.other.any_within(centre, grown + kClusterEmptySlackMm)) {
    apart = true;  // nothing within the grown ball and the slack: remember that ball
    memory->cluster_empty_centre[cs] = centre.cast<float>();
    memory->cluster_empty_radius[cs] = static_cast<float>(grown + kClusterEmptySlackMm);
  } else {
    apart = !s.other.any_within(centre, grown);
  }
  return apart;
}

// The first search's radius (mm) of a vertex whose radial gap is g (mm; NaN: none): the reach, or the gap's
// bound (|g| plus kBoundMarginMm, at most the reach; beyond it below -reach).
double search_radius(double g, double reach_mm) {
  double radius = reach_mm;
  if (std::isfinite(g))
    radius = g < -reach_mm ? -g + kBoundMarginMm : std::min(reach_mm, std::abs(g) + kBoundMarginMm);
  return radius;
}

// Vertex k's nearby triangles in the memory (a slot given at its first search) when it learns; else null.
NearbyTriangles* nearby_of(DistanceScanMemory* memory, std::size_t k, bool learn_vertices) {
  if (memory == nullptr || !learn_vertices) return nullptr;
  if (memory->nearby_slot[k] < 0) {
    memory->nearby_slot[k] = static_cast<std::int32_t>(memory->nearby.size());
    memory->nearby.emplace_back();
  }
  return &memory->nearby[static_cast<std::size_t>(memory->nearby_slot[k])];
}

// The search of vertex k posed at q (mm), its gap g (mm; NaN: none) and first radius (mm), sign hint, seed
// triangle `start` and nearby triangles: whether s.cp found a point of the other surface within the reach.
bool search_vertex(DistanceScan& s, std::size_t k, const Eigen::Vector3d& q, double g, double radius, int hint,
                   std::int64_t start, NearbyTriangles* nearby, bool learn_vertices) {
  const double reach_mm = s.reach_mm;
  bool found = false;
  if (s.memory != nullptr && learn_vertices && radius == reach_mm && !(g < reach_mm)) {
    // Likely beyond the reach (a gap beyond it, or none): whether the surface comes within the reach
    // plus the slack (if not, that ball is remembered empty), and only then the search within the reach.
    if (!s.other.any_within(q, reach_mm + kEmptySlackMm)) {
      s.memory->empty_centre[k] = q.cast<float>();
      s.memory->empty_radius[k] = static_cast<float>(reach_mm + kEmptySlackMm);
    } else {
      found = s.other.signed_distance(q, reach_mm, hint, s.cp, start, nearby);
    }
  } else {
    found = s.other.signed_distance(q, radius, hint, s.cp, start, nearby);
    if (!found && radius < reach_mm) found = s.other.signed_distance(q, reach_mm, hint, s.cp, start, nearby);
  }
  return found;
}

// The set's vertices [b, e) (one cluster not pruned): each one's signed distance (s.distance_mm at its index, mm)
// when a search finds the surface within the reach; NaN left where the memory's empty ball or the search proves
// it beyond. Each search starts from the vertex's remembered seed, else the previous vertex's closest triangle.
void measure_cluster(DistanceScan& s, std::size_t b, std::size_t e, bool learn_vertices) {
  const double reach_mm = s.reach_mm;
  DistanceScanMemory* memory = s.memory;
  std::int64_t seed = -1;  // the previous vertex's closest triangle: neighbours share them
  for (std::size_t k = b; k < e; ++k) {
    const auto i = static_cast<std::size_t>(s.set.index[k]);
    const Eigen::Vector3d q = s.R * s.set.position[k] + s.shift;
    const double g = s.gap_mm.empty() ? std::numeric_limits<double>::quiet_NaN() : s.gap_mm[i];
    const int hint = g > kHintMm ? 1 : (g < -kHintMm ? -1 : 0);
    const double radius = search_radius(g, reach_mm);
    if (memory != nullptr && radius <= reach_mm &&
        inside_empty(q, reach_mm, memory->empty_centre[k], memory->empty_radius[k])) {
      ++s.st.vertices_recalled;  // no point of the surface within the reach: NaN, as a search would find
      continue;
    }
    const std::int64_t start = memory != nullptr && memory->seed[k] >= 0 ? memory->seed[k] : seed;
    NearbyTriangles* nearby = nearby_of(memory, k, learn_vertices);
    ++s.st.searches;
    if (!search_vertex(s, k, q, g, radius, hint, start, nearby, learn_vertices)) continue;
    seed = s.cp.triangle;
    if (memory != nullptr)
      memory->seed[k] =
          s.cp.triangle <= std::numeric_limits<std::int32_t>::max() ? static_cast<std::int32_t>(s.cp.triangle) : -1;
    s.distance_mm[i] = static_cast<float>(s.cp.signed_mm());
    ++s.st.measured;
    s.st.winding += s.cp.rule == SignRule::winding_number;
    if (s.cp.rule == SignRule::undecided) {
      ++s.st.undecided;
      if (s.undecided != nullptr) (*s.undecided)[i] = 1;
    }
  }
}
}  // namespace

DistanceScanStats scan_distances(const DistanceScanSet& set, const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
                                 const Eigen::Vector3d& cor, const SignedDistanceQuery& other, double reach_mm,
                                 const std::vector<float>& gap_mm, std::vector<float>& distance_mm,
                                 DistanceScanMemory* memory, std::vector<std::uint8_t>* sign_undecided) {
  require(reach_mm > 0 && std::isfinite(reach_mm), "distance scan: the reach must be > 0 mm and finite");
  require(
      gap_mm.empty() || static_cast<std::int64_t>(gap_mm.size()) == set.vertices,
      "distance scan: " + std::to_string(gap_mm.size()) + " gaps for " + std::to_string(set.vertices) + " vertices");
  DistanceScanStats st;
  distance_mm.assign(static_cast<std::size_t>(set.vertices), std::numeric_limits<float>::quiet_NaN());
  const std::size_t k_all = set.index.size(), c_all = static_cast<std::size_t>(set.clusters());
  if (memory != nullptr) fit_memory(*memory, other.id(), k_all, c_all);
  const Eigen::Vector3d shift = cor + t;
  ClosestSurfacePoint cp;
  if (sign_undecided != nullptr) sign_undecided->assign(static_cast<std::size_t>(set.vertices), 0);
  DistanceScan s{set, R, shift, other, reach_mm, gap_mm, distance_mm, memory, st, cp, sign_undecided};
  for (std::int64_t c = 0; c < set.clusters(); ++c) {
    const auto cs = static_cast<std::size_t>(c);
    const auto b = static_cast<std::size_t>(set.cluster_begin[cs]);
    const auto e = static_cast<std::size_t>(set.cluster_begin[cs + 1]);
    const double deepest = deepest_gap(s, b, e);
    const Eigen::Vector3d centre = R * set.centre[cs] + shift;
    // How far the cluster moved since the last scan (NaN at the first): the memory's new facts (empty balls
    // 2 and 4 mm beyond the reach, nearby triangles 2 mm beyond a search) pay back only where the next scan
    // comes within those margins; after a jump they cost extra walks for nothing (a motion of scattered poses).
    const double moved = cluster_moved(s, cs, centre);
    const bool learn_cluster = moved <= kClusterEmptySlackMm, learn_vertices = moved <= kEmptySlackMm;
    // No point of the surface within the cluster's ball grown by the reach: every vertex is beyond it.
    if (deepest == 0 && cluster_beyond_reach(s, cs, centre, set.radius[cs] + reach_mm, learn_cluster)) {
      ++st.clusters_pruned;
      continue;
    }
    measure_cluster(s, b, e, learn_vertices);
  }
  return st;
}

ScanSet order_by_position(const ScanSet& set) {
  ScanSet out;
  out.vertices = set.vertices;
  for (const std::int32_t j : position_order(positions_of(set))) {
    const auto k = static_cast<std::size_t>(j);
    out.index.push_back(set.index[k]);
    out.x.push_back(set.x[k]), out.y.push_back(set.y[k]), out.z.push_back(set.z[k]);
  }
  return out;
}

ScanSet order_in_boxes(const ScanSet& set, const std::vector<std::int64_t>& run_sizes) {
  require(!run_sizes.empty() && run_sizes.front() >= 1, "order in boxes: needs run sizes >= 1");
  for (std::size_t j = 1; j < run_sizes.size(); ++j)
    require(run_sizes[j] >= run_sizes[j - 1] && run_sizes[j] % run_sizes[j - 1] == 0,
            "order in boxes: each run size must be a multiple of the one before");
  const auto n = static_cast<std::size_t>(set.size());
  const std::vector<std::int32_t> order = detail::box_order(n, run_sizes, [&](std::int32_t k, int axis) {
    const auto j = static_cast<std::size_t>(k);
    return axis == 0 ? set.x[j] : axis == 1 ? set.y[j] : set.z[j];
  });
  ScanSet out;
  out.vertices = set.vertices;
  out.index.reserve(n), out.x.reserve(n), out.y.reserve(n), out.z.reserve(n);
  for (const std::int32_t k : order) {
    const auto j = static_cast<std::size_t>(k);
    out.index.push_back(set.index[j]);
    out.x.push_back(set.x[j]), out.y.push_back(set.y[j]), out.z.push_back(set.z[j]);
  }
  return out;
}

ScanClusters cluster_scan_set(const ScanSet& set, int cluster_size) {
  require(cluster_size >= 1, "scan clusters: the cluster size must be >= 1");
  ScanClusters c;
  const std::vector<Eigen::Vector3d> p = positions_of(set);
  for (std::size_t j = 0; j < p.size(); j += static_cast<std::size_t>(cluster_size)) {
    const std::size_t n = std::min(p.size() - j, static_cast<std::size_t>(cluster_size));
    c.cluster_begin.push_back(static_cast<std::int32_t>(j));
    const auto [centre, radius] = bounding_ball(p.data() + j, n);
    c.centre.push_back(centre);
    c.radius.push_back(radius);
  }
  c.cluster_begin.push_back(static_cast<std::int32_t>(p.size()));
  return c;
}

bool cluster_apart(const Eigen::Vector3d& centre, double radius_mm, const LayeredMap& map, const Eigen::Vector3d& cor,
                   const SignedDistanceQuery& other, double reach_mm) {
  if (other.any_within(centre + cor, radius_mm + reach_mm)) return false;
  double gap = 0;
  std::uint8_t flag = 1;
  map.signed_distance_many_soa(&centre.x(), &centre.y(), &centre.z(), 1, &gap, &flag);
  return gap > 0 && flag == 0;  // outside (+inf: the bone is nowhere along the ray)
}

bool cluster_apart(const Eigen::Vector3d& centre, double radius_mm, const FirstHitCaster& caster,
                   const Eigen::Vector3d& cor, const SignedDistanceQuery& other, double reach_mm) {
  if (other.any_within(centre + cor, radius_mm + reach_mm)) return false;
  return signed_radial_distance_exact(caster, centre) > 0;  // outside (+inf: the bone is nowhere along the ray)
}

namespace {

// The clusters' loop shared by both layered scans: `apart(centre, radius)` proves a posed cluster beyond the reach
// (its members get +inf), `scan(first, count)` fills the others' gaps and returns the exact casts it made.
template <class Apart, class Scan>
LayeredNearStats layered_near(const ScanSet& set, const ScanClusters& clusters, const Eigen::Matrix3d& R,
                              const Eigen::Vector3d& t, double reach_mm, float* gap_mm, Apart&& apart, Scan&& scan) {
  require(reach_mm > 0 && std::isfinite(reach_mm), "layered scan: the reach must be > 0 mm and finite");
  require(!clusters.cluster_begin.empty() && clusters.cluster_begin.back() == set.size(),
          "layered scan: the clusters are not the set's (" + std::to_string(set.size()) + " vertices)");
  LayeredNearStats st;
  for (std::int64_t c = 0; c < clusters.clusters(); ++c) {
    const auto k = static_cast<std::size_t>(c);
    const std::int64_t first = clusters.cluster_begin[k];
    const std::int64_t count = clusters.cluster_begin[k + 1] - first;
    if (apart(Eigen::Vector3d(R * clusters.centre[k] + t), clusters.radius[k])) {
      std::fill(gap_mm + first, gap_mm + first + count, std::numeric_limits<float>::infinity());
      ++st.clusters_skipped;
      continue;
    }
    st.refined += scan(first, count);
    st.vertices_scanned += count;
  }
  return st;
}

}  // namespace

LayeredNearStats scan_layered_near_exact(const ScanSet& set, const ScanClusters& clusters, const Eigen::Matrix3d& R,
                                         const Eigen::Vector3d& t, const FirstHitCaster& exact,
                                         const Eigen::Vector3d& cor, const SignedDistanceQuery& other, double reach_mm,
                                         float* gap_mm) {
  return layered_near(
      set, clusters, R, t, reach_mm, gap_mm,
      [&](const Eigen::Vector3d& centre, double radius) {
        return cluster_apart(centre, radius, exact, cor, other, reach_mm);
      },
      [&](std::int64_t first, std::int64_t count) {
        for (std::int64_t j = first; j < first + count; ++j) {
          const auto k = static_cast<std::size_t>(j);
          const double g = signed_radial_distance_exact(exact, R * Eigen::Vector3d(set.x[k], set.y[k], set.z[k]) + t);
          gap_mm[j] = std::isfinite(g) ? static_cast<float>(g) : std::numeric_limits<float>::quiet_NaN();
        }
        return count;
      });
}

LayeredNearStats scan_layered_near(const ScanSet& set, const ScanClusters& clusters, const Eigen::Matrix3d& R,
                                   const Eigen::Vector3d& t, const LayeredMap& map, const Eigen::Vector3d& cor,
                                   const SignedDistanceQuery& other, double reach_mm, float* gap_mm,
                                   const FirstHitCaster* exact) {
  return layered_near(
      set, clusters, R, t, reach_mm, gap_mm,
      [&](const Eigen::Vector3d& centre, double radius) {
        return cluster_apart(centre, radius, map, cor, other, reach_mm);
      },
      [&](std::int64_t first, std::int64_t count) {
        return scan_layered(set, first, count, R, t, map, gap_mm, exact);
      });
}

}  // namespace impinge
