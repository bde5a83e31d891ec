#pragma once
// Private to libcore/src/clinical: the least-gap scanner of the ROM searches (rom.hpp), which skips
// the clusters whose bound cannot reach the threshold (rom_bounds.hpp). Included by rom.cpp and
// rom_envelope.cpp only.

#include "clinical/rom_bounds.hpp"

namespace impinge {
namespace rom_detail {
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

}  // namespace rom_detail
}  // namespace impinge
