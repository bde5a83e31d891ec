#pragma once
// Private to libcore/src/clinical: the scanner of a ROM search's metric (rom.hpp): the least radial gap
// (CompactScanner, rom_scanner.hpp) or the least signed Euclidean distance (DistanceScanner), screened by the
// radial scan where that is exact. Included by rom.cpp and rom_envelope.cpp only.

#include <optional>

#include "clinical/rom_exact.hpp"

namespace impinge {
namespace rom_detail {

// The least counted signed Euclidean distance (RomMetric::distance), in one of two ways:
// - whole (operator()): Joint::detect with its distances (exact closest points, radial gaps as bounds and
//   sign hints; surface_distance.hpp), the least taken over the vertices that the baseline counts, the
//   pelvis' contacts with the head's joint surface classed at each pose as CompactScanner::take does.
//   Vertices beyond the joint's distance reach (>= the threshold, check_metric) cannot meet.
// - screened (of()): the exact signed distance of the listed vertices only (CompactScanner's `collect`,
//   already counted and classed), each searched within its radial gap's magnitude plus 0.5 mm (the gap
//   bounds the distance), with the gap's sign as the hint where |gap| > 0.1 mm.
class DistanceScanner {
 public:
  DistanceScanner(const Joint& joint, const RomBaseline& base) : joint_(joint), base_(base), pelvis_(base) {}
  Least operator()(const Eigen::Matrix3d& R, const Eigen::Vector3d& t) {
    joint_.detect(R, t, res_);
    Least l;
    take(res_.ball_gaps, base_.skip_ball, true, R, t, l);
    take(res_.socket_gaps, base_.skip_socket, false, R, t, l);
    return l;
  }
  Least of(const Eigen::Matrix3d& R, const Eigen::Vector3d& t, const std::vector<Candidate>& listed) {
    Least l;
    const Eigen::Vector3d& cor = joint_.cor();
    const Eigen::Matrix3d Rt = R.transpose();
    for (const Candidate& c : listed) {
      const auto row = static_cast<Eigen::Index>(c.vertex);
      // Into the other body's mesh frame: a femur vertex posed (R, t); a pelvis vertex by the inverse.
      const Eigen::Vector3d q = c.ball ? Eigen::Vector3d(cor + R * joint_.ball().relative.row(row).transpose() + t)
                                       : Eigen::Vector3d(cor + Rt * (joint_.socket().relative.row(row).transpose() - t));
      const SignedDistanceQuery& other = c.ball ? *joint_.socket().distance_query : *joint_.ball().distance_query;
      const int hint = c.gap < -0.1f ? -1 : c.gap > 0.1f ? 1 : 0;
      ClosestSurfacePoint p;
      if (!other.signed_distance(q, std::abs(double(c.gap)) + 0.5, hint, p))
        other.signed_distance(q, std::numeric_limits<double>::infinity(), hint, p);
      ++vertices_looked_up;
      const double d = p.signed_mm();
      if (d < l.gap) l.gap = d, l.ball = c.ball, l.hidden = c.hidden, l.vertex = c.vertex;
    }
    return l;
  }
  std::int64_t vertices_looked_up = 0;

 private:
  void take(const ScanGaps& g, const std::vector<std::uint8_t>& skip, bool ball, const Eigen::Matrix3d& R,
            const Eigen::Vector3d& t, Least& l) {
    const bool classed = !ball && pelvis_.classed();
    const auto& rel = ball ? joint_.ball().relative : joint_.socket().relative;
    for (std::size_t k = 0; k < g.distance_mm.size(); ++k) {
      const float d = g.distance_mm[k];
      if (std::isnan(d)) continue;
      ++vertices_looked_up;
      if (skip[k] || !(d < l.gap)) continue;
      if (classed) {
        const Eigen::Vector3d y = R.transpose() * (rel.row(static_cast<Eigen::Index>(k)).transpose() - t);
        if (!pelvis_.counts(y)) continue;
      }
      l.gap = d, l.ball = ball, l.hidden = g.status[k] == ScanGaps::tested_layered, l.vertex = k;
    }
  }
  const Joint& joint_;
  const RomBaseline& base_;
  PelvisContacts pelvis_;
  PoseResult res_;
};

// The scanner of a search's metric (RomOptions::metric): CompactScanner, or DistanceScanner.
// At or below a cut of 0 a radial scan screens the distance's: a vertex inside the other bone lies
// behind that bone's surface along the ray from the COR (which lies outside both bones), at least its
// Euclidean depth behind it, so its radial gap is at most its distance (up to the maps' interpolation
// error: kDistanceScreenSlackMm; for the vertices the radial scans test). So the cluster-bounded radial
// scan lists the vertices whose gap is at most the cut plus the slack, and only they get a distance;
// where none is listed, no distance reaches the cut. Where the ray runs inside the other bone (issue
// 26) the radial gap is far below the distance, and the distance decides. Above a cut of 0 the radial
// gap bounds an outside vertex's distance from above, not below: every pose is a whole distance scan.
// `exact` poses (a search's start and limit) are whole distance scans too. Where the search finds its
// contacts exactly (exact_search), ExactScanner alone serves every pose.
class GapScanner {
 public:
  GapScanner(const Joint& joint, const RomBaseline& base, const RomSearchBounds* bounds, const RomOptions& o) {
    if (exact_search(o, base)) {  // the exact test throughout (rom_exact.hpp)
      exact_.emplace(joint, base, cut_of(o));
      return;
    }
    if (o.metric == RomMetric::distance) distance_.emplace(joint, base);
    if (screened_or_radial(o)) compact_.emplace(joint, base, bounds, scan_cut_of(o), o.vertices);
  }
  Least operator()(const Eigen::Matrix3d& R, const Eigen::Vector3d& t, bool exact) {
    if (exact_) return (*exact_)(R, t, exact);
    if (!distance_) return (*compact_)(R, t, exact);
    if (!compact_ || exact) return (*distance_)(R, t);
    const Least radial = (*compact_)(R, t, false, &listed_);
    if (listed_.empty()) return radial;  // no radial gap within the screen: no distance within the cut
    return distance_->of(R, t, listed_);
  }
  std::int64_t vertices_looked_up() const {
    return (distance_ ? distance_->vertices_looked_up : 0) + (compact_ ? compact_->vertices_looked_up : 0);
  }
  std::int64_t vertices_skipped() const { return compact_ ? compact_->vertices_skipped : 0; }

 private:
  std::vector<Candidate> listed_;
  std::optional<CompactScanner> compact_;
  std::optional<DistanceScanner> distance_;
  std::optional<ExactScanner> exact_;
};

}  // namespace rom_detail
}  // namespace impinge
