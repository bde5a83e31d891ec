#include "clinical/rom_exact.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace impinge {
namespace rom_detail {
namespace {
constexpr double kDeg = 180.0 / 3.14159265358979323846;

// The angle from the neck's direction and the azimuth (from twelve towards three, [0, 360)) of p about the
// zone's clock, deg; across: p's distance from the neck axis, mm (FemoralHeadZone::on_head_side's polar).
void polar(const ClockFace& k, const Eigen::Vector3d& p, double& from_neck, double& azimuth, double& across) {
  const Eigen::Vector3d q = p - k.centre;
  const double along = -q.dot(k.axis);
  across = (q + along * k.axis).norm();
  from_neck = std::atan2(across, along) * kDeg;
  azimuth = std::atan2(q.dot(k.three), q.dot(k.twelve)) * kDeg;
  if (azimuth < 0) azimuth += 360;
}

// The junction's least and largest angle over the azimuths [lo, hi] (deg; junction_at is constant on each
// 5 deg bin's [5k, 5k + 5)); NaN in either: some azimuth has no junction.
void junction_range(const FemoralHeadZone& z, double lo, double hi, double& jmin, double& jmax) {
  jmin = std::numeric_limits<double>::infinity(), jmax = -jmin;
  auto take = [&](double a) {
    const double j = z.junction_at(a);
    if (std::isnan(j)) jmin = jmax = j;
    if (!std::isnan(jmin)) jmin = std::fmin(jmin, j), jmax = std::fmax(jmax, j);
  };
  take(lo);
  for (double a = std::ceil(lo / 5) * 5; a <= hi && !std::isnan(jmin); a += 5) take(a);
  if (!std::isnan(jmin)) take(hi);
}
}  // namespace

int head_side_of_face(const FemoralHeadZone& z, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                      const Eigen::Vector3d& c) {
  const Eigen::Vector3d p[3] = {a, b, c};
  const double edge = std::max({(a - b).norm(), (b - c).norm(), (c - a).norm()});
  double r_min = std::numeric_limits<double>::infinity(), r_max = 0, f_lo = 360, f_hi = -360, across_min = r_min;
  double az[3];
  for (int k = 0; k < 3; ++k) {
    const double r = (p[k] - z.clock.centre).norm();
    double from_neck = 0, across = 0;
    polar(z.clock, p[k], from_neck, az[k], across);
    r_min = std::fmin(r_min, r), r_max = std::fmax(r_max, r), across_min = std::fmin(across_min, across);
    f_lo = std::fmin(f_lo, from_neck), f_hi = std::fmax(f_hi, from_neck);
  }
  // Wholly beyond the reach: every point of the triangle lies within `edge` of a corner.
  if (r_min - edge > z.reach_mm) return 0;
  // Any point's angle from the neck lies within the corners' range widened by the angle an edge subtends.
  const double widen = r_min > edge ? std::asin(std::fmin(1.0, edge / r_min)) * kDeg : 180;
  f_lo -= widen, f_hi += widen;
  // Azimuths: the corners' span about the first (unwrapped), widened likewise about the axis.
  double lo = 0, hi = 0;
  for (int k = 1; k < 3; ++k) {
    const double d = std::remainder(az[k] - az[0], 360.0);
    lo = std::fmin(lo, d), hi = std::fmax(hi, d);
  }
  const double spin = across_min > edge ? std::asin(std::fmin(1.0, edge / across_min)) * kDeg : 180;
  lo += az[0] - spin, hi += az[0] + spin;
  if (hi - lo >= 360) lo = 0, hi = 360;
  double jmin = 0, jmax = 0;
  junction_range(z, lo, hi, jmin, jmax);
  if (std::isnan(jmin)) return -1;
  if (r_max <= z.reach_mm && f_lo >= jmax) return 1;  // the ball is convex: the corners within it hold the face
  if (f_hi < jmin) return 0;
  return -1;
}

std::shared_ptr<const MeshContact> baseline_contact(const Joint& joint, const RomBaseline& base,
                                                    const std::vector<std::uint8_t>& skip_ball_pre,
                                                    const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
                                                    double threshold) {
  const Faces& F = joint.ball().mesh.F;
  const Vertices& V = joint.ball().relative;
  auto contact = std::make_shared<MeshContact>(V, F, joint.socket().relative, joint.socket().mesh.F);
  const bool classed = base.head_zone.has_value() && base.contacts != RomContacts::all;
  const bool articular_only = base.contacts == RomContacts::articular;
  std::vector<std::uint8_t> ball(static_cast<std::size_t>(F.rows()), 1);
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    std::uint8_t& s = ball[static_cast<std::size_t>(f)];
    for (int c = 0; c < 3; ++c) s &= skip_ball_pre[static_cast<std::size_t>(F(f, c))] == 0;
    if (!s || !classed) continue;
    const int side = head_side_of_face(*base.head_zone, V.row(F(f, 0)).transpose(), V.row(F(f, 1)).transpose(),
                                       V.row(F(f, 2)).transpose());
    s = side < 0 ? 2 : (side == 1) == articular_only;
  }
  // Every pair within the threshold at the baseline, counted or not (as every vertex within it is skipped,
  // whatever its class), is left out: a pair the pose classes as counted later must not bring a pre-existing
  // overlap with it.
  for (const auto& [a, b] : contact->pairs_within(R, t, threshold, MeshContact::Query{})) ball[static_cast<std::size_t>(a)] = 0;
  // The pelvis' triangles count only through the femur's: every pair is classed by its femur side.
  contact->set_counted(std::move(ball), std::vector<std::uint8_t>(static_cast<std::size_t>(joint.socket().mesh.F.rows()), 0));
  return contact;
}

ExactScanner::ExactScanner(const Joint& joint, const RomBaseline& base, double cut)
    : joint_(joint), base_(base), contact_(*base.contact), pelvis_(base), cut_(cut) {}

MeshContact::Query ExactScanner::query_at(const Eigen::Matrix3d& R, const Eigen::Vector3d& t, double reach,
                                          bool first) const {
  MeshContact::Query q;
  q.reach = reach, q.first = first;
  if (!pelvis_.classed()) return q;
  // A pair across the junction: classed by the femur's closest point carried back onto the unposed femur.
  q.pair_counts = [this, Rt = Eigen::Matrix3d(R.transpose()), t](std::int64_t, const Eigen::Vector3d& on_a,
                                                                  const Eigen::Vector3d&) {
    return pelvis_.counts(Rt * (on_a - t));
  };
  return q;
}

Least ExactScanner::operator()(const Eigen::Matrix3d& R, const Eigen::Vector3d& t, bool full) const {
  const MeshContact::Query q = query_at(R, t, full ? std::numeric_limits<double>::infinity() : cut_, !full);
  const MeshContact::Closest c = contact_.least(R, t, q);
  Least l;
  l.gap = c.distance;
  if (c.face_a < 0) return l;
  // The femur's corner nearest the contact (every counted pair is counted by its femur triangle).
  const Faces& F = joint_.ball().mesh.F;
  const Vertices& V = joint_.ball().relative;
  const auto f = static_cast<Eigen::Index>(c.face_a);
  double best = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 3; ++k) {
    const double d = (Eigen::Vector3d(R * V.row(F(f, k)).transpose() + t) - c.on_a).squaredNorm();
    if (d < best) best = d, l.vertex = static_cast<std::size_t>(F(f, k));
  }
  l.ball = true;
  l.point = c.on_a;  // on the femur's surface (the two coincide where the surfaces cross)
  return l;
}

}  // namespace rom_detail
}  // namespace impinge
