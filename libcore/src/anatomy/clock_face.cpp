#include "impinge/anatomy/clock_face.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <cstdint>
#include <string>
#include <unordered_map>
#include <vector>

#include "impinge/core/error.hpp"

namespace impinge {

double ClockFace::hour(const Eigen::Vector3d& p) const {
  const Eigen::Vector3d d = p - centre;
  const double a = d.dot(twelve), b = d.dot(three);
  if (a == 0 && b == 0) return std::nan("");
  double h = std::atan2(b, a) * 6.0 / M_PI;  // (-6, 6], 0 at twelve, +3 at three
  if (h <= 0) h += 12;
  return h;
}

ClockFace ClockFace::transformed(const Eigen::Matrix3d& R, const Eigen::Vector3d& t) const {
  return ClockFace{R * centre + t, R * axis, R * twelve, R * three};
}

int ClockFace::sector(double hour) {
  const int k = static_cast<int>(std::ceil(hour)) - 1;
  return std::clamp(k, 0, 11);
}

namespace {
// In-plane unit vector: v without its component along unit n.
Eigen::Vector3d in_plane(const Eigen::Vector3d& v, const Eigen::Vector3d& n) { return (v - v.dot(n) * n).normalized(); }
}  // namespace

namespace {
/// One triangle of the pelvis as the lunate fit sees it: centroid, area, unit outward normal.
struct Facet {
  Eigen::Vector3d centroid, normal;
  double area;
};

std::vector<Facet> facets(const TriangleMesh& mesh) {
  std::vector<Facet> out(static_cast<std::size_t>(mesh.F.rows()));
  double volume6 = 0;  // six times the signed volume: > 0 when the normals point out
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)).transpose(), b = mesh.V.row(mesh.F(f, 1)).transpose(),
                          c = mesh.V.row(mesh.F(f, 2)).transpose();
    const Eigen::Vector3d n = (b - a).cross(c - a);
    const double len = n.norm();
    out[static_cast<std::size_t>(f)] = {(a + b + c) / 3, len > 0 ? Eigen::Vector3d(n / len) : Eigen::Vector3d::Zero(),
                                        len / 2};
    volume6 += a.dot(b.cross(c));
  }
  if (volume6 < 0)
    for (Facet& t : out) t.normal = -t.normal;
  return out;
}

// Whether facet t faces the point c (its outward normal within acos(kLunateFacing) of the direction to c); `n`: |d|
// for d = t.centroid - c.
bool faces(const Facet& t, const Eigen::Vector3d& d, double n) { return n > 0 && t.normal.dot(d) <= -kLunateFacing * n; }

// The facets on the sphere (c, r) within `band` mm whose outward normal faces its centre.
std::vector<std::size_t> on_sphere(const std::vector<Facet>& T, const Eigen::Vector3d& c, double r, double band) {
  std::vector<std::size_t> sel;
  for (std::size_t f = 0; f < T.size(); ++f) {
    const Eigen::Vector3d d = T[f].centroid - c;
    const double n = d.norm();
    if (T[f].area > 0 && std::abs(n - r) <= band && faces(T[f], d, n)) sel.push_back(f);
  }
  return sel;
}

// 1. The joint space at the scan pose (mm): the mode (area-weighted, 0.25 mm bins smoothed over +-1 mm) of the
//    distance from the head sphere (c, r) of the triangles facing the head within [-3, 12] mm of it.
double joint_space_mode(const std::vector<Facet>& T, const Eigen::Vector3d& c, double r, const std::string& ctx) {
  constexpr double kBin = 0.25, kLow = -3, kHigh = 12;
  std::vector<double> hist(static_cast<std::size_t>((kHigh - kLow) / kBin), 0.0);
  for (const Facet& t : T) {
    const Eigen::Vector3d d = t.centroid - c;
    const double n = d.norm(), s = n - r;
    if (s >= kLow && s < kHigh && faces(t, d, n))
      hist[std::min(hist.size() - 1, static_cast<std::size_t>((s - kLow) / kBin))] += t.area;
  }
  std::size_t mode = 0;
  double best = -1;
  for (std::size_t b = 0; b < hist.size(); ++b) {
    double sum = 0;
    for (int k = -4; k <= 4; ++k)
      if (b + k < hist.size()) sum += hist[b + k];  // (size_t wraps below 0: out of range)
    if (sum > best) best = sum, mode = b;
  }
  require(best > 0, ctx + ": no pelvis surface faces the femoral head within 12 mm of its sphere (is the head in "
                          "the acetabulum?)");
  return kLow + (static_cast<double>(mode) + 0.5) * kBin;
}

// 2. The lunate sphere (A.sphere, A.lunate_area_mm2, A.lunate_triangles): from the sphere (centre, radius; mm) given,
//    the sphere of the surface facing its centre within kLunateBandMm (fit_sphere_to_surface: the deeper fossa and
//    the rim's flare weigh nothing, the whole lunate surface is in, however wide the joint space); centre and radius
//    end as that sphere. The area and triangles reported are those within kLunateBandMm of it and facing it
//    (kLunateFacing). (Until 2026-12 the fit took the facets whose centroid lay in the band, refitted until they no
//    longer changed: a file with its triangles split in four moved the centre by 0.35 mm on mc22-left, and its ROM
//    limits by up to 6.9 deg.)
void fit_lunate_sphere(const TriangleMesh& mesh, const std::vector<Facet>& T, const std::string& ctx, Acetabulum& A,
                       Eigen::Vector3d& centre, double& radius) {
  const SurfaceSphereFit fit =
      fit_sphere_to_surface(mesh, centre, radius, kLunateBandMm, kLunateFacing, SurfaceSide::concave, "acetabulum");
  A.sphere = fit.sphere;
  centre = A.sphere.centre, radius = A.sphere.radius;
  const std::size_t facets_in = on_sphere(T, centre, radius, kLunateBandMm).size();
  require(facets_in >= 20, ctx + ": fewer than 20 triangles on the acetabular sphere (" + std::to_string(facets_in) +
                               " within " + std::to_string(kLunateBandMm) + " mm of it, facing the head)");
  A.lunate_area_mm2 = fit.area_in_band_mm2;
  A.lunate_triangles = static_cast<std::int64_t>(facets_in);
}

// 3. The cup: the pelvis vertices within radius + margin (mm) of the acetabular centre; `mean_dir` gets the sum of
//    their unit directions from the centre, weighted by vertex area.
std::vector<Eigen::Index> cup_vertices(const TriangleMesh& pelvis, const Eigen::Vector3d& centre, double radius,
                                       double margin, Eigen::Vector3d& mean_dir) {
  const Vertices& V = pelvis.V;
  const Eigen::VectorXd area = vertex_areas(pelvis);
  std::vector<Eigen::Index> cup;
  for (Eigen::Index i = 0; i < V.rows(); ++i) {
    const Eigen::Vector3d d = V.row(i).transpose() - centre;
    const double n = d.norm();
    if (n > 0 && n < radius + margin) cup.push_back(i), mean_dir += area[i] * d / n;
  }
  return cup;
}

constexpr int kRimBins = 72;  // the rim's azimuth bins: 5 degrees each

// The rim: per 5-degree azimuth bin around the cup's axis (from e1 towards e2), the cup vertex with the largest angle
// from the pole, appended to `rim` in bin order; `cover`: each bin's angle (rad; -1 where the bin has no vertex).
void find_rim(const Vertices& V, const std::vector<Eigen::Index>& cup, const Eigen::Vector3d& centre,
              const Eigen::Vector3d& pole, const Eigen::Vector3d& e1, const Eigen::Vector3d& e2,
              std::vector<double>& cover, std::vector<Eigen::Vector3d>& rim_out) {
  cover.assign(kRimBins, -1);
  std::vector<Eigen::Vector3d> rim(kRimBins);
  for (Eigen::Index i : cup) {
    const Eigen::Vector3d d = V.row(i).transpose() - centre;
    const double theta = std::acos(std::clamp(d.normalized().dot(pole), -1.0, 1.0));
    double psi = std::atan2(d.dot(e2), d.dot(e1));
    if (psi < 0) psi += 2 * M_PI;
    const int b = std::min(kRimBins - 1, static_cast<int>(psi / (2 * M_PI) * kRimBins));
    if (theta > cover[static_cast<std::size_t>(b)])
      cover[static_cast<std::size_t>(b)] = theta, rim[static_cast<std::size_t>(b)] = V.row(i).transpose();
  }
  for (int b = 0; b < kRimBins; ++b)
    if (cover[static_cast<std::size_t>(b)] >= 0) rim_out.push_back(rim[static_cast<std::size_t>(b)]);
}

// The rim plane: A.rim_centre the rim points' mean, A.opening the plane's normal out of the cup (along `axis`), the
// rim's mean radius and the points' rms distance from the plane (mm).
void fit_rim_plane(Acetabulum& A, const Eigen::Vector3d& axis) {
  Eigen::Vector3d m = Eigen::Vector3d::Zero();
  for (const auto& p : A.rim) m += p;
  m /= static_cast<double>(A.rim.size());
  Eigen::Matrix3d C = Eigen::Matrix3d::Zero();
  for (const auto& p : A.rim) C += (p - m) * (p - m).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(C);
  Eigen::Vector3d n = es.eigenvectors().col(0);
  if (n.dot(axis) < 0) n = -n;
  A.rim_centre = m;
  A.opening = n;
  double rr = 0, rms = 0;
  for (const auto& p : A.rim) rr += (p - m).norm(), rms += std::pow((p - m).dot(n), 2);
  A.rim_radius_mm = rr / static_cast<double>(A.rim.size());
  A.rim_plane_rms_mm = std::sqrt(rms / static_cast<double>(A.rim.size()));
}

// The notch, the least rim extent (`cover` smoothed over +-22.5 deg; empty bins count as no extent) in the inferior
// half (by P's y), and the acetabular clock on the rim plane with 6 o'clock there and 3 o'clock anterior; also the
// median and the notch's coverage (deg).
void find_notch_and_clock(Acetabulum& A, const std::vector<double>& cover, const Eigen::Vector3d& e1,
                          const Eigen::Vector3d& e2, const AnatomicalFrame& P) {
  const Eigen::Vector3d m = A.rim_centre, n = A.opening;
  std::vector<double> cov(kRimBins);
  for (int b = 0; b < kRimBins; ++b)
    cov[static_cast<std::size_t>(b)] = std::max(0.0, cover[static_cast<std::size_t>(b)]);
  int notch = -1;
  double best_v = 1e300;
  std::vector<double> sorted;
  for (int b = 0; b < kRimBins; ++b) {
    double s = 0;
    for (int k = -4; k <= 4; ++k) s += cov[static_cast<std::size_t>((b + k + kRimBins) % kRimBins)];
    s /= 9;
    const double psi = (b + 0.5) * 2 * M_PI / kRimBins;
    const Eigen::Vector3d dir = std::cos(psi) * e1 + std::sin(psi) * e2;
    if (dir.dot(P.axes.col(1)) < 0 && s < best_v) best_v = s, notch = b;
    sorted.push_back(cov[static_cast<std::size_t>(b)]);
  }
  std::nth_element(sorted.begin(), sorted.begin() + kRimBins / 2, sorted.end());
  A.median_coverage_deg = sorted[kRimBins / 2] * 180 / M_PI;
  A.notch_coverage_deg = best_v * 180 / M_PI;
  const double psi = (notch + 0.5) * 2 * M_PI / kRimBins;
  const Eigen::Vector3d six = in_plane(std::cos(psi) * e1 + std::sin(psi) * e2, n);
  A.clock.centre = m;
  A.clock.axis = n;
  A.clock.twelve = -six;
  A.clock.three = n.cross(A.clock.twelve);
  if (A.clock.three.dot(P.axes.col(0)) < 0) A.clock.three = -A.clock.three;  // 3 o'clock anterior on both sides
}
}  // namespace

Acetabulum find_acetabulum(const TriangleMesh& pelvis, const Eigen::Vector3d& c, double r, const AnatomicalFrame& P,
                           double margin) {
  const std::string ctx = pelvis.source + ": acetabulum";
  require(c.allFinite() && std::isfinite(r) && r > 0, ctx + ": head centre and radius must be finite");
  const Vertices& V = pelvis.V;
  Acetabulum A;
  // The lunate surface and its sphere, from the triangles (their centroids and areas: the surface's, not its
  // vertices', so a file that splits, duplicates or renumbers them gives the same sphere).
  const std::vector<Facet> T = facets(pelvis);
  A.joint_space_mode_mm = joint_space_mode(T, c, r, ctx);
  // The lunate sphere, from the head-centred sphere at that joint space.
  Eigen::Vector3d centre = c;
  double radius = r + A.joint_space_mode_mm;
  fit_lunate_sphere(pelvis, T, ctx, A, centre, radius);
  Eigen::Vector3d mean_dir = Eigen::Vector3d::Zero();
  const std::vector<Eigen::Index> cup = cup_vertices(pelvis, centre, radius, margin, mean_dir);
  A.cup_vertices = static_cast<std::int64_t>(cup.size());
  require(cup.size() >= 50, ctx + ": only " + std::to_string(cup.size()) + " pelvis vertices within " +
                                std::to_string(radius + margin) + " mm of the acetabular centre");
  // The cup's pole (its deepest direction) and axis out of the cup.
  const Eigen::Vector3d pole = mean_dir.normalized();
  const Eigen::Vector3d axis = -pole;
  const Eigen::Vector3d e1 = in_plane(P.axes.col(1), axis);  // superior, in the plane across the axis
  const Eigen::Vector3d e2 = axis.cross(e1);
  std::vector<double> cover;
  find_rim(V, cup, centre, pole, e1, e2, cover, A.rim);
  require(A.rim.size() >= 36, ctx + ": the cup has vertices in only " + std::to_string(A.rim.size()) +
                                  " of 72 azimuths around its axis: no rim");
  fit_rim_plane(A, axis);
  find_notch_and_clock(A, cover, e1, e2, P);
  return A;
}

namespace {

// The closed loop, nearest p0, in which the plane through p0 normal to n (unit) cuts the triangles `near` of `mesh`:
// its centroid (by length, mm) and perimeter (mm; NaN when the plane cuts none). The loops are the cut segments
// joined where they share a mesh edge or an end point (to 1e-6 mm: a T-junction, where a split triangle's edge
// half meets its neighbour's whole edge).
struct Section {
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  double perimeter = std::numeric_limits<double>::quiet_NaN();
};
Section nearest_section(const TriangleMesh& mesh, const std::vector<Eigen::Index>& near, const Eigen::Vector3d& p0,
                        const Eigen::Vector3d& n) {
  std::unordered_map<std::uint64_t, int> node;  // a cut mesh edge -> its point's node
  std::vector<int> parent;
  auto node_of = [&](Eigen::Index a, Eigen::Index b) {
    if (a > b) std::swap(a, b);
    const auto [it, added] =
        node.emplace((static_cast<std::uint64_t>(a) << 32) | static_cast<std::uint64_t>(b), static_cast<int>(parent.size()));
    if (added) parent.push_back(static_cast<int>(parent.size()));
    return it->second;
  };
  std::unordered_map<std::uint64_t, int> at_point;  // an end point, rounded to 1e-6 mm -> its first node
  auto point_key = [](const Eigen::Vector3d& p) {
    std::uint64_t h = 1469598103934665603ull;
    for (int k = 0; k < 3; ++k) {
      h ^= static_cast<std::uint64_t>(std::llround(p[k] * 1e6));
      h *= 1099511628211ull;
    }
    return h;
  };
  auto root = [&](int x) {
    while (parent[static_cast<std::size_t>(x)] != x)
      x = parent[static_cast<std::size_t>(x)] = parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(x)])];
    return x;
  };
  struct Segment {
    int node;
    Eigen::Vector3d mid;
    double length;
  };
  std::vector<Segment> segments;
  for (const Eigen::Index f : near) {
    const Eigen::Index v[3] = {mesh.F(f, 0), mesh.F(f, 1), mesh.F(f, 2)};
    double s[3];
    for (int k = 0; k < 3; ++k) s[k] = (mesh.V.row(v[k]).transpose() - p0).dot(n);
    int cuts = 0, nodes[2] = {0, 0};
    Eigen::Vector3d points[2];
    for (int k = 0; k < 3; ++k) {
      const int l = (k + 1) % 3;
      if ((s[k] < 0) == (s[l] < 0)) continue;
      if (cuts < 2) {
        const double t = s[k] / (s[k] - s[l]);
        points[cuts] = mesh.V.row(v[k]).transpose() + t * (mesh.V.row(v[l]) - mesh.V.row(v[k])).transpose();
        nodes[cuts] = node_of(v[k], v[l]);
      }
      ++cuts;
    }
    if (cuts != 2) continue;
    for (int k = 0; k < 2; ++k) {  // the same point on another edge (a T-junction): one node
      const int other = at_point.try_emplace(point_key(points[k]), nodes[k]).first->second;
      const int a = root(nodes[k]), b = root(other);
      if (a != b) parent[static_cast<std::size_t>(a)] = b;
    }
    const int a = root(nodes[0]), b = root(nodes[1]);
    if (a != b) parent[static_cast<std::size_t>(a)] = b;
    segments.push_back({nodes[0], 0.5 * (points[0] + points[1]), (points[0] - points[1]).norm()});
  }
  std::unordered_map<int, std::pair<Eigen::Vector3d, double>> loops;  // root -> (sum of length x midpoint, length)
  for (const Segment& g : segments) {
    auto it = loops.try_emplace(root(g.node), Eigen::Vector3d::Zero(), 0.0).first;
    it->second.first += g.length * g.mid;
    it->second.second += g.length;
  }
  Section best;
  double nearest = std::numeric_limits<double>::infinity();
  for (const auto& [key, loop] : loops) {
    if (!(loop.second > 0)) continue;
    const Eigen::Vector3d g = loop.first / loop.second;
    if ((g - p0).norm() < nearest) nearest = (g - p0).norm(), best.centroid = g, best.perimeter = loop.second;
  }
  return best;
}

}  // namespace

Eigen::Vector3d femoral_neck_axis(const TriangleMesh& femur, const Eigen::Vector3d& c, double r,
                                  const Eigen::Vector3d& seed) {
  require(c.allFinite() && std::isfinite(r) && r > 0 && seed.allFinite() && seed.norm() > 0,
          femur.source + ": femoral neck axis: head centre, radius and seed axis must be finite");
  // The triangles within reach of the sections (the head, the neck, the trochanters' start).
  std::vector<Eigen::Index> near;
  for (Eigen::Index f = 0; f < femur.F.rows(); ++f)
    for (int k = 0; k < 3; ++k)
      if ((femur.V.row(femur.F(f, k)).transpose() - c).norm() <= r + 30) {
        near.push_back(f);
        break;
      }
  Eigen::Vector3d a = seed.normalized();
  for (int it = 0; it < 20; ++it) {
    Section narrowest;
    for (double d = r - 8; d <= r + 16 + 1e-9; d += 0.5) {
      const Section s = nearest_section(femur, near, c - d * a, a);
      if (std::isfinite(s.perimeter) && !(s.perimeter >= narrowest.perimeter)) narrowest = s;
    }
    if (!std::isfinite(narrowest.perimeter) || (c - narrowest.centroid).norm() < 1e-9) return seed.normalized();
    const Eigen::Vector3d next = (c - narrowest.centroid).normalized();
    const bool done = (next - a).norm() < 1e-7;
    a = next;
    if (done) break;
  }
  // Far from the seed, the sections found something other than the neck (a short or cut femur): the seed.
  return a.dot(seed.normalized()) >= std::cos(30 * M_PI / 180) ? a : Eigen::Vector3d(seed.normalized());
}

ClockFace femoral_clock_face(const TriangleMesh& femur, const Eigen::Vector3d& c, double r,
                             const AnatomicalFrame& F) {
  require(c.allFinite() && std::isfinite(r) && r > 0, femur.source + ": femoral clock: head centre and radius must be finite");
  // The area-weighted centroid of the triangles whose centroids lie in the shell, so that the centroid is the
  // surface's, not the tessellation's: a mesh refined on one side of the neck pulls a plain vertex mean towards it
  // (issue 49: the femoral version moved by up to 5 deg with the weighting on the shared hips), and a triangle at
  // the shell's edge is in or out by its centroid, without bias towards either side.
  Eigen::Vector3d s = Eigen::Vector3d::Zero();
  double w = 0;
  int n = 0;
  for (Eigen::Index f = 0; f < femur.F.rows(); ++f) {
    const Eigen::Vector3d p = femur.V.row(femur.F(f, 0)).transpose(), q = femur.V.row(femur.F(f, 1)).transpose(),
                          e = femur.V.row(femur.F(f, 2)).transpose();
    const Eigen::Vector3d g = (p + q + e) / 3;
    const double d = (g - c).norm(), area = (q - p).cross(e - p).norm() / 2;
    if (d > r + 4 && d < r + 12 && area > 0) s += area * g, w += area, ++n;
  }
  require(n >= 10, femur.source + ": femoral clock: no neck triangles 4 to 12 mm outside the head sphere");
  ClockFace k;
  k.centre = c;
  // The shell's centroid seeds the neck axis through the narrowest section (femoral_neck_axis).
  k.axis = femoral_neck_axis(femur, c, r, (c - s / w).normalized());
  k.twelve = in_plane(F.axes.col(1), k.axis);
  k.three = k.axis.cross(k.twelve);
  if (k.three.dot(F.axes.col(0)) < 0) k.three = -k.three;
  return k;
}

AcetabularOrientation radiographic_orientation(const Acetabulum& acetabulum, const AnatomicalFrame& pelvis_frame,
                                               Side side) {
  const Eigen::Vector3d n = pelvis_frame.axes.transpose() * acetabulum.opening;
  const double m = side == Side::right ? 1.0 : -1.0;
  constexpr double deg = 180.0 / 3.14159265358979323846;
  return {std::atan2(m * n.z(), -n.y()) * deg, std::asin(std::clamp(n.x(), -1.0, 1.0)) * deg};
}

}  // namespace impinge
