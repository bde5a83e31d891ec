#include "impinge/sampling/rasterize.hpp"

// The banded driver of the rasteriser (thesis sec. 3.2, Algorithm 1; issue 4): per triangle or per
// planned cone, its box and row spans (raster_row_spans), then the exact or linear kernel
// (raster_exact_kernels, raster_linear_kernels) on cones set up by raster_cone_setup.

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "impinge/core/error.hpp"
#include "impinge/core/interrupt.hpp"
#include "sampling/raster_cone_setup.hpp"
#include "sampling/raster_exact_kernels.hpp"
#include "sampling/raster_linear_kernels.hpp"
#include "sampling/raster_row_spans.hpp"
#include "sampling/raster_tables.hpp"

namespace impinge {

DistanceMode parse_distance_mode(const std::string& name, const std::string& context) {
  return parse_enum(kDistanceModeNames, name, context);
}

const char* to_string(DistanceMode mode) { return enum_name(kDistanceModeNames, mode); }

namespace {

using namespace detail;

/// Boxes narrower than this many columns (plus one) are tested whole (measured on lhdl-ct's
/// pelvis at 0.05 deg: 16 is about 7 % faster than spans everywhere; the map is the same).
constexpr int kMinSpanBox = 16;

/// Rows reset together by MapStart::reset with a plan: 512 KiB of map, half of this machine's
/// per-core L2 (lhdl-ct pelvis at 0.05 deg: 128 KiB 19-21 ms, 256 KiB 18 ms, 512 KiB 17-17.8 ms,
/// 1 MiB 18-19 ms; the cones that start in a band reach into the next ones).
constexpr std::size_t kResetBandBytes = 512 * 1024;

/// Cones made and drawn at a time from a plan without cones (RasterPlan::with_cones false): 4096 of 240
/// bytes, about 1 MB.
constexpr std::size_t kStreamedCones = 4096;

template <typename Scalar>
class Rasterizer {
 public:
  Rasterizer(RadialDistanceMapT<Scalar>& map, DistanceMode mode, SamplingStats& stats, int keep_sign, bool row_spans)
      : map_(map),
        mode_(mode),
        stats_(stats),
        grid_(equiangular_grid_of(map.scheme())),
        keep_sign_(keep_sign),
        row_spans_(row_spans),
        t_(grid_tables(grid_)),
        inv_h_(1 / grid_.step()) {}

  /// Nodes that had no surface before this rasteriser and have one now.
  std::int64_t newly_covered() const { return newly_covered_; }

  void triangle(const Corner& a, const Corner& b, const Corner& c) {
    ++stats_.triangles;
    const double det = a.p.dot(b.p.cross(c.p));
    if (!(std::abs(det) > 1e-12 * a.d * b.d * c.d)) {
      ++stats_.triangles_edge_on;
      return;
    }
    if (keep_sign_ != 0 && (det > 0 ? 1 : -1) != keep_sign_) {  // never the nearest hit (raster_plan.hpp)
      ++stats_.triangles_culled;
      return;
    }
    const bool north = in_cone(a.p, b.p, c.p, det, V3::UnitZ());
    const bool south = in_cone(a.p, b.p, c.p, det, -V3::UnitZ());
    if (mode_ == DistanceMode::exact) {
      exact_cone(make_cone(a, b, c, det, north, south));
      return;
    }
    if (north || south) ++stats_.pole_triangles;
    if (north || south) {
      // Thesis Fig. 34: split at the pole so that each part has the pole as a corner.
      const Corner* axis_vertex = a.axis ? &a : b.axis ? &b : c.axis ? &c : nullptr;
      if (axis_vertex != nullptr) {  // case 1, vertex case: already a corner
        const Corner& p = *axis_vertex;
        const Corner& x = (&p == &a) ? b : a;
        const Corner& y = (&p == &c) ? b : c;
        linear_cone(x, y, p, /*apex=*/true, north, south);
      } else {  // cases 2 and 3: the pole on an edge or inside the face
        const V3 n = (b.p - a.p).cross(c.p - a.p);
        const Corner p = corner(V3(0, 0, n.dot(a.p) / n.z()));
        linear_cone(a, b, p, true, north, south);
        linear_cone(b, c, p, true, north, south);
        linear_cone(c, a, p, true, north, south);
      }
      return;
    }
    linear_cone(a, b, c, false, north, south);
  }

  /// Exact mode: the nodes of the cone's row spans (or of its whole box without row spans).
  void exact_cone(const TriangleCone& t) { exact_cone(t, box_of(t, inv_h_, grid_.rows(), grid_.columns())); }

  /// Exact mode with every node first set to no surface, in bands of rows: each band is reset
  /// just before the cones that start in it are drawn, so that their map lines are still in the
  /// cache (the rows a cone reaches below its band are reset with it). Same map as a reset
  /// followed by exact_cone over `cones` in order: a node's value is the minimum over the cones
  /// covering it, whatever the order.
  void exact_cones_fresh(const std::vector<TriangleCone>& cones) {
    const int rows = grid_.rows(), cols = grid_.columns();
    const int band = std::max(1, static_cast<int>(kResetBandBytes / (sizeof(Scalar) * std::size_t(cols))));
    const int bands = (rows + band - 1) / band;
    thread_local std::vector<Box> boxes;
    thread_local std::vector<std::int32_t> order, start;
    const std::size_t n = cones.size();
    boxes.resize(n), order.resize(n), start.assign(std::size_t(bands) + 1, 0);
    for (std::size_t i = 0; i < n; ++i) {
      boxes[i] = box_of(cones[i], inv_h_, rows, cols);
      if (boxes[i].r1 >= boxes[i].r0) ++start[std::size_t(boxes[i].r0 / band) + 1];
    }
    for (int g = 0; g < bands; ++g) start[std::size_t(g) + 1] += start[std::size_t(g)];
    std::vector<std::int32_t> next(start.begin(), start.end() - 1);
    for (std::size_t i = 0; i < n; ++i)
      if (boxes[i].r1 >= boxes[i].r0) order[std::size_t(next[std::size_t(boxes[i].r0 / band)]++)] = std::int32_t(i);
    Scalar* map = map_.data();
    int reset = 0;  // rows 0 .. reset - 1 are reset
    const auto reset_to = [&](int r) {
      if (r <= reset) return;
      std::fill(map + std::int64_t(reset) * cols, map + std::int64_t(r) * cols, RadialDistanceMapT<Scalar>::no_surface());
      reset = r;
    };
    for (int g = 0; g < bands; ++g) {
      const auto b0 = std::size_t(start[std::size_t(g)]), b1 = std::size_t(start[std::size_t(g) + 1]);
      int need = std::min(rows, (g + 1) * band);
      for (std::size_t j = b0; j < b1; ++j) need = std::max(need, boxes[std::size_t(order[j])].r1 + 1);
      reset_to(need);
      for (std::size_t j = b0; j < b1; ++j) {
        if (j + 4 < b1) {  // the cones of a band are scattered in the plan (Z order)
          const char* ahead = reinterpret_cast<const char*>(&cones[std::size_t(order[j + 4])]);
          for (std::size_t line = 0; line < sizeof(TriangleCone); line += 64) __builtin_prefetch(ahead + line);
        }
        exact_cone(cones[std::size_t(order[j])], boxes[std::size_t(order[j])]);
      }
    }
    reset_to(rows);
  }

  /// exact_cone, except that a cone whose box holds no row is not counted (stats' pole and seam triangles) either:
  /// as exact_cones_fresh counts them, so that a streamed plan reports what the plan's cones report.
  void exact_cone_in_rows(const TriangleCone& t) {
    const Box b = box_of(t, inv_h_, grid_.rows(), grid_.columns());
    if (b.r1 >= b.r0) exact_cone(t, b);
  }

  /// exact_cone with the cone's box b (box_of).
  void exact_cone(const TriangleCone& t, const Box& b) {
    const int cols = grid_.columns();
    if (t.north || t.south) ++stats_.pole_triangles;
    if (t.seam) ++stats_.seam_triangles;
    if (b.r1 < b.r0) return;
    const auto n = static_cast<std::size_t>(b.r1 - b.r0 + 1);
    if (lo_.size() < n) lo_.resize(n), hi_.resize(n), sure_.resize(n / 8 + 1);
    // Rows of 16 columns or fewer take one or two vector steps anyway: no spans for them.
    const std::uint8_t* sure = nullptr;
    if (row_spans_ && !t.full_theta && b.c1 - b.c0 >= kMinSpanBox) {
      stats_.node_tests += row_spans(span_setup(t, b, inv_h_, cols), b.r0, b.r1, t_.cot_phi.data(),
                                     t_.rsqrt_sin_phi.data(), lo_.data(), hi_.data(), sure_.data());
      sure = sure_.data();
    } else {
      std::fill(lo_.begin(), lo_.begin() + std::ptrdiff_t(n), b.c0);
      std::fill(hi_.begin(), hi_.begin() + std::ptrdiff_t(n), b.c1);
      stats_.node_tests += std::int64_t(n) * (b.c1 - b.c0 + 1);
    }
    const SpanRows S{b.r0, b.r1, lo_.data(), hi_.data(), sure, t.e, t.bias, t.n, t.adet};
    newly_covered_ += exact_rows(map_.data(), cols, S, t_);
  }

 private:
  /// Linear mode: rasterise the cone of triangle (a, b, c). With `apex`, c lies on the z axis
  /// (the pole corner) and the trapezoid interpolation of thesis Fig. 34 is used. `north` /
  /// `south`: the cone holds that pole (computed once per mesh triangle; a part split at a pole
  /// holds the same pole at its apex and never the other).
  void linear_cone(const Corner& ka, const Corner& kb, const Corner& kc, bool apex, bool north, bool south) {
    const V3 &a = ka.p, &b = kb.p, &c = kc.p;
    const double det = a.dot(b.cross(c));
    if (!(std::abs(det) > 1e-12 * ka.d * kb.d * kc.d)) return;  // empty part
    const TriangleCone t = make_cone(ka, kb, kc, det, north, south);
    const int rows = grid_.rows(), cols = grid_.columns();
    const double h = grid_.step();
    const Box bx = box_of(t, inv_h_, rows, cols);
    const int r0 = bx.r0, r1 = bx.r1, c0 = bx.c0, c1 = bx.c1;
    if (t.seam) ++stats_.seam_triangles;
    const bool full = t.full_theta;

    // Corners in the (theta, phi) plane, theta unwrapped around a.
    const double ta = ka.theta, tb = ka.theta + wrap_pi(kb.theta - ka.theta),
                 tc = ka.theta + wrap_pi(kc.theta - ka.theta);
    const double area2 = (tb - ta) * (kc.phi - ka.phi) - (tc - ta) * (kb.phi - ka.phi);
    const double dtheta_ab = wrap_pi(kb.theta - ka.theta);

    if (!apex && !full && std::abs(area2) >= 1e-18) {  // away from the poles: vectorised
      LinearBox L{make_box(bx, cols, t), h, ta, tb, tc, ka.phi, kb.phi, kc.phi, ka.d, kb.d, kc.d, 1 / area2};
      if (r1 >= r0)
        newly_covered_ += linear_rows(map_.data(), cols, L, t_.sin_phi.data(), t_.cos_phi.data(), t_.cos_theta.data(),
                                      t_.sin_theta.data());
      stats_.node_tests += std::int64_t(std::max(0, r1 - r0 + 1)) * (c1 - c0 + 1);
      return;
    }
    const V3 e0(t.e[0], t.e[1], t.e[2]), e1(t.e[3], t.e[4], t.e[5]), e2(t.e[6], t.e[7], t.e[8]);
    for (int r = r0; r <= r1; ++r) {
      const double sp = t_.sin_phi[r], cp = t_.cos_phi[r];
      const double A0 = sp * e0.x(), B0 = sp * e0.y(), C0 = cp * e0.z();
      const double A1 = sp * e1.x(), B1 = sp * e1.y(), C1 = cp * e1.z();
      const double A2 = sp * e2.x(), B2 = sp * e2.y(), C2 = cp * e2.z();
      Scalar* row = map_.data() + std::int64_t(r) * cols;
      const double phi = r * h;
      for (int cc = c0; cc <= c1; ++cc) {
        const int col = cc < 0 ? cc + cols : (cc >= cols ? cc - cols : cc);
        const double ct = t_.cos_theta[col], st = t_.sin_theta[col];
        const double f0 = A0 * ct + B0 * st + C0;
        const double f1 = A1 * ct + B1 * st + C1;
        const double f2 = A2 * ct + B2 * st + C2;
        if (f0 < 0 || f1 < 0 || f2 < 0) continue;
        const double value = apex ? apex_value(ka, kb, kc, dtheta_ab, phi, col * h)
                                  : planar_value(ka, kb, kc, ta, tb, tc, area2, phi, col * h, t.adet / (f0 + f1 + f2));
        const Scalar v = static_cast<Scalar>(value);
        newly_covered_ += row[col] == RadialDistanceMapT<Scalar>::no_surface() ? 1 : 0;
        if (v < row[col]) row[col] = v;
      }
      stats_.node_tests += (c1 - c0 + 1);
    }
  }

  /// Thesis linear mode: barycentric interpolation in the (theta, phi) plane.
  static double planar_value(const Corner& ka, const Corner& kb, const Corner& kc, double ta, double tb, double tc,
                             double area2, double phi, double theta, double exact) {
    if (std::abs(area2) < 1e-18) return exact;  // collapsed in the grid: no 2-D interpolant
    const double tn = ta + wrap_pi(theta - ta);
    double lb = ((tn - ta) * (kc.phi - ka.phi) - (tc - ta) * (phi - ka.phi)) / area2;
    double lc = ((tb - ta) * (phi - ka.phi) - (tn - ta) * (kb.phi - ka.phi)) / area2;
    double la = 1 - lb - lc;
    // Nodes inside the 3-D cone but just outside the straight-edged 2-D triangle: clamp to it.
    la = std::max(la, 0.0), lb = std::max(lb, 0.0), lc = std::max(lc, 0.0);
    const double sum = la + lb + lc;
    return (la * ka.d + lb * kb.d + lc * kc.d) / sum;
  }

  /// Thesis Fig. 34: corner p (kc) on the axis, the others x (ka), y (kb). Linear in theta
  /// along the edge x-y, then linear in phi from the pole to that edge.
  static double apex_value(const Corner& kx, const Corner& ky, const Corner& kp, double dtheta, double phi,
                           double theta) {
    double s = 0.5;
    if (std::abs(dtheta) > 1e-15) s = std::clamp(wrap_pi(theta - kx.theta) / dtheta, 0.0, 1.0);
    const double phi_e = (1 - s) * kx.phi + s * ky.phi;
    const double d_e = (1 - s) * kx.d + s * ky.d;
    const double span = std::abs(phi_e - kp.phi);
    const double u = span > 1e-15 ? std::clamp(std::abs(phi - kp.phi) / span, 0.0, 1.0) : 1.0;
    return (1 - u) * kp.d + u * d_e;
  }

  RadialDistanceMapT<Scalar>& map_;
  DistanceMode mode_;
  SamplingStats& stats_;
  const EquiangularGrid& grid_;
  int keep_sign_;                   ///< 0: no culling
  bool row_spans_;                  ///< exact mode: test only the row spans (else whole boxes)
  const GridTables& t_;             ///< this grid's trigonometry
  double inv_h_;                    ///< 1 / the grid's step (1/rad)
  std::int64_t newly_covered_ = 0;  ///< nodes that had no surface and now have one
  std::vector<int> lo_, hi_;        ///< row spans of the current cone
  std::vector<std::uint8_t> sure_;  ///< their sure bits (row_spans)
};

}  // namespace

template <typename Scalar>
SamplingStats rasterize(const TriangleMesh& mesh, const Eigen::Vector3d& cor, DistanceMode mode,
                        RadialDistanceMapT<Scalar>& map, const RasterizeOptions& options) {
  const RasterPlan* culling = options.plan;
  const bool row_spans = options.row_spans;
  const MapStart start = options.start;
  require(cor.allFinite(), mesh.source + ": centre of rotation is not finite");
  validate_mesh(mesh);  // a bad index is an error before anything is read or changed
  (void)equiangular_grid_of(map.scheme());  // throws for a map that is not equiangular, before anything is changed
  const bool planned = culling != nullptr && mode == DistanceMode::exact;
  // The plan's cones: the kept triangles (all when culling is disabled), set up once.
  if (planned && (culling->cor != cor || culling->mesh_fingerprint != mesh_fingerprint(mesh)))
    throw Error(mesh.source + ": rasterisation plan was made for another mesh or centre of rotation");
  const bool banded = planned && culling->with_cones && start == MapStart::reset;  // the reset fused with the drawing
  if (start == MapStart::reset && !banded)
    std::fill(map.data(), map.data() + map.num_nodes(), RadialDistanceMapT<Scalar>::no_surface());
  SamplingStats stats;
  const int keep = planned && culling->enabled ? culling->keep_sign : 0;
  Rasterizer<Scalar> raster(map, mode, stats, keep, row_spans);
  if (planned) {
    std::int64_t edge_on = culling->cones_edge_on;
    if (!culling->with_cones) {
      // The cones made and drawn kStreamedCones at a time in the plan's order (Z order of direction: each run
      // covers a compact part of the map), so that they never take more than some 1 MB at once.
      const std::vector<Corner>& k = vertex_corners(mesh, cor);
      const std::vector<std::int32_t>& order = culling->triangle_order;
      thread_local std::vector<TriangleCone> cones;
      edge_on = 0;
      for (std::size_t first = 0; first < order.size(); first += kStreamedCones) {
        interruption_point();  // a front end's stop (Ctrl-C in Python), between runs of cones
        cones.clear();
        edge_on += append_triangle_cones(mesh, k, order, first, std::min(order.size(), first + kStreamedCones), cones);
        for (const TriangleCone& t : cones) raster.exact_cone_in_rows(t);
      }
    } else if (banded) {
      raster.exact_cones_fresh(culling->cones);
    } else {
      for (const TriangleCone& t : culling->cones) raster.exact_cone(t);
    }
    const auto kept = static_cast<std::int64_t>(culling->triangle_order.size());
    stats.triangles = mesh.F.rows();
    stats.triangles_edge_on = edge_on;
    stats.triangles_culled = mesh.F.rows() - kept;
  } else {
    const std::vector<Corner>& k = vertex_corners(mesh, cor);
    for (Eigen::Index f = 0; f < mesh.F.rows(); ++f)
      raster.triangle(k[static_cast<std::size_t>(mesh.F(f, 0))], k[static_cast<std::size_t>(mesh.F(f, 1))],
                      k[static_cast<std::size_t>(mesh.F(f, 2))]);
  }
  stats.nodes_covered = raster.newly_covered();
  return stats;
}

template SamplingStats rasterize<float>(const TriangleMesh&, const Eigen::Vector3d&, DistanceMode,
                                        RadialDistanceMapT<float>&, const RasterizeOptions&);
template SamplingStats rasterize<double>(const TriangleMesh&, const Eigen::Vector3d&, DistanceMode,
                                         RadialDistanceMapT<double>&, const RasterizeOptions&);

RadialDistanceMap rasterize_map(const TriangleMesh& mesh, const Eigen::Vector3d& cor, double precision_deg,
                                DistanceMode mode, SamplingStats* stats) {
  RadialDistanceMap map{EquiangularGrid(precision_deg)};
  const SamplingStats s = rasterize(mesh, cor, mode, map);
  if (stats != nullptr) *stats = s;
  return map;
}

}  // namespace impinge
