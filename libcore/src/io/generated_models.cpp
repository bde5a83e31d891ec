#include "impinge/io/generated_models.hpp"

#include <algorithm>
#include <cmath>

#include "impinge/core/error.hpp"
#include "impinge/core/spherical_frame.hpp"

namespace impinge {

namespace {
/// Orthonormal basis whose third column is `axis`.
Eigen::Matrix3d frame_of(const Eigen::Vector3d& axis) {
  const Eigen::Vector3d z = axis.normalized();
  const Eigen::Vector3d helper = std::abs(z.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  const Eigen::Vector3d x = helper.cross(z).normalized();
  Eigen::Matrix3d B;
  B.col(0) = x;
  B.col(1) = z.cross(x);
  B.col(2) = z;
  return B;
}
}  // namespace

TriangleMesh make_radial_surface(const std::function<double(const Eigen::Vector3d&)>& radius,
                                 const Eigen::Vector3d& centre, int n_theta, int n_phi, const Eigen::Vector3d& axis) {
  require(n_theta >= 3 && n_phi >= 2, "radial surface: need n_theta >= 3 and n_phi >= 2");
  const Eigen::Matrix3d B = frame_of(axis);
  TriangleMesh m;
  m.source = "generated radial surface";
  const int rings = n_phi - 1;
  m.V.resize(2 + rings * n_theta, 3);
  auto put = [&](int i, const Eigen::Vector3d& local) {
    const Eigen::Vector3d u = B * local;
    m.V.row(i) = (centre + radius(u) * u).transpose();
  };
  put(0, {0, 0, 1});
  for (int j = 1; j <= rings; ++j)
    for (int k = 0; k < n_theta; ++k) {
      const double phi = kPi * j / n_phi, th = 2 * kPi * k / n_theta;
      put(1 + (j - 1) * n_theta + k, direction(phi, th));
    }
  const int south = 1 + rings * n_theta;
  put(south, {0, 0, -1});
  m.F.resize(2 * n_theta * rings, 3);
  int f = 0;
  auto idx = [&](int j, int k) { return 1 + (j - 1) * n_theta + (k % n_theta); };
  for (int k = 0; k < n_theta; ++k) m.F.row(f++) << 0, idx(1, k), idx(1, k + 1);
  for (int j = 1; j < rings; ++j)
    for (int k = 0; k < n_theta; ++k) {
      m.F.row(f++) << idx(j, k), idx(j + 1, k), idx(j + 1, k + 1);
      m.F.row(f++) << idx(j, k), idx(j + 1, k + 1), idx(j, k + 1);
    }
  for (int k = 0; k < n_theta; ++k) m.F.row(f++) << south, idx(rings, k + 1), idx(rings, k);
  return m;
}

TriangleMesh make_uv_sphere(double radius_mm, const Eigen::Vector3d& centre, int n_theta, int n_phi,
                            const Eigen::Vector3d& axis) {
  TriangleMesh m =
      make_radial_surface([radius_mm](const Eigen::Vector3d&) { return radius_mm; }, centre, n_theta, n_phi, axis);
  m.source = "generated sphere";
  return m;
}

TriangleMesh make_cup(double inner_mm, double outer_mm, double coverage_deg, const Eigen::Vector3d& centre,
                      const Eigen::Vector3d& axis, int n_beta, int n_alpha) {
  require(inner_mm > 0 && outer_mm > inner_mm, "cup: need 0 < inner < outer radius");
  require(coverage_deg > 0 && coverage_deg < 180, "cup: coverage must be in (0, 180) deg");
  require(n_beta >= 3 && n_alpha >= 1, "cup: need n_beta >= 3 and n_alpha >= 1");
  const Eigen::Matrix3d B = frame_of(axis);
  TriangleMesh m;
  m.source = "generated cup";
  const int per_shell = 1 + n_alpha * n_beta;
  m.V.resize(2 * per_shell, 3);
  for (int s = 0; s < 2; ++s) {
    const double r = s == 0 ? inner_mm : outer_mm;
    m.V.row(s * per_shell) = (centre + r * B.col(2)).transpose();
    for (int i = 1; i <= n_alpha; ++i)
      for (int k = 0; k < n_beta; ++k) {
        const double a = coverage_deg * kDegToRad * i / n_alpha, b = 2 * kPi * k / n_beta;
        m.V.row(s * per_shell + 1 + (i - 1) * n_beta + k) = (centre + r * (B * direction(a, b))).transpose();
      }
  }
  auto idx = [&](int s, int i, int k) { return s * per_shell + 1 + (i - 1) * n_beta + (k % n_beta); };
  m.F.resize(4 * n_alpha * n_beta, 3);
  int f = 0;
  for (int s = 0; s < 2; ++s) {
    // inner shell faces the COR, outer faces away: opposite windings
    auto tri = [&](int a, int b, int c) {
      if (s == 0)
        m.F.row(f++) << a, c, b;
      else
        m.F.row(f++) << a, b, c;
    };
    for (int k = 0; k < n_beta; ++k) tri(s * per_shell, idx(s, 1, k), idx(s, 1, k + 1));
    for (int i = 1; i < n_alpha; ++i)
      for (int k = 0; k < n_beta; ++k) {
        tri(idx(s, i, k), idx(s, i + 1, k), idx(s, i + 1, k + 1));
        tri(idx(s, i, k), idx(s, i + 1, k + 1), idx(s, i, k + 1));
      }
  }
  // The rim band, wound as the shells are (each rim edge runs opposite to the shell's).
  for (int k = 0; k < n_beta; ++k) {
    m.F.row(f++) << idx(0, n_alpha, k), idx(1, n_alpha, k + 1), idx(1, n_alpha, k);
    m.F.row(f++) << idx(0, n_alpha, k), idx(0, n_alpha, k + 1), idx(1, n_alpha, k + 1);
  }
  return m;
}

TriangleMesh make_sliced_sphere(double radius_mm, double slice_mm, const Eigen::Vector3d& centre, int segments) {
  require(radius_mm > 0 && slice_mm > 0 && slice_mm <= radius_mm && segments >= 3,
          "sliced sphere: need 0 < slice <= radius and segments >= 3");
  // Slice k covers [k t, (k+1) t] for k = -n..n-1; keep those whose mid height is inside.
  const int n = static_cast<int>(std::ceil(radius_mm / slice_mm));
  std::vector<std::pair<double, double>> z_band;  // (z_lo, z_hi) of kept slices, bottom to top
  std::vector<double> rho;
  for (int k = -n; k < n; ++k) {
    const double zm = (k + 0.5) * slice_mm;
    if (std::abs(zm) >= radius_mm) continue;
    z_band.emplace_back(k * slice_mm, (k + 1) * slice_mm);
    rho.push_back(std::sqrt(radius_mm * radius_mm - zm * zm));
  }
  TriangleMesh m;
  m.source = "generated sliced sphere";
  std::vector<Eigen::Vector3d> V;
  std::vector<Eigen::Vector3i> F;
  auto ring = [&](double z, double r) {
    const int first = static_cast<int>(V.size());
    for (int j = 0; j < segments; ++j) {
      const double a = 2 * kPi * j / segments;
      V.push_back(centre + Eigen::Vector3d(r * std::cos(a), r * std::sin(a), z));
    }
    return first;
  };
  auto band = [&](int lo, int hi, bool outward_up) {  // quads between two rings
    for (int j = 0; j < segments; ++j) {
      const int j1 = (j + 1) % segments;
      if (outward_up) {
        F.push_back({lo + j, lo + j1, hi + j1});
        F.push_back({lo + j, hi + j1, hi + j});
      } else {
        F.push_back({lo + j, hi + j1, lo + j1});
        F.push_back({lo + j, hi + j, hi + j1});
      }
    }
  };
  const int bottom_c = static_cast<int>(V.size());
  V.push_back(centre + Eigen::Vector3d(0, 0, z_band.front().first));
  int prev_top = -1;
  for (std::size_t k = 0; k < z_band.size(); ++k) {
    const int lo = ring(z_band[k].first, rho[k]);
    const int hi = ring(z_band[k].second, rho[k]);
    if (k == 0) {
      for (int j = 0; j < segments; ++j) F.push_back({bottom_c, lo + (j + 1) % segments, lo + j});
    } else {
      band(prev_top, lo, rho[k] > rho[k - 1]);  // flat step between slices
    }
    band(lo, hi, true);
    prev_top = hi;
  }
  const int top_c = static_cast<int>(V.size());
  V.push_back(centre + Eigen::Vector3d(0, 0, z_band.back().second));
  for (int j = 0; j < segments; ++j) F.push_back({top_c, prev_top + j, prev_top + (j + 1) % segments});
  m.V.resize(static_cast<Eigen::Index>(V.size()), 3);
  for (std::size_t i = 0; i < V.size(); ++i) m.V.row(static_cast<Eigen::Index>(i)) = V[i].transpose();
  m.F.resize(static_cast<Eigen::Index>(F.size()), 3);
  for (std::size_t i = 0; i < F.size(); ++i) m.F.row(static_cast<Eigen::Index>(i)) = F[i].transpose();
  return m;
}

TriangleMesh make_conchoid_surface(double a_mm, double b_mm, const Eigen::Vector3d& origin, int n_theta, int n_phi,
                                   const Eigen::Vector3d& axis) {
  require(a_mm > b_mm && b_mm >= 0, "conchoid surface: need a > b >= 0");
  const Eigen::Vector3d ax = axis.normalized();
  TriangleMesh m =
      make_radial_surface([&](const Eigen::Vector3d& u) { return a_mm + b_mm * std::clamp(u.dot(ax), -1.0, 1.0); },
                          origin, n_theta, n_phi, ax);
  m.source = "generated conchoid surface";
  return m;
}

HipModel make_hip_model(const HipModelOptions& o) {
  check_in_range("HipModelOptions::target_triangles", o.target_triangles, HipModelOptions::kTargetTrianglesRange);
  check_in_range("HipModelOptions::cup_coverage_deg", o.cup_coverage_deg, HipModelOptions::kCupCoverageRange, "deg");
  check_in_range("HipModelOptions::cam_height_mm", o.cam_height_mm, HipModelOptions::kCamHeightRange, "mm");
  require(o.neck_radius_mm < o.head_radius_mm && o.neck_length_mm > o.head_radius_mm,
          "hip model: need neck radius < head radius < neck length");
  HipModel h;
  h.cor = o.cor;
  const Eigen::Vector3d neck = Eigen::Vector3d(0.80, 0.25, -0.55).normalized();
  const double alpha0 = std::asin(o.neck_radius_mm / o.head_radius_mm);
  // cam bump: antero-superior side of the head-neck junction
  const Eigen::Vector3d up_ant =
      (Eigen::Vector3d(0, 0.5, 1) - neck * neck.dot(Eigen::Vector3d(0, 0.5, 1))).normalized();
  const Eigen::Vector3d cam_dir = (std::cos(alpha0 + 0.12) * neck + std::sin(alpha0 + 0.12) * up_ant).normalized();
  auto ball_radius = [&](const Eigen::Vector3d& u) {
    const double ca = std::clamp(u.dot(neck), -1.0, 1.0), alpha = std::acos(ca);
    double r = o.head_radius_mm;
    if (alpha < alpha0) r = std::min(o.neck_radius_mm / std::max(std::sin(alpha), 1e-12), o.neck_length_mm / ca);
    if (o.cam_height_mm > 0) {
      const double g = std::acos(std::clamp(u.dot(cam_dir), -1.0, 1.0)) / (12 * kDegToRad);
      r += o.cam_height_mm * std::exp(-g * g);
    }
    return r;
  };
  const int nt = std::max(8, static_cast<int>(std::lround(std::sqrt(static_cast<double>(o.target_triangles)))));
  const int np = std::max(2, static_cast<int>(std::lround(o.target_triangles / (2.0 * nt))) + 1);
  // Pole of the UV parameterisation along the neck axis: a fan caps the neck's cut end.
  h.ball = make_radial_surface(ball_radius, o.cor, nt, np, neck);
  h.ball.source = "generated ball (" + std::to_string(o.target_triangles) + " triangles)";
  const Eigen::Vector3d cup_axis = Eigen::Vector3d(-0.65, -0.2, 0.73).normalized();
  const int nb =
      std::max(6, static_cast<int>(std::lround(std::sqrt(o.target_triangles * 360.0 / (4 * o.cup_coverage_deg)))));
  const int na = std::max(1, static_cast<int>(std::lround(o.target_triangles / (4.0 * nb))));
  const double inner = o.head_radius_mm + o.cartilage_gap_mm;
  h.socket = make_cup(inner, inner + o.cup_wall_mm, o.cup_coverage_deg, o.cor, cup_axis, nb, na);
  h.socket.source = "generated socket (" + std::to_string(o.target_triangles) + " triangles)";
  return h;
}

}  // namespace impinge
