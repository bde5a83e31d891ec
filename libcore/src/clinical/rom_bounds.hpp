#pragma once
// Private to libcore/src/clinical: the bounds of the ROM searches (rom.hpp): pyramids of minima,
// maxima and shell occupancies over an equiangular map, clusters of scan-set vertices, and the
// RomSearchBounds a baseline shares. Included by rom.cpp and rom_envelope.cpp only.

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "impinge/clinical/rom.hpp"
#include "impinge/core/error.hpp"
#include "impinge/core/fast_angles.hpp"
#include "impinge/detection/detection.hpp"
#include "impinge/detection/surface_distance.hpp"
#include "impinge/schemes/equiangular_grid.hpp"

namespace impinge {
namespace rom_detail {

// The gap at which a search's bones meet: the threshold less the contact depth.
inline double cut_of(const RomOptions& o) { return o.threshold_mm - o.contact_depth_mm; }

// The distance metric's radial screen (GapScanner) lists the vertices whose radial gap is at most the
// cut plus this, mm: the radial gap of a vertex inside the other bone is at most its distance, up to the
// maps' interpolation error (about 0.05 mm at 0.1 deg, growing with the node spacing), which this covers.
inline constexpr double kDistanceScreenSlackMm = 0.5;
// Whether a search scans radially (and so uses the cluster bounds): the radial metric, or the distance
// metric's screen at or below a cut of 0 (GapScanner).
inline bool screened_or_radial(const RomOptions& o) { return o.metric == RomMetric::radial || cut_of(o) <= 0; }
// The threshold of the cluster-bounded radial scans: the cut, or with the distance metric the screen's.
inline double scan_cut_of(const RomOptions& o) {
  return o.metric == RomMetric::distance ? cut_of(o) + kDistanceScreenSlackMm : cut_of(o);
}

inline void check(const RomOptions& o) {
  // The declared ranges (RomOptions::k...Range), the option table's too.
  check_in_range("RomOptions::threshold_mm", o.threshold_mm, RomOptions::kThresholdRange, "mm");
  check_in_range("RomOptions::contact_depth_mm", o.contact_depth_mm, RomOptions::kContactDepthRange, "mm");
  check_in_range("RomOptions::step_deg", o.step_deg, RomOptions::kStepRange, "deg");
  check_in_range("RomOptions::max_deg", o.max_deg, RomOptions::kMaxRange, "deg");
  require(o.tolerance_deg > 0 && o.tolerance_deg <= o.step_deg, [&] {
    std::ostringstream m;
    m << "--search-tolerance " << o.tolerance_deg << " deg is more than --step " << o.step_deg
      << " deg: the bisection halves the last step until its bracket is this narrow, so give at most the step";
    return m.str();
  });
  require(o.metric == RomMetric::radial || o.vertices == RomVertices::all,
          "rom: the distance metric counts every vertex (RomVertices::all)");
}

// The joint can give the distance metric what it needs: distances within the threshold.
inline void check_metric(const Joint& joint, const RomOptions& o) {
  if (o.metric != RomMetric::distance) return;
  const JointOptions& jo = joint.options();
  require(jo.distances, "rom: the distance metric needs the joint's distances on (JointOptions::distances)");
  require(jo.reach_mm() >= std::max(o.threshold_mm, 0.0),
          "rom: the distance metric needs a distance reach (" + std::to_string(jo.reach_mm()) +
              " mm) of at least the threshold (" + std::to_string(o.threshold_mm) + " mm)");
}

// ---- bounds ----------------------------------------------------------------------------------
// A pyramid of minima (or maxima) over an equiangular map: at level L, block (i, j) holds the min
// (max) of the finite node values in fine rows [i 2^L, (i+1) 2^L] and columns [j 2^L, (j+1) 2^L]
// (boundaries shared, columns periodic); +inf (-inf) when none is finite. A fine bilinear value
// whose four nodes are finite is >= (<=) the bound of any block range covering those nodes; a
// stencil with an infinite node gives NaN, no gap, so infinite nodes can be ignored.
// Combining node values over blocks: the least or the greatest distance, or the union of shells.
struct MinOrMax {
  bool lower = true;
  float operator()(float a, float b) const { return lower ? std::min(a, b) : std::max(a, b); }
};
struct BitOr {
  std::uint64_t operator()(std::uint64_t a, std::uint64_t b) const { return a | b; }
};

template <typename V, typename Combine>
class BlockPyramid {
 public:
  static constexpr int kFirstLevel = 2;
  // Blocks across a cap, at most: finer is tighter, coarser is fewer reads.
  static constexpr int kMaxBlocksPerSpan = 16;
  // Each stored row repeats its first kPad blocks after its last, so a cap's column range (at most
  // blocks_per_span + 3 blocks, or the whole row) is read without wrapping.
  static constexpr int kPad = kMaxBlocksPerSpan + 4;
  // value(i): node i's value (called from several threads); none: the identity of `combine` (the
  // value of an empty block).
  template <typename Value>
  BlockPyramid(const SamplingScheme& scheme, Value value, V none, Combine combine) : none_(none), combine_(combine) {
    // Bounds over the rows and columns of an equiangular grid; maps of other schemes scan every vertex.
    const auto g = conformable_equiangular_grid(scheme);
    if (!g) return;
    rows_ = g->rows(), cols_ = g->columns(), step_ = g->step();
    for (int L = kFirstLevel;; ++L) {
      const int b = 1 << L, br = (rows_ - 1 + b - 1) / b, bc = (cols_ + b - 1) / b, stride = bc + kPad;
      // Stored padded: row i holds blocks 0 .. bc + kPad - 1, block j at (j mod bc).
      std::vector<V> v(static_cast<std::size_t>(br) * stride, none);
      if (L == kFirstLevel) {
#pragma omp parallel
        {
          std::vector<V> row(static_cast<std::size_t>(bc) * b + 1);  // one node row, wrapped
#pragma omp for schedule(static)
          for (int i = 0; i < br; ++i) {
            V* out = v.data() + static_cast<std::size_t>(i) * stride;
            for (int r = i * b; r <= std::min((i + 1) * b, rows_ - 1); ++r) {
              const std::int64_t first = std::int64_t(r) * cols_;
              for (int c = 0; c < cols_; ++c) row[static_cast<std::size_t>(c)] = value(first + c);
              for (int c = cols_; c <= bc * b; ++c) row[static_cast<std::size_t>(c)] = row[static_cast<std::size_t>(c - cols_)];
              for (int j = 0; j < bc; ++j) {
                V m = out[j];
                for (int c = j * b; c <= (j + 1) * b; ++c) m = combine(m, row[static_cast<std::size_t>(c)]);
                out[j] = m;
              }
            }
          }
        }
      } else {
        const std::vector<V>& p = levels_.back();
        const int pbr = (rows_ - 1 + b / 2 - 1) / (b / 2), pbc = (cols_ + b / 2 - 1) / (b / 2), pstride = pbc + kPad;
        for (int i = 0; i < br; ++i)
          for (int j = 0; j < bc; ++j) {
            V m = none;
            for (int di = 0; di < 2; ++di)
              for (int dj = 0; dj < 2; ++dj) {
                const int pi = 2 * i + di, pj = 2 * j + dj;
                if (pi >= pbr) continue;
                m = combine(m, p[static_cast<std::size_t>(pi) * pstride + (pj % pbc)]);
              }
            v[static_cast<std::size_t>(i) * stride + j] = m;
          }
      }
      for (int i = 0; i < br; ++i)
        for (int j = bc; j < stride; ++j)
          v[static_cast<std::size_t>(i) * stride + j] = v[static_cast<std::size_t>(i) * stride + (j % bc)];
      levels_.push_back(std::move(v));
      if (br <= 2 && bc <= 2) break;
    }
  }
  bool valid() const { return !levels_.empty(); }
  // Combined value over every node (none when the pyramid is not valid).
  V all() const {
    V m = none_;
    for (const V& x : levels_.empty() ? std::vector<V>{} : levels_.back()) m = combine_(m, x);
    return m;
  }
  // Combined value over every stencil node of the directions within angle rho of unit u (sin_rho =
  // sin(rho)). Angles by fast_angles.hpp (within 1e-13 rad; the row and column ranges are padded by a
  // node on each side).
  V cap(const Eigen::Vector3d& u, double rho, double sin_rho, int blocks_per_span) const {
    return cap(u, rho, sin_rho, blocks_per_span, [](const V&) { return false; });
  }
  // The same, but returned as soon as stop(the value so far) holds after a row of blocks (callers that
  // only compare the value with a threshold: once stop holds, the rest cannot change the comparison).
  template <typename Stop>
  V cap(const Eigen::Vector3d& u, double rho, double sin_rho, int blocks_per_span, Stop stop) const {
    double phi, theta;
    fast_spherical_angles(u.x(), u.y(), u.z(), phi, theta);
    double r_lo = (phi - rho) / step_, r_hi = (phi + rho) / step_ + 1;
    int c_lo = 0, c_hi = cols_;  // whole rows when the cap holds a pole or is wide
    if (phi - rho > 0 && phi + rho < M_PI) {
      const double sin_phi = std::sqrt(std::max(0.0, u.x() * u.x() + u.y() * u.y()));
      const double v = std::min(1.0, sin_rho / sin_phi);
      const double half = fast_azimuth(v, std::sqrt(std::max(0.0, 1 - v * v)));  // asin(v)
      if (half < M_PI / 2) {
        c_lo = static_cast<int>(std::floor((theta - half) / step_)) - 1;
        c_hi = static_cast<int>(std::floor((theta + half) / step_)) + 2;
      }
    }
    const int r0 = std::max(0, static_cast<int>(std::floor(r_lo)) - 1);
    const int r1 = std::min(rows_ - 1, static_cast<int>(std::floor(r_hi)) + 1);
    const int span = std::max(r1 - r0, c_hi - c_lo);
    int L = kFirstLevel;
    while ((1 << L) * blocks_per_span < span && L - kFirstLevel + 1 < static_cast<int>(levels_.size())) ++L;
    const int b = 1 << L, br = (rows_ - 1 + b - 1) / b, bc = (cols_ + b - 1) / b, stride = bc + kPad;
    const V* v = levels_[static_cast<std::size_t>(L - kFirstLevel)].data();
    const int i0 = r0 / b, i1 = std::min(br - 1, r1 / b);
    int j0 = 0, j1 = bc - 1;  // inclusive
    if (c_hi - c_lo < cols_) {
      j0 = static_cast<int>(std::floor(double(c_lo) / b));
      j1 = static_cast<int>(std::floor(double(c_hi) / b));
      if (j1 - j0 >= bc) {
        j0 = 0, j1 = bc - 1;
      } else {
        const int shift = j0 >= 0 ? -(j0 / bc) * bc : ((-j0 + bc - 1) / bc) * bc;  // j0 into [0, bc)
        j0 += shift, j1 += shift;
        if (j1 >= bc + kPad) j0 = 0, j1 = bc - 1;  // cannot happen for a cap of the chosen level
      }
    }
    V m = none_;
    for (int i = i0; i <= i1; ++i) {
      const V* row = v + static_cast<std::size_t>(i) * stride;
      for (int j = j0; j <= j1; ++j) m = combine_(m, row[j]);
      if (stop(m)) return m;
    }
    return m;
  }

 private:
  V none_;
  Combine combine_;
  int rows_ = 0, cols_ = 0;
  double step_ = 0;
  std::vector<std::vector<V>> levels_;
};

// A pyramid of minima (or maxima) over an equiangular map: at level L, block (i, j) holds the min
// (max) of the finite node values in fine rows [i 2^L, (i+1) 2^L] and columns [j 2^L, (j+1) 2^L]
// (boundaries shared, columns periodic); +inf (-inf) when none is finite. A fine bilinear value
// whose four nodes are finite is >= (<=) the bound of any block range covering those nodes; a
// stencil with an infinite node gives NaN, no gap, so infinite nodes can be ignored.
using BoundPyramid = BlockPyramid<float, MinOrMax>;
using OccupancyPyramid = BlockPyramid<std::uint64_t, BitOr>;
inline BoundPyramid bound_pyramid(const RadialDistanceMap& map, bool lower) {
  const float none = lower ? std::numeric_limits<float>::infinity() : -std::numeric_limits<float>::infinity();
  return BoundPyramid(
      map.scheme(),
      [&map, none](std::int64_t i) {
        const float d = map.at(i);
        return std::isfinite(d) ? d : none;
      },
      none, MinOrMax{lower});
}

// The radial shells a layered map's solid meets (LayeredMap::occupancy), OR-ed over blocks: a cluster
// none of whose radii lies within the threshold of a set shell over its cone is apart from the bone.
constexpr double kOccupancyBinMm = 2.5;
inline OccupancyPyramid occupancy_pyramid(const LayeredMap& map) {
  return OccupancyPyramid(
      map.scheme(), [&map](std::int64_t i) { return map.occupancy(i, kOccupancyBinMm); }, std::uint64_t(0), BitOr{});
}
// The shells [lo, hi] (mm) meets.
inline std::uint64_t shells(double lo, double hi) { return radial_shell_bits(lo, hi, kOccupancyBinMm); }

// Clusters of a scan set: `size` consecutive vertices (Z order: neighbours on the sphere), their
// directions' cone (unit axis, half-angle) and radius range, in the body's frame. Two levels: leaves
// of kLeaf vertices, looked up together, in groups of kGroup vertices, whose bound is tried first.
constexpr std::int64_t kLeaf = 32, kGroup = 128;
// The hidden vertices (many, and most far from the other bone at every pose) have a third level: blocks of
// kBlock vertices, whose bound is tried before their groups'; and leaves of kHiddenLeaf, whose balls are
// tighter for the Euclidean bound (lhdl-ct's ROM map: 16 against 32 saves a sixth of the map's time; 8
// and 4 save less, 16 and 64 for the first surface cost more than 32).
constexpr std::int64_t kBlock = 1024, kHiddenLeaf = 16;
// A cluster's bound over its cap widened by this angle serves every later pose of a search within
// the angle (CompactScanner): two steps of the default search.
constexpr double kReuseRad = 4.1 * M_PI / 180;
// A wider one, tried first until it fails in a search (far clusters), serves the poses within this angle:
// six steps (lhdl-ct's ROM map: 8.1, 12.1 and 20.1 deg save a fifth of the map's time, 12.1 the most).
constexpr double kWideReuseRad = 12.1 * M_PI / 180;
// ... and for translations (the joint-centre methods) up to this much beyond the pose's, mm.
constexpr double kReuseShiftMm = 0.5;
// The ball's reachable subset holds for translations up to this, mm (beyond: every vertex).
constexpr double kReachableShiftMm = 5;
// Blocks across the bounding cap of a group, a leaf and a hidden cluster (measured on lhdl-ct). A hidden
// cluster's occupancy bound is read at the finer level of 24 blocks: its shells OR-ed over fewer, larger
// blocks merge the neck's and the trochanters' radii into those of the head's directions, and the bound
// then fails for clusters far from the bone (lhdl-ct's ROM map, 5 alternated runs: 4 -> 24 blocks cut its
// time by 30 %, tlem2-mri's and mc22-left's by 21-25 %; 8, 12, 16 and 32 cut less, 48 and 64 less still;
// the first surface's 8 stay best at 4, 12 and 16). The results are the same: only the skipping changes.
constexpr int kGroupBlocks = 8, kLeafBlocks = 8, kHiddenBlocks = 24;
struct Cluster {
  std::int64_t first = 0, count = 0;
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();
  double rho = 0, sin_rho = 0, r_min = 0, r_max = 0;
  double sin_rho_widened = 0;  ///< sin(rho + kReuseRad), for the bounds reused at nearby poses
  double cos_rho = 1;          ///< cos(rho)
  double r_mid = 0;            ///< (r_min + r_max) / 2
  double ball_radius = 0;      ///< every vertex lies within this of r_mid * axis, mm (bounds under translation)
};
inline std::vector<Cluster> clusters_of(const ScanSet& s, std::int64_t kSize) {
  std::vector<Cluster> out;
  for (std::int64_t f = 0; f < s.size(); f += kSize) {
    Cluster c;
    c.first = f;
    c.count = std::min(kSize, s.size() - f);
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    c.r_min = std::numeric_limits<double>::infinity();
    for (std::int64_t k = f; k < f + c.count; ++k) {
      const Eigen::Vector3d p(s.x[k], s.y[k], s.z[k]);
      sum += p.normalized();
      c.r_min = std::min(c.r_min, p.norm());
      c.r_max = std::max(c.r_max, p.norm());
    }
    c.axis = sum.norm() > 1e-9 ? Eigen::Vector3d(sum.normalized()) : Eigen::Vector3d::UnitZ();
    for (std::int64_t k = f; k < f + c.count; ++k)
      c.rho = std::max(c.rho, std::acos(std::clamp(Eigen::Vector3d(s.x[k], s.y[k], s.z[k]).normalized().dot(c.axis),
                                                   -1.0, 1.0)));
    c.rho += 1e-9;  // rounding of the angles
    c.sin_rho = std::sin(std::min(c.rho, M_PI / 2));  // a wider cone takes whole rows (cap)
    c.sin_rho_widened = std::sin(std::min(c.rho + kReuseRad, M_PI / 2));
    c.cos_rho = std::cos(c.rho);
    c.r_mid = 0.5 * (c.r_min + c.r_max);
    for (std::int64_t k = f; k < f + c.count; ++k)
      c.ball_radius = std::max(c.ball_radius, (Eigen::Vector3d(s.x[k], s.y[k], s.z[k]) - c.r_mid * c.axis).norm());
    c.ball_radius += 1e-9;
    out.push_back(c);
  }
  return out;
}

// The least gap over the counted vertices of both scans at a femur rotation. Clusters whose bound
// cannot reach the threshold are skipped; the others are looked up exactly (a search needs only the
// minimum: no per-vertex expansion or summary). Shared, read-only, by every search of a joint.
struct Least {
  double gap = std::numeric_limits<double>::infinity();
  bool ball = false;
  bool hidden = false;  ///< a hidden vertex, tested by the other body's layered map
  std::size_t vertex = 0;
  /// With exact contacts (rom_exact.hpp): where the two surfaces come nearest (the closest point on the
  /// surface of the vertex's bone), joint frame, mm; NaN from a per-vertex scan (the vertex is the place).
  Eigen::Vector3d point = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
};
// The ball's first-surface vertices that can meet the socket at some pose: a vertex at radius r
// has gap >= (least finite node of the socket map) - (r + |t|) at every rotation and translation t
// (a bilinear value is at least its least node), so a vertex with r < that least node - threshold
// - kReachableShiftMm never counts while |t| <= kReachableShiftMm. Their
// clusters serve the searches that ask only whether the bones meet; the exact least gap scans all.
inline ScanSet reachable_subset(const ScanSet& s, double least_node, double threshold) {
  ScanSet out;
  out.vertices = s.vertices;
  for (std::int64_t k = 0; k < s.size(); ++k)
    if (!(std::sqrt(s.x[k] * s.x[k] + s.y[k] * s.y[k] + s.z[k] * s.z[k]) < least_node - threshold)) {
      out.index.push_back(s.index[k]);
      out.x.push_back(s.x[k]), out.y.push_back(s.y[k]), out.z.push_back(s.z[k]);
    }
  return out;
}
// A scan set with its levels of clusters: leaves of `leaf` vertices in groups of kGroup, and for the
// hidden vertices (hidden) blocks of kBlock over the groups (empty otherwise).
struct Clustered {
  Clustered() = default;
  explicit Clustered(const ScanSet& s, bool hidden = false)
      : leaves(clusters_of(s, hidden ? kHiddenLeaf : kLeaf)),
        groups(clusters_of(s, kGroup)),
        blocks(hidden ? clusters_of(s, kBlock) : std::vector<Cluster>{}) {}
  std::vector<Cluster> leaves, groups, blocks;
};

// The vertices of a scan set that a baseline counts (skip: per vertex of the body, 1 = never counted:
// a pre-existing overlap or a joint surface left out); all of them with no skip list.
inline ScanSet counted_subset(const ScanSet& s, const std::vector<std::uint8_t>* skip) {
  if (skip == nullptr) return s;
  ScanSet out;
  out.vertices = s.vertices;
  for (std::int64_t k = 0; k < s.size(); ++k)
    if (!(*skip)[static_cast<std::size_t>(s.index[static_cast<std::size_t>(k)])]) {
      out.index.push_back(s.index[static_cast<std::size_t>(k)]);
      out.x.push_back(s.x[static_cast<std::size_t>(k)]), out.y.push_back(s.y[static_cast<std::size_t>(k)]),
          out.z.push_back(s.z[static_cast<std::size_t>(k)]);
    }
  return out;
}

// A scan set in the order of its clusters: median splits in space, so that every aligned run of kLeaf,
// kGroup and kBlock vertices is compact (order_in_boxes). Taken after the baseline's skip lists
// (counted_subset), which leave gaps in any order made before them: a run of 32 counted hidden pelvis
// vertices in Z order was seen to span a ball of 116 mm, whose bounds never part it from the femur.
inline ScanSet compact_order(const ScanSet& s, bool hidden = false) {
  return order_in_boxes(s, {hidden ? kHiddenLeaf : kLeaf, kGroup, kBlock});
}

}  // namespace rom_detail

// Bounds for the searches of one joint at one threshold: the map pyramids and the clusters
// (shared by every search that holds the baseline they were made with; read-only). With the
// baseline's skip lists, the scan sets hold only the vertices it counts (a vertex never counted is
// never looked up: the joint surfaces left out of an impingement search are most of those near
// contact at every pose).
struct RomSearchBounds {
  RomSearchBounds(const Joint& j, double threshold, const std::vector<std::uint8_t>* ball_skips = nullptr,
                  const std::vector<std::uint8_t>* socket_skips = nullptr)
      : joint(&j),
        threshold_mm(threshold),
        skip_ball(ball_skips != nullptr ? *ball_skips : std::vector<std::uint8_t>{}),
        skip_socket(socket_skips != nullptr ? *socket_skips : std::vector<std::uint8_t>{}),
        ball_set(rom_detail::compact_order(rom_detail::counted_subset(j.ball().scan_set, ball_skips))),
        socket_set(rom_detail::compact_order(rom_detail::counted_subset(j.socket().scan_set, socket_skips))),
        ball_hidden_set(rom_detail::compact_order(rom_detail::counted_subset(j.ball().hidden_set, ball_skips), true)),
        socket_hidden_set(rom_detail::compact_order(rom_detail::counted_subset(j.socket().hidden_set, socket_skips), true)),
        socket_min(rom_detail::bound_pyramid(j.socket().map, true)),
        ball_max(rom_detail::bound_pyramid(j.ball().map, false)),
        ball_reachable(rom_detail::reachable_subset(ball_set, socket_min.all(), threshold + rom_detail::kReachableShiftMm)),
        ball(ball_set),
        socket(socket_set),
        ball_reachable_clusters(ball_reachable) {
    if (j.socket().layered) {
      socket_occupancy.emplace(rom_detail::occupancy_pyramid(*j.socket().layered));
      ball_hidden = rom_detail::Clustered(ball_hidden_set, true);
    }
    if (j.ball().layered) {
      ball_occupancy.emplace(rom_detail::occupancy_pyramid(*j.ball().layered));
      socket_hidden = rom_detail::Clustered(socket_hidden_set, true);
    }
  }
  // Whether these bounds serve a search of `joint` at `threshold` whose baseline skips these vertices.
  bool serves(const Joint& j, double threshold, const std::vector<std::uint8_t>& ball_skips,
              const std::vector<std::uint8_t>& socket_skips) const {
    return joint == &j && threshold_mm == threshold && skip_ball == ball_skips && skip_socket == socket_skips;
  }
  const Joint* joint;
  double threshold_mm;
  std::vector<std::uint8_t> skip_ball, skip_socket;  // the skip lists the sets were made with (empty: none)
  ScanSet ball_set, socket_set, ball_hidden_set, socket_hidden_set;  // the counted vertices
  rom_detail::BoundPyramid socket_min, ball_max;
  ScanSet ball_reachable;
  rom_detail::Clustered ball, socket, ball_reachable_clusters;
  std::optional<rom_detail::OccupancyPyramid> socket_occupancy, ball_occupancy;
  rom_detail::Clustered ball_hidden, socket_hidden;
};

namespace rom_detail {
// The baseline's bounds when they were made for this joint and threshold, else new ones (null
// without bounds).
inline std::shared_ptr<const RomSearchBounds> bounds_for(const Joint& joint, const RomOptions& o, const RomBaseline& base) {
  if (!o.use_bounds || !screened_or_radial(o)) return nullptr;
  if (base.bounds && base.bounds->serves(joint, scan_cut_of(o), base.skip_ball, base.skip_socket)) return base.bounds;
  return std::make_shared<const RomSearchBounds>(joint, scan_cut_of(o), &base.skip_ball, &base.skip_socket);
}
}  // namespace rom_detail
}  // namespace impinge
