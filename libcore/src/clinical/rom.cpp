#include "impinge/clinical/rom.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <optional>

#include "impinge/core/error.hpp"
#include "impinge/core/fast_angles.hpp"
#include "impinge/detection/detection.hpp"
#include "impinge/schemes/equiangular_grid.hpp"

namespace impinge {

const char* to_string(ImpingementSite site) {
  switch (site) {
    case ImpingementSite::intra_articular: return "intra_articular";
    case ImpingementSite::extra_articular: return "extra_articular";
    case ImpingementSite::none: break;
  }
  return "";
}

const char* to_string(RomMapStatus status) {
  switch (status) {
    case RomMapStatus::limited: return "limited";
    case RomMapStatus::contact_at_zero: return "contact_at_zero";
    case RomMapStatus::free: break;
  }
  return "free";
}

std::vector<StandardMotion> standard_motions() {
  return {
      {"flexion", [](double t) { return PoseAngles{t, 0, 0}; }},
      {"extension", [](double t) { return PoseAngles{-t, 0, 0}; }},
      {"abduction", [](double t) { return PoseAngles{0, -t, 0}; }},
      {"adduction", [](double t) { return PoseAngles{0, t, 0}; }},
      {"internal_rotation", [](double t) { return PoseAngles{0, 0, t}; }},
      {"external_rotation", [](double t) { return PoseAngles{0, 0, -t}; }},
      {"internal_rotation_90_flexion", [](double t) { return PoseAngles{90, 0, t}; }},
      {"external_rotation_90_flexion", [](double t) { return PoseAngles{90, 0, -t}; }},
      {"fadir", [](double t) { return PoseAngles{90, 10, t}; }},
  };
}

namespace {

void check(const RomOptions& o) {
  require(std::isfinite(o.threshold_mm), "rom: threshold must be finite");
  require(o.step_deg > 0 && o.max_deg > 0 && o.tolerance_deg > 0 && o.tolerance_deg <= o.step_deg,
          "rom: need step > 0, max > 0 and 0 < tolerance <= step (degrees)");
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
BoundPyramid bound_pyramid(const RadialDistanceMap& map, bool lower) {
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
OccupancyPyramid occupancy_pyramid(const LayeredMap& map) {
  return OccupancyPyramid(
      map.scheme(), [&map](std::int64_t i) { return map.occupancy(i, kOccupancyBinMm); }, std::uint64_t(0), BitOr{});
}
// The shells [lo, hi] (mm) meets.
std::uint64_t shells(double lo, double hi) { return radial_shell_bits(lo, hi, kOccupancyBinMm); }

// Clusters of a scan set: `size` consecutive vertices (Z order: neighbours on the sphere), their
// directions' cone (unit axis, half-angle) and radius range, in the body's frame. Two levels: leaves
// of kLeaf vertices, looked up together, in groups of kGroup vertices, whose bound is tried first.
constexpr std::int64_t kLeaf = 32, kGroup = 128;
// A cluster's bound over its cap widened by this angle serves every later pose of a search within
// the angle (CompactScanner): two steps of the default search.
constexpr double kReuseRad = 4.1 * M_PI / 180;
// Blocks across the bounding cap of a group, a leaf and a hidden cluster (measured on lhdl-ct).
constexpr int kGroupBlocks = 8, kLeafBlocks = 8, kHiddenBlocks = 4;
struct Cluster {
  std::int64_t first = 0, count = 0;
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();
  double rho = 0, sin_rho = 0, r_min = 0, r_max = 0;
  double sin_rho_widened = 0;  ///< sin(rho + kReuseRad), for the bounds reused at nearby poses
};
std::vector<Cluster> clusters_of(const ScanSet& s, std::int64_t kSize) {
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
};
// The ball's first-surface vertices that can meet the socket at some rotation: a vertex at radius r
// has gap >= (least finite node of the socket map) - r at every rotation (a bilinear value is at
// least its least node), so a vertex with r < that least node - threshold never counts. Their
// clusters serve the searches that ask only whether the bones meet; the exact least gap scans all.
ScanSet reachable_subset(const ScanSet& s, double least_node, double threshold) {
  ScanSet out;
  out.vertices = s.vertices;
  for (std::int64_t k = 0; k < s.size(); ++k)
    if (!(std::sqrt(s.x[k] * s.x[k] + s.y[k] * s.y[k] + s.z[k] * s.z[k]) < least_node - threshold)) {
      out.index.push_back(s.index[k]);
      out.x.push_back(s.x[k]), out.y.push_back(s.y[k]), out.z.push_back(s.z[k]);
    }
  return out;
}
// A scan set with its two levels of clusters.
struct Clustered {
  Clustered() = default;
  explicit Clustered(const ScanSet& s) : leaves(clusters_of(s, kLeaf)), groups(clusters_of(s, kGroup)) {}
  std::vector<Cluster> leaves, groups;
};
}  // namespace

// Bounds for the searches of one joint at one threshold: the map pyramids and the clusters
// (shared by every search that holds the baseline they were made with; read-only).
struct RomSearchBounds {
  RomSearchBounds(const Joint& j, double threshold)
      : joint(&j),
        threshold_mm(threshold),
        socket_min(bound_pyramid(j.socket().map, true)),
        ball_max(bound_pyramid(j.ball().map, false)),
        ball_reachable(reachable_subset(j.ball().scan_set, socket_min.all(), threshold)),
        ball(j.ball().scan_set),
        socket(j.socket().scan_set),
        ball_reachable_clusters(ball_reachable) {
    if (j.socket().layered) {
      socket_occupancy.emplace(occupancy_pyramid(*j.socket().layered));
      ball_hidden = Clustered(j.ball().hidden_set);
    }
    if (j.ball().layered) {
      ball_occupancy.emplace(occupancy_pyramid(*j.ball().layered));
      socket_hidden = Clustered(j.socket().hidden_set);
    }
  }
  const Joint* joint;
  double threshold_mm;
  BoundPyramid socket_min, ball_max;
  ScanSet ball_reachable;
  Clustered ball, socket, ball_reachable_clusters;
  std::optional<OccupancyPyramid> socket_occupancy, ball_occupancy;
  Clustered ball_hidden, socket_hidden;
};

namespace {
class CompactScanner {
 public:
  CompactScanner(const Joint& joint, const RomBaseline& base, const RomSearchBounds* bounds, double threshold,
                 RomVertices counted)
      : joint_(joint), bounds_(bounds), threshold_(threshold), counted_(counted) {
    auto skips = [](const ScanSet& set, const std::vector<std::uint8_t>& by_vertex) {
      std::vector<std::uint8_t> out;
      for (std::int32_t i : set.index) out.push_back(by_vertex[static_cast<std::size_t>(i)]);
      return out;
    };
    skip_ball_ = skips(joint.ball().scan_set, base.skip_ball);
    skip_socket_ = skips(joint.socket().scan_set, base.skip_socket);
    skip_ball_hidden_ = skips(joint.ball().hidden_set, base.skip_ball);
    skip_socket_hidden_ = skips(joint.socket().hidden_set, base.skip_socket);
    if (bounds_ != nullptr) skip_ball_reachable_ = skips(bounds_->ball_reachable, base.skip_ball);
    buf_.resize(static_cast<std::size_t>(std::max({joint.ball().scan_set.size(), joint.socket().scan_set.size(),
                                                   joint.ball().hidden_set.size(), joint.socket().hidden_set.size()})));
  }
  // The least counted gap at rotation R. exact: the true minimum; otherwise the true minimum when it
  // is <= the threshold, and some value > the threshold when it is not (clusters above it and the
  // ball vertices that no rotation brings within it are skipped). Without `exact`, the scan stops at
  // the first counted gap <= the threshold (the caller asks only whether the bones meet), starting
  // with the cluster that met last time.
  Least operator()(const Eigen::Matrix3d& R, bool exact) {
    Least l;
    const double cut = exact ? std::numeric_limits<double>::infinity() : threshold_;
    exact_ = exact;
    if (!exact && last_.cluster != nullptr) {
      recheck(R, l);
      if (l.gap <= threshold_) return l;
    }
    last_ = {};
    if (counted_ != RomVertices::hidden) {
      const Part ball = bounds_ == nullptr ? Part{&joint_.ball().scan_set, &skip_ball_, nullptr, true}
                        : exact ? Part{&joint_.ball().scan_set, &skip_ball_, &bounds_->ball, true}
                                : Part{&bounds_->ball_reachable, &skip_ball_reachable_, &bounds_->ball_reachable_clusters, true};
      const Part socket{&joint_.socket().scan_set, &skip_socket_, bounds_ == nullptr ? nullptr : &bounds_->socket, false};
      scan(R, ball, joint_.socket().map, cut, l);
      if (done(l)) return l;
      scan(R.transpose(), socket, joint_.ball().map, cut, l);
      if (done(l)) return l;
    }
    if (counted_ == RomVertices::first_surface) return l;
    if (joint_.socket().layered)
      scan_hidden(R, joint_.ball().hidden_set, *joint_.socket().layered, joint_.socket().caster.get(), skip_ball_hidden_,
                  true, cut, l);
    if (done(l)) return l;
    if (joint_.ball().layered)
      scan_hidden(R.transpose(), joint_.socket().hidden_set, *joint_.ball().layered, joint_.ball().caster.get(),
                  skip_socket_hidden_, false, cut, l);
    return l;
  }
  std::int64_t vertices_looked_up = 0, vertices_skipped = 0;

 private:
  // First-surface vertices of one body, their skip flags (pre-existing overlap) and clusters (null:
  // no bounds); ball: the femur's, looked up in the socket map (inside), else the pelvis' (outside).
  struct Part {
    const ScanSet* set = nullptr;
    const std::vector<std::uint8_t>* skip = nullptr;
    const Clustered* clusters = nullptr;
    bool ball = true;
  };
  void scan(const Eigen::Matrix3d& R, const Part& part, const RadialDistanceMap& map, double cut, Least& l) {
    const ScanSet& set = *part.set;
    const bool ball = part.ball;
    const ScanSide side = ball ? ScanSide::inside : ScanSide::outside;
    const BoundPyramid* pyr = bounds_ == nullptr ? nullptr : ball ? &bounds_->socket_min : &bounds_->ball_max;
    if (pyr == nullptr || !pyr->valid() || part.clusters == nullptr) {
      scan_gaps_compact(set, R, Eigen::Vector3d::Zero(), map, side, buf_.data());
      take(set, *part.skip, 0, set.size(), ball, l);
      vertices_looked_up += set.size();
      return;
    }
    const std::vector<Cluster>& cl = part.clusters->leaves;
    // Lower bound of every gap in a cluster whose directions lie within `widen` of where R takes
    // them: inside, d - r >= min d - r_max; outside, r - d >= r_min - max d.
    auto lower_bound = [&](const Cluster& c, double widen) {  // widen: 0 or kReuseRad
      const double rho = c.rho + widen;
      const float bound = pyr->cap(R * c.axis, rho, widen == 0 ? c.sin_rho : c.sin_rho_widened,
                                   c.count > kLeaf ? kGroupBlocks : kLeafBlocks);
      return ball ? double(bound) - c.r_max : c.r_min - double(bound);
    };
    auto skipped = [&](const Cluster& c) {
      const double lb = lower_bound(c, 0);
      return lb > cut || lb > l.gap;
    };
    // A search's poses follow each other closely: a cluster whose bound over a cap widened by
    // kReuseRad stays above the cut is skipped at every later pose within that angle of this one
    // (the directions of its vertices move by at most the angle of the relative rotation).
    const bool reusable = !exact_;
    std::vector<Reuse>& reuse_g = ball ? reuse_ball_groups_ : reuse_socket_groups_;
    std::vector<Reuse>& reuse_l = ball ? reuse_ball_leaves_ : reuse_socket_leaves_;
    if (reusable && reuse_g.size() != part.clusters->groups.size()) {
      reuse_g.assign(part.clusters->groups.size(), Reuse{});
      reuse_l.assign(cl.size(), Reuse{});
    }
    auto skip_reusing = [&](const Cluster& c, Reuse& u) {
      if (u.valid && (u.R.array() * R.array()).sum() >= kReuseMinTrace) return true;
      bool skip;
      if (!u.failed) {
        u.valid = lower_bound(c, kReuseRad) > cut, u.R = R;
        skip = u.valid || lower_bound(c, 0) > cut;
      } else {
        skip = lower_bound(c, 0) > cut, u.valid = false;
      }
      u.failed = !skip;
      return skip;
    };
    for (std::size_t gi = 0; gi < part.clusters->groups.size(); ++gi) {
      const Cluster& g = part.clusters->groups[gi];
      if (done(l)) return;
      if (reusable ? skip_reusing(g, reuse_g[gi]) : skipped(g)) {
        vertices_skipped += g.count;
        continue;
      }
      for (std::int64_t i = g.first / kLeaf; i < (g.first + g.count + kLeaf - 1) / kLeaf; ++i) {
        const Cluster& c = cl[static_cast<std::size_t>(i)];
        if (done(l)) return;
        if (reusable ? skip_reusing(c, reuse_l[static_cast<std::size_t>(i)]) : skipped(c)) {
          vertices_skipped += c.count;
          continue;
        }
        look_up(R, set, map, side, c);
        take(set, *part.skip, c.first, c.first + c.count, ball, l);
        vertices_looked_up += c.count;
        if (l.gap <= threshold_) last_ = {part, &c};
      }
    }
  }
  void look_up(const Eigen::Matrix3d& R, const ScanSet& set, const RadialDistanceMap& map, ScanSide side,
               const Cluster& c) {
    double x[kLeaf], y[kLeaf], z[kLeaf], d[kLeaf];
    for (std::int64_t k = 0; k < c.count; ++k) {
      const Eigen::Vector3d q = R * Eigen::Vector3d(set.x[c.first + k], set.y[c.first + k], set.z[c.first + k]);
      x[k] = q.x(), y[k] = q.y(), z[k] = q.z();
    }
    map.lookup_many_soa(x, y, z, c.count, d);
    for (std::int64_t k = 0; k < c.count; ++k) {
      const double r = std::sqrt(x[k] * x[k] + y[k] * y[k] + z[k] * z[k]);
      buf_[static_cast<std::size_t>(c.first + k)] = static_cast<float>(static_cast<double>(side) * (d[k] - r));
    }
  }
  // The first-surface cluster that met at the previous evaluation, looked up first.
  void recheck(const Eigen::Matrix3d& R, Least& l) {
    const Part& p = last_.part;
    if (p.ball)
      look_up(R, *p.set, joint_.socket().map, ScanSide::inside, *last_.cluster);
    else
      look_up(R.transpose(), *p.set, joint_.ball().map, ScanSide::outside, *last_.cluster);
    take(*p.set, *p.skip, last_.cluster->first, last_.cluster->first + last_.cluster->count, p.ball, l);
    vertices_looked_up += last_.cluster->count;
  }
  bool done(const Least& l) const { return !exact_ && l.gap <= threshold_; }
  // Hidden vertices of one body against the other's layered map: a cluster is skipped when no radial
  // shell of the other bone over its cone lies within min(cut, least gap so far) of its radii.
  void scan_hidden(const Eigen::Matrix3d& R, const ScanSet& set, const LayeredMap& map, const FirstHitCaster* exact,
                   const std::vector<std::uint8_t>& skip, bool ball, double cut, Least& l) {
    const OccupancyPyramid* pyr =
        bounds_ == nullptr ? nullptr : ball ? &*bounds_->socket_occupancy : &*bounds_->ball_occupancy;
    const std::vector<Cluster>* cl =
        bounds_ == nullptr ? nullptr : ball ? &bounds_->ball_hidden.leaves : &bounds_->socket_hidden.leaves;
    if (pyr == nullptr || !pyr->valid()) {
      scan_layered(set, R, Eigen::Vector3d::Zero(), map, buf_.data(), exact);
      take(set, skip, 0, set.size(), ball, l, true);
      vertices_looked_up += set.size();
      return;
    }
    const std::vector<Cluster>* groups = ball ? &bounds_->ball_hidden.groups : &bounds_->socket_hidden.groups;
    auto skipped = [&](const Cluster& c) {
      const double reach = std::max(0.0, std::min(cut, l.gap));
      return std::isfinite(reach) && (pyr->cap(R * c.axis, c.rho, c.sin_rho, kHiddenBlocks) & shells(c.r_min - reach, c.r_max + reach)) == 0;
    };
    for (const Cluster& g : *groups) {
      if (done(l)) return;
      if (skipped(g)) {
        vertices_skipped += g.count;
        continue;
      }
      for (std::int64_t i = g.first / kLeaf; i < (g.first + g.count + kLeaf - 1) / kLeaf; ++i) {
        const Cluster& c = (*cl)[static_cast<std::size_t>(i)];
        if (done(l)) return;
        if (skipped(c)) {
          vertices_skipped += c.count;
          continue;
        }
        scan_layered(set, c.first, c.count, R, Eigen::Vector3d::Zero(), map, buf_.data(), exact);
        take(set, skip, c.first, c.first + c.count, ball, l, true);
        vertices_looked_up += c.count;
      }
    }
  }
  void take(const ScanSet& set, const std::vector<std::uint8_t>& skip, std::int64_t from, std::int64_t to, bool ball,
            Least& l, bool hidden = false) const {
    for (std::int64_t j = from; j < to; ++j)
      if (!skip[static_cast<std::size_t>(j)] && buf_[static_cast<std::size_t>(j)] < l.gap)
        l.gap = buf_[static_cast<std::size_t>(j)], l.ball = ball, l.hidden = hidden,
        l.vertex = static_cast<std::size_t>(set.index[j]);
  }
  const Joint& joint_;
  const RomSearchBounds* bounds_;
  double threshold_;
  RomVertices counted_;
  bool exact_ = true;
  // A group's bound at an earlier pose over a widened cap (valid: it was above the cut), or that
  // its bound failed at the last pose (failed: try the plain cap first next time).
  struct Reuse {
    Eigen::Matrix3d R = Eigen::Matrix3d::Zero();
    bool valid = false, failed = false;
  };
  static inline const double kReuseMinTrace = 1 + 2 * std::cos(kReuseRad);  // trace of a rotation by kReuseRad
  std::vector<Reuse> reuse_ball_groups_, reuse_socket_groups_, reuse_ball_leaves_, reuse_socket_leaves_;
  struct Met {
    Part part;
    const Cluster* cluster = nullptr;
  } last_;  ///< the first-surface cluster that met at the last evaluation (cluster null: none)
  std::vector<std::uint8_t> skip_ball_reachable_, skip_ball_, skip_socket_, skip_ball_hidden_, skip_socket_hidden_;
  std::vector<float> buf_;
};

}  // namespace

RomBaseline rom_baseline(const HipJoint& hip, const Eigen::Matrix3d& R, const RomOptions& o) {
  check(o);
  PoseResult r;
  hip.joint().detect(R, Eigen::Vector3d::Zero(), r);
  RomBaseline b;
  b.skip_ball.resize(r.ball_gaps.gap_mm.size());
  b.skip_socket.resize(r.socket_gaps.gap_mm.size());
  for (std::size_t i = 0; i < b.skip_ball.size(); ++i) b.skip_ball[i] = r.ball_gaps.gap_mm[i] <= o.threshold_mm;
  for (std::size_t i = 0; i < b.skip_socket.size(); ++i) b.skip_socket[i] = r.socket_gaps.gap_mm[i] <= o.threshold_mm;
  for (auto s : b.skip_ball) b.excluded_vertices += s;
  for (auto s : b.skip_socket) b.excluded_vertices += s;
  b.min_gap_mm = std::fmin(r.ball.min_gap_mm, r.socket.min_gap_mm);
  if (o.use_bounds) b.bounds = std::make_shared<const RomSearchBounds>(hip.joint(), o.threshold_mm);
  return b;
}

namespace {
// The baseline's bounds when they were made for this joint and threshold, else new ones (null
// without bounds).
std::shared_ptr<const RomSearchBounds> bounds_for(const Joint& joint, const RomOptions& o, const RomBaseline& base) {
  if (!o.use_bounds) return nullptr;
  if (base.bounds && base.bounds->joint == &joint && base.bounds->threshold_mm == o.threshold_mm) return base.bounds;
  return std::make_shared<const RomSearchBounds>(joint, o.threshold_mm);
}
// limit_only: only limit_deg, contact_at_start and the counts are wanted (a ROM map's cell), so
// neither end is scanned for the exact least gap and the monotony is not checked.
RomLimit search(const HipJoint& hip, const std::function<Eigen::Matrix3d(double)>& rotation, const RomOptions& o,
                const RomBaseline& base, const RomSearchBounds* bounds, bool limit_only = false) {
  const Joint& joint = hip.joint();
  require(base.skip_ball.size() == static_cast<std::size_t>(joint.ball().relative.rows()) &&
              base.skip_socket.size() == static_cast<std::size_t>(joint.socket().relative.rows()),
          "rom: the baseline belongs to another joint");
  RomLimit out;
  out.excluded_vertices = base.excluded_vertices;
  require(o.vertices != RomVertices::hidden || (joint.ball().layered && joint.socket().layered),
          "rom: counting hidden vertices needs layered maps (JointOptions::layers > 0)");
  CompactScanner scan(joint, base, bounds, o.threshold_mm, o.vertices);
  auto gap_at = [&](double t, bool exact = false) {
    ++out.evaluations;
    return scan(rotation(t), exact);
  };
  double lo = 0, hi = 0;
  const double start_gap = gap_at(0, !limit_only).gap;
  if (!limit_only) out.min_gap_at_start_mm = start_gap;
  bool found = start_gap <= o.threshold_mm;
  out.contact_at_start = found;
  for (int k = 1; !found; ++k) {
    const double t = std::min(o.max_deg, k * o.step_deg);
    const double g = gap_at(t).gap;
    if (g <= o.threshold_mm) {
      found = true, hi = t;
    } else {
      lo = t;
      if (t >= o.max_deg) return out;
    }
  }
  while (hi - lo > o.tolerance_deg) {
    const double mid = 0.5 * (lo + hi);
    (gap_at(mid).gap <= o.threshold_mm ? hi : lo) = mid;
  }
  if (limit_only) {
    out.vertices_looked_up = scan.vertices_looked_up;
    out.vertices_skipped = scan.vertices_skipped;
    out.limit_deg = hi;
    return out;
  }
  const Least l = gap_at(hi, true);  // the least gap and where, not only whether they meet
  // A transient touch: the bones part again one step farther.
  if (hi + o.step_deg <= o.max_deg) out.monotone = gap_at(hi + o.step_deg).gap <= o.threshold_mm;
  out.vertices_looked_up = scan.vertices_looked_up;
  out.vertices_skipped = scan.vertices_skipped;
  out.limit_deg = hi;
  out.min_gap_at_limit_mm = l.gap;
  out.limited_by_ball = l.ball;
  // The contact point: the vertex, posed, in the joint frame (the pelvis does not move).
  const Eigen::Matrix3d R = rotation(hi);
  const Eigen::Vector3d p_joint =
      l.ball ? Eigen::Vector3d(R * joint.ball().relative.row(static_cast<Eigen::Index>(l.vertex)).transpose())
             : Eigen::Vector3d(joint.socket().relative.row(static_cast<Eigen::Index>(l.vertex)).transpose());
  out.contact_mm = hip.to_working(p_joint);
  const double rim = hip.acetabulum() ? hip.acetabulum()->rim_radius_mm : hip.head_radius_mm() + 5;
  out.limited_by = p_joint.norm() <= rim + o.intra_articular_margin_mm ? ImpingementSite::intra_articular
                                                                      : ImpingementSite::extra_articular;
  out.limited_by_hidden_vertex = l.hidden;
  if (hip.socket_clock()) {
    // On the socket the contact point itself; on the femur the point carried back onto the unposed femur.
    out.socket_clock_h = hip.socket_clock()->hour(p_joint);
    out.femur_clock_h = hip.ball_clock()->hour(R.transpose() * p_joint);
  }
  return out;
}

}  // namespace

RomLimit find_rom_limit(const HipJoint& hip, const std::function<Eigen::Matrix3d(double)>& rotation,
                        const RomOptions& o, const RomBaseline& base) {
  check(o);
  const std::shared_ptr<const RomSearchBounds> bounds = bounds_for(hip.joint(), o, base);
  return search(hip, rotation, o, base, bounds.get());
}

RomLimit find_rom_limit(const HipJoint& hip, const std::function<PoseAngles(double)>& motion, const RomOptions& o,
                        const RomBaseline& base) {
  return find_rom_limit(
      hip, std::function<Eigen::Matrix3d(double)>([&](double t) { return hip.femur_rotation(motion(t)); }), o, base);
}

std::vector<RomLimit> find_rom_limits(const HipJoint& hip, const std::vector<StandardMotion>& motions,
                                      const RomOptions& o, const RomBaseline& base) {
  check(o);
  const std::shared_ptr<const RomSearchBounds> bounds = bounds_for(hip.joint(), o, base);
  std::vector<RomLimit> out(motions.size());
  std::vector<std::string> errors(motions.size());
  const auto n = static_cast<std::int64_t>(motions.size());
#pragma omp parallel for schedule(dynamic, 1)
  for (std::int64_t k = 0; k < n; ++k) {
    try {
      const auto& m = motions[static_cast<std::size_t>(k)];
      out[static_cast<std::size_t>(k)] = search(
          hip, std::function<Eigen::Matrix3d(double)>([&](double t) { return hip.femur_rotation(m.angles(t)); }), o,
          base, bounds.get());
    } catch (const std::exception& e) {
      errors[static_cast<std::size_t>(k)] = e.what();
    }
  }
  for (const auto& e : errors) require(e.empty(), e);
  return out;
}

std::vector<RomMapCell> rom_map(const HipJoint& hip, const std::vector<double>& flexion,
                                const std::vector<double>& adduction, const RomOptions& o, const RomBaseline& base) {
  check(o);
  const std::shared_ptr<const RomSearchBounds> bounds = bounds_for(hip.joint(), o, base);
  std::vector<RomMapCell> cells;
  for (double f : flexion)
    for (double a : adduction) cells.push_back({f, a, std::numeric_limits<double>::quiet_NaN(), RomMapStatus::free});
  const auto n = static_cast<std::int64_t>(cells.size());
  std::vector<std::string> errors(cells.size());
#pragma omp parallel for schedule(dynamic, 1)
  for (std::int64_t k = 0; k < n; ++k) {
    RomMapCell& c = cells[static_cast<std::size_t>(k)];
    try {
      const RomLimit l = search(hip, std::function<Eigen::Matrix3d(double)>([&](double t) {
                                  return hip.femur_rotation(PoseAngles{c.flexion_deg, c.adduction_deg, t});
                                }),
                                o, base, bounds.get(), true);
      c.vertices_looked_up = l.vertices_looked_up;
      c.vertices_skipped = l.vertices_skipped;
      c.evaluations = l.evaluations;
      c.max_internal_rotation_deg = l.contact_at_start ? std::numeric_limits<double>::quiet_NaN() : l.limit_deg;
      c.status = l.contact_at_start          ? RomMapStatus::contact_at_zero
                 : std::isnan(l.limit_deg) ? RomMapStatus::free
                                           : RomMapStatus::limited;
    } catch (const std::exception& e) {
      errors[static_cast<std::size_t>(k)] = e.what();
    }
  }
  for (const auto& e : errors) require(e.empty(), e);
  return cells;
}

namespace {
std::vector<double> envelope_axis(double lo, double hi, double step, const char* name) {
  require(std::isfinite(lo) && std::isfinite(hi) && hi >= lo, std::string("rom envelope: bad ") + name + " range");
  const double n = (hi - lo) / step;
  require(std::abs(n - std::round(n)) < 1e-6 && n < 1e6,
          std::string("rom envelope: the ") + name + " range is not a whole number of steps");
  std::vector<double> a;
  for (long k = 0; k <= std::lround(n); ++k) a.push_back(lo + double(k) * step);
  return a;
}
// A box of grid indices [lo, hi] per axis.
struct Box {
  std::array<int, 3> lo, hi;
};
}  // namespace

RomEnvelope rom_envelope(const HipJoint& hip, const RomEnvelopeOptions& e, const RomOptions& o,
                         const RomBaseline& base) {
  check(o);
  require(e.step_deg > 0 && e.coarse_steps >= 1, "rom envelope: need step > 0 and coarse_steps >= 1");
  RomEnvelope out;
  out.flexion_deg = envelope_axis(e.flexion_min_deg, e.flexion_max_deg, e.step_deg, "flexion");
  out.adduction_deg = envelope_axis(e.adduction_min_deg, e.adduction_max_deg, e.step_deg, "adduction");
  out.internal_rotation_deg =
      envelope_axis(e.internal_rotation_min_deg, e.internal_rotation_max_deg, e.step_deg, "internal rotation");
  const std::array<int, 3> n{static_cast<int>(out.flexion_deg.size()), static_cast<int>(out.adduction_deg.size()),
                             static_cast<int>(out.internal_rotation_deg.size())};
  out.poses = std::int64_t(n[0]) * n[1] * n[2];
  auto index = [&](int i, int j, int k) { return (std::size_t(i) * n[1] + j) * n[2] + k; };
  std::vector<std::int8_t> state(static_cast<std::size_t>(out.poses), -1);  // -1 unknown, 0 contact, 1 valid
  const Joint& joint = hip.joint();
  const std::shared_ptr<const RomSearchBounds> bounds = bounds_for(joint, o, base);

  // Scan the listed poses on all cores; each thread keeps its scanner.
  std::int64_t looked = 0, skipped = 0;
  auto scan_all = [&](const std::vector<std::size_t>& poses) {
    const auto m = static_cast<std::int64_t>(poses.size());
#pragma omp parallel reduction(+ : looked, skipped)
    {
      CompactScanner scan(joint, base, bounds.get(), o.threshold_mm, o.vertices);
#pragma omp for schedule(dynamic, 64)
      for (std::int64_t q = 0; q < m; ++q) {
        const std::size_t p = poses[static_cast<std::size_t>(q)];
        const std::size_t k = p % n[2], j = (p / n[2]) % n[1], i = p / (std::size_t(n[1]) * n[2]);
        const Eigen::Matrix3d R =
            hip.femur_rotation(PoseAngles{out.flexion_deg[i], out.adduction_deg[j], out.internal_rotation_deg[k]});
        state[p] = scan(R, false).gap > o.threshold_mm ? 1 : 0;
      }
      looked += scan.vertices_looked_up;
      skipped += scan.vertices_skipped;
    }
    out.poses_evaluated += m;
  };
  // The corners of a box not yet known.
  auto unknown_corners = [&](const Box& b, std::vector<std::size_t>& list) {
    for (int c = 0; c < 8; ++c) {
      const std::size_t p = index((c & 1) ? b.hi[0] : b.lo[0], (c & 2) ? b.hi[1] : b.lo[1], (c & 4) ? b.hi[2] : b.lo[2]);
      if (state[p] < 0) {
        state[p] = 2;  // listed
        list.push_back(p);
      }
    }
  };
  // The coarse lattice's cells.
  std::vector<Box> boxes;
  std::array<std::vector<int>, 3> cuts;
  for (int a = 0; a < 3; ++a) {
    for (int v = 0; v < n[a] - 1; v += e.coarse_steps) cuts[a].push_back(v);
    cuts[a].push_back(n[a] - 1);
  }
  for (std::size_t x = 0; x + 1 < std::max<std::size_t>(cuts[0].size(), 2); ++x)
    for (std::size_t y = 0; y + 1 < std::max<std::size_t>(cuts[1].size(), 2); ++y)
      for (std::size_t z = 0; z + 1 < std::max<std::size_t>(cuts[2].size(), 2); ++z) {
        auto at = [](const std::vector<int>& c, std::size_t k) { return c[std::min(k, c.size() - 1)]; };
        boxes.push_back({{at(cuts[0], x), at(cuts[1], y), at(cuts[2], z)},
                         {at(cuts[0], x + 1), at(cuts[1], y + 1), at(cuts[2], z + 1)}});
      }
  std::vector<Box> uniform;  // boxes whose corners agree: filled at the end
  while (!boxes.empty()) {
    std::vector<std::size_t> list;
    for (const Box& b : boxes) unknown_corners(b, list);
    scan_all(list);
    std::vector<Box> next;
    for (const Box& b : boxes) {
      int sum = 0;
      for (int c = 0; c < 8; ++c)
        sum += state[index((c & 1) ? b.hi[0] : b.lo[0], (c & 2) ? b.hi[1] : b.lo[1], (c & 4) ? b.hi[2] : b.lo[2])];
      if (sum == 0 || sum == 8) {
        uniform.push_back(b);
        continue;
      }
      // Split every axis wider than one step at its middle.
      std::array<std::array<int, 3>, 3> cut;  // per axis: lo, mid, hi (mid = hi when not split)
      std::array<int, 3> parts;
      for (int a = 0; a < 3; ++a) {
        const int w = b.hi[a] - b.lo[a];
        cut[a] = {b.lo[a], w > 1 ? b.lo[a] + w / 2 : b.hi[a], b.hi[a]};
        parts[a] = w > 1 ? 2 : 1;
      }
      if (parts[0] * parts[1] * parts[2] == 1) continue;  // single steps: every corner is known
      for (int x = 0; x < parts[0]; ++x)
        for (int y = 0; y < parts[1]; ++y)
          for (int z = 0; z < parts[2]; ++z)
            next.push_back({{cut[0][x], cut[1][y], cut[2][z]},
                            {parts[0] == 1 ? cut[0][2] : cut[0][x + 1], parts[1] == 1 ? cut[1][2] : cut[1][y + 1],
                             parts[2] == 1 ? cut[2][2] : cut[2][z + 1]}});
    }
    boxes = std::move(next);
  }
  for (const Box& b : uniform) {
    const std::int8_t v = state[index(b.lo[0], b.lo[1], b.lo[2])];
    for (int i = b.lo[0]; i <= b.hi[0]; ++i)
      for (int j = b.lo[1]; j <= b.hi[1]; ++j)
        for (int k = b.lo[2]; k <= b.hi[2]; ++k)
          if (state[index(i, j, k)] < 0) state[index(i, j, k)] = v;
  }
  out.valid.resize(state.size());
  for (std::size_t p = 0; p < state.size(); ++p) {
    require(state[p] == 0 || state[p] == 1, "rom envelope: internal error, a pose was left undecided");
    out.valid[p] = static_cast<std::uint8_t>(state[p]);
  }
  out.vertices_looked_up = looked;
  out.vertices_skipped = skipped;
  return out;
}

}  // namespace impinge
