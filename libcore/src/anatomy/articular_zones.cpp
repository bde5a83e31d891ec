#include "impinge/anatomy/articular_zones.hpp"

#include <algorithm>
#include <cmath>

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

namespace {
double tolerance(double rms, const ArticularZoneOptions& o) {
  return std::isfinite(rms) ? std::max(o.min_tolerance_mm, o.rms_factor * rms) : o.min_tolerance_mm;
}
}  // namespace

ArticularZones find_articular_zones(const TriangleMesh& femur, const SphereFitResult& head, const TriangleMesh& pelvis,
                                    const Acetabulum& acetabulum, const ArticularZoneOptions& o) {
  ArticularZones z;
  z.head_tolerance_mm = tolerance(head.rms_residual, o);
  z.lunate_tolerance_mm = tolerance(acetabulum.sphere.rms_residual, o);
  z.head_sphere_reach_mm = head.radius + z.head_tolerance_mm;
  z.femur.assign(static_cast<std::size_t>(femur.V.rows()), 0);
  z.pelvis.assign(static_cast<std::size_t>(pelvis.V.rows()), 0);
  const SphereFitResult& cup = acetabulum.sphere;
  const double reach =
      std::max(head.radius + z.head_tolerance_mm, cup.radius + z.lunate_tolerance_mm + (cup.centre - head.centre).norm());
  for (Eigen::Index i = 0; i < femur.V.rows(); ++i) {
    const bool on = (femur.V.row(i).transpose() - head.centre).norm() <= reach;
    z.femur[static_cast<std::size_t>(i)] = on;
    z.femur_vertices += on;
  }
  for (Eigen::Index i = 0; i < pelvis.V.rows(); ++i) {
    const Eigen::Vector3d p = pelvis.V.row(i).transpose();
    const bool in_shell = (p - cup.centre).norm() <= cup.radius + z.lunate_tolerance_mm;
    const bool inside = (p - acetabulum.rim_centre).dot(acetabulum.opening) <= -o.rim_margin_mm;
    const bool on = in_shell && inside;
    z.pelvis[static_cast<std::size_t>(i)] = on;
    z.pelvis_vertices += on;
  }
  return z;
}

}  // namespace impinge
