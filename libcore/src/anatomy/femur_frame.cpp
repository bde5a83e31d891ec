#include "impinge/anatomy/femur_frame.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <sstream>
#include <vector>

#include "impinge/core/concurrent.hpp"
#include "impinge/core/error.hpp"

namespace impinge {

Landmarks FemurLandmarks::as_map() const {
  return {{"head_centre", head_centre},
          {"epicondyle_lateral", epicondyle_lateral},
          {"epicondyle_medial", epicondyle_medial},
          {"posterior_condyle_lateral", posterior_condyle_lateral},
          {"posterior_condyle_medial", posterior_condyle_medial}};
}

Eigen::Vector3d femur_long_axis(PointsRef V, const Eigen::Vector3d& proximal_hint) {
  require(V.rows() >= 4, "femur long axis: too few vertices");
  const Eigen::RowVector3d c = V.colwise().mean();
  const Eigen::MatrixXd D = V.rowwise() - c;
  const Eigen::Matrix3d C = D.transpose() * D / static_cast<double>(V.rows());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(C);
  Eigen::Vector3d L = es.eigenvectors().col(2);  // largest eigenvalue
  if (proximal_hint.allFinite() && L.dot(proximal_hint - c.transpose()) < 0) L = -L;
  return L;
}

Eigen::Vector3d principal_extents(PointsRef V) {
  if (V.rows() < 4) return Eigen::Vector3d::Zero();
  const Eigen::RowVector3d c = V.colwise().mean();
  const Eigen::MatrixXd D = V.rowwise() - c;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(D.transpose() * D);
  const Eigen::MatrixXd t = D * es.eigenvectors();  // columns: along the axes, smallest variance first
  const Eigen::Vector3d e = (t.colwise().maxCoeff() - t.colwise().minCoeff()).transpose();
  return Eigen::Vector3d(e[2], e[1], e[0]);
}

namespace {

// Distance (mm) from p to the nearest vertex of `mesh`.
double nearest_vertex_distance(const TriangleMesh& mesh, const Eigen::Vector3d& p) {
  return std::sqrt((mesh.V.rowwise() - p.transpose()).rowwise().squaredNorm().minCoeff());
}

// An end whose sphere after the refinement rounds lies this much farther from the pelvis than
// kHeadInAcetabulumMm is not refined to its fixed point (see head_candidates).
constexpr double kFixedPointMarginMm = 20.0;

// The sphere of each end of the femur's long axis (fit_femoral_head with that end up); an end
// without a plausible sphere has an empty result and its error in `errors`. With a pelvis (valid, the
// femur's frame), an end far from its acetabulum stops after the refinement rounds (may_sit below).
std::array<std::optional<SphereFitResult>, 2> head_candidates(const TriangleMesh& femur, const HeadFitOptions& options,
                                                              std::string& errors, const TriangleMesh* pelvis) {
  validate_mesh(femur);
  const Eigen::Vector3d L = femur_long_axis(femur.V, Eigen::Vector3d::Constant(std::nan("")));
  std::array<std::optional<SphereFitResult>, 2> out;
  std::array<std::string, 2> error;  // each end's, joined in order below
  // The two ends are independent fits (each with its own seeded RANSAC): one thread each. A fit's own
  // error (impinge::Error) is kept for the message below; any other failure is rethrown by run_both.
  const auto fit_end = [&](int k) {
    const double s = k == 0 ? 1.0 : -1.0;
    // Rotate so that s L becomes +z, fit there, rotate the centre back.
    const Eigen::Matrix3d Q = Eigen::Quaterniond::FromTwoVectors(s * L, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    TriangleMesh m;
    m.V = femur.V * Q.transpose();
    m.F = femur.F;
    m.source = femur.source;
    try {
      // Beside a pelvis, an end's sphere matters only if it may sit in the acetabulum: an end whose refined
      // sphere lies more than kFixedPointMarginMm beyond that is not the head, and is not refined to its fixed
      // point (the refits that move the shared hips' spheres by at most 0.3 mm, and lhdl-ct's subdivided 4x by
      // 1.4 mm, and take a distal end 11 to 50 rounds). The head's own sphere is refined as before.
      const auto may_sit = [&](const SphereFitResult& refined) {
        const double gap = nearest_vertex_distance(*pelvis, Q.transpose() * refined.centre) - refined.radius;
        return std::abs(gap) <= kHeadInAcetabulumMm + kFixedPointMarginMm;
      };
      SphereFitResult r = pelvis != nullptr ? fit_femoral_head(m, options, may_sit) : fit_femoral_head(m, options);
      r.centre = Q.transpose() * r.centre;
      out[static_cast<std::size_t>(k)] = r;
    } catch (const Error& e) {
      error[static_cast<std::size_t>(k)] = e.what();
    }
  };
  run_both([&] { fit_end(0); }, [&] { fit_end(1); });
  for (const std::string& e : error)
    if (!e.empty()) errors += std::string(errors.empty() ? "" : "; ") + e;
  return out;
}

}  // namespace

SphereFitResult locate_femoral_head(const TriangleMesh& femur, const HeadFitOptions& options) {
  std::string errors;
  const auto c = head_candidates(femur, options, errors, nullptr);
  require(c[0] || c[1], femur.source + ": no femoral head found at either end of the long axis (" + errors + ")");
  if (c[0] && c[1]) return c[0]->points_used >= c[1]->points_used ? *c[0] : *c[1];
  return c[0] ? *c[0] : *c[1];
}

SphereFitResult locate_femoral_head(const TriangleMesh& femur, const TriangleMesh& pelvis,
                                    const HeadFitOptions& options) {
  validate_mesh(pelvis);
  std::string errors;
  auto c = head_candidates(femur, options, errors, &pelvis);
  require(c[0] || c[1], femur.source + ": no femoral head found at either end of the long axis (" + errors + ")");
  // Both ends can find the same sphere (a short proximal femur): one head, the better fit.
  if (c[0] && c[1] && (c[0]->centre - c[1]->centre).norm() < 2.0) {
    if (c[1]->points_used > c[0]->points_used) c[0] = c[1];
    c[1].reset();
  }
  std::ostringstream seen;
  std::optional<SphereFitResult> head;
  int in_acetabulum = 0;
  for (const auto& k : c) {
    if (!k) continue;
    const double gap = nearest_vertex_distance(pelvis, k->centre) - k->radius;
    seen << (seen.tellp() > 0 ? "; " : "") << "sphere of radius " << k->radius << " mm at (" << k->centre.x() << ", "
         << k->centre.y() << ", " << k->centre.z() << "): its surface " << gap << " mm from the pelvis";
    if (std::abs(gap) <= kHeadInAcetabulumMm) ++in_acetabulum, head = k;
  }
  require(in_acetabulum == 1, femur.source + ": cannot tell which end of the femur is proximal: " +
                                  (in_acetabulum == 0 ? std::string("neither") : std::string("both")) +
                                  " end's sphere sits in the acetabulum of " + pelvis.source + " (within " +
                                  std::to_string(int(kHeadInAcetabulumMm)) + " mm; " + seen.str() +
                                  "). Are the femur and pelvis one hip in one frame? A given COR or head region "
                                  "avoids the search");
  return *head;
}

namespace {

// Vertices of the distal slab: projection on L within `fraction` of the femur's length from its distal end.
std::vector<Eigen::Index> distal_slab(const Vertices& V, const Eigen::Vector3d& L, double fraction, double& length) {
  const Eigen::VectorXd t = V * L;
  const double tmin = t.minCoeff(), tmax = t.maxCoeff();
  length = tmax - tmin;
  std::vector<Eigen::Index> slab;
  for (Eigen::Index i = 0; i < V.rows(); ++i)
    if (t[i] <= tmin + fraction * length) slab.push_back(i);
  return slab;
}

// v without its component along the unit long axis L.
Eigen::Vector3d perp(Eigen::Vector3d v, const Eigen::Vector3d& L) { return Eigen::Vector3d(v - v.dot(L) * L); }

// p: the vertex of `set` farthest along dir (the first of equals).
void extreme(const Vertices& V, const Eigen::Vector3d& dir, const std::vector<Eigen::Index>& set, Eigen::Vector3d& p) {
  double best = -std::numeric_limits<double>::infinity();
  for (Eigen::Index i : set) {
    const double s = V.row(i).dot(dir);
    if (s > best) best = s, p = V.row(i).transpose();
  }
}

// The epicondyles (mm): the slab's extremes along e (medial) and -e (lateral), e turned to their direction across
// the long axis L until it settles (at most 20 rounds). e: the start in, the last direction out.
void find_epicondyles(const Vertices& V, const Eigen::Vector3d& L, const std::vector<Eigen::Index>& slab,
                      const std::string& ctx, Eigen::Vector3d& e, Eigen::Vector3d& med, Eigen::Vector3d& lat) {
  for (int it = 0; it < 20; ++it) {
    extreme(V, e, slab, med);
    extreme(V, -e, slab, lat);
    Eigen::Vector3d e2 = perp(med - lat, L);
    require(e2.norm() > 1e-6, ctx + ": the epicondyles coincide");
    e2.normalize();
    if ((e2 - e).norm() < 1e-12) break;
    e = e2;
  }
}

// Posterior condyles (mm): split the slab at the midpoint of the epicondyles (med, lat; e the medial direction);
// posterior = -(anterior), anterior = L x (lateral direction) for a right femur (x = y x z with z = lateral),
// mirrored for the left; each half's extreme along posterior, posterior turned normal to L and the condylar axis
// until it settles (at most 20 rounds).
void find_posterior_condyles(const Vertices& V, const Eigen::Vector3d& L, const std::vector<Eigen::Index>& slab,
                             const Eigen::Vector3d& e, const Eigen::Vector3d& med, const Eigen::Vector3d& lat,
                             Side side, const std::string& ctx, Eigen::Vector3d& pm, Eigen::Vector3d& pl) {
  const Eigen::Vector3d lateral_dir = -e;
  const Eigen::Vector3d right_dir = side == Side::right ? lateral_dir : Eigen::Vector3d(-lateral_dir);
  Eigen::Vector3d post = -L.cross(right_dir).normalized();
  const double split = 0.5 * (med + lat).dot(e);
  std::vector<Eigen::Index> med_half, lat_half;
  for (Eigen::Index i : slab) (V.row(i).dot(e) > split ? med_half : lat_half).push_back(i);
  require(!med_half.empty() && !lat_half.empty(), ctx + ": a condyle is missing from the distal slab");
  for (int it = 0; it < 20; ++it) {
    extreme(V, post, med_half, pm);
    extreme(V, post, lat_half, pl);
    Eigen::Vector3d axis = perp(pm - pl, L);
    require(axis.norm() > 1e-6, ctx + ": the posterior condyles coincide");
    Eigen::Vector3d post2 = L.cross(axis).normalized();
    if (post2.dot(post) < 0) post2 = -post2;
    if ((post2 - post).norm() < 1e-12) break;
    post = post2;
  }
}

}  // namespace

FemurLandmarks find_femur_landmarks(const TriangleMesh& femur, const Eigen::Vector3d& head_centre, Side side,
                                    const Landmarks& given, double distal_fraction) {
  const std::string ctx = femur.source + ": automatic femoral landmarks";
  require(head_centre.allFinite(), ctx + ": head centre is not finite");
  require(distal_fraction > 0 && distal_fraction < 0.5, ctx + ": distal fraction must be in (0, 0.5)");
  FemurLandmarks out;
  out.head_centre = head_centre;
  Landmarks found;
  bool need = false;
  for (const char* name : kFemurLandmarkNames) need = need || !given.count(name);
  if (need) {
    validate_mesh(femur);
    const Vertices& V = femur.V;
    const Eigen::Vector3d L = femur_long_axis(V, head_centre);
    double length = 0;
    const std::vector<Eigen::Index> slab = distal_slab(V, L, distal_fraction, length);
    require(slab.size() >= 50,
            ctx + ": the femur is too short or too coarse along its long axis for a distal slab (a whole femur "
                  "is needed; give the landmarks in subject.json)");
    Eigen::Vector3d slab_centre = Eigen::Vector3d::Zero();
    for (Eigen::Index i : slab) slab_centre += V.row(i).transpose();
    slab_centre /= static_cast<double>(slab.size());
    // Medial: towards the head's offset from the shaft's line through the slab centre.
    Eigen::Vector3d medial = perp(head_centre - slab_centre, L);
    require(medial.norm() > 1e-6, ctx + ": the head centre lies on the long axis; cannot tell medial from lateral");
    medial.normalize();
    // Start from the slab's widest direction across the long axis (2-D principal axis), medial sign.
    Eigen::Matrix3d C = Eigen::Matrix3d::Zero();
    for (Eigen::Index i : slab) {
      const Eigen::Vector3d d = perp(V.row(i).transpose() - slab_centre, L);
      C += d * d.transpose();
    }
    Eigen::Vector3d e = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(C).eigenvectors().col(2);
    if (e.dot(medial) < 0) e = -e;
    Eigen::Vector3d med = Eigen::Vector3d::Zero(), lat = Eigen::Vector3d::Zero();
    find_epicondyles(V, L, slab, ctx, e, med, lat);
    require(length >= 3 * (med - lat).norm(),
            ctx + ": the mesh is " + std::to_string(length) + " mm long but " + std::to_string((med - lat).norm()) +
                " mm wide at its distal end: not a whole femur (give the landmarks in subject.json)");
    found["epicondyle_medial"] = med;
    found["epicondyle_lateral"] = lat;
    Eigen::Vector3d pm = Eigen::Vector3d::Zero(), pl = Eigen::Vector3d::Zero();
    find_posterior_condyles(V, L, slab, e, med, lat, side, ctx, pm, pl);
    found["posterior_condyle_medial"] = pm;
    found["posterior_condyle_lateral"] = pl;
  }
  auto pick = [&](const char* name, Eigen::Vector3d& p) {
    const auto g = given.find(name);
    require(g == given.end() || g->second.allFinite(), femur.source + ": given landmark " + name + " is not finite");
    p = g != given.end() ? g->second : found.at(name);
    out.source[name] = g != given.end() ? "given" : "found";
  };
  pick("epicondyle_lateral", out.epicondyle_lateral);
  pick("epicondyle_medial", out.epicondyle_medial);
  pick("posterior_condyle_lateral", out.posterior_condyle_lateral);
  pick("posterior_condyle_medial", out.posterior_condyle_medial);
  return out;
}

AnatomicalFrame femur_frame(const FemurLandmarks& L, Side side, FemurFrameKind kind) {
  AnatomicalFrame F;
  F.origin = L.head_centre;
  const Eigen::Vector3d y = L.head_centre - 0.5 * (L.epicondyle_lateral + L.epicondyle_medial);
  const double m = side == Side::right ? 1.0 : -1.0;  // lateral is right on a right femur
  if (kind == FemurFrameKind::epicondyles) {
    F.axes = orthonormal_axes(y, 1, m * (L.epicondyle_lateral - L.epicondyle_medial), 2, "ISB femoral frame");
    F.definition = "ISB femur (Wu et al. 2002): y from the epicondyles' midpoint to the head centre, z in the plane "
                   "of the head centre and both epicondyles (right), x = y x z (anterior); origin at the head centre";
  } else {
    F.axes = orthonormal_axes(y, 1, m * (L.posterior_condyle_lateral - L.posterior_condyle_medial), 2,
                              "femoral frame (posterior condylar axis)");
    F.definition = "femur: y from the epicondyles' midpoint to the head centre, z parallel to the posterior "
                   "condylar axis (right), x = y x z (anterior); origin at the head centre";
  }
  F.landmarks = L.as_map();
  F.landmark_source = L.source;
  return F;
}

FemurFrameKind parse_femur_frame_kind(const std::string& text, const std::string& context) {
  return parse_enum(kFemurFrameKindNames, text, context);
}

}  // namespace impinge
