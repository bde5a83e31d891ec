// Depth discontinuities (issue 15, item 1). Invariants checked:
// - a smooth surface (a sphere about the COR) marks no node; a jump marks the nodes beside it and
//   only those, for the equiangular grid's own neighbours and for the generic (interpolated) path;
// - the marked kernel returns -inf exactly where a stencil holds a marked node, else the plain value;
// - with exact look-ups at discontinuities, every gap of a joint whose socket has a depth jump (a cup
//   in front of a larger one: the acetabular rim in front of the ilium) is within the tolerance of
//   the exact radial gap (CGAL), for every scheme, where the maps alone are off by the jump; and the
//   first-surface masks equal the exact ones.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <Eigen/Geometry>

#include "impinge/casters/exact_reference.hpp"
#include "impinge/casters/first_hit_caster.hpp"
#include "impinge/core/error.hpp"
#include "impinge/core/spherical_frame.hpp"
#include "impinge/detection/joint.hpp"
#include "impinge/io/generated_models.hpp"
#include "impinge/maps/depth_discontinuity.hpp"
#include "impinge/sampling/sampling.hpp"
#include "impinge/schemes/equiangular_grid.hpp"

using namespace impinge;

namespace {
TriangleMesh merged(const TriangleMesh& a, const TriangleMesh& b) {
  TriangleMesh m;
  m.source = "cup in front of a larger cup";
  m.V.resize(a.V.rows() + b.V.rows(), 3);
  m.V << a.V, b.V;
  m.F.resize(a.F.rows() + b.F.rows(), 3);
  m.F << a.F, (b.F.array() + static_cast<int>(a.V.rows())).matrix();
  return m;
}
// The mesh without its triangles edge-on to `o` (their plane through it): CGAL's ray-triangle
// intersection returns meaningless distances for a ray inside such a plane (hits at 19.5 mm on a
// 25 mm cup), and every ray meets their points on their neighbours too. The oracle uses this.
TriangleMesh without_edge_on(const TriangleMesh& m, const Eigen::Vector3d& o) {
  TriangleMesh r = m;
  std::vector<Eigen::Index> keep;
  for (Eigen::Index f = 0; f < m.F.rows(); ++f) {
    const Eigen::Vector3d a = m.V.row(m.F(f, 0)).transpose() - o, b = m.V.row(m.F(f, 1)).transpose() - o,
                          c = m.V.row(m.F(f, 2)).transpose() - o;
    if (std::abs((b - a).cross(c - a).normalized().dot(a)) > 1e-6 * a.norm()) keep.push_back(f);
  }
  r.F.resize(Eigen::Index(keep.size()), 3);
  for (std::size_t k = 0; k < keep.size(); ++k) r.F.row(Eigen::Index(k)) = m.F.row(keep[k]);
  return r;
}
const std::vector<std::pair<std::string, double>> kSchemes{
    {"equiangular", 0.5}, {"helix", 458}, {"helix-eq10", 458}, {"conchoid", 0.5}};
}  // namespace

TEST(DepthDiscontinuity, ASphereAboutTheCorMarksNothing) {
  const Eigen::Vector3d cor(3, -2, 7);
  const TriangleMesh ball = make_uv_sphere(22, cor, 720, 360, Eigen::Vector3d(0.3, 0.2, 0.93));
  for (const auto& [name, res] : kSchemes) {
    RadialDistanceMap map(make_scheme(name, res));
    sample_surface(ball, cor, SamplingOptions{}, map);
    EXPECT_EQ(mark_depth_discontinuities(map, 0.05), 0) << name;
    EXPECT_EQ(count_depth_discontinuities(map), 0) << name;
  }
}

TEST(DepthDiscontinuity, AJumpMarksTheNodesBesideItAndOnlyThose) {
  // Distance 20 mm on the northern hemisphere, 30 mm on the southern: a jump along the equator.
  for (const auto& [name, res] : kSchemes) {
    RadialDistanceMap map(make_scheme(name, res));
    const double h = map.scheme().max_node_spacing();
    for (std::int64_t i = 0; i < map.num_nodes(); ++i) map.data()[i] = map.scheme().node_direction(i).z() > 0 ? 20 : 30;
    const std::int64_t marked = mark_depth_discontinuities(map, 0.05);
    EXPECT_GT(marked, 0) << name;
    for (std::int64_t i = 0; i < map.num_nodes(); ++i) {
      const double lat = std::asin(std::clamp(map.scheme().node_direction(i).z(), -1.0, 1.0));
      const bool m = has_discontinuity_mark(map.at(i));
      if (std::abs(lat) > 2.5 * h) {
        ASSERT_FALSE(m) << name << " node " << i << " at latitude " << lat;
      }
    }
    // Every look-up straddling the equator comes back marked (-inf); far from it, the plain value.
    std::vector<double> x, y, z;
    for (int k = 0; k < 360; ++k) {
      const double th = k * kDegToRad + 0.1234;
      for (double lat : {0.3 * h, -0.3 * h, 0.3, -0.3}) {
        x.push_back(std::cos(lat) * std::cos(th)), y.push_back(std::cos(lat) * std::sin(th)), z.push_back(std::sin(lat));
      }
    }
    std::vector<double> out(x.size()), plain(x.size());
    map.lookup_many_soa_marked(x.data(), y.data(), z.data(), std::int64_t(x.size()), out.data());
    map.lookup_many_soa(x.data(), y.data(), z.data(), std::int64_t(x.size()), plain.data());
    for (std::size_t j = 0; j < x.size(); ++j) {
      if (j % 4 < 2) {
        EXPECT_EQ(out[j], -std::numeric_limits<double>::infinity()) << name << " point " << j;
      } else {
        EXPECT_EQ(out[j], plain[j]) << name << " point " << j;
      }
    }
  }
}

// The equiangular grid's marks (read by index) are those of its neighbour stencils (the definition, as the
// generic path computes it): on a rough map with steps, "no surface" patches and both poles, node by node.
TEST(DepthDiscontinuity, TheEquiangularMarksAreThoseOfItsNeighbourStencils) {
  for (const double p : {1.0, 0.25}) {
    RadialDistanceMap map(make_scheme("equiangular", p));
    const SamplingScheme& scheme = map.scheme();
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> U(0, 1);
    for (std::int64_t i = 0; i < map.num_nodes(); ++i) {
      const Eigen::Vector3d u = scheme.node_direction(i);
      double v = 25 + 0.02 * U(rng) + (u.x() > 0.3 ? 6 : 0);  // a step, and roughness near the tolerance
      if (u.y() > 0.8 && U(rng) < 0.5) v = std::numeric_limits<double>::infinity();  // patches of no surface
      map.data()[i] = static_cast<float>(v);
    }
    RadialDistanceMap reference = map;
    const std::int64_t marked = mark_depth_discontinuities(map, 0.05);
    std::int64_t expected = 0;
    std::vector<Stencil> nb(4);
    auto value_of = [&](const Stencil& st) {
      double v = 0;
      for (int k = 0; k < 4; ++k)
        if (st.weights[static_cast<std::size_t>(k)] > 0) {
          const double u = double(reference.at(st.nodes[static_cast<std::size_t>(k)]));
          if (!std::isfinite(u)) return std::numeric_limits<double>::infinity();
          v += st.weights[static_cast<std::size_t>(k)] * u;
        }
      return v;
    };
    for (std::int64_t i = 0; i < map.num_nodes(); ++i) {
      const double d = reference.at(i);
      bool m = false;
      if (std::isfinite(d)) {
        scheme.neighbour_stencils(i, 1, nb.data());
        const double dp = value_of(nb[0]) - 2 * d + value_of(nb[1]), dt = value_of(nb[2]) - 2 * d + value_of(nb[3]);
        m = !(std::abs(dp) <= 0.05 && std::abs(dt) <= 0.05);
      }
      expected += m;
      ASSERT_EQ(has_discontinuity_mark(map.at(i)), m) << "p " << p << " node " << i;
    }
    EXPECT_EQ(marked, expected);
    EXPECT_GT(marked, 0);
  }
}

TEST(DepthDiscontinuity, GapsAtARimMatchTheExactRadialGapForEveryScheme) {
  if (!have_exact_reference() || !FirstHitCaster::available()) GTEST_SKIP() << "no CGAL or Embree in this build";
  const Eigen::Vector3d cor(1, 2, 3), axis = Eigen::Vector3d(0.1, -0.2, 1).normalized();
  // Different angular grids for the three surfaces, so that no vertex lies exactly behind another.
  const TriangleMesh ball = make_uv_sphere(22, cor, 200, 100, Eigen::Vector3d(0.2, 0.3, 0.9));
  const TriangleMesh socket = merged(make_cup(25, 28, 100, cor, axis, 170, 70), make_cup(40, 44, 150, cor, axis, 230, 90));
  const ExactReference exact_socket(without_edge_on(socket, cor)), exact_ball(ball);
  for (const auto& [name, res] : kSchemes) {
    double worst[2] = {0, 0};
    for (bool refine : {true, false}) {
      JointOptions o;
      o.scheme = make_scheme(name, res);
      o.exact_at_discontinuities = refine;
      const Joint j(ball, socket, cor, o);
      // Rotated 30 deg about an axis across the cup, so that ball vertices look past the rim.
      const Eigen::Matrix3d R = Eigen::AngleAxisd(0.5, axis.unitOrthogonal()).toRotationMatrix();
      const PoseResult r = j.detect(R);
      if (refine) {
        EXPECT_GT(r.ball.vertices_refined, 0) << name;
      }
      for (Eigen::Index i = 0; i < ball.V.rows(); ++i) {
        if (r.ball_gaps.status[std::size_t(i)] != ScanGaps::tested) continue;
        const Eigen::Vector3d q = R * j.ball().relative.row(i).transpose();
        const auto h = exact_socket.first_hit(cor, q.normalized());
        if (!h) continue;
        worst[refine] = std::max(worst[refine], std::abs(r.ball_gaps.gap_mm[std::size_t(i)] - (*h - q.norm())));
      }
      if (!refine) continue;
      // The first-surface masks: exactly the vertices no nearer surface hides (1 mm tolerance).
      for (int body = 0; body < 2; ++body) {
        const JointBody& b = body == 0 ? j.ball() : j.socket();
        const ExactReference& own = body == 0 ? exact_ball : exact_socket;
        std::int64_t differ = 0;
        for (Eigen::Index i = 0; i < b.relative.rows(); ++i) {
          // Each cup's two shells share an angular grid, so a hidden vertex lies exactly behind a
          // vertex of the shell in front (or on the edge of its polar hole): the oracle takes the
          // nearest hit of rays within 1e-6 rad, the surface in front of the vertex's neighbourhood.
          const Eigen::Vector3d p = b.relative.row(i).transpose(), u = p.normalized();
          const Eigen::Vector3d e1 = u.unitOrthogonal(), e2 = u.cross(e1);
          double h = std::numeric_limits<double>::infinity();
          for (const Eigen::Vector3d& d : {u, Eigen::Vector3d(u + 1e-6 * e1), Eigen::Vector3d(u - 1e-6 * e1),
                                           Eigen::Vector3d(u + 1e-6 * e2), Eigen::Vector3d(u - 1e-6 * e2)}) {
            const auto hit = own.first_hit(cor, d.normalized());
            if (hit) h = std::min(h, *hit);
          }
          differ += (h >= p.norm() - 1.0) != (b.mask[std::size_t(i)] != 0);
        }
        EXPECT_EQ(differ, 0) << name << (body == 0 ? " ball" : " socket") << " mask";
      }
    }
    EXPECT_LE(worst[1], 0.05) << name << ": with exact look-ups at discontinuities";
    EXPECT_GT(worst[0], 1.0) << name << ": the maps alone straddle the 15 mm jump";
  }
}

TEST(DepthDiscontinuity, RejectsABadTolerance) {
  RadialDistanceMap map{EquiangularGrid(10)};
  EXPECT_THROW(mark_depth_discontinuities(map, 0), Error);
  EXPECT_THROW(mark_depth_discontinuities(map, std::nan("")), Error);
  JointOptions o;
  o.discontinuity_tolerance_mm = -1;
  const TriangleMesh ball = make_uv_sphere(22, Eigen::Vector3d::Zero(), 40, 20, Eigen::Vector3d::UnitZ());
  EXPECT_THROW(Joint(ball, ball, Eigen::Vector3d::Zero(), o), Error);
}
