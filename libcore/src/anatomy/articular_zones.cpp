#include "impinge/anatomy/articular_zones.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace impinge {

const char* to_string(ContactClass c) {
  switch (c) {
    case ContactClass::articular: return "articular";
    case ContactClass::intra_articular_impingement: return "intra_articular_impingement";
    case ContactClass::extra_articular_impingement: return "extra_articular_impingement";
    case ContactClass::labral: return "labral";
    case ContactClass::none: break;
  }
  return "";
}

const char* to_string(FemoralZone z) {
  switch (z) {
    case FemoralZone::head: return "head";
    case FemoralZone::head_neck_junction: return "head_neck_junction";
    case FemoralZone::neck: return "neck";
    case FemoralZone::trochanter: return "trochanter";
    case FemoralZone::none: break;
  }
  return "";
}

const char* to_string(PelvicZone z) {
  switch (z) {
    case PelvicZone::lunate: return "lunate";
    case PelvicZone::fossa: return "fossa";
    case PelvicZone::rim: return "rim";
    case PelvicZone::aiis: return "aiis";
    case PelvicZone::pubis: return "pubis";
    case PelvicZone::ischium: return "ischium";
    case PelvicZone::ilium: return "ilium";
    case PelvicZone::none: break;
  }
  return "";
}

double head_junction_tolerance_mm(double rms) { return std::max(0.5, std::isfinite(rms) ? 2 * rms : 0.0); }

namespace {
constexpr double kDeg = 180.0 / M_PI;
constexpr double kBinDeg = 360.0 / kJunctionBins;
constexpr double kFromNeckDeg = 5;  // the alpha angle's sweep starts this far from the neck's direction

// Angle from the neck's direction (deg, [0, 180]) and azimuth (deg, [0, 360)) of p about the clock.
void polar(const ClockFace& k, const Eigen::Vector3d& p, double& from_neck, double& azimuth) {
  const Eigen::Vector3d q = p - k.centre;
  const double along = -q.dot(k.axis), across = (q + along * k.axis).norm();
  from_neck = std::atan2(across, along) * kDeg;
  azimuth = std::atan2(q.dot(k.three), q.dot(k.twelve)) * kDeg;
  if (azimuth < 0) azimuth += 360;
}
}  // namespace

double FemoralHeadZone::junction_at(double azimuth_deg) const {
  const double a = std::fmod(std::fmod(azimuth_deg, 360) + 360, 360) / kBinDeg;
  const int lo = static_cast<int>(std::floor(a)) % kJunctionBins, hi = (lo + 1) % kJunctionBins;
  return std::fmax(junction_deg[static_cast<std::size_t>(lo)], junction_deg[static_cast<std::size_t>(hi)]);
}

bool FemoralHeadZone::on_head_side(const Eigen::Vector3d& p) const {
  double from_neck = 0, azimuth = 0;
  polar(clock, p, from_neck, azimuth);
  const double j = junction_at(azimuth);
  return std::isfinite(j) && from_neck >= j;
}

bool FemoralHeadZone::contains(const Eigen::Vector3d& p) const {
  return (p - clock.centre).norm() <= reach_mm && on_head_side(p);
}

FemoralHeadZone FemoralHeadZone::transformed(const Eigen::Matrix3d& R, const Eigen::Vector3d& t) const {
  FemoralHeadZone z = *this;
  z.clock = clock.transformed(R, t);
  return z;
}

FemoralHeadZone find_femoral_head_zone(const TriangleMesh& femur, const ClockFace& clock, double radius_mm,
                                       double tolerance_mm, double reach_tolerance_mm) {
  FemoralHeadZone z;
  z.clock = clock;
  z.radius_mm = radius_mm;
  z.tolerance_mm = tolerance_mm;
  z.reach_mm = radius_mm + reach_tolerance_mm;
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  std::array<double, kJunctionBins> least;
  least.fill(kNaN);
  for (Eigen::Index i = 0; i < femur.V.rows(); ++i) {
    const Eigen::Vector3d v = femur.V.row(i).transpose();
    if ((v - clock.centre).norm() > radius_mm + tolerance_mm) continue;
    double from_neck = 0, azimuth = 0;
    polar(clock, v, from_neck, azimuth);
    if (from_neck < kFromNeckDeg) continue;
    const auto k = static_cast<std::size_t>(std::lround(azimuth / kBinDeg)) % kJunctionBins;
    least[k] = std::fmin(least[k], from_neck);
  }
  // An empty bin (a coarse mesh, a hole): the larger of its nearest non-empty neighbours' on either side.
  for (int k = 0; k < kJunctionBins; ++k) {
    double j = least[static_cast<std::size_t>(k)];
    for (int d = 1; std::isnan(j) && d < kJunctionBins / 2; ++d)
      j = std::fmax(least[static_cast<std::size_t>((k + d) % kJunctionBins)],
                    least[static_cast<std::size_t>((k - d + kJunctionBins) % kJunctionBins)]);
    z.junction_deg[static_cast<std::size_t>(k)] = j;
  }
  return z;
}

FemoralZone femoral_zone(const FemoralHeadZone& head, const Eigen::Vector3d& p) {
  double from_neck = 0, azimuth = 0;
  polar(head.clock, p, from_neck, azimuth);
  const double j = head.junction_at(azimuth);
  if (!std::isfinite(j)) return FemoralZone::none;
  if (from_neck >= j) return FemoralZone::head;
  if (from_neck >= j - 20) return FemoralZone::head_neck_junction;
  const Eigen::Vector3d q = p - head.clock.centre;
  const double along = -q.dot(head.clock.axis), off_axis = (q + along * head.clock.axis).norm();
  return along <= 2 * head.radius_mm && off_axis <= head.radius_mm ? FemoralZone::neck : FemoralZone::trochanter;
}

namespace {
double tolerance(double rms, const ArticularZoneOptions& o) {
  return std::isfinite(rms) ? std::max(o.min_tolerance_mm, o.rms_factor * rms) : o.min_tolerance_mm;
}
}  // namespace

ArticularZones find_articular_zones(const TriangleMesh& femur, const SphereFitResult& head, const ClockFace& clock,
                                    const TriangleMesh& pelvis, const Acetabulum& acetabulum,
                                    const ArticularZoneOptions& o) {
  ArticularZones z;
  z.head_tolerance_mm = tolerance(head.rms_residual, o);
  z.lunate_tolerance_mm = tolerance(acetabulum.sphere.rms_residual, o);
  z.head_sphere_reach_mm = head.radius + z.head_tolerance_mm;
  ClockFace k = clock;
  k.centre = head.centre;
  const SphereFitResult& cup = acetabulum.sphere;
  const double reach =
      std::max(head.radius + z.head_tolerance_mm, cup.radius + z.lunate_tolerance_mm + (cup.centre - head.centre).norm());
  z.head = find_femoral_head_zone(femur, k, head.radius, head_junction_tolerance_mm(head.rms_residual),
                                  reach - head.radius);
  z.femur.assign(static_cast<std::size_t>(femur.V.rows()), 0);
  z.pelvis.assign(static_cast<std::size_t>(pelvis.V.rows()), 0);
  for (Eigen::Index i = 0; i < femur.V.rows(); ++i) {
    const Eigen::Vector3d v = femur.V.row(i).transpose();
    const bool on = z.head.contains(v);
    z.femur[static_cast<std::size_t>(i)] = on;
    z.femur_vertices += on;
  }
  for (Eigen::Index i = 0; i < pelvis.V.rows(); ++i) {
    const Eigen::Vector3d p = pelvis.V.row(i).transpose();
    const bool on = pelvic_zone(acetabulum, z, p, o) == PelvicZone::lunate;
    z.pelvis[static_cast<std::size_t>(i)] = on;
    z.pelvis_vertices += on;
  }
  return z;
}

PelvicZone pelvic_zone(const Acetabulum& A, const ArticularZones& z, const Eigen::Vector3d& p,
                       const ArticularZoneOptions& o) {
  const bool in_shell = (p - A.sphere.centre).norm() <= A.sphere.radius + z.lunate_tolerance_mm;
  const double below_rim = -(p - A.rim_centre).dot(A.opening);
  const Eigen::Vector3d across = (p - A.rim_centre) + below_rim * A.opening;
  if (below_rim >= o.rim_margin_mm && in_shell) return PelvicZone::lunate;
  constexpr double kRimMm = 5;
  for (const Eigen::Vector3d& r : A.rim)
    if ((p - r).squaredNorm() <= kRimMm * kRimMm) return PelvicZone::rim;
  if (below_rim >= o.rim_margin_mm && across.norm() <= A.rim_radius_mm) return PelvicZone::fossa;
  const double h = A.clock.hour(p);
  if (!std::isfinite(h)) return PelvicZone::fossa;
  return h >= 1 && h < 3 ? PelvicZone::aiis : h >= 3 && h < 6 ? PelvicZone::pubis : h >= 6 && h < 9 ? PelvicZone::ischium
                                                                                                  : PelvicZone::ilium;
}

}  // namespace impinge
