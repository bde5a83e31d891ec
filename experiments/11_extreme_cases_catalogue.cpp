// 11_extreme_cases, the catalogue (cases 2 to 6); see 11_extreme_cases_catalogue.hpp.
//
// Cases 2-4 share one oracle. Every mesh is a closed sphere of radius R about the COR (a UV sphere,
// its vertices on the sphere), changed in one way that must not change the surface: rotated so that a
// vertex, an edge or a face sits on the pole or an edge on the seam; faces split into slivers of
// aspect ratio 1e6; faces duplicated and duplicated with reversed winding; non-manifold fins outside;
// a second, turned tessellation of the same sphere (self-intersecting); scaled; moved far from the
// origin; read through float coordinates; tessellated with a million triangles; sampled at 0.01 deg.
// Whatever the scheme and the mode, every node value lies on the mesh (exact mode) or is an
// interpolation of vertex distances (linear mode), so it lies in [R - s, R], s the largest distance
// between the mesh and its circumscribed sphere (the sagitta: R minus the mesh's distance to the COR,
// CGAL closest point); a look-up is a convex combination of node values, and the exact first hit
// (CGAL) lies in [R - s, R] too. Claimed: no look-up without a surface (no hole), and
// |look-up - exact hit| <= s + rounding (16 eps of the storage type times R, 16 double eps times the
// coordinates' magnitude). Probed at uniform random directions and at directions crowded within
// 2 deg of both poles and 1 deg of the seam.
#include "11_extreme_cases_catalogue.hpp"

#include <gsl/gsl_errno.h>
#include <gsl/gsl_integration.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <chrono>
#include <cmath>
#include <iostream>
#include <limits>
#include <map>
#include <random>
#include <sstream>

#include "impinge/anatomy/sphere_fit.hpp"
#include "impinge/casters/exact_reference.hpp"
#include "impinge/detection/joint.hpp"
#include "impinge/io/generated_models.hpp"
#include "impinge/sampling/sampling.hpp"
#include "impinge/schemes/conchoid.hpp"
#include "impinge/schemes/helix_arc_length.hpp"
#include "impinge/schemes/helix_scheme.hpp"

namespace impinge::experiment {

namespace {

using Schemes = std::vector<std::pair<std::string, double>>;

std::string fmt(double v) {
  std::ostringstream os;
  os.precision(3);
  os << v;
  return os.str();
}

// Probe directions: uniform, then within 2 deg of each pole, then within 1 deg of the seam
// (theta = 0, both sides).
std::vector<Eigen::Vector3d> probe_directions(int n, std::mt19937_64& rng) {
  std::normal_distribution<double> g(0, 1);
  std::uniform_real_distribution<double> u01(0, 1);
  std::vector<Eigen::Vector3d> out;
  for (int i = 0; i < n; ++i) out.push_back(Eigen::Vector3d(g(rng), g(rng), g(rng)).normalized());
  const double d2r = M_PI / 180;
  for (int pole = 0; pole < 2; ++pole)
    for (int i = 0; i < n / 10; ++i) {
      const double phi = 2 * d2r * std::sqrt(u01(rng)), th = 2 * M_PI * u01(rng);
      const double z = std::cos(phi) * (pole ? -1 : 1);
      out.emplace_back(std::sin(phi) * std::cos(th), std::sin(phi) * std::sin(th), z);
    }
  for (int i = 0; i < n / 10; ++i) {
    const double phi = M_PI * u01(rng), th = d2r * (2 * u01(rng) - 1);
    out.emplace_back(std::sin(phi) * std::cos(th), std::sin(phi) * std::sin(th), std::cos(phi));
  }
  return out;
}

TriangleMesh transformed(TriangleMesh m, const Eigen::Matrix3d& R, const Eigen::Vector3d& centre) {
  for (Eigen::Index i = 0; i < m.V.rows(); ++i)
    m.V.row(i) = (R * (m.V.row(i).transpose() - centre) + centre).transpose();
  return m;
}

Eigen::Vector3d vertex(const TriangleMesh& m, Eigen::Index f, int k) { return m.V.row(m.F(f, k)).transpose(); }

// Slivers without T-junctions: the first edge of every 5th face is split at 1e-6 of its length,
// and so is the same edge of the face on its other side, each face into a sliver of aspect ratio
// about 1e6 and a normal triangle. The same surface, still closed.
TriangleMesh with_slivers(const TriangleMesh& m) {
  std::vector<Eigen::Vector3d> V;
  for (Eigen::Index i = 0; i < m.V.rows(); ++i) V.push_back(m.V.row(i).transpose());
  std::map<std::pair<int, int>, Eigen::Index> face_of;  // directed edge -> its face
  for (Eigen::Index f = 0; f < m.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) face_of[{m.F(f, k), m.F(f, (k + 1) % 3)}] = f;
  std::vector<bool> touched(std::size_t(m.F.rows()), false);  // at most one split edge per face
  std::map<std::pair<int, int>, int> split;  // directed edge (a, b) -> index of its split point
  for (Eigen::Index f = 0; f < m.F.rows(); f += 5) {
    const int a = m.F(f, 0), b = m.F(f, 1);
    const auto other = face_of.find({b, a});
    if (other == face_of.end() || touched[std::size_t(f)] || touched[std::size_t(other->second)]) continue;
    touched[std::size_t(f)] = touched[std::size_t(other->second)] = true;
    V.push_back(V[std::size_t(a)] + 1e-6 * (V[std::size_t(b)] - V[std::size_t(a)]));
    split[{a, b}] = split[{b, a}] = int(V.size()) - 1;
  }
  std::vector<Eigen::Vector3i> F;
  for (Eigen::Index f = 0; f < m.F.rows(); ++f) {
    const Eigen::Vector3i t = m.F.row(f).transpose();
    bool done = false;
    for (int k = 0; k < 3 && !done; ++k) {
      const auto it = split.find({t[k], t[(k + 1) % 3]});
      if (it == split.end()) continue;
      F.emplace_back(t[k], it->second, t[(k + 2) % 3]);
      F.emplace_back(it->second, t[(k + 1) % 3], t[(k + 2) % 3]);
      done = true;
    }
    if (!done) F.push_back(t);
  }
  TriangleMesh r;
  r.V.resize(Eigen::Index(V.size()), 3);
  for (std::size_t i = 0; i < V.size(); ++i) r.V.row(Eigen::Index(i)) = V[i].transpose();
  r.F.resize(Eigen::Index(F.size()), 3);
  for (std::size_t i = 0; i < F.size(); ++i) r.F.row(Eigen::Index(i)) = F[i].transpose();
  return r;
}

// Copies of every 7th face and reversed copies of every 11th: the same surface, not a valid closed
// mesh any more (face culling must notice and turn itself off).
TriangleMesh with_duplicates(const TriangleMesh& m) {
  std::vector<Eigen::Vector3i> F;
  for (Eigen::Index f = 0; f < m.F.rows(); ++f) {
    const Eigen::Vector3i t = m.F.row(f).transpose();
    F.push_back(t);
    if (f % 7 == 0) F.push_back(t);
    if (f % 11 == 0) F.emplace_back(t[0], t[2], t[1]);
  }
  TriangleMesh r;
  r.V = m.V;
  r.F.resize(Eigen::Index(F.size()), 3);
  for (std::size_t i = 0; i < F.size(); ++i) r.F.row(Eigen::Index(i)) = F[i].transpose();
  return r;
}

// A non-manifold mesh: every 9th edge of the sphere gets a third face, a fin pointing outwards (its
// far corner 5 mm beyond the edge's midpoint). Rays from the COR meet the sphere first: the same
// first surface.
TriangleMesh with_fins(const TriangleMesh& m, const Eigen::Vector3d& centre) {
  TriangleMesh r = m;
  std::vector<Eigen::Vector3i> extra;
  Vertices V = m.V;
  for (Eigen::Index f = 0; f < m.F.rows(); f += 9) {
    const Eigen::Vector3d a = vertex(m, f, 0), b = vertex(m, f, 1), mid = (a + b) / 2;
    const Eigen::Vector3d tip = mid + 5 * (mid - centre).normalized();
    V.conservativeResize(V.rows() + 1, 3);
    V.row(V.rows() - 1) = tip.transpose();
    extra.emplace_back(m.F(f, 0), m.F(f, 1), int(V.rows() - 1));
  }
  r.V = V;
  r.F.conservativeResize(m.F.rows() + Eigen::Index(extra.size()), 3);
  for (std::size_t i = 0; i < extra.size(); ++i) r.F.row(m.F.rows() + Eigen::Index(i)) = extra[i].transpose();
  return r;
}

// A self-intersecting mesh: two tessellations of one sphere, the second turned by 2.5 deg about an
// oblique axis, in one mesh; their facets cross everywhere. Every facet of either lies in [R - s, R].
TriangleMesh with_second_tessellation(const TriangleMesh& m, const Eigen::Vector3d& centre) {
  const Eigen::Matrix3d R = Eigen::AngleAxisd(2.5 * M_PI / 180, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const TriangleMesh t = transformed(m, R, centre);
  TriangleMesh r;
  r.V.resize(2 * m.V.rows(), 3);
  r.V << m.V, t.V;
  r.F.resize(2 * m.F.rows(), 3);
  r.F << m.F, (t.F.array() + int(m.V.rows())).matrix();
  return r;
}

template <typename Scalar>
void sample_lookups(const TriangleMesh& mesh, const Eigen::Vector3d& cor, const std::string& scheme, double res,
                    DistanceMode mode, const std::vector<double>& pts, std::vector<double>& out) {
  RadialDistanceMapT<Scalar> map{make_scheme(scheme, res)};
  SamplingOptions so;
  so.mode = mode;
  sample_surface(mesh, cor, so, map);
  out.assign(pts.size() / 3, 0);
  map.lookup_many(pts.data(), std::int64_t(out.size()), out.data());
}

struct SphereCase {
  std::string variant;
  TriangleMesh mesh;
  Eigen::Vector3d cor;
  Schemes schemes;
  std::string note;
  std::vector<DistanceMode> modes{DistanceMode::exact, DistanceMode::linear};
  double first_surface_radius = 0;  ///< R of the sphere the rays meet first; 0: the farthest vertex
};

void run_sphere_case(CsvWriter& csv, const std::string& case_name, const SphereCase& c, int probes,
                    std::mt19937_64& rng) {
  const ExactReference ref(c.mesh);
  const double inner = ref.closest_distance(c.cor);
  double outer = 0, magnitude = c.cor.cwiseAbs().maxCoeff();
  for (Eigen::Index i = 0; i < c.mesh.V.rows(); ++i) {
    outer = std::max(outer, (c.mesh.V.row(i).transpose() - c.cor).norm());
    magnitude = std::max(magnitude, c.mesh.V.row(i).cwiseAbs().maxCoeff());
  }
  if (c.first_surface_radius > 0) outer = c.first_surface_radius;
  const double sagitta = outer - inner;
  const std::vector<Eigen::Vector3d> dirs = probe_directions(probes, rng);
  std::vector<double> pts, exact;
  for (const Eigen::Vector3d& u : dirs) {
    const auto h = ref.first_hit(c.cor, u);
    if (!h) continue;  // cannot happen on a closed sphere about the COR; counted by `compared`
    exact.push_back(*h);
    pts.insert(pts.end(), {u.x(), u.y(), u.z()});
  }
  for (const auto& [scheme, res] : c.schemes)
    for (DistanceMode mode : c.modes)
      for (int storage = 0; storage < 2; ++storage) {
        std::vector<double> got;
        if (storage == 0)
          sample_lookups<float>(c.mesh, c.cor, scheme, res, mode, pts, got);
        else
          sample_lookups<double>(c.mesh, c.cor, scheme, res, mode, pts, got);
        std::int64_t holes = 0;
        double worst = 0;
        for (std::size_t i = 0; i < got.size(); ++i) {
          if (!std::isfinite(got[i])) {
            ++holes;
            continue;
          }
          worst = std::max(worst, std::abs(got[i] - exact[i]));
        }
        const double eps = storage == 0 ? std::numeric_limits<float>::epsilon() : std::numeric_limits<double>::epsilon();
        const double bound = sagitta + 16 * eps * outer + 16 * std::numeric_limits<double>::epsilon() * magnitude;
        csv.row(case_name, c.variant, scheme, res, to_string(mode), storage == 0 ? "float" : "double", c.mesh.F.rows(),
                got.size(), holes, worst, bound, "mm", int(holes == 0 && worst <= bound),
                c.note.empty() ? "sagitta " + fmt(sagitta) + " mm" : c.note + "; sagitta " + fmt(sagitta) + " mm");
      }
}

// Case 5: touching (gap 1e-6 and 0 mm) and deeply penetrating (10 mm) bones: a ball sphere of
// radius R and a socket sphere of radius R + g with the same tessellation about the COR, so the exact
// radial gap of every vertex is g (its ray meets the other mesh at a vertex). Claimed: every gap
// within max(s_ball, s_socket) + float rounding of g (the maps are float in a Joint).
void run_touching(CsvWriter& csv, const Schemes& schemes) {
  const double R = 22;
  for (double g : {1e-6, 0.0, -10.0}) {
    const TriangleMesh ball = make_uv_sphere(R, Eigen::Vector3d::Zero(), 72, 36);
    const TriangleMesh socket = make_uv_sphere(R + g, Eigen::Vector3d::Zero(), 72, 36);
    const double s_ball = R - ExactReference(ball).closest_distance(Eigen::Vector3d::Zero());
    const double s_socket = (R + g) - ExactReference(socket).closest_distance(Eigen::Vector3d::Zero());
    const std::string variant = g > 0 ? "gap 1e-6 mm" : (g == 0 ? "touching, gap 0" : "penetration 10 mm");
    for (const auto& [scheme, res] : schemes)
      for (DistanceMode mode : {DistanceMode::exact, DistanceMode::linear}) {
        JointOptions o;
        o.scheme = make_scheme(scheme, res);
        o.mode = mode;
        const Joint j(ball, socket, Eigen::Vector3d::Zero(), o);
        const PoseResult r = j.detect(Eigen::Matrix3d::Identity());
        double worst = 0, min_gap = std::numeric_limits<double>::infinity();
        std::int64_t compared = 0, holes = 0, wrong_sign = 0;
        for (const ScanGaps* sg : {&r.ball_gaps, &r.socket_gaps})
          for (std::size_t i = 0; i < sg->gap_mm.size(); ++i) {
            if (sg->status[i] == ScanGaps::beyond_reach) continue;
            const double v = sg->gap_mm[i];
            ++compared;
            if (!std::isfinite(v)) {
              ++holes;
              continue;
            }
            worst = std::max(worst, std::abs(v - g));
            min_gap = std::min(min_gap, v);
            wrong_sign += (g > 0 && v <= 0) || (g < 0 && v >= 0);
          }
        const double bound = std::max(s_ball, s_socket) + 16 * std::numeric_limits<float>::epsilon() * (R + std::abs(g));
        std::ostringstream note;
        note << "min gap " << fmt(min_gap) << " mm (exact " << fmt(g) << "); " << wrong_sign
             << " gaps of the wrong sign";
        csv.row("5 touching and penetrating bones", variant, scheme, res, to_string(mode), "float", ball.F.rows(),
                compared, holes, worst, bound, "mm", int(holes == 0 && worst <= bound), note.str());
      }
  }
}

// Case 8: the COR near the ball's surface: 1 mm inside a ball sphere (R = 22 mm, socket sphere
// R + 2 about the same centre), 0.01 mm below one of its faces, on that face, at a vertex. Inside, every direction must meet
// the ball (no hole) and every tested gap must be within 0.05 mm of the exact radial gap (CGAL on
// both meshes from the COR), at 0.1 deg; on the surface about half the directions meet no ball, which
// HipJoint refuses (more than 1e-4 of the nodes uncovered): the row passes when the map shows it.
void run_cor_cases(CsvWriter& csv, const Schemes& schemes) {
  const double R = 22;
  const Eigen::Vector3d c = Eigen::Vector3d::Zero();
  const TriangleMesh ball = make_uv_sphere(R, c, 72, 36), socket = make_uv_sphere(R + 2, c, 72, 36);
  const Eigen::Index f = ball.F.rows() / 3;
  const Eigen::Vector3d face = (vertex(ball, f, 0) + vertex(ball, f, 1) + vertex(ball, f, 2)) / 3;
  const Eigen::Vector3d face_normal =
      (vertex(ball, f, 1) - vertex(ball, f, 0)).cross(vertex(ball, f, 2) - vertex(ball, f, 0)).normalized() *
      ((vertex(ball, f, 1) - vertex(ball, f, 0)).cross(vertex(ball, f, 2) - vertex(ball, f, 0)).dot(face - c) > 0 ? 1.0
                                                                                                             : -1.0);
  const Eigen::Vector3d top = ball.V.row(0).transpose();  // a vertex of the sphere (make_uv_sphere's pole)
  const Eigen::Vector3d in_dir = Eigen::Vector3d(0.3, -0.5, 0.8).normalized();
  const std::vector<std::pair<std::string, Eigen::Vector3d>> cors{
      {"1 mm inside the ball", c + (R - 1) * in_dir},
      {"0.01 mm inside the ball mesh (below a face)", face - 0.01 * face_normal},
      {"on a face of the ball", face},
      {"at a vertex of the ball", top}};
  const ExactReference eb(ball), es(socket);  // about any origin: built once for every COR
  for (const auto& [variant, cor] : cors) {
    const bool inside = variant.find("inside") != std::string::npos;
    for (const auto& [scheme, res] : schemes) {
      JointOptions o;
      o.scheme = make_scheme(scheme, res);
      const Joint j(ball, socket, cor, o);
      const double uncovered = 1.0 - double(j.ball().map.nodes_covered()) / double(j.ball().map.num_nodes());
      if (!inside) {
        csv.row("8 COR near the ball's surface", variant, scheme, res, "exact", "float", ball.F.rows(),
                j.ball().map.num_nodes(), 0, uncovered, 1e-4, "fraction uncovered", int(uncovered > 1e-4),
                "HipJoint refuses a COR with more than 1e-4 of the directions uncovered");
        continue;
      }
      const PoseResult r = j.detect(Eigen::Matrix3d::Identity());
      double worst = 0;
      std::int64_t compared = 0, holes = 0;
      for (int b = 0; b < 2; ++b) {
        const JointBody& body = b == 0 ? j.ball() : j.socket();
        const ScanGaps& g = b == 0 ? r.ball_gaps : r.socket_gaps;
        for (std::size_t i = 0; i < g.gap_mm.size(); ++i) {
          if (g.status[i] == ScanGaps::beyond_reach) continue;
          const Eigen::Vector3d q = body.relative.row(Eigen::Index(i)).transpose();
          const auto h = (b == 0 ? es : eb).first_hit(cor, q.normalized());
          if (!h) continue;
          ++compared;
          if (!std::isfinite(g.gap_mm[i])) {
            ++holes;
            continue;
          }
          worst = std::max(worst, std::abs(g.gap_mm[i] - (b == 0 ? *h - q.norm() : q.norm() - *h)));
        }
      }
      std::ostringstream note;
      note << "fraction of directions without ball surface " << fmt(uncovered);
      csv.row("8 COR near the ball's surface", variant, scheme, res, "exact", "float", ball.F.rows(), compared, holes,
              worst, 0.05, "mm", int(holes == 0 && worst <= 0.05 && uncovered <= 1e-4), note.str());
    }
  }
}

// Case 6a: the geometric sphere fit on caps of 5 to 45 deg: the RMS centre error over trials against
// its first-order prediction sigma * sqrt(trace of the centre block of (J^T J)^-1), J the Jacobian of
// the residuals |p - c| - r at the true sphere; claimed within 1.5 times the prediction (plus 1e-9 R
// for the noise-free fit), and cond(J^T J) reported.
void run_sphere_fits(CsvWriter& csv, bool quick) {
  const double R = 22;
  const int n = 2000, trials = quick ? 10 : 50;
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u01(0, 1);
  std::normal_distribution<double> gauss(0, 1);
  for (double cap : {5.0, 10.0, 20.0, 45.0})
    for (double sigma : {0.0, 0.1}) {
      double sum2 = 0, cond = 0, predicted = 0;
      for (int t = 0; t < trials; ++t) {
        Vertices P(n, 3);
        Eigen::Matrix4d JtJ = Eigen::Matrix4d::Zero();
        const double cmin = std::cos(cap * M_PI / 180);
        for (int i = 0; i < n; ++i) {
          const double z = cmin + (1 - cmin) * u01(rng), th = 2 * M_PI * u01(rng), s = std::sqrt(1 - z * z);
          const Eigen::Vector3d u(s * std::cos(th), s * std::sin(th), z);
          P.row(i) = ((R + sigma * gauss(rng)) * u).transpose();
          Eigen::Vector4d J;
          J << -u, -1;
          JtJ += J * J.transpose();
        }
        const SphereFitResult f = fit_sphere_geometric(P);
        sum2 += f.centre.squaredNorm();
        const Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d> es(JtJ);
        cond = es.eigenvalues().maxCoeff() / es.eigenvalues().minCoeff();
        predicted = sigma * std::sqrt(JtJ.inverse().topLeftCorner<3, 3>().trace());
      }
      const double rms = std::sqrt(sum2 / trials);
      const double bound = 1.5 * predicted + 1e-9 * R;
      std::ostringstream variant, note;
      variant << "cap " << cap << " deg, noise " << sigma << " mm";
      note << "cond(J^T J) " << fmt(cond) << ", predicted RMS " << fmt(predicted) << " mm over " << trials
           << " trials";
      csv.row("6 stiff numerics: sphere fit", variant.str(), "-", n, "geometric", "double", 0, trials, 0, rms, bound,
              "mm", int(rms <= bound), note.str());
    }
}

// Case 6b: the helix arc length s(phi) (Carlson form and the tabulated fast form) against GSL's
// adaptive Gauss-Kronrod quadrature of sqrt(1 + 4 k^2 sin^2 t), for k = 2 .. 1e5, at 1000 uniform
// angles and at 1e-1 .. 1e-8 rad from both poles (kappa -> 1), in node spacings (total / (k^2 - 1)).
// Claimed: within 1e-7 node spacings plus the rounding of s itself (64 double eps * total / spacing).
double helix_integrand(double t, void* k) {
  const double kk = *static_cast<double*>(k), s = std::sin(t);
  return std::sqrt(1 + 4 * kk * kk * s * s);
}

double quadrature(double k, double phi, gsl_integration_workspace* ws) {
  gsl_function f{&helix_integrand, &k};
  double result = 0, err = 0;
  // Pieces of at most 0.05 rad, so that every piece is smooth on its own scale.
  const int pieces = std::max(1, int(std::ceil(phi / 0.05)));
  for (int i = 0; i < pieces; ++i) {
    double r = 0;
    gsl_integration_qag(&f, phi * i / pieces, phi * (i + 1) / pieces, 0, 1e-13, 1000, GSL_INTEG_GAUSS61, ws, &r, &err);
    result += r;
  }
  return result;
}

void run_helix_arc(CsvWriter& csv, bool quick) {
  gsl_set_error_handler_off();
  gsl_integration_workspace* ws = gsl_integration_workspace_alloc(1000);
  for (double k : {2.0, 10.0, 229.0, 4584.0, 1e5}) {
    const HelixArcLength arc(k);
    std::vector<double> phis;
    const int m = quick ? 100 : 1000;
    for (int i = 1; i < m; ++i) phis.push_back(M_PI * i / m);
    for (int e = 1; e <= 8; ++e) phis.insert(phis.end(), {std::pow(10.0, -e), M_PI - std::pow(10.0, -e)});
    const double spacing = arc.total() / (k * k - 1);
    double worst_exact = 0, worst_fast = 0;
    for (double phi : phis) {
      const double q = quadrature(k, phi, ws);
      worst_exact = std::max(worst_exact, std::abs(arc.exact(phi) - q) / spacing);
      worst_fast = std::max(worst_fast, std::abs(arc(phi) - q) / spacing);
    }
    const double bound = 1e-7 + 64 * std::numeric_limits<double>::epsilon() * arc.total() / spacing;
    std::ostringstream variant;
    variant << "k = " << k;
    for (int form = 0; form < 2; ++form) {
      const double w = form == 0 ? worst_exact : worst_fast;
      csv.row("6 stiff numerics: helix arc length", variant.str(), "helix", k, form == 0 ? "Carlson" : "tabulated",
              "double", 0, phis.size(), 0, w, bound, "node spacings", int(w <= bound),
              "against GSL QAG (Gauss-Kronrod 61) in pieces of 0.05 rad; angles to 1e-8 rad from the poles");
    }
  }
  gsl_integration_workspace_free(ws);
}

// Case 6c: the conchoid's inversion phi(s) at its end points: on a circle (b = 0, s = a phi exactly)
// against the closed form, and on Menschik's conchoid by the forward length (|L(phi(s)) - s| / r,
// an angle). Claimed: within 1e-12 rad.
void run_conchoid_inversion(CsvWriter& csv) {
  for (int which = 0; which < 2; ++which) {
    const Conchoid c = which == 0 ? Conchoid(20.0, 0.0) : Conchoid(kMenschikA, kMenschikB);
    const double phi_max = M_PI / 2, L = c.arc_length(phi_max);
    std::vector<double> fractions{0, 1e-15, 1e-12, 1e-9, 1e-6, 1e-3, 0.5};
    for (double f : std::vector<double>(fractions)) fractions.push_back(1 - f);
    double worst = 0;
    for (double f : fractions) {
      const double s = f * L, phi = c.angle_at_length(s, phi_max);
      const double err = which == 0 ? std::abs(phi - s / c.a()) : std::abs(c.arc_length(phi) - s) / c.radius(phi);
      worst = std::max(worst, err);
    }
    csv.row("6 stiff numerics: conchoid inversion", which == 0 ? "circle (b = 0), closed form" : "Menschik's conchoid",
            "conchoid", 0, "Brent", "double", 0, fractions.size(), 0, worst, 1e-12, "rad", int(worst <= 1e-12),
            "s at 0, 1e-15 .. 1e-3, 0.5 of the length and as near its end");
  }
}

}  // namespace

int run_extreme_case_catalogue(const Args& args, const std::string& dir) {
  CsvWriter csv(dir + "/cases.csv", {"case", "variant", "scheme", "resolution", "mode", "storage", "triangles",
                                     "compared", "holes", "max_abs", "bound", "unit", "pass", "note"});
  std::mt19937_64 rng(2026);
  const double p = 0.5;
  const Schemes all{{"equiangular", p}, {"helix", matched_helix_turns(p)}, {"helix-eq10", matched_helix_turns(p)},
                    {"conchoid", p}};
  const int probes = args.quick ? 5000 : 20000;
  const Eigen::Vector3d O = Eigen::Vector3d::Zero();
  const double R = 22;
  const TriangleMesh base = make_uv_sphere(R, O, 72, 36);
  const Eigen::Index k = base.F.rows() / 2 + 3;  // a face away from the poles
  const Eigen::Vector3d a = vertex(base, k, 0), b = vertex(base, k, 1), c3 = vertex(base, k, 2);
  auto onto_pole = [](const Eigen::Vector3d& d) {
    return Eigen::Quaterniond::FromTwoVectors(d, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  };
  Eigen::Matrix3d seam;  // edge ab into the half-plane theta = 0
  {
    const Eigen::Vector3d e1 = (a + b).normalized(), n = a.cross(b).normalized();
    seam.row(0) = e1.transpose();
    seam.row(1) = n.transpose();
    seam.row(2) = e1.cross(n).transpose();
  }
  std::vector<SphereCase> geometry{
      {"vertex on the pole", base, O, all, ""},
      {"edge on the pole", transformed(base, onto_pole(a + b), O), O, all, ""},
      {"face on the pole", transformed(base, onto_pole(a + b + c3), O), O, all, ""},
      {"edge on the seam", transformed(base, seam, O), O, all, ""},
      {"slivers (aspect 1e6)", with_slivers(base), O, all, ""},
      {"duplicate and inverted faces", with_duplicates(base), O, all, ""},
      {"non-manifold edges (outward fins)", with_fins(base, O), O, all, "", {DistanceMode::exact, DistanceMode::linear}, R},
      {"self-intersecting (two tessellations)", with_second_tessellation(base, O), O, all, ""}};
  int steps = 0;
  for (const SphereCase& c : geometry) {
    progress("11_extreme_cases catalogue", ++steps, 17, "2 triangles: " + c.variant);
    run_sphere_case(csv, "2 triangles: poles, seam, slivers, duplicates, non-manifold, self-intersecting", c, probes, rng);
  }
  // Case 3: scales and placement.
  const Eigen::Vector3d far(1e5, -1e5, 1e5);
  TriangleMesh far_float = make_uv_sphere(R, far, 72, 36);
  double quantum = 0;
  for (Eigen::Index i = 0; i < far_float.V.rows(); ++i)
    for (int d = 0; d < 3; ++d) {
      const double v = far_float.V(i, d), f = double(float(v));
      quantum = std::max(quantum, std::abs(f - v));
      far_float.V(i, d) = f;
    }
  std::vector<SphereCase> placement{
      {"radius 0.022 mm (scale 1e-3)", make_uv_sphere(R * 1e-3, O, 72, 36), O, all, ""},
      {"radius 2.2e6 mm (scale 1e5)", make_uv_sphere(R * 1e5, O, 72, 36), O, all, ""},
      {"1e5 mm from the origin, double input", make_uv_sphere(R, far, 72, 36), far, all, ""},
      {"1e5 mm from the origin, float input", far_float, far, all,
       "float coordinates moved the vertices by up to " + fmt(quantum) + " mm; the oracle is the float mesh"}};
  for (const SphereCase& c : placement) {
    progress("11_extreme_cases catalogue", ++steps, 17, "3 scale: " + c.variant);
    run_sphere_case(csv, "3 scales and placement", c, probes, rng);
  }
  // Case 4: size of the problem: a million triangles at 0.1 deg; precision 0.01 deg (0.05 quick).
  {
    const double pf = 0.1;
    const Schemes fine{{"equiangular", pf}, {"helix", matched_helix_turns(pf)}, {"conchoid", pf}};
    // Quick mode: a quarter of a million (the full run's million takes most of this case's time).
    const int nt = args.quick ? 502 : 1002, np = args.quick ? 250 : 500;
    SphereCase million{args.quick ? "250k triangles, 0.1 deg" : "a million triangles, 0.1 deg",
                       make_uv_sphere(R, O, nt, np), O, fine, ""};
    progress("11_extreme_cases catalogue", ++steps, 17, "4 size: a million triangles");
    run_sphere_case(csv, "4 problem size", million, probes, rng);
    const double pmin = args.quick ? 0.05 : 0.01;
    SphereCase finest{"precision " + fmt(pmin) + " deg", base, O, {{"equiangular", pmin}}, ""};
    progress("11_extreme_cases catalogue", ++steps, 17, "4 size: precision " + fmt(pmin));
    run_sphere_case(csv, "4 problem size", finest, probes, rng);
  }
  progress("11_extreme_cases catalogue", ++steps, 17, "5 touching and penetrating bones");
  run_touching(csv, {{"equiangular", 0.1}, {"helix", matched_helix_turns(0.1)}, {"conchoid", 0.1}});
  progress("11_extreme_cases catalogue", ++steps, 17, "8 COR near the ball's surface");
  run_cor_cases(csv, {{"equiangular", 0.1}, {"helix", matched_helix_turns(0.1)}, {"conchoid", 0.1}});
  progress("11_extreme_cases catalogue", ++steps, 17, "6 stiff numerics");
  run_sphere_fits(csv, args.quick);
  run_helix_arc(csv, args.quick);
  run_conchoid_inversion(csv);
  return steps;
}

}  // namespace impinge::experiment
