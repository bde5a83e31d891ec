// USID helix scheme (thesis ch. 4):
//  - w = k^2 nodes, node 0 at the north pole, node w-1 at the south pole, consecutive nodes one
//    arc-length step apart (checked against the exact arc length);
//  - node(direction(i)) == i for every i at several k;
//  - the stencil's neighbours are the two nearest helix points (brute force over the nodes of
//    the turn) on each of the two bracketing turns, for random directions including the poles
//    and the theta seam;
//  - weights are >= 0 and sum to 1, so a constant map interpolates to the constant everywhere;
//  - Eq. 10 locating picks other neighbours for a fraction of directions (reported).
#include "impinge/schemes/helix_scheme.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <limits>
#include <random>
#include <set>

#include "impinge/core/error.hpp"
#include "impinge/core/spherical_frame.hpp"
#include "impinge/maps/radial_distance_map.hpp"

using namespace impinge;

namespace {
std::vector<Eigen::Vector3d> test_directions(std::uint64_t seed, int n) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> U(0, 1);
  std::vector<Eigen::Vector3d> d;
  for (int j = 0; j < n; ++j) d.push_back(direction(std::acos(2 * U(rng) - 1), 2 * kPi * U(rng)));
  for (double phi : {1e-6, 0.003, 0.02, kPi - 0.02, kPi - 0.003, kPi - 1e-6})  // poles
    for (double th : {0.0, 1e-9, 1.0, 2 * kPi - 1e-9}) d.push_back(direction(phi, th));
  for (int j = 0; j < 200; ++j) d.push_back(direction(std::acos(2 * U(rng) - 1), (j % 2 ? 1e-12 : -1e-12) + 0.0));
  for (auto& v : d) v.normalize();
  return d;
}
double angle(const Eigen::Vector3d& a, const Eigen::Vector3d& b) { return std::atan2(a.cross(b).norm(), a.dot(b)); }
}  // namespace

TEST(HelixScheme, NodesEquallySpacedAlongTheHelix) {
  for (double k : {2.0, 10.0, 40.0, 229.0}) {
    const HelixScheme h(k);
    ASSERT_EQ(h.num_nodes(), std::int64_t(k * k));
    EXPECT_LT((h.node_direction(0) - Eigen::Vector3d::UnitZ()).norm(), 1e-12);
    EXPECT_LT((h.node_direction(h.num_nodes() - 1) + Eigen::Vector3d::UnitZ()).norm(), 1e-12);
    std::vector<double> phi(h.num_nodes()), theta(h.num_nodes());
    h.node_angles(0, h.num_nodes(), phi.data(), theta.data());
    for (std::int64_t i = 0; i < h.num_nodes(); i += std::max<std::int64_t>(1, h.num_nodes() / 997)) {
      EXPECT_NEAR(h.arc_length().exact(phi[i]), double(i) * h.node_spacing(), 1e-9) << "k=" << k << " i=" << i;
      double t = std::fmod(2 * k * phi[i], 2 * kPi);
      EXPECT_NEAR(std::remainder(theta[i] - t, 2 * kPi), 0, 1e-9);  // on the helix theta = 2 k phi
    }
  }
  EXPECT_THROW(HelixScheme(1), Error);
  EXPECT_THROW(HelixScheme(10.5), Error);
}

TEST(HelixScheme, NodeOfDirectionRoundTrips) {
  for (double k : {3.0, 17.0, 100.0, 229.0}) {
    const HelixScheme h(k);
    std::vector<double> phi(h.num_nodes()), theta(h.num_nodes());
    h.node_angles(0, h.num_nodes(), phi.data(), theta.data());
    for (std::int64_t i = 0; i < h.num_nodes(); ++i) ASSERT_EQ(h.node(direction(phi[i], theta[i])), i) << "k=" << k;
  }
}

TEST(HelixScheme, NeighboursAreNearestOnBracketingTurns) {
  for (double k : {12.0, 40.0}) {
    const HelixScheme h(k);
    const std::int64_t w = h.num_nodes();
    std::vector<Eigen::Vector3d> node(w);
    for (std::int64_t i = 0; i < w; ++i) node[i] = h.node_direction(i);
    int checked = 0;
    for (const Eigen::Vector3d& u : test_directions(21, 3000)) {
      const Stencil st = h.interpolate(u);
      const SphericalCoordinates sc = to_spherical(u);
      // the helix crossings of u's meridian just above and below u (independent of the scheme)
      std::vector<double> crossings;
      for (int j = -1; j <= int(k) + 1; ++j) {
        const double p = (sc.theta + 2 * kPi * j) / (2 * k);
        if (p >= 0 && p <= kPi) crossings.push_back(p);
      }
      double above = -1, below = 10;
      for (double p : crossings) {
        if (p <= sc.phi) above = std::max(above, p);
        if (p > sc.phi) below = std::min(below, p);
      }
      for (int side = 0; side < 2; ++side) {
        const double pc = side == 0 ? above : below;
        const std::int64_t* nd = st.nodes.data() + 2 * side;
        if (pc < 0 || pc > kPi) {  // first / last turn: the pole node
          EXPECT_EQ(nd[0], side == 0 ? 0 : w - 1);
          continue;
        }
        // Within two turns of a pole the pole node itself can be nearer than the bracketing
        // pair (the turns shrink to the pole): the bracketing rule is checked away from there.
        if (pc < 2 * kPi / k || pc > kPi - 2 * kPi / k) continue;
        // brute force: the two nodes of this turn nearest to the crossing point
        const Eigen::Vector3d P = direction(pc, 2 * k * pc);
        const double s_c = h.arc_length().exact(pc), half_turn = kPi * std::sin(pc);
        std::vector<std::pair<double, std::int64_t>> near;
        for (std::int64_t i = 0; i < w; ++i)
          if (std::abs(double(i) * h.node_spacing() - s_c) <= half_turn + h.node_spacing())
            near.emplace_back(angle(node[i], P), i);
        if (near.size() < 3) continue;
        std::sort(near.begin(), near.end());
        const std::set<std::int64_t> brute{near[0].second, near[1].second}, got{nd[0], nd[1]};
        EXPECT_EQ(brute, got) << "k=" << k << " phi=" << sc.phi << " theta=" << sc.theta;
        ++checked;
      }
    }
    EXPECT_GT(checked, 3000);
  }
}

TEST(HelixScheme, ConstantMapInterpolatesToConstant) {
  for (const auto locate : {TraveledDistance::exact, TraveledDistance::fitted}) {
    const HelixScheme h(40, locate);
    RadialDistanceMap map{h};
    std::fill(map.data(), map.data() + map.num_nodes(), 17.25f);
    for (const Eigen::Vector3d& u : test_directions(5, 5000)) {
      const Stencil st = h.interpolate(u);
      double sum = 0;
      for (int j = 0; j < 4; ++j) {
        EXPECT_GE(st.weights[j], 0);
        EXPECT_GE(st.nodes[j], 0);
        EXPECT_LT(st.nodes[j], h.num_nodes());
        sum += st.weights[j];
      }
      EXPECT_NEAR(sum, 1, 1e-12);
      EXPECT_NEAR(map.lookup(3.0 * u), 17.25, 1e-5);
    }
  }
}

TEST(HelixScheme, Eq10LocatingDisagreesSometimes) {
  // The fitted formula is not the arc length: for large k it moves the located index by up to
  // about half a node (measured in experiment 07). Here: it disagrees for some directions but
  // its stencil still brackets the direction within one node spacing along the curve.
  const HelixScheme exact(229), fitted(229, TraveledDistance::fitted);
  int differ = 0, total = 0;
  for (const Eigen::Vector3d& u : test_directions(8, 20000)) {
    const Stencil a = exact.interpolate(u), b = fitted.interpolate(u);
    ++total;
    if (a.nodes != b.nodes) ++differ;
    for (int j = 0; j < 4; ++j) EXPECT_LE(std::abs(a.nodes[j] - b.nodes[j]), 1);
  }
  EXPECT_GT(differ, 0);
  EXPECT_LT(differ, total);
}

// The vectorised look-up (block stencils_soa through a map) against the scalar stencil (stencil_at
// through interpolate, combined here), on random values with holes (no surface), at random directions, directions
// in the first and last turns, and node directions themselves: the same value (to rounding) and
// the same no-surface verdict, except at node directions whose zero-weight neighbour has no surface.
TEST(HelixScheme, VectorisedLookUpEqualsTheScalarStencil) {
  std::mt19937_64 rng(17);
  std::normal_distribution<double> g;
  std::uniform_real_distribution<double> val(20, 60), unit(0, 1);
  for (double k : {3.0, 229.0, 2292.0}) {
    const auto hp = std::make_shared<HelixScheme>(k);
    const HelixScheme& h = *hp;
    RadialDistanceMap map(hp);
    float* values = map.data();
    for (std::int64_t i = 0; i < map.num_nodes(); ++i)
      values[i] = unit(rng) < 0.1 ? std::numeric_limits<float>::infinity() : float(val(rng));
    std::vector<double> x, y, z;
    for (int i = 0; i < 4000; ++i) {
      Eigen::Vector3d d(g(rng), g(rng), g(rng));
      if (i % 8 == 1) d = Eigen::Vector3d(1e-3 * g(rng), 1e-3 * g(rng), 1.0);   // first turn
      if (i % 8 == 2) d = Eigen::Vector3d(1e-3 * g(rng), 1e-3 * g(rng), -1.0);  // last turn
      if (i % 8 == 3) d = h.node_direction(std::uniform_int_distribution<std::int64_t>(0, h.num_nodes() - 1)(rng));
      x.push_back(d.x()), y.push_back(d.y()), z.push_back(d.z());
    }
    const auto n = static_cast<std::int64_t>(x.size());
    std::vector<double> pts, soa(static_cast<std::size_t>(n)), aos(static_cast<std::size_t>(n));
    for (std::int64_t i = 0; i < n; ++i) pts.insert(pts.end(), {x[i], y[i], z[i]});
    map.lookup_many_soa(x.data(), y.data(), z.data(), n, soa.data());
    for (std::int64_t i = 0; i < n; ++i) {
      const Stencil st = h.interpolate(Eigen::Vector3d(x[i], y[i], z[i]));
      double v = 0;
      for (int j = 0; j < 4; ++j) {
        if (st.weights[j] == 0) continue;
        const double d = values[st.nodes[j]];
        v = std::isfinite(d) ? v + st.weights[j] * d : std::numeric_limits<double>::quiet_NaN();
      }
      aos[std::size_t(i)] = v;
    }
    int nan = 0, knife_edge = 0;
    for (std::int64_t i = 0; i < n; ++i) {
      if (std::isnan(soa[i]) != std::isnan(aos[i])) {
        // Only at a node direction, where a neighbour's weight is 0 in exact arithmetic and
        // either exactly 0 or ~1e-16 after rounding (the two paths contract multiply-adds
        // differently): a neighbour without surface then counts in one path and not the other.
        EXPECT_EQ(i % 8, 3) << "k " << k << " point " << i;
        ++knife_edge;
        continue;
      }
      if (std::isnan(aos[i])) {
        ++nan;
        continue;
      }
      // The traveled distance reaches w = k^2 steps: its rounding (~w 2^-52 steps, the two paths
      // contract multiply-adds differently) times a neighbour difference of up to 40 mm.
      EXPECT_NEAR(soa[i], aos[i], 1e-6) << "k " << k << " point " << i;
    }
    EXPECT_GT(nan, 100);  // the holes are exercised
    EXPECT_LE(knife_edge, n / 80);
  }
}
