#include "impinge/anatomy/sphere_fit.hpp"

#include <gsl/gsl_blas.h>
#include <gsl/gsl_multifit_nlinear.h>
#include <gsl/gsl_vector.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>

#include "impinge/core/error.hpp"

namespace impinge {

using PointMatrix = Vertices;

namespace {
double rms_of(PointsRef P, const Eigen::Vector3d& c, double r) {
  double s = 0;
  for (Eigen::Index i = 0; i < P.rows(); ++i) {
    const double e = (P.row(i).transpose() - c).norm() - r;
    s += e * e;
  }
  return std::sqrt(s / static_cast<double>(P.rows()));
}

int residual_f(const gsl_vector* x, void* data, gsl_vector* f) {
  const auto& P = *static_cast<const PointsRef*>(data);
  const Eigen::Vector3d c(gsl_vector_get(x, 0), gsl_vector_get(x, 1), gsl_vector_get(x, 2));
  const double r = gsl_vector_get(x, 3);
  for (Eigen::Index i = 0; i < P.rows(); ++i)
    gsl_vector_set(f, static_cast<std::size_t>(i), (P.row(i).transpose() - c).norm() - r);
  return GSL_SUCCESS;
}

int residual_df(const gsl_vector* x, void* data, gsl_matrix* J) {
  const auto& P = *static_cast<const PointsRef*>(data);
  const Eigen::Vector3d c(gsl_vector_get(x, 0), gsl_vector_get(x, 1), gsl_vector_get(x, 2));
  for (Eigen::Index i = 0; i < P.rows(); ++i) {
    const Eigen::Vector3d d = P.row(i).transpose() - c;
    const double L = d.norm();
    const auto row = static_cast<std::size_t>(i);
    for (int k = 0; k < 3; ++k) gsl_matrix_set(J, row, static_cast<std::size_t>(k), L > 0 ? -d[k] / L : 0.0);
    gsl_matrix_set(J, row, 3, -1.0);
  }
  return GSL_SUCCESS;
}
}  // namespace

SphereFitResult fit_sphere_algebraic(PointsRef P) {
  require(P.rows() >= 4, "sphere fit: needs at least 4 points, got " + std::to_string(P.rows()));
  // Centre the data for conditioning.
  const Eigen::RowVector3d mean = P.colwise().mean();
  const PointMatrix Q = P.rowwise() - mean;
  Eigen::MatrixXd A(Q.rows(), 4);
  Eigen::VectorXd b(Q.rows());
  for (Eigen::Index i = 0; i < Q.rows(); ++i) {
    A(i, 0) = 2 * Q(i, 0);
    A(i, 1) = 2 * Q(i, 1);
    A(i, 2) = 2 * Q(i, 2);
    A(i, 3) = 1;
    b[i] = Q.row(i).squaredNorm();
  }
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(A);
  require(qr.rank() == 4, "sphere fit: points are coplanar or degenerate (rank " + std::to_string(qr.rank()) + ")");
  const Eigen::Vector4d x = qr.solve(b);
  SphereFitResult res;
  const Eigen::Vector3d c = x.head<3>();
  const double r2 = x[3] + c.squaredNorm();
  require(r2 > 0, "sphere fit: no real sphere fits the points");
  res.centre = c + mean.transpose();
  res.radius = std::sqrt(r2);
  res.rms_residual = rms_of(P, res.centre, res.radius);
  res.points_used = P.rows();
  res.converged = true;
  return res;
}

SphereFitResult fit_sphere_geometric(PointsRef P) { return fit_sphere_geometric(P, {}); }

SphereFitResult fit_sphere_geometric(PointsRef P, const std::vector<double>& weights) {
  require(weights.empty() || weights.size() == static_cast<std::size_t>(P.rows()),
          "sphere fit: " + std::to_string(weights.size()) + " weights for " + std::to_string(P.rows()) + " points");
  for (double w : weights) require(std::isfinite(w) && w >= 0, "sphere fit: a weight is negative or not finite");
  SphereFitResult start = fit_sphere_algebraic(P);
  const gsl_multifit_nlinear_type* T = gsl_multifit_nlinear_trust;
  gsl_multifit_nlinear_parameters params = gsl_multifit_nlinear_default_parameters();
  // The step from the normal equations (4 x 4, Cholesky) rather than a QR of the k x 4 Jacobian: a third less
  // time per fit (some 2,600 head points: 0.98 -> 0.70 ms), the same sphere to the last digit on the shared hips'
  // heads (a weighted acetabular fit moved in its 16th digit). The Jacobian's columns, a unit direction and -1,
  // are well conditioned whatever the points' offset.
  params.solver = gsl_multifit_nlinear_solver_cholesky;
  const std::size_t n = static_cast<std::size_t>(P.rows()), p = 4;
  gsl_multifit_nlinear_workspace* w = gsl_multifit_nlinear_alloc(T, &params, n, p);
  gsl_multifit_nlinear_fdf fdf;
  fdf.f = residual_f;
  fdf.df = residual_df;
  fdf.fvv = nullptr;
  fdf.n = n;
  fdf.p = p;
  fdf.params = const_cast<PointsRef*>(&P);
  gsl_vector* x0 = gsl_vector_alloc(p);
  for (int k = 0; k < 3; ++k) gsl_vector_set(x0, static_cast<std::size_t>(k), start.centre[k]);
  gsl_vector_set(x0, 3, start.radius);
  gsl_vector* wts = nullptr;
  if (weights.empty()) {
    gsl_multifit_nlinear_init(x0, &fdf, w);
  } else {
    wts = gsl_vector_alloc(n);
    for (std::size_t i = 0; i < n; ++i) gsl_vector_set(wts, i, weights[i]);
    gsl_multifit_nlinear_winit(x0, wts, &fdf, w);
  }
  int info = 0;
  const int status = gsl_multifit_nlinear_driver(200, 1e-12, 1e-12, 1e-12, nullptr, nullptr, &info, w);
  const gsl_vector* x = gsl_multifit_nlinear_position(w);
  SphereFitResult res;
  res.centre = Eigen::Vector3d(gsl_vector_get(x, 0), gsl_vector_get(x, 1), gsl_vector_get(x, 2));
  res.radius = std::abs(gsl_vector_get(x, 3));
  res.iterations = static_cast<int>(gsl_multifit_nlinear_niter(w));
  res.converged = (status == GSL_SUCCESS);
  gsl_vector_free(x0);
  if (wts != nullptr) gsl_vector_free(wts);
  gsl_multifit_nlinear_free(w);
  require(res.centre.allFinite() && std::isfinite(res.radius), "sphere fit: solver diverged");
  if (weights.empty()) {
    res.rms_residual = rms_of(P, res.centre, res.radius);
  } else {
    double sw = 0, se = 0;
    for (Eigen::Index i = 0; i < P.rows(); ++i) {
      const double e = (P.row(i).transpose() - res.centre).norm() - res.radius;
      sw += weights[static_cast<std::size_t>(i)], se += weights[static_cast<std::size_t>(i)] * e * e;
    }
    res.rms_residual = sw > 0 ? std::sqrt(se / sw) : std::nan("");
  }
  res.points_used = P.rows();
  return res;
}

namespace {
// A point of a surface fit's quadrature: where, the area it stands for, its triangle's unit outward normal.
struct SurfacePoint {
  Eigen::Vector3d p, normal;
  double area;
};

constexpr double kQuadratureEdgeMm = 0.5;  // the quadrature's sub-triangles are at most this long
constexpr int kSurfaceFitSteps = 2000;      // the reweighted Gauss-Newton steps at most

// The triangles of `mesh` whose centroid lies within reach_mm (plus the triangle's longest edge) of the sphere
// (c, r) (fit_sphere_to_surface): their indices. The points are made from them on each pass (for_each_point), not
// kept: a million points of a fine pelvis would hold 60 MB through the maps' build.
std::vector<Eigen::Index> shell_triangles(const TriangleMesh& mesh, const Eigen::Vector3d& c, double r,
                                          double reach_mm) {
  std::vector<Eigen::Index> out;
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)).transpose(), b = mesh.V.row(mesh.F(f, 1)).transpose(),
                          e = mesh.V.row(mesh.F(f, 2)).transpose();
    const double longest = std::max({(b - a).norm(), (e - b).norm(), (a - e).norm()});
    if (std::abs(((a + b + e) / 3 - c).norm() - r) <= reach_mm + longest) out.push_back(f);
  }
  return out;
}

// Calls fn(point) for the quadrature points of the triangles T of `mesh`: each cut into k x k congruent triangles, k
// the least power of two that makes them at most kQuadratureEdgeMm long (at most 64), their centroids; `flip`: -1
// when the mesh's normals point in.
template <class Fn>
void for_each_point(const TriangleMesh& mesh, const std::vector<Eigen::Index>& T, double flip, Fn&& fn) {
  for (const Eigen::Index f : T) {
    const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)).transpose(), b = mesh.V.row(mesh.F(f, 1)).transpose(),
                          e = mesh.V.row(mesh.F(f, 2)).transpose();
    const Eigen::Vector3d n = (b - a).cross(e - a);
    const double twice_area = n.norm();
    if (!(twice_area > 0)) continue;
    const double longest = std::max({(b - a).norm(), (e - b).norm(), (a - e).norm()});
    int k = 1;
    while (k < 64 && longest / k > kQuadratureEdgeMm) k *= 2;
    const Eigen::Vector3d u = (b - a) / k, v = (e - a) / k;
    SurfacePoint x{Eigen::Vector3d::Zero(), flip * n / twice_area, twice_area / 2 / (static_cast<double>(k) * k)};
    for (int p = 0; p < k; ++p)
      for (int q = 0; p + q < k; ++q) {
        x.p = a + (p + 1.0 / 3) * u + (q + 1.0 / 3) * v;  // the sub-triangle pointing up
        fn(x);
        if (p + q < k - 1) x.p = a + (p + 2.0 / 3) * u + (q + 2.0 / 3) * v, fn(x);  // and down
      }
  }
}

// A point's weight in the fit to the sphere (c, r) (fit_sphere_to_surface); `towards`: +1 concave, -1 convex.
double surface_weight(const SurfacePoint& x, const Eigen::Vector3d& c, double r, double band, double facing_cos,
                      double towards) {
  const Eigen::Vector3d d = x.p - c;
  const double n = d.norm();
  if (!(n > 0)) return 0;
  const double s = (n - r) / band;
  if (std::abs(s) >= 1) return 0;
  const double f = std::clamp((-towards * x.normal.dot(d) / n - (facing_cos - 0.1)) / 0.2, 0.0, 1.0);
  return x.area * (1 - s * s) * (1 - s * s) * f * f * (3 - 2 * f);
}
}  // namespace

SurfaceSphereFit fit_sphere_to_surface(const TriangleMesh& mesh, const Eigen::Vector3d& centre, double radius,
                                       double band_mm, double facing_cos, SurfaceSide side, const std::string& what) {
  std::ostringstream band_text;
  band_text << band_mm;
  const std::string failure = mesh.source + ": " + what + ": no surface within " + band_text.str() +
                              " mm of the sphere faces it";
  require(centre.allFinite() && std::isfinite(radius) && radius > 0 && std::isfinite(band_mm) && band_mm > 0, failure);
  // Six times the signed volume about the start centre: > 0 when the normals point out. About a point inside the
  // ball or the socket's sphere, so that an open cut far away (a proximal femur) weighs little in the sign.
  double volume6 = 0;
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)).transpose() - centre,
                          b = mesh.V.row(mesh.F(f, 1)).transpose() - centre,
                          e = mesh.V.row(mesh.F(f, 2)).transpose() - centre;
    volume6 += a.dot(b.cross(e));
  }
  const double flip = volume6 < 0 ? -1.0 : 1.0, towards = side == SurfaceSide::concave ? 1.0 : -1.0;
  const double reach = band_mm + 3;  // the shell: the sphere may move 2.5 mm before its triangles are found again
  Eigen::Vector3d c = centre, drawn_c = centre;
  double r = radius, drawn_r = radius;
  std::vector<Eigen::Index> T = shell_triangles(mesh, c, r, reach);
  auto redraw = [&] {  // the shell holds every triangle within band_mm of (c, r) while |dc| + |dr| <= reach - band
    if ((c - drawn_c).norm() + std::abs(r - drawn_r) > reach - band_mm - 0.5)
      T = shell_triangles(mesh, c, r, reach), drawn_c = c, drawn_r = r;
  };
  int steps = 0;
  for (; steps < kSurfaceFitSteps; ++steps) {
    redraw();
    Eigen::Matrix4d H = Eigen::Matrix4d::Zero();
    Eigen::Vector4d g = Eigen::Vector4d::Zero();
    for_each_point(mesh, T, flip, [&](const SurfacePoint& x) {  // a Gauss-Newton step of sum w (|p - c| - r)^2
      const double w = surface_weight(x, c, r, band_mm, facing_cos, towards);
      if (!(w > 0)) return;
      const Eigen::Vector3d d = x.p - c;
      const double n = d.norm();
      Eigen::Vector4d J;
      J << -d / n, -1.0;  // d(|p - c| - r) / d(c, r)
      H.noalias() += w * J * J.transpose();
      g.noalias() += w * (n - r) * J;
    });
    require(H(3, 3) > 0, failure);
    Eigen::Vector4d step = -H.ldlt().solve(g);
    require(step.allFinite(), failure);
    if (step.norm() > band_mm) step *= band_mm / step.norm();  // a nearly flat patch: no leap past the band
    c += step.head<3>(), r += step[3];
    require(r > 0, [&] { return failure + " (the fitted radius fell to " + std::to_string(r) + " mm)"; });
    if (step.norm() < 1e-6) break;
  }
  redraw();
  std::vector<double> w, xyz;
  SurfaceSphereFit out;
  for_each_point(mesh, T, flip, [&](const SurfacePoint& x) {
    if (const double v = surface_weight(x, c, r, band_mm, facing_cos, towards); v > 0)
      w.push_back(v), xyz.insert(xyz.end(), {x.p.x(), x.p.y(), x.p.z()});
    const Eigen::Vector3d d = x.p - c;
    if (std::abs(d.norm() - r) <= band_mm && -towards * x.normal.dot(d) >= facing_cos * d.norm())
      out.area_in_band_mm2 += x.area;
  });
  require(w.size() >= 4, failure);
  PointMatrix P(static_cast<Eigen::Index>(w.size()), 3);
  for (std::size_t k = 0; k < w.size(); ++k)
    P.row(static_cast<Eigen::Index>(k)) = Eigen::RowVector3d(xyz[3 * k], xyz[3 * k + 1], xyz[3 * k + 2]);
  xyz = {};
  try {
    out.sphere = fit_sphere_geometric(P, w);
  } catch (const Error& e) {
    throw Error(mesh.source + ": " + what + ": " + e.what());
  }
  out.sphere.iterations = steps + 1;
  out.sphere.converged = out.sphere.converged && steps < kSurfaceFitSteps;
  return out;
}

namespace {
PointMatrix gather(const Vertices& V, const std::vector<Eigen::Index>& idx) {
  PointMatrix P(static_cast<Eigen::Index>(idx.size()), 3);
  for (std::size_t i = 0; i < idx.size(); ++i) P.row(static_cast<Eigen::Index>(i)) = V.row(idx[i]);
  return P;
}

/// How many of the n points (x, y, z) lie strictly between squared distances lo2 and hi2 of c (RANSAC's inlier
/// count: 3000 passes over some 10,000 candidates per femur end). Built for AVX-512, AVX2 and the baseline, chosen
/// at run time: the same double arithmetic in wider lanes (no fused multiply-add: the file is built with
/// -ffp-contract=off, anatomy/CMakeLists.txt),
/// so every count is the same.
__attribute__((target_clones("avx512f", "avx2", "default"))) std::size_t count_in_band(
    const double* x, const double* y, const double* z, std::size_t n, double cx, double cy, double cz, double lo2,
    double hi2) {
  std::size_t count = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const double dx = x[k] - cx, dy = y[k] - cy, dz = z[k] - cz;
    const double d2 = dx * dx + dy * dy + dz * dz;
    count += static_cast<std::size_t>((d2 > lo2) & (d2 < hi2));
  }
  return count;
}

/// Sphere through four points, or false if they are (nearly) coplanar.
bool sphere_through(const Eigen::Vector3d p[4], Eigen::Vector3d& c, double& r) {
  Eigen::Matrix3d A;
  Eigen::Vector3d b;
  for (int k = 0; k < 3; ++k) {
    A.row(k) = 2 * (p[k + 1] - p[0]).transpose();
    b[k] = p[k + 1].squaredNorm() - p[0].squaredNorm();
  }
  const double det = A.determinant();
  const double scale = A.row(0).norm() * A.row(1).norm() * A.row(2).norm();
  if (!(std::abs(det) > 1e-9 * scale)) return false;
  c = A.partialPivLu().solve(b);
  r = (p[0] - c).norm();
  return std::isfinite(r);
}

/// RANSAC over the candidate vertices `cand` of V: o.ransac_iterations spheres through four random candidates
/// (seeded by o.seed), those of radius within o's range scored by their candidates within o.inlier_threshold_mm.
/// Returns the best score; best_c, best_r (mm): its sphere (unchanged when none scores).
std::size_t ransac_sphere(const Vertices& V, const std::vector<Eigen::Index>& cand, const HeadFitOptions& o,
                          Eigen::Vector3d& best_c, double& best_r) {
  // The candidates' coordinates side by side, for the inlier counts (3000 passes over them).
  std::vector<double> cx(cand.size()), cy(cand.size()), cz(cand.size());
  for (std::size_t k = 0; k < cand.size(); ++k) cx[k] = V(cand[k], 0), cy[k] = V(cand[k], 1), cz[k] = V(cand[k], 2);
  std::mt19937_64 rng(o.seed);
  std::uniform_int_distribution<std::size_t> pick(0, cand.size() - 1);
  std::size_t best_count = 0;
  for (int it = 0; it < o.ransac_iterations; ++it) {
    Eigen::Vector3d p[4];
    for (auto& q : p) q = V.row(cand[pick(rng)]).transpose();
    Eigen::Vector3d c;
    double r;
    if (!sphere_through(p, c, r) || r < o.min_radius_mm || r > o.max_radius_mm) continue;
    // |d - r| < threshold, as r - threshold < d < r + threshold, squared (no root per candidate).
    const double lo = r - o.inlier_threshold_mm, hi = r + o.inlier_threshold_mm;
    const double lo2 = lo > 0 ? lo * lo : -1.0, hi2 = hi * hi;
    const std::size_t count = count_in_band(cx.data(), cy.data(), cz.data(), cand.size(), c.x(), c.y(), c.z(), lo2, hi2);
    if (count > best_count) {
      best_count = count;
      best_c = c;
      best_r = r;
    }
  }
  return best_count;
}

/// The refinement rounds: o.refinement_rounds geometric refits of the sphere (c, r; mm, in and out) on the candidates
/// within `threshold` mm of it (in and out: tightened each round). Returns the last fit (a default result when there
/// are no rounds); throws `failure` when fewer than 4 candidates are left.
SphereFitResult refine_sphere(const Vertices& V, const std::vector<Eigen::Index>& cand, const HeadFitOptions& o,
                              const std::string& failure, Eigen::Vector3d& c, double& r, double& threshold) {
  SphereFitResult res;
  for (int round = 0; round < o.refinement_rounds; ++round) {
    std::vector<Eigen::Index> in;
    std::vector<double> abs_res;
    for (Eigen::Index i : cand) {
      const double e = std::abs((V.row(i).transpose() - c).norm() - r);
      if (e < threshold) {
        in.push_back(i);
        abs_res.push_back(e);
      }
    }
    require(in.size() >= 4, failure);
    res = fit_sphere_geometric(gather(V, in));
    c = res.centre;
    r = res.radius;
    // Tighten the band to 3 robust sigmas (1.4826 MAD) of the inliers, within
    // [0.2, 1] x the user's threshold: drops the neck and cam points that the first band let in.
    std::nth_element(abs_res.begin(), abs_res.begin() + abs_res.size() / 2, abs_res.end());
    const double sigma = 1.4826 * abs_res[abs_res.size() / 2];
    threshold = std::clamp(3 * sigma, 0.2 * o.inlier_threshold_mm, o.inlier_threshold_mm);
  }
  return res;
}
}  // namespace

SphereFitResult fit_femoral_head(const TriangleMesh& femur, const HeadFitOptions& o) {
  return fit_femoral_head(femur, o, {});
}

SphereFitResult fit_femoral_head(const TriangleMesh& femur, const HeadFitOptions& o,
                                 const std::function<bool(const SphereFitResult&)>& to_fixed_point) {
  const Vertices& V = femur.V;
  require(V.rows() >= 4, femur.source + ": too few vertices for a head fit");
  const double zmax = V.col(2).maxCoeff();
  std::vector<Eigen::Index> cand;
  for (Eigen::Index i = 0; i < V.rows(); ++i)
    if (V(i, 2) >= zmax - o.proximal_extent_mm) cand.push_back(i);
  require(cand.size() >= 4, femur.source + ": too few proximal vertices for a head fit");

  Eigen::Vector3d best_c = Eigen::Vector3d::Zero();
  double best_r = 0;
  const std::size_t best_count = ransac_sphere(V, cand, o, best_c, best_r);
  std::ostringstream msg;
  msg << femur.source << ": no sphere of radius " << o.min_radius_mm << "-" << o.max_radius_mm
      << " mm found on the proximal femur (is +z superior?)";
  require(best_count >= 20, msg.str());

  Eigen::Vector3d c = best_c;
  double r = best_r;
  double threshold = o.inlier_threshold_mm;
  SphereFitResult res = refine_sphere(V, cand, o, msg.str(), c, r, threshold);
  res.iterations = o.refinement_rounds;
  if (to_fixed_point) {
    res.centre = c, res.radius = r;  // as it is after the refinement rounds (the RANSAC sphere without them)
    if (!to_fixed_point(res)) return res;
  }
  // Then to the fixed point at the last band: refit until the inliers no longer change, so that the sphere
  // depends on the surface and not on which RANSAC draw led here (the draws follow the vertex numbering).
  std::vector<Eigen::Index> last;
  for (int round = 0; round < 50; ++round) {
    std::vector<Eigen::Index> in;
    for (Eigen::Index i : cand)
      if (std::abs((V.row(i).transpose() - c).norm() - r) < threshold) in.push_back(i);
    if (in == last || in.size() < 4) break;
    res = fit_sphere_geometric(gather(V, in));
    c = res.centre;
    r = res.radius;
    last = std::move(in);
  }
  // Then the sphere of the surface (fit_sphere_to_surface) from there, with Tukey's biweight at 4.685 sigma of the
  // last band (3 sigma): the vertices' fixed point moves when a file splits its triangles (0.012-0.05 mm on the
  // shared MRI heads split in four, and their ROM limits by up to 0.69 deg); the surface's does not.
  if (!o.surface_stage) {
    res.iterations = o.refinement_rounds;
    return res;
  }
  const std::int64_t inliers = last.empty() ? res.points_used : static_cast<std::int64_t>(last.size());
  res = fit_sphere_to_surface(femur, c, r, threshold * 4.685 / 3, kHeadFacing, SurfaceSide::convex, "femoral head").sphere;
  res.points_used = inliers;
  res.iterations = o.refinement_rounds;
  return res;
}

SphereFitResult fit_sphere_in_region(const TriangleMesh& femur, const Eigen::Vector3d& region_centre,
                                     double region_radius_mm) {
  std::vector<Eigen::Index> in;
  for (Eigen::Index i = 0; i < femur.V.rows(); ++i)
    if ((femur.V.row(i).transpose() - region_centre).norm() <= region_radius_mm) in.push_back(i);
  require(in.size() >= 4, femur.source + ": fewer than 4 vertices in the head selection region");
  return fit_sphere_geometric(gather(femur.V, in));
}

}  // namespace impinge
