#pragma once
// Private to libcore/src/clinical: the least-gap scanner of the ROM searches (rom.hpp), which skips
// the clusters whose bound cannot reach the threshold (rom_bounds.hpp). The searches use it through
// GapScanner (rom_gap_scanner.hpp).

#include "clinical/rom_bounds.hpp"

namespace impinge {
namespace rom_detail {
// A counted vertex with a gap at or below a scan's threshold (CompactScanner's `collect`).
struct Candidate {
  float gap;    // its gap, mm
  bool ball;    // a femur vertex (else a pelvis vertex)
  bool hidden;  // tested by the other body's layered map
  std::size_t vertex;
};

// How the pelvis' contacts are counted at each pose (RomBaseline::head_zone, contacts): a pelvis vertex
// meeting the femur's head up to its head-neck junction meets its joint surface (articular), wherever on the
// acetabulum it lies; the lunate surface meeting the neck or a cam does not (issue 81).
struct PelvisContacts {
  explicit PelvisContacts(const RomBaseline& base)
      : base_(&base), articular_only(base.contacts == RomContacts::articular) {}
  bool classed() const { return base_->head_zone.has_value(); }
  // Whether a pelvis vertex at y (femur frame, unposed: relative to the COR) counts.
  bool counts(const Eigen::Vector3d& y) const { return base_->meets_head(y) == articular_only; }
  const RomBaseline* base_;  // its head zone (joint frame; empty: pelvis contacts not classed per pose)
  bool articular_only;       // count the joint surfaces only (RomContacts::articular)
};

class CompactScanner {
 public:
  CompactScanner(const Joint& joint, const RomBaseline& base, const RomSearchBounds* bounds, double threshold,
                 RomVertices counted)
      : joint_(joint),
        bounds_(bounds),
        threshold_(threshold),
        counted_(counted),
        pelvis_(base),
        // With bounds, the counted vertices only (RomSearchBounds); their skip flags are then all 0.
        ball_set_(bounds != nullptr ? &bounds->ball_set : &joint.ball().scan_set),
        socket_set_(bounds != nullptr ? &bounds->socket_set : &joint.socket().scan_set),
        ball_hidden_set_(bounds != nullptr ? &bounds->ball_hidden_set : &joint.ball().hidden_set),
        socket_hidden_set_(bounds != nullptr ? &bounds->socket_hidden_set : &joint.socket().hidden_set) {
    auto skips = [](const ScanSet& set, const std::vector<std::uint8_t>& by_vertex) {
      std::vector<std::uint8_t> out(set.index.size());
      for (std::size_t k = 0; k < out.size(); ++k) out[k] = by_vertex[static_cast<std::size_t>(set.index[k])];
      return out;
    };
    skip_ball_ = skips(*ball_set_, base.skip_ball);
    skip_socket_ = skips(*socket_set_, base.skip_socket);
    skip_ball_hidden_ = skips(*ball_hidden_set_, base.skip_ball);
    skip_socket_hidden_ = skips(*socket_hidden_set_, base.skip_socket);
    if (bounds_ != nullptr) skip_ball_reachable_ = skips(bounds_->ball_reachable, base.skip_ball);
    buf_.resize(static_cast<std::size_t>(std::max({joint.ball().scan_set.size(), joint.socket().scan_set.size(),
                                                   joint.ball().hidden_set.size(), joint.socket().hidden_set.size()})));
  }
  // The least counted gap with the femur posed by rotation R and translation t (joint frame, mm:
  // a femur point p goes to R p + t), as Joint::detect computes it (exact ray casts at the maps'
  // depth discontinuities included). exact: the true minimum; otherwise the true minimum when it
  // is <= the threshold, and some value > the threshold when it is not (clusters above it and the
  // ball vertices that no rotation brings within it are skipped). Without `exact`, the scan stops at
  // the first counted gap <= the threshold (the caller asks only whether the bones meet), starting
  // with the cluster that met last time.
  //
  // With `collect`, every counted vertex whose gap is <= the threshold is listed there too (the least
  // is then taken over the clusters the bounds cannot skip, and the scan does not stop at the first).
  Least operator()(const Eigen::Matrix3d& R, const Eigen::Vector3d& t, bool exact,
                   std::vector<Candidate>* collect = nullptr) {
    Least l;
    collect_ = collect;
    if (collect_ != nullptr) collect_->clear(), exact = false;
    const double cut = exact ? std::numeric_limits<double>::infinity() : threshold_;
    exact_ = exact;
    // The femur's vertices into the pelvis' frame (R, t); the pelvis' into the femur's (R^T, -R^T t).
    shift_mm_ = t.norm();
    ball_pose_ = {R, t, shift_mm_};
    socket_pose_ = {R.transpose(), Eigen::Vector3d(-(R.transpose() * t)), shift_mm_};
    if (!exact && collect_ == nullptr && last_.cluster != nullptr) {
      recheck(l);
      if (l.gap <= threshold_) return l;
    }
    last_ = {};
    if (counted_ != RomVertices::hidden) {
      const bool reachable = !exact && bounds_ != nullptr && shift_mm_ <= kReachableShiftMm;
      const Part ball = bounds_ == nullptr ? Part{ball_set_, &skip_ball_, nullptr, true}
                        : !reachable ? Part{ball_set_, &skip_ball_, &bounds_->ball, true}
                                     : Part{&bounds_->ball_reachable, &skip_ball_reachable_, &bounds_->ball_reachable_clusters, true};
      const Part socket{socket_set_, &skip_socket_, bounds_ == nullptr ? nullptr : &bounds_->socket, false};
      scan(ball, cut, l);
      if (done(l)) return l;
      scan(socket, cut, l);
      if (done(l)) return l;
    }
    if (counted_ == RomVertices::first_surface) return l;
    if (joint_.socket().layered)
      scan_hidden(ball_pose_, *ball_hidden_set_, *joint_.socket().layered, joint_.socket().caster.get(),
                  skip_ball_hidden_, true, cut, l);
    if (done(l)) return l;
    if (joint_.ball().layered)
      scan_hidden(socket_pose_, *socket_hidden_set_, *joint_.ball().layered, joint_.ball().caster.get(),
                  skip_socket_hidden_, false, cut, l);
    return l;
  }
  std::int64_t vertices_looked_up = 0, vertices_skipped = 0;
  std::int64_t vertices_refined = 0;  ///< looked up by an exact ray cast at a depth discontinuity

 private:
  // A rigid map from one body's frame into the other's: q = M p + s.
  struct Rigid {
    Eigen::Matrix3d M = Eigen::Matrix3d::Identity();
    Eigen::Vector3d s = Eigen::Vector3d::Zero();
    double shift = 0;  // |s|, mm (computed once per pose)
  };
  // First-surface vertices of one body, their skip flags (pre-existing overlap) and clusters (null:
  // no bounds); ball: the femur's, looked up in the socket map (inside), else the pelvis' (outside).
  struct Part {
    const ScanSet* set = nullptr;
    const std::vector<std::uint8_t>* skip = nullptr;
    const Clustered* clusters = nullptr;
    bool ball = true;
  };
  const Rigid& pose_of(bool ball) const { return ball ? ball_pose_ : socket_pose_; }
  const RadialDistanceMap& map_of(bool ball) const { return ball ? joint_.socket().map : joint_.ball().map; }
  const FirstHitCaster* exact_of(bool ball) const { return ball ? joint_.socket().exact.get() : joint_.ball().exact.get(); }
  // Where a cluster's vertices lie after the pose P: every direction within rho of `axis` (sin_rho =
  // sin(min(rho, pi/2))), every radius in [r_lo, r_hi].
  struct Cap {
    Eigen::Vector3d axis;
    double rho, sin_rho, r_lo, r_hi;
  };
  // The cap after pose P = (M, s). Without translation: the cluster's cone turned by M. With one, for
  // a vertex p = r u (u within rho of the axis a, r in [r_min, r_max]): |M p + s|^2 = r^2 + 2 r (M u).s
  // + |s|^2, with (M u).s between |s| cos(phi + rho) and |s| cos(phi - rho) (phi: the angle of M a and
  // s); and the direction turns by at most the asin of s's component across M u, at most |s| times
  // the largest sine of an angle in [phi - rho, phi + rho], over the radius. The cluster's ball
  // (radius ball_radius about r_mid * a), posed, bounds the directions and radii too (a translation
  // moves the whole cluster alike): the tighter is taken.
  // An upper bound of asin(x) for 0 <= x < 1 (x / sqrt(1 - x^2) = tan(asin x)); pi/2 and more for x >= 1.
  static double asin_above(double x) { return x < 1 ? x / std::sqrt(1 - x * x) : M_PI; }
  // The cap's angle widened by beta (rad, an upper bound) and an upper bound of its sine (sin is
  // 1-Lipschitz), for BlockPyramid::cap.
  static void widen(Cap& cap, double beta) {
    cap.sin_rho = cap.rho + beta >= M_PI / 2 ? 1.0 : std::min(1.0, cap.sin_rho + beta);
    cap.rho += beta;
  }
  static Cap cap_of(const Cluster& c, const Rigid& P) {
    const Eigen::Vector3d axis = P.M * c.axis;
    const double shift = P.shift;
    if (shift == 0) return {axis, c.rho, c.sin_rho, c.r_min, c.r_max};
    // cos and sin of phi - rho and phi + rho from those of phi and rho (phi in [0, pi]).
    const double cos_phi = std::clamp(axis.dot(P.s) / shift, -1.0, 1.0), sin_phi = std::sqrt(1 - cos_phi * cos_phi);
    const double cos_minus = cos_phi * c.cos_rho + sin_phi * c.sin_rho, sin_minus = sin_phi * c.cos_rho - cos_phi * c.sin_rho;
    const double cos_plus = cos_phi * c.cos_rho - sin_phi * c.sin_rho, sin_plus = sin_phi * c.cos_rho + cos_phi * c.sin_rho;
    const bool below_zero = sin_minus < 0 || c.rho >= M_PI / 2;  // phi - rho < 0: the cone holds s's direction
    const bool above_pi = sin_plus < 0 || c.rho >= M_PI / 2;     // phi + rho > pi: it holds -s's direction
    const double dot_hi = shift * (below_zero ? 1.0 : cos_minus), dot_lo = shift * (above_pi ? -1.0 : cos_plus);
    auto radius2 = [&](double r, double dot) { return r * r + 2 * r * dot + shift * shift; };
    const double r_hi = std::sqrt(std::max(radius2(c.r_min, dot_hi), radius2(c.r_max, dot_hi)));
    const double r_lo = std::sqrt(std::max(0.0, std::min(radius2(c.r_min, dot_lo), radius2(c.r_max, dot_lo))));
    // The largest sine over [phi - rho, phi + rho]: 1 when the range holds pi/2.
    const bool holds_right_angle = (below_zero || cos_minus >= 0) && (above_pi || cos_plus <= 0);
    const double across = shift * (holds_right_angle ? 1.0
                                                     : std::max(below_zero ? 0.0 : sin_minus, above_pi ? 0.0 : sin_plus));
    Cap cap{axis, c.rho, c.sin_rho, r_lo, r_hi};
    widen(cap, r_lo > 0 ? asin_above(across / r_lo) : M_PI);
    const Eigen::Vector3d centre = c.r_mid * axis + P.s;
    const double d = centre.norm();
    if (c.ball_radius >= d) return cap;
    cap.r_lo = std::max(cap.r_lo, d - c.ball_radius), cap.r_hi = std::min(cap.r_hi, d + c.ball_radius);
    const double rho_ball = asin_above(c.ball_radius / d);
    if (rho_ball < cap.rho) cap.axis = centre / d, cap.rho = rho_ball, cap.sin_rho = c.ball_radius / d;
    return cap;
  }
  // This pose's cap of one cluster (cap_of), computed once however many of its bounds ask for it.
  struct PoseCap {
    const Cluster& c;
    const Rigid& P;
    std::optional<Cap> cap;
    PoseCap(const Cluster& cluster, const Rigid& pose) : c(cluster), P(pose) {}
    const Cap& get() {
      if (!cap) cap = cap_of(c, P);
      return *cap;
    }
  };
  // The cap of every pose (M Q, s + e) near P = (M, s): Q a rotation by at most kReuseRad, |e| <=
  // kReuseShiftMm. Without translation (s = 0, e = 0) the cone widened by kReuseRad. Otherwise a
  // vertex x = M p + s moves by at most |(Q - I) p| + |e| <= 2 r_max sin(kReuseRad / 2) + |e|, which
  // turns it by at most the asin of that over its radius; its squared radius changes by at most
  // 2 |s| |(Q - I) p| (a rotation about the origin keeps |p|), and then by |e|.
  // wide: for rotations within kWideReuseRad instead (a bound that serves more poses, tried first).
  // here: the cluster's PoseCap at P (its cap_of, computed once).
  static Cap reuse_cap_of(const Cluster& c, const Rigid& P, bool wide, PoseCap& here) {
    const double angle = wide ? kWideReuseRad : kReuseRad;
    if (P.shift == 0)
      return {P.M * c.axis, c.rho + angle, wide ? std::sin(std::min(c.rho + angle, M_PI / 2)) : c.sin_rho_widened,
              c.r_min, c.r_max};
    Cap cap = here.get();
    static const double kChord = 2 * std::sin(kReuseRad / 2), kWideChord = 2 * std::sin(kWideReuseRad / 2);
    const double move = c.r_max * (wide ? kWideChord : kChord);
    const double r_lo = std::max(0.0, std::sqrt(std::max(0.0, cap.r_lo * cap.r_lo - 2 * P.shift * move)) - kReuseShiftMm);
    cap.r_hi = std::sqrt(cap.r_hi * cap.r_hi + 2 * P.shift * move) + kReuseShiftMm;
    widen(cap, r_lo > 0 ? asin_above((move + kReuseShiftMm) / r_lo) : M_PI);
    cap.r_lo = r_lo;
    return cap;
  }
  void scan(const Part& part, double cut, Least& l) {
    const ScanSet& set = *part.set;
    const bool ball = part.ball;
    const Rigid& P = pose_of(ball);
    const ScanSide side = ball ? ScanSide::inside : ScanSide::outside;
    const RadialDistanceMap& map = map_of(ball);
    const BoundPyramid* pyr = bounds_ == nullptr ? nullptr : ball ? &bounds_->socket_min : &bounds_->ball_max;
    if (pyr == nullptr || !pyr->valid() || part.clusters == nullptr) {
      vertices_refined += scan_gaps_compact(set, P.M, P.s, map, side, buf_.data(), exact_of(ball));
      take(set, *part.skip, 0, set.size(), ball, l);
      vertices_looked_up += set.size();
      return;
    }
    const std::vector<Cluster>& cl = part.clusters->leaves;
    // Lower bound of every gap in a cluster whose directions lie within `widen` of where R takes
    // them, for translations of at most `shift` mm: the radii move by at most `shift` and the
    // directions by at most asin(shift / r): inside, d - r >= min d - (r_max + shift); outside,
    // r - d >= (r_min - shift) - max d.
    // tier 0: this pose's cap; 1: every pose within kReuseRad; 2: within kWideReuseRad.
    // Only whether the bound exceeds `limit` matters: the blocks are read until it cannot.
    auto lower_bound_above = [&](const Cluster& c, int tier, PoseCap& here, double limit) {
      const Cap& cap = tier > 0 ? reuse_cap_of(c, P, tier == 2, here) : here.get();
      const int blocks = c.count > kLeaf ? kGroupBlocks : kLeafBlocks;
      // ball: bound - r_hi > limit while the least so far > limit + r_hi; else r_lo - bound > limit
      // while the greatest so far < r_lo - limit.
      const double edge = ball ? limit + cap.r_hi : cap.r_lo - limit;
      const float bound = pyr->cap(cap.axis, cap.rho, cap.sin_rho, blocks,
                                   [&](float m) { return ball ? double(m) <= edge : double(m) >= edge; });
      return (ball ? double(bound) - cap.r_hi : cap.r_lo - double(bound)) > limit;
    };
    auto skipped = [&](const Cluster& c) {
      PoseCap here(c, P);
      return lower_bound_above(c, 0, here, collect_ == nullptr ? std::min(cut, l.gap) : cut);
    };
    // A search's poses follow each other closely: a cluster whose bound over the cap of every pose
    // near this one (reuse_cap_of: rotations within kReuseRad, translations within kReuseShiftMm)
    // stays above the cut is skipped at every later pose that near.
    const bool reusable = !exact_;
    std::vector<Reuse>& reuse_g = ball ? reuse_ball_groups_ : reuse_socket_groups_;
    std::vector<Reuse>& reuse_l = ball ? reuse_ball_leaves_ : reuse_socket_leaves_;
    const Clustered*& owner = ball ? reuse_ball_owner_ : reuse_socket_owner_;
    if (reusable && owner != part.clusters) {  // another cluster set (the ball's reachable subset or all)
      reuse_g.assign(part.clusters->groups.size(), Reuse{});
      reuse_l.assign(cl.size(), Reuse{});
      owner = part.clusters;
    }
    auto skip_reusing = [&](const Cluster& c, Reuse& u) {
      PoseCap here(c, P);
      return reuse_or_bound(u, P, [&](bool wide) { return lower_bound_above(c, wide ? 2 : 1, here, cut); },
                            [&] { return lower_bound_above(c, 0, here, cut); });
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
        look_up(part, c, l);
        if (l.gap <= threshold_) last_ = {part, &c};
      }
    }
  }
  // One cluster's gaps, as Joint::detect computes them, taken into l.
  void look_up(const Part& part, const Cluster& c, Least& l) {
    const Rigid& P = pose_of(part.ball);
    vertices_refined += scan_gaps_compact(*part.set, c.first, c.count, P.M, P.s, map_of(part.ball),
                                          part.ball ? ScanSide::inside : ScanSide::outside, buf_.data(),
                                          exact_of(part.ball));
    take(*part.set, *part.skip, c.first, c.first + c.count, part.ball, l);
    vertices_looked_up += c.count;
  }
  // The first-surface cluster that met at the previous evaluation, looked up first.
  void recheck(Least& l) { look_up(last_.part, *last_.cluster, l); }
  bool done(const Least& l) const { return !exact_ && collect_ == nullptr && l.gap <= threshold_; }
  // Hidden vertices of one body against the other's layered map: a cluster is skipped when no radial
  // shell of the other bone over its cone lies within min(cut, least gap so far) of its radii.
  void scan_hidden(const Rigid& P, const ScanSet& set, const LayeredMap& map, const FirstHitCaster* exact,
                   const std::vector<std::uint8_t>& skip, bool ball, double cut, Least& l) {
    const OccupancyPyramid* pyr =
        bounds_ == nullptr ? nullptr : ball ? &*bounds_->socket_occupancy : &*bounds_->ball_occupancy;
    const std::vector<Cluster>* cl =
        bounds_ == nullptr ? nullptr : ball ? &bounds_->ball_hidden.leaves : &bounds_->socket_hidden.leaves;
    if (pyr == nullptr || !pyr->valid()) {
      vertices_refined += scan_layered(set, P.M, P.s, map, buf_.data(), exact);
      take(set, skip, 0, set.size(), ball, l, true);
      vertices_looked_up += set.size();
      return;
    }
    const std::vector<Cluster>* groups = ball ? &bounds_->ball_hidden.groups : &bounds_->socket_hidden.groups;
    auto apart = [&](const Cap& cap, double reach) {
      const std::uint64_t near = shells(cap.r_lo - reach, cap.r_hi + reach);
      return (pyr->cap(cap.axis, cap.rho, cap.sin_rho, kHiddenBlocks, [near](std::uint64_t m) { return (m & near) != 0; }) &
              near) == 0;
    };
    auto skipped_at = [&](PoseCap& here) {
      const double reach = std::max(0.0, collect_ == nullptr ? std::min(cut, l.gap) : cut);
      return std::isfinite(reach) && apart(here.get(), reach);
    };
    auto skipped = [&](const Cluster& c) {
      PoseCap here(c, P);
      return skipped_at(here);
    };
    // As for the first surface (scan()): a cluster apart from the other bone over the cap of every pose
    // near this one is skipped at every later pose that near, while only contact is asked (the reach
    // is then at most max(0, cut)).
    const bool reusable = !exact_;
    const std::vector<Cluster>* blocks = ball ? &bounds_->ball_hidden.blocks : &bounds_->socket_hidden.blocks;
    std::vector<Reuse>& reuse_b = ball ? reuse_hidden_ball_blocks_ : reuse_hidden_socket_blocks_;
    std::vector<Reuse>& reuse_g = ball ? reuse_hidden_ball_groups_ : reuse_hidden_socket_groups_;
    std::vector<Reuse>& reuse_l = ball ? reuse_hidden_ball_leaves_ : reuse_hidden_socket_leaves_;
    if (reusable && reuse_g.size() != groups->size())
      reuse_b.assign(blocks->size(), Reuse{}), reuse_g.assign(groups->size(), Reuse{}), reuse_l.assign(cl->size(), Reuse{});
    auto skip_reusing = [&](const Cluster& c, Reuse& u) {
      const double reach = std::max(0.0, cut);
      PoseCap here(c, P);
      return reuse_or_bound(u, P, [&](bool wide) { return apart(reuse_cap_of(c, P, wide, here), reach); },
                            [&] { return skipped_at(here); });
    };
    for (std::size_t bi = 0; bi < blocks->size(); ++bi) {
      const Cluster& b = (*blocks)[bi];
      if (done(l)) return;
      if (reusable ? skip_reusing(b, reuse_b[bi]) : skipped(b)) {
        vertices_skipped += b.count;
        continue;
      }
      const auto groups_end = static_cast<std::size_t>((b.first + b.count + kGroup - 1) / kGroup);
      for (auto gi = static_cast<std::size_t>(b.first / kGroup); gi < groups_end; ++gi) {
        const Cluster& g = (*groups)[gi];
        if (done(l)) return;
        if (reusable ? skip_reusing(g, reuse_g[gi]) : skipped(g)) {
          vertices_skipped += g.count;
          continue;
        }
        for (std::int64_t i = g.first / kHiddenLeaf; i < (g.first + g.count + kHiddenLeaf - 1) / kHiddenLeaf; ++i) {
          const Cluster& c = (*cl)[static_cast<std::size_t>(i)];
          if (done(l)) return;
          if ((reusable ? skip_reusing(c, reuse_l[static_cast<std::size_t>(i)]) : skipped(c)) ||
              beyond_euclidean(c, P, map, ball, cut, l)) {
            vertices_skipped += c.count;
            continue;
          }
          vertices_refined += scan_layered(set, c.first, c.count, P.M, P.s, map, buf_.data(), exact);
          take(set, skip, c.first, c.first + c.count, ball, l, true);
          vertices_looked_up += c.count;
        }
      }
    }
  }
  // The Euclidean bound of a hidden cluster where the radial shells cannot part it from the other bone
  // (the pelvis wraps round the femoral neck): cluster_apart of its ball (ball_radius about r_mid * axis,
  // posed, grown by the maps' interpolation slack) at the reach min(cut, least gap so far), at least 0.
  bool beyond_euclidean(const Cluster& c, const Rigid& P, const LayeredMap& map, bool ball, double cut,
                        const Least& l) const {
    const SignedDistanceQuery* other = ball ? joint_.socket().distance_query.get() : joint_.ball().distance_query.get();
    const double reach = std::max(0.0, collect_ == nullptr ? std::min(cut, double(l.gap)) : cut);
    return other != nullptr && std::isfinite(reach) &&
           cluster_apart(P.M * (c.r_mid * c.axis) + P.s, c.ball_radius + kDistanceScreenSlackMm, map, joint_.cor(),
                         *other, reach);
  }
  void take(const ScanSet& set, const std::vector<std::uint8_t>& skip, std::int64_t from, std::int64_t to, bool ball,
            Least& l, bool hidden = false) {
    const bool classed = !ball && pelvis_.classed();
    for (std::int64_t j = from; j < to; ++j) {
      const auto k = static_cast<std::size_t>(j);
      const bool listed = collect_ != nullptr && buf_[k] <= threshold_;
      if (skip[k] || !(buf_[k] < l.gap || listed)) continue;
      if (classed) {
        // A pelvis vertex meeting the femur's head up to its junction meets its joint surface.
        const Eigen::Vector3d y = socket_pose_.M * Eigen::Vector3d(set.x[k], set.y[k], set.z[k]) + socket_pose_.s;
        if (!pelvis_.counts(y)) continue;
      }
      if (listed) collect_->push_back({buf_[k], ball, hidden, static_cast<std::size_t>(set.index[j])});
      if (buf_[k] < l.gap) l.gap = buf_[k], l.ball = ball, l.hidden = hidden, l.vertex = static_cast<std::size_t>(set.index[j]);
    }
  }
  const Joint& joint_;
  const RomSearchBounds* bounds_;
  double threshold_;
  RomVertices counted_;
  PelvisContacts pelvis_;
  const ScanSet *ball_set_, *socket_set_, *ball_hidden_set_, *socket_hidden_set_;  // the vertices scanned
  bool exact_ = true;
  std::vector<Candidate>* collect_ = nullptr;  // the listed gaps of the current scan (null: none)
  Rigid ball_pose_, socket_pose_;
  double shift_mm_ = 0;  // |t|
  // A group's bound at an earlier pose (M, s) over the cap of the poses near it (valid: it was above
  // the cut), or that its bound failed at the last pose (failed: try the plain cap first next time).
  // wide: the bound holds within kWideReuseRad (else kReuseRad); wide_failed: the wide bound failed once in
  // this search (the cluster is near the other bone: not tried again, the poses only come nearer);
  // narrow_failed: so did the one within kReuseRad, and neither is tried again (the cluster's own bound at
  // each pose decides; lhdl-ct's ROM map takes 3-6 % less time than when it retried the narrow one).
  struct Reuse {
    Eigen::Matrix3d M = Eigen::Matrix3d::Zero();
    Eigen::Vector3d s = Eigen::Vector3d::Zero();
    bool valid = false, failed = false, wide = false, wide_failed = false, narrow_failed = false;
    // Whether the bound made at (M, s) serves the pose P: P's rotation relative to M within the bound's
    // angle (the trace of M^T P.M at least that of a rotation by it) and its translation within
    // kReuseShiftMm of s.
    bool holds(const Rigid& P) const {
      return valid && (s - P.s).squaredNorm() <= kReuseShiftMm * kReuseShiftMm &&
             (M.array() * P.M.array()).sum() >= (wide ? kWideReuseMinTrace : kReuseMinTrace);
    }
  };
  // Whether a cluster is skipped at the pose P: by the bound `u` made at an earlier pose while it holds;
  // else by a new one over every pose near P (reused(wide): the bound over the poses within kWideReuseRad,
  // tried until it fails once in the search, or within kReuseRad, likewise), kept in `u`; else by
  // this pose's own bound (here()). After a pose where neither held, this pose's bound is tried first.
  template <typename Reused, typename Here>
  static bool reuse_or_bound(Reuse& u, const Rigid& P, Reused reused, Here here) {
    if (u.holds(P)) return true;
    bool skip;
    if (!u.failed) {
      u.M = P.M, u.s = P.s;
      u.wide = !u.wide_failed && reused(true);
      u.wide_failed = !u.wide;
      u.valid = u.wide || (!u.narrow_failed && reused(false));
      u.narrow_failed = !u.valid;
      skip = u.valid || here();
    } else {
      skip = here(), u.valid = false;
    }
    u.failed = !skip;
    return skip;
  }
  static inline const double kReuseMinTrace = 1 + 2 * std::cos(kReuseRad);  // trace of a rotation by kReuseRad
  static inline const double kWideReuseMinTrace = 1 + 2 * std::cos(kWideReuseRad);
  std::vector<Reuse> reuse_ball_groups_, reuse_socket_groups_, reuse_ball_leaves_, reuse_socket_leaves_;
  std::vector<Reuse> reuse_hidden_ball_blocks_, reuse_hidden_socket_blocks_;
  std::vector<Reuse> reuse_hidden_ball_groups_, reuse_hidden_socket_groups_, reuse_hidden_ball_leaves_,
      reuse_hidden_socket_leaves_;
  const Clustered* reuse_ball_owner_ = nullptr;  // the clusters reuse_ball_* belong to
  const Clustered* reuse_socket_owner_ = nullptr;
  struct Met {
    Part part;
    const Cluster* cluster = nullptr;
  } last_;  ///< the first-surface cluster that met at the last evaluation (cluster null: none)
  std::vector<std::uint8_t> skip_ball_reachable_, skip_ball_, skip_socket_, skip_ball_hidden_, skip_socket_hidden_;
  std::vector<float> buf_;
};

}  // namespace rom_detail
}  // namespace impinge
