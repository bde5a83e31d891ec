#include "impinge/clinical/morphology.hpp"

#include "impinge/anatomy/articular_zones.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "impinge/anatomy/pelvis_frame.hpp"
#include "impinge/casters/exact_reference.hpp"
#include "impinge/core/error.hpp"

namespace impinge {

namespace {
constexpr double kDeg = 180.0 / M_PI;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// The unit vector of v's component across unit n.
Eigen::Vector3d across(const Eigen::Vector3d& v, const Eigen::Vector3d& n) { return (v - v.dot(n) * n).normalized(); }

// femoral_version_deg under its old name here.
double version_deg(const Eigen::Vector3d& neck, const Eigen::Vector3d& medial, const Eigen::Vector3d& lateral,
                   const Eigen::Vector3d& y, const Eigen::Vector3d& anterior) {
  return femoral_version_deg(neck, medial, lateral, y, anterior);
}

// The femoral versions (deg) of `n` (the neck axis, towards the head) against the posterior condylar and the
// transepicondylar axes of L, across the mechanical axis fy (knee centre to head centre) and across the shaft axis
// (m.shaft_axis, when measure_neck_shaft found it; else NaN, with a note); fx: the femoral frame's anterior.
void measure_versions(const Eigen::Vector3d& n, const FemurLandmarks& L, const Eigen::Vector3d& fy,
                      const Eigen::Vector3d& fx, Morphology& m) {
  m.version_posterior_condylar_deg = version_deg(n, L.posterior_condyle_medial, L.posterior_condyle_lateral, fy, fx);
  m.version_transepicondylar_deg = version_deg(n, L.epicondyle_medial, L.epicondyle_lateral, fy, fx);
  const Eigen::Vector3d s = m.shaft_axis;
  if (s.norm() > 0.5) {
    m.version_posterior_condylar_shaft_deg =
        version_deg(n, L.posterior_condyle_medial, L.posterior_condyle_lateral, s, fx);
    m.version_transepicondylar_shaft_deg = version_deg(n, L.epicondyle_medial, L.epicondyle_lateral, s, fx);
  } else {
    m.version_posterior_condylar_shaft_deg = m.version_transepicondylar_shaft_deg = kNaN;
    m.notes.push_back("femoral version across the shaft: no shaft axis (see the neck-shaft angle's note)");
  }
}

// The centre-edge angle (deg): rays from the head centre c (mm) in the plane normal to `normal` swept from `up`
// towards `towards` (unit vectors, orthogonal) every 0.1 deg; the edge is the last ray before the first that meets no
// bone of the pelvis within the head radius r + kReachMm (mm; the MRI joint spaces are 3.5-6 mm); the median of the
// edges in the planes 4, 2 and 0 mm to either side (a notch in an MRI rim lets one plane's ray out early). NaN when
// even the ray along `up` meets nothing. The rim points' median this replaced read mc22-left's lateral centre-edge
// angle as 10.7 deg where the roof's bone reaches 19.8 deg (Wiberg's edge: where the roof ends).
double centre_edge_deg(const ExactReference& pelvis, const Eigen::Vector3d& c, double r, const Eigen::Vector3d& normal,
                       const Eigen::Vector3d& up, const Eigen::Vector3d& towards) {
  constexpr double kReachMm = 10, kStepDeg = 0.1;
  std::vector<double> edges;
  for (double offset = -4; offset <= 4 + 1e-9; offset += 2) {
    const Eigen::Vector3d o = c + offset * normal;
    double last = kNaN;
    for (double a = 0; a < 90; a += kStepDeg) {
      const Eigen::Vector3d u = std::cos(a / kDeg) * up + std::sin(a / kDeg) * towards;
      const std::optional<double> hit = pelvis.first_hit(o, u);
      if (!hit || *hit > r + kReachMm) break;
      last = a;
    }
    if (!std::isnan(last)) edges.push_back(last);
  }
  if (edges.empty()) return kNaN;
  std::sort(edges.begin(), edges.end());
  const std::size_t k = edges.size() / 2;
  return edges.size() % 2 == 1 ? edges[k] : 0.5 * (edges[k - 1] + edges[k]);
}

// Sphericity over the head's cap away from the neck: each vertex's deviation from the sphere (c, r) within r + 5 mm
// and at least 100 deg from `down_neck` into m.head_deviation_mm, and their rms and largest (mm).
void measure_sphericity(const TriangleMesh& femur, const Eigen::Vector3d& c, double r, const Eigen::Vector3d& down_neck,
                        Morphology& m) {
  m.head_deviation_mm.assign(static_cast<std::size_t>(femur.V.rows()), kNaN);
  const double cap = std::cos(100.0 / kDeg);
  double sum2 = 0;
  for (Eigen::Index i = 0; i < femur.V.rows(); ++i) {
    const Eigen::Vector3d d = femur.V.row(i).transpose() - c;
    const double len = d.norm();
    if (len == 0 || len > r + 5 || d.dot(down_neck) / len > cap) continue;
    const double dev = len - r;
    m.head_deviation_mm[static_cast<std::size_t>(i)] = dev;
    sum2 += dev * dev;
    m.sphericity_max_mm = std::max(m.sphericity_max_mm, std::abs(dev));
    ++m.sphericity_vertices;
  }
  m.sphericity_rms_mm = m.sphericity_vertices > 0 ? std::sqrt(sum2 / double(m.sphericity_vertices)) : kNaN;
}

// The shaft axis, the principal axis of the diaphysis' surface (35-65 % of the head-to-knee length along fy), and
// the neck-shaft angle (deg) against the neck axis n; nothing without landmarks (the caller has noted why).
void measure_neck_shaft(const TriangleMesh& femur, const Eigen::Vector3d& c, const Eigen::Vector3d& fy,
                        const Eigen::Vector3d& n, const FemurLandmarks& L, bool landmarks, Morphology& m) {
  const Eigen::Vector3d knee = 0.5 * (L.epicondyle_lateral + L.epicondyle_medial);
  const double length = (c - knee).dot(fy);
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3d> shaft;
  for (Eigen::Index i = 0; landmarks && i < femur.V.rows(); ++i) {
    const Eigen::Vector3d v = femur.V.row(i).transpose();
    const double s = (c - v).dot(fy) / length;
    if (s >= 0.35 && s <= 0.65) shaft.push_back(v), mean += v;
  }
  if (shaft.size() >= 30) {
    mean /= double(shaft.size());
    Eigen::Matrix3d C = Eigen::Matrix3d::Zero();
    for (const auto& v : shaft) C += (v - mean) * (v - mean).transpose();
    Eigen::Vector3d s = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(C).eigenvectors().col(2);
    if (s.dot(fy) < 0) s = -s;
    m.shaft_axis = s;
    m.neck_shaft_angle_deg = std::acos(std::clamp(n.dot(-s), -1.0, 1.0)) * kDeg;
  } else if (landmarks) {
    m.neck_shaft_angle_deg = kNaN;
    m.notes.push_back("neck-shaft angle: fewer than 30 vertices on the diaphysis (a proximal femur only?)");
  }
}

// The alpha angle (deg) per clock hour and its largest, by exact rays from the head centre c (radius r, mm; `tol`
// mm beyond it counts as the head). Swept from the neck (5 deg from its axis, where the ray leaves through the neck
// far from the centre) towards the head: the first direction in which the surface lies within the head's radius +
// tol is where the contour crosses the circle (Noetzli's point, seen from the neck side: the fovea and any bump on
// the head beyond it are never reached).
void measure_alpha_angles(const ExactReference& ref, const Eigen::Vector3d& c, double r, double tol,
                          const ClockFace& clock, const Eigen::Vector3d& down_neck, Morphology& m) {
  constexpr double kStep = 0.5, kFrom = 5, kTo = 150;
  m.alpha_max_deg = -1;
  for (int h = 1; h <= 12; ++h) {
    const double psi = h * 30.0 / kDeg;
    const Eigen::Vector3d e = std::cos(psi) * clock.twelve + std::sin(psi) * clock.three;
    double alpha = kNaN, previous_excess = kNaN;
    for (double phi = kFrom; phi <= kTo; phi += kStep) {
      const Eigen::Vector3d u = std::cos(phi / kDeg) * down_neck + std::sin(phi / kDeg) * e;
      const std::optional<double> rho = ref.first_hit(c, u);
      const double excess = rho ? *rho - r - tol : std::numeric_limits<double>::infinity();
      if (excess <= 0) {
        // Between the last step past the head's reach and this one, where the surface crosses r + tol.
        alpha = std::isfinite(previous_excess) ? phi - kStep * excess / (excess - previous_excess) : phi;
        break;
      }
      previous_excess = excess;
    }
    m.alpha_deg[static_cast<std::size_t>(h - 1)] = alpha;
    if (std::isfinite(alpha) && alpha > m.alpha_max_deg) m.alpha_max_deg = alpha, m.alpha_max_hour = h;
  }
  if (m.alpha_max_deg < 0) m.alpha_max_deg = m.alpha_max_hour = kNaN;
}

// The anterior head-neck offset (mm) and its ratio to the head's diameter: r less the neck's narrowest anterior
// depth (along the clock's three) 0.5-1.3 r down the neck from the head centre c.
void measure_head_neck_offset(const ExactReference& ref, const Eigen::Vector3d& c, double r, const ClockFace& clock,
                              const Eigen::Vector3d& down_neck, Morphology& m) {
  double waist = std::numeric_limits<double>::infinity();
  for (double s = 0.5 * r; s <= 1.3 * r; s += 0.25) {
    const std::optional<double> w = ref.first_hit(c + s * down_neck, clock.three);
    if (w) waist = std::min(waist, *w);
  }
  if (std::isfinite(waist)) {
    m.head_neck_offset_mm = r - waist;
    m.head_neck_offset_ratio = m.head_neck_offset_mm / (2 * r);
  } else {
    m.head_neck_offset_mm = m.head_neck_offset_ratio = kNaN;
    m.notes.push_back("head-neck offset: no anterior neck surface found along the neck axis");
  }
}

// Coverage: the cap inside the rim, seen from the head centre c (the pole: into the acetabulum): the share of the
// head sphere covered and the rim's angle from the pole (deg) per acetabular clock hour.
void measure_coverage(const Acetabulum& A, const Eigen::Vector3d& c, Morphology& m) {
  std::vector<Eigen::Vector3d> d;  // the rim points relative to the head centre
  for (const Eigen::Vector3d& p : A.rim) d.push_back(p - c);
  const Eigen::Vector3d pole = -A.opening;
  std::array<double, 12> sum{};
  std::array<int, 12> count{};
  double covered = 0;
  for (std::size_t i = 0; i < d.size(); ++i) {
    const double theta = std::acos(std::clamp(d[i].normalized().dot(pole), -1.0, 1.0));
    covered += (1 - std::cos(theta)) / 2;
    const double hour = A.clock.hour(A.rim[i]);
    if (std::isfinite(hour)) {
      const auto k = static_cast<std::size_t>(ClockFace::sector(hour));
      sum[k] += theta * kDeg, ++count[k];
    }
  }
  m.head_coverage = d.empty() ? kNaN : covered / double(d.size());
  for (std::size_t k = 0; k < 12; ++k) m.coverage_deg[k] = count[k] > 0 ? sum[k] / count[k] : kNaN;
}
}  // namespace

double femoral_version_deg(const Eigen::Vector3d& neck, const Eigen::Vector3d& medial, const Eigen::Vector3d& lateral,
                           const Eigen::Vector3d& axis, const Eigen::Vector3d& anterior) {
  const Eigen::Vector3d y = axis.normalized();
  const Eigen::Vector3d to_medial = across(medial - lateral, y);
  const Eigen::Vector3d ant = across(across(anterior, y) - across(anterior, y).dot(to_medial) * to_medial, y);
  const Eigen::Vector3d n = across(neck, y);
  return std::atan2(n.dot(ant), n.dot(to_medial)) * kDeg;
}

Morphology measure_morphology(const TriangleMesh& femur, const TriangleMesh& pelvis, Side side, const HipFrames& frames,
                              const Acetabulum& A, const ClockFace* head_neck_clock) {
  Morphology m;
  const SphereFitResult& head = frames.head;
  const Eigen::Vector3d c = head.centre;
  const double r = head.radius;
  require(c.allFinite() && std::isfinite(r) && r > 0,
          femur.source + ": morphology: the femoral head sphere is not set");
  m.head_centre_mm = c;
  m.head_radius_mm = r;
  m.head_fit_rms_mm = head.rms_residual;
  const double lateral_sign = side == Side::right ? 1.0 : -1.0;
  const AnatomicalFrame& F = frames.femur;
  const Eigen::Vector3d fx = F.axes.col(0), fy = F.axes.col(1);

  // Neck axis (towards the head) and the head-neck clock.
  const ClockFace clock = head_neck_clock ? *head_neck_clock : femoral_clock_face(femur, c, r, F);
  const Eigen::Vector3d n = clock.axis, down_neck = -n;
  m.neck_axis = n;
  m.head_neck_clock = clock;
  measure_sphericity(femur, c, r, down_neck, m);

  // Without femoral landmarks (scan neutral: a generated hip, a proximal femur) there is no knee: no shaft, no version.
  const FemurLandmarks& L = frames.femur_landmarks;
  const bool landmarks = !L.source.empty();
  if (!landmarks) {
    m.neck_shaft_angle_deg = m.version_posterior_condylar_deg = m.version_transepicondylar_deg = kNaN;
    m.version_posterior_condylar_shaft_deg = m.version_transepicondylar_shaft_deg = kNaN;
    m.notes.push_back(
        "no femoral landmarks (scan neutral): no neck-shaft angle or femoral version; the input frame's "
        "axes stand for the femoral and pelvic frames");
  }
  measure_neck_shaft(femur, c, fy, n, L, landmarks, m);
  // Femoral version against both condylar axes, across the mechanical axis (ISB y) and across the shaft axis.
  if (landmarks) measure_versions(n, L, fy, fx, m);

  // Alpha angle per clock hour and the anterior head-neck offset, by exact rays from inside the femur.
  const ExactReference ref(femur);
  const double tol = head_junction_tolerance_mm(head.rms_residual);  // the head-neck junction's (articular_zones.hpp)
  measure_alpha_angles(ref, c, r, tol, clock, down_neck, m);
  measure_head_neck_offset(ref, c, r, clock, down_neck, m);

  // The acetabulum.
  m.acetabular_centre_mm = A.sphere.centre;
  m.acetabular_radius_mm = A.sphere.radius;
  m.acetabular_fit_rms_mm = A.sphere.rms_residual;
  m.lunate_area_mm2 = A.lunate_area_mm2;
  // The anterior pelvic plane and the ISB frames from the same landmarks, whichever frames.pelvis is.
  const bool pelvic_landmarks = !frames.pelvis_landmarks.source.empty();
  const auto pelvic = [&](PelvisFrameKind kind) {
    return pelvic_landmarks ? pelvis_frame(frames.pelvis_landmarks, c, kind) : frames.pelvis;
  };
  const AnatomicalFrame app = pelvic(PelvisFrameKind::anterior_pelvic_plane);
  m.orientation_app = radiographic_orientation(A, app, side);
  m.orientation_isb = radiographic_orientation(A, pelvic(PelvisFrameKind::isb), side);
  const Eigen::Vector3d X = app.axes.col(0), Y = app.axes.col(1), lateral = lateral_sign * app.axes.col(2);
  // Lateral: in the coronal plane (normal X) from superior towards lateral; anterior: in the sagittal plane (normal:
  // lateral) from superior towards anterior.
  const ExactReference pelvis_ref(pelvis);
  m.lateral_centre_edge_deg = centre_edge_deg(pelvis_ref, c, r, X, Y, lateral);
  m.anterior_centre_edge_deg = centre_edge_deg(pelvis_ref, c, r, lateral, Y, X);
  if (std::isnan(m.lateral_centre_edge_deg))
    m.notes.push_back("lateral centre-edge angle: no bone of the pelvis above the head within its radius + 10 mm");
  if (std::isnan(m.anterior_centre_edge_deg))
    m.notes.push_back("anterior centre-edge angle: no bone of the pelvis above the head within its radius + 10 mm");
  measure_coverage(A, c, m);
  return m;
}

}  // namespace impinge
