// Conformance of every registered sampling scheme (scheme_names(), scheme_registry.cpp) at several
// resolutions, so that a new scheme is checked with no test code of its own (issue 12):
//  - node(node_direction(i)) == i, or a node of exactly the same direction (the equiangular grid's
//    pole rows repeat the pole), for every node at coarse resolutions and a sample at fine ones;
//  - stencils: node indices in range, weights >= 0 summing to 1, at random directions and at
//    directions at and near both poles and across the seam;
//  - the single look-up (interpolate and the weighted sum), the map's row-major batch (lookup_many)
//    and its structure-of-arrays batch (lookup_many_soa) give the same values within the rounding of
//    their angle computations, float and double maps;
//  - max_node_spacing() against brute force (CGAL kd-tree over the node directions): no direction
//    is farther than it from its nearest node, and it is not overstated (the largest such distance
//    is at least a quarter of it);
//  - resolution_for_spacing gives the coarsest resolution that reaches a node spacing;
//  - node_angles matches node_direction; block stencils (stencils_soa) are convex combinations;
//  - sparse maps give the dense maps' bits (plain and marked look-ups, float and double);
//  - a sampled sphere agrees with CGAL's exact first hit within the interpolation bound;
//  - capabilities (HEALPix's neighbors, query_disc, conformable): neighbour stencils are valid,
//    within four node spacings of their node and the same in blocks as one at a time; neighbours()
//    is sorted, unique and without the node; nodes_in_cap equals a brute-force scan over every node
//    (also at the poles, the seam, radius 0 and pi); a scheme is conformable with itself and with
//    the same scheme made again, not with another resolution or another scheme.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <random>

#include "impinge/casters/exact_reference.hpp"
#include "impinge/core/error.hpp"
#include "impinge/core/spherical_frame.hpp"
#include "impinge/io/generated_models.hpp"
#include "impinge/sampling/sampling.hpp"
#include "impinge/schemes/sampling_scheme.hpp"

using namespace impinge;

namespace {

// Resolutions in degrees ("precision_deg") are finer when smaller; every other resolution is a
// whole count (turns, cells, nside) that is finer when larger.
bool resolution_in_degrees(const std::string& unit) {
  return unit.size() > 4 && unit.compare(unit.size() - 4, 4, "_deg") == 0;
}

std::vector<Eigen::Vector3d> directions(std::mt19937_64& rng, int n) {
  std::normal_distribution<double> g(0, 1);
  std::vector<Eigen::Vector3d> out{Eigen::Vector3d::UnitZ(), -Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitX(),
                                   Eigen::Vector3d(1, -1e-15, 0).normalized(), Eigen::Vector3d(1, 1e-15, 0).normalized(),
                                   Eigen::Vector3d(1e-9, 0, 1).normalized(), Eigen::Vector3d(0, 1e-9, -1).normalized()};
  for (int i = 0; i < n; ++i) out.push_back(Eigen::Vector3d(g(rng), g(rng), g(rng)).normalized());
  for (int i = 0; i < n / 10; ++i)  // near the poles and the seam
    out.push_back(Eigen::Vector3d(1e-3 * g(rng), 1e-3 * g(rng), i % 2 ? 1 : -1).normalized()),
        out.push_back(Eigen::Vector3d(1, 1e-4 * g(rng), g(rng)).normalized());
  return out;
}

// One case: a registered scheme at the coarsest resolution with node spacings of at most 2 or 1 deg
// (resolution_for_spacing), or at its default (spacing_deg 0). The resolution is found when a test
// asks for it, not when the cases are listed: ctest runs each test in its own process, and finding
// every case's resolution up front cost each of them 1.6 s.
struct Case {
  std::string name;
  double spacing_deg;  // 2, 1, or 0 for default_resolution(name)
  double resolution() const {
    static std::map<std::pair<std::string, double>, double> found;
    const auto key = std::make_pair(name, spacing_deg);
    auto it = found.find(key);
    if (it == found.end())
      it = found.emplace(key, spacing_deg > 0 ? resolution_for_spacing(name, spacing_deg) : default_resolution(name)).first;
    return it->second;
  }
};
// Readable names in test output (gtest prints unknown types as bytes).
void PrintTo(const Case& c, std::ostream* os) {
  *os << c.name << (c.spacing_deg > 0 ? " at node spacing <= " + std::to_string(c.spacing_deg) + " deg" : " at its default");
}

std::vector<Case> cases() {
  std::vector<Case> out;
  for (const auto& [name, unit] : scheme_names())
    for (double p : {2.0, 1.0, 0.0}) out.push_back({name, p});
  return out;
}

}  // namespace

class SchemeConformance : public ::testing::TestWithParam<Case> {};

TEST_P(SchemeConformance, NodeOfItsOwnDirectionIsItself) {
  const auto s = make_scheme(GetParam().name, GetParam().resolution());
  const std::int64_t n = s->num_nodes();
  std::mt19937_64 rng(3);
  std::uniform_int_distribution<std::int64_t> pick(0, n - 1);
  const bool all = n <= 300000;
  std::int64_t wrong = 0, checked = 0;
  for (std::int64_t k = 0; k < (all ? n : 200000); ++k) {
    const std::int64_t i = all ? k : pick(rng);
    // A scheme may store one direction several times (the equiangular grid's pole rows hold
    // 360/p copies of each pole): then any node of that direction is the right answer.
    const Eigen::Vector3d d = s->node_direction(i);
    const std::int64_t j = s->node(d);
    wrong += j != i && s->node_direction(j) != d;
    ++checked;
  }
  EXPECT_EQ(wrong, 0) << s->name() << " " << s->resolution() << ": of " << checked;
}

TEST_P(SchemeConformance, NodeAnglesAreThoseOfNodeDirections) {
  // node_angles (the resampling fast path, overridden by most schemes) against the angles of
  // node_direction, on every node at coarse resolutions and a run of nodes at fine ones.
  const auto s = make_scheme(GetParam().name, GetParam().resolution());
  const std::int64_t n = std::min<std::int64_t>(s->num_nodes(), 300000);
  std::vector<double> phi(static_cast<std::size_t>(n)), theta(phi.size());
  s->node_angles(0, n, phi.data(), theta.data());
  for (std::int64_t i = 0; i < n; ++i) {
    const Eigen::Vector3d d = s->node_direction(i);
    const double sp = std::sin(phi[std::size_t(i)]);
    const Eigen::Vector3d a(sp * std::cos(theta[std::size_t(i)]), sp * std::sin(theta[std::size_t(i)]),
                            std::cos(phi[std::size_t(i)]));
    // Schemes may invert their node placement iteratively (the helix's arc length by Newton): a
    // billionth of the node spacing moves a resampled value by nothing measurable.
    ASSERT_LT((a - d).norm(), 1e-9 * s->max_node_spacing()) << s->name() << " node " << i;
    ASSERT_GE(theta[std::size_t(i)], 0) << s->name() << " node " << i;
    ASSERT_LT(theta[std::size_t(i)], 2 * M_PI) << s->name() << " node " << i;
  }
}

TEST_P(SchemeConformance, StencilsAreConvexCombinationsOfValidNodes) {
  const auto s = make_scheme(GetParam().name, GetParam().resolution());
  std::mt19937_64 rng(5);
  for (const Eigen::Vector3d& u : directions(rng, 20000)) {
    const Stencil st = s->interpolate(u);
    double sum = 0;
    for (int k = 0; k < 4; ++k) {
      ASSERT_GE(st.nodes[k], 0) << s->name() << " at " << u.transpose();
      ASSERT_LT(st.nodes[k], s->num_nodes()) << s->name() << " at " << u.transpose();
      ASSERT_GE(st.weights[k], 0) << s->name() << " at " << u.transpose();
      sum += st.weights[k];
    }
    ASSERT_NEAR(sum, 1.0, 1e-12) << s->name() << " at " << u.transpose();
  }
}

TEST_P(SchemeConformance, SingleBatchAndSoaLookUpsAgree) {
  const auto s = make_scheme(GetParam().name, GetParam().resolution());
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> val(20, 30);
  RadialDistanceMap mf(s);
  RadialDistanceMapDouble md(s);
  for (std::int64_t i = 0; i < s->num_nodes(); ++i) md.data()[i] = val(rng), mf.data()[i] = float(md.data()[i]);
  const std::vector<Eigen::Vector3d> dirs = directions(rng, 5000);
  const std::int64_t n = std::int64_t(dirs.size());
  std::vector<double> unit, scaled, x, y, z;
  for (const Eigen::Vector3d& u : dirs) {
    unit.insert(unit.end(), {u.x(), u.y(), u.z()});
    const Eigen::Vector3d p = 17.5 * u;  // any length: only the direction matters
    scaled.insert(scaled.end(), {p.x(), p.y(), p.z()});
    x.push_back(u.x()), y.push_back(u.y()), z.push_back(u.z());
  }
  for (int storage = 0; storage < 2; ++storage) {
    std::vector<double> batch(static_cast<std::size_t>(n)), soa(static_cast<std::size_t>(n)),
        far(static_cast<std::size_t>(n));
    if (storage == 0) {
      mf.lookup_many(unit.data(), n, batch.data());
      mf.lookup_many(scaled.data(), n, far.data());
      mf.lookup_many_soa(x.data(), y.data(), z.data(), n, soa.data());
    } else {
      md.lookup_many(unit.data(), n, batch.data());
      md.lookup_many(scaled.data(), n, far.data());
      md.lookup_many_soa(x.data(), y.data(), z.data(), n, soa.data());
    }
    for (std::int64_t j = 0; j < n; ++j) {
      const Stencil st = s->interpolate(dirs[std::size_t(j)]);
      double single = 0;
      for (int k = 0; k < 4; ++k) single += st.weights[k] * (storage == 0 ? double(mf.at(st.nodes[k])) : md.at(st.nodes[k]));
      // The block stencils may turn directions into angles with polynomials (fast_angles.hpp,
      // within 1e-13 rad): a weight moves by at most 1e-13 / h per unit (h the node spacing), a
      // look-up by at most 4e-13 / h times the spread of the values (10 mm here).
      const double tol = 4e-13 / s->max_node_spacing() * 10 + 1e-12 * single;
      ASSERT_NEAR(batch[std::size_t(j)], single, tol) << s->name() << " storage " << storage << " point " << j;
      // The row-major batch and the structure-of-arrays batch are the same block look-up.
      ASSERT_EQ(soa[std::size_t(j)], batch[std::size_t(j)]) << s->name() << " point " << j;
      // Only the direction matters: a point 17.5 mm out along it gives the same value up to the
      // rounding of its angles (1e-9 relative is far below any sampling error).
      ASSERT_NEAR(far[std::size_t(j)], batch[std::size_t(j)], 1e-9 * single) << s->name() << " point " << j;
    }
  }
}

TEST_P(SchemeConformance, BlockStencilsAreConvexCombinationsOfValidNodes) {
  const auto s = make_scheme(GetParam().name, GetParam().resolution());
  std::mt19937_64 rng(13);
  const std::vector<Eigen::Vector3d> dirs = directions(rng, 3000);
  std::vector<double> x, y, z;
  for (const Eigen::Vector3d& u : dirs) x.push_back(u.x()), y.push_back(u.y()), z.push_back(u.z());
  std::int32_t nd[4 * kStencilBlock];
  double w[4 * kStencilBlock];
  for (std::size_t b = 0; b < x.size(); b += kStencilBlock) {
    const int m = int(std::min<std::size_t>(kStencilBlock, x.size() - b));
    s->stencils_soa(x.data() + b, y.data() + b, z.data() + b, m, nd, w);
    for (int j = 0; j < m; ++j) {
      double sum = 0;
      for (int k = 0; k < 4; ++k) {
        ASSERT_GE(nd[k * m + j], 0) << s->name() << " at " << dirs[b + j].transpose();
        ASSERT_LT(nd[k * m + j], s->num_nodes()) << s->name() << " at " << dirs[b + j].transpose();
        ASSERT_GE(w[k * m + j], 0) << s->name() << " at " << dirs[b + j].transpose();
        sum += w[k * m + j];
      }
      ASSERT_NEAR(sum, 1.0, 1e-12) << s->name() << " at " << dirs[b + j].transpose();
    }
  }
}

TEST_P(SchemeConformance, SparseMapsGiveTheDenseMapsBits) {
  // A map with holes (no surface) and depth-discontinuity marks, dense against its sparse copies:
  // with the whole map as region every look-up has the same bits, plain and marked, float and
  // double; with a region of 25 mm, the same bits wherever every weighted node is within it, and
  // NaN (no surface within the region) wherever a weighted node lies in an absent tile.
  const auto s = make_scheme(GetParam().name, GetParam().resolution());
  std::mt19937_64 rng(15);
  std::uniform_real_distribution<double> val(20, 30), unit(0, 1);
  RadialDistanceMap mf(s);
  RadialDistanceMapDouble md(s);
  // Surfaces over a cap (z > 0.8, a tenth of the sphere), with holes and marks; nothing elsewhere.
  for (std::int64_t i = 0; i < s->num_nodes(); ++i) {
    if (s->node_direction(i).z() <= 0.8 || unit(rng) < 0.02) continue;
    double v = val(rng);
    float f = float(v);
    if (unit(rng) < 0.05) {  // a marked node: least significant bit set
      std::uint32_t bits;
      std::memcpy(&bits, &f, 4);
      bits |= 1u;
      std::memcpy(&f, &bits, 4);
    }
    mf.data()[i] = f, md.data()[i] = v;
  }
  const std::vector<Eigen::Vector3d> dirs = directions(rng, 5000);
  const std::int64_t n = std::int64_t(dirs.size());
  std::vector<double> x, y, z;
  for (const Eigen::Vector3d& u : dirs) x.push_back(u.x()), y.push_back(u.y()), z.push_back(u.z());
  auto bits_equal = [](double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; };
  auto check = [&](const auto& dense, auto sparse) {
    const auto un = static_cast<std::size_t>(n);
    std::vector<double> a(un), b(un), am(un), bm(un);
    const std::size_t dense_bytes = dense.bytes();
    sparse.make_sparse();
    EXPECT_TRUE(sparse.sparse());
    // How many tiles a cap touches depends on the node order (a tile is kTileNodes consecutive
    // indices): rows of a grid, turns of a helix, rings of HEALPix, rows of the octahedral square.
    EXPECT_LT(sparse.bytes(), dense_bytes * 3 / 4) << s->name() << ": nine tenths of the sphere have no surface";
    EXPECT_EQ(sparse.nodes_covered(), dense.nodes_covered());
    EXPECT_THROW((void)sparse.data(), Error);
    dense.lookup_many_soa(x.data(), y.data(), z.data(), n, a.data());
    sparse.lookup_many_soa(x.data(), y.data(), z.data(), n, b.data());
    dense.lookup_many_soa_marked(x.data(), y.data(), z.data(), n, am.data());
    sparse.lookup_many_soa_marked(x.data(), y.data(), z.data(), n, bm.data());
    int nan = 0, marked = 0;
    for (std::int64_t j = 0; j < n; ++j) {
      ASSERT_TRUE(bits_equal(a[j], b[j])) << s->name() << " point " << j << ": " << a[j] << " vs " << b[j];
      ASSERT_TRUE(bits_equal(am[j], bm[j])) << s->name() << " point " << j << ": " << am[j] << " vs " << bm[j];
      nan += std::isnan(a[j]), marked += am[j] == -std::numeric_limits<double>::infinity();
    }
    EXPECT_GT(nan, n / 4) << "the empty part is looked up";
    EXPECT_GT(marked, 0) << "marks are looked up";
    for (std::int64_t i = 0; i < dense.num_nodes(); i += 97) ASSERT_TRUE(bits_equal(dense.at(i), sparse.at(i)));
    // A copy of a sparse map is a sparse map with its own tiles.
    const auto copy = sparse;
    std::vector<double> c(un);
    copy.lookup_many_soa(x.data(), y.data(), z.data(), n, c.data());
    for (std::int64_t j = 0; j < n; ++j) ASSERT_TRUE(bits_equal(a[j], c[j]));
  };
  check(mf, mf);
  check(md, md);
  // A region of 25 mm keeps the tiles with a node within it.
  RadialDistanceMap near = mf;
  near.make_sparse(25.0);
  std::vector<double> a(static_cast<std::size_t>(n)), b(static_cast<std::size_t>(n));
  mf.lookup_many_soa(x.data(), y.data(), z.data(), n, a.data());
  near.lookup_many_soa(x.data(), y.data(), z.data(), n, b.data());
  int same = 0;
  for (std::int64_t j = 0; j < n; ++j) {
    const Stencil st = s->interpolate(dirs[std::size_t(j)]);
    bool all_kept = true;
    for (int k = 0; k < 4; ++k)
      if (st.weights[k] > 1e-9 && !(near.at(st.nodes[k]) == mf.at(st.nodes[k]))) all_kept = false;
    if (all_kept) {
      ASSERT_TRUE(bits_equal(a[j], b[j]) || (std::isnan(a[j]) && std::isnan(b[j]))) << s->name() << " point " << j;
      ++same;
    } else {
      ASSERT_TRUE(std::isnan(b[j])) << s->name() << " point " << j;
    }
  }
  EXPECT_GT(same, 0);
  EXPECT_THROW(near.make_sparse(std::nan("")), Error);
  RadialDistanceMap bad(s);
  EXPECT_THROW(bad.make_sparse(0), Error);
}

TEST_P(SchemeConformance, MaxNodeSpacingAgainstBruteForce) {
  if (!have_exact_reference()) GTEST_SKIP() << "no CGAL in this build";
  const auto s = make_scheme(GetParam().name, GetParam().resolution());
  if (s->num_nodes() > 300000) GTEST_SKIP() << "brute force at the coarse resolutions only";
  std::vector<Eigen::Vector3d> nodes;
  for (std::int64_t i = 0; i < s->num_nodes(); ++i) nodes.push_back(s->node_direction(i));
  const PointCloudIndex index(nodes);
  double largest_gap = 0;  // largest distance from a random direction to its nearest node (chord)
  std::mt19937_64 rng(9);
  for (const Eigen::Vector3d& u : directions(rng, 50000)) largest_gap = std::max(largest_gap, index.nearest_distance(u));
  const double spacing = s->max_node_spacing();
  const double gap_angle = 2 * std::asin(std::min(1.0, largest_gap / 2));
  // Every direction lies within the spacing of a node (a covering radius above the largest spacing
  // between neighbours would leave a hole between them).
  EXPECT_LE(gap_angle, spacing * (1 + 1e-9)) << s->name() << " " << s->resolution();
  // And the stated spacing is not overstated: the covering radius of a grid of spacing h is at
  // least h / 2 (half the largest gap between neighbours).
  EXPECT_GE(gap_angle, 0.5 * spacing / 2) << s->name() << " " << s->resolution();
}

TEST_P(SchemeConformance, ResolutionForSpacingIsTheCoarsestThatReachesIt) {
  // resolution_for_spacing(name, s): max_node_spacing <= s, and the next coarser resolution does not
  // reach s (minimal), for spacings around this case's own.
  const auto here = make_scheme(GetParam().name, GetParam().resolution());
  const double s_deg = here->max_node_spacing() * 180 / M_PI * 1.05;
  const double r = resolution_for_spacing(GetParam().name, s_deg);
  const auto s = make_scheme(GetParam().name, r);
  EXPECT_LE(s->max_node_spacing() * 180 / M_PI, s_deg * (1 + 1e-9)) << s->name() << " " << r;
  // The next coarser resolution the scheme accepts: one count fewer, or the next p = 180 / n.
  std::shared_ptr<const SamplingScheme> coarser;
  if (!resolution_in_degrees(s->resolution_name())) {
    if (r > 2) coarser = make_scheme(GetParam().name, r - 1);
  } else {
    for (long n = std::lround(180.0 / r) - 1; n >= 2 && !coarser; --n) {
      try {
        coarser = make_scheme(GetParam().name, 180.0 / double(n));
      } catch (const Error&) {
      }
    }
  }
  if (coarser) {
    EXPECT_GT(coarser->max_node_spacing() * 180 / M_PI, s_deg)
        << s->name() << ": " << coarser->resolution() << " also reaches " << s_deg << " deg";
  }
  EXPECT_THROW(resolution_for_spacing(GetParam().name, 0), Error);
  EXPECT_THROW(resolution_for_spacing(GetParam().name, -1), Error);
  EXPECT_THROW(resolution_for_spacing("no-such-scheme", 1), Error);
}

TEST_P(SchemeConformance, SampledSphereAgreesWithTheExactReference) {
  // Every scheme's map of a sphere 3 mm off the COR (radius 22 mm, 2-deg facets), filled with exact
  // node values (CGAL's first hit along every node's ray) and by its default method (rasterised, or
  // resampled from a rasterised equiangular map), looked up at random directions against CGAL's first
  // hit on the same mesh. Bound: bilinear or barycentric interpolation over nodes within 2 h of the point
  // (h = max_node_spacing) of a radius function whose second derivative is below 7 mm, plus twice
  // the facet sagitta; resampling adds the same bound at the temporary grid's spacing.
  if (!have_exact_reference()) GTEST_SKIP() << "no CGAL in this build";
  const auto s = make_scheme(GetParam().name, GetParam().resolution());
  if (s->num_nodes() > 30000) GTEST_SKIP() << "exact node values at the coarse resolutions only";
  const TriangleMesh mesh = make_uv_sphere(22, Eigen::Vector3d(1.5, -2.0, 1.6), 180, 90, Eigen::Vector3d(0.2, 0.1, 0.97));
  const ExactReference exact(mesh);
  RadialDistanceMap cast(s), fast(s);
  SamplingOptions o;
  const SamplingReport rep = sample_surface(mesh, Eigen::Vector3d::Zero(), o, fast);
  for (std::int64_t i = 0; i < s->num_nodes(); ++i) {
    const auto hit = exact.first_hit(Eigen::Vector3d::Zero(), s->node_direction(i));
    ASSERT_TRUE(hit.has_value()) << s->name() << " node " << i;
    cast.data()[i] = float(*hit);
  }
  auto bound = [](double h) { return (2 * h) * (2 * h) / 8 * 7; };
  const double sagitta = 22 * (1 - std::cos(std::sqrt(2.0) * 2 * M_PI / 180));
  const double h = s->max_node_spacing();
  const double cast_bound = bound(h) + 2 * sagitta + 1e-5;  // + float rounding of the node values
  const double fast_bound = cast_bound + bound(std::sqrt(2.0) * rep.resample_precision_deg * M_PI / 180);
  std::mt19937_64 rng(11);
  double worst_cast = 0, worst_fast = 0;
  for (const Eigen::Vector3d& u : directions(rng, 2000)) {
    const auto r = exact.first_hit(Eigen::Vector3d::Zero(), u);
    ASSERT_TRUE(r.has_value());
    worst_cast = std::max(worst_cast, std::abs(cast.lookup(u) - *r));
    worst_fast = std::max(worst_fast, std::abs(fast.lookup(u) - *r));
  }
  EXPECT_LT(worst_cast, cast_bound) << s->name() << " " << s->resolution();
  EXPECT_LT(worst_fast, fast_bound) << s->name() << " " << s->resolution() << " (" << to_string(rep.method) << ")";
  EXPECT_GT(worst_cast, 0);  // an interpolation, not a copy of the oracle
}

TEST_P(SchemeConformance, BadResolutionsAreRefusedByName) {
  // NaN, negative, zero and absurdly fine or coarse resolutions: an impinge::Error naming the scheme,
  // never a crash, a hang or a map too large to hold.
  const std::string name = GetParam().name;
  for (double r : {std::nan(""), -1.0, 0.0, 1e12, -1e12, std::numeric_limits<double>::infinity()}) {
    try {
      const auto s = make_scheme(name, r);
      ADD_FAILURE() << name << " accepted resolution " << r << " (" << s->num_nodes() << " nodes)";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(name.substr(0, 5)), std::string::npos) << e.what();
    }
  }
}

// Great-circle distance between two unit vectors, radians.
double arc(const Eigen::Vector3d& a, const Eigen::Vector3d& b) { return std::atan2(a.cross(b).norm(), a.dot(b)); }

TEST_P(SchemeConformance, NeighbourStencilsAreNearValidAndBlockIndependent) {
  const auto s = make_scheme(GetParam().name, GetParam().resolution());
  const std::int64_t n = s->num_nodes();
  const double h = s->max_node_spacing();
  std::mt19937_64 rng(11);
  std::uniform_int_distribution<std::int64_t> pick(0, n - 1);
  // A block that straddles the first nodes (a pole), one at the end, and random nodes.
  std::vector<std::int64_t> firsts{0, std::max<std::int64_t>(0, n - 300)};
  for (int k = 0; k < 20; ++k) firsts.push_back(std::min(pick(rng), n - 100));
  std::vector<Stencil> block(4 * 300), one(4);
  std::vector<std::int64_t> nb;
  for (const std::int64_t first : firsts) {
    const std::int64_t count = std::min<std::int64_t>(first == 0 || first + 300 >= n ? 300 : 100, n - first);
    s->neighbour_stencils(first, count, block.data());
    for (std::int64_t k = 0; k < count; ++k) {
      const std::int64_t i = first + k;
      s->neighbour_stencils(i, 1, one.data());
      const Eigen::Vector3d u = s->node_direction(i);
      for (int q = 0; q < 4; ++q) {
        const Stencil& st = block[static_cast<std::size_t>(4 * k + q)];
        double sum = 0;
        for (int j = 0; j < 4; ++j) {
          ASSERT_GE(st.nodes[j], 0) << i;
          ASSERT_LT(st.nodes[j], n) << i;
          ASSERT_GE(st.weights[j], -1e-12) << i;  // HEALPix rounds to -2e-16
          sum += st.weights[j];
          if (st.weights[j] > 0) {
            EXPECT_LE(arc(u, s->node_direction(st.nodes[j])), 4 * h) << "node " << i;
          }
        }
        EXPECT_NEAR(sum, 1, 1e-9) << "node " << i;
        // The same stencil from a block and from a single call, to the rounding of a vectorised
        // stencil: the same weighted direction.
        Eigen::Vector3d a = Eigen::Vector3d::Zero(), b = Eigen::Vector3d::Zero();
        for (int j = 0; j < 4; ++j) {
          a += st.weights[j] * s->node_direction(st.nodes[j]);
          b += one[q].weights[j] * s->node_direction(one[q].nodes[j]);
        }
        EXPECT_LT((a - b).norm(), 1e-9) << "node " << i << ", neighbour " << q << ": block and single calls differ";
      }
      s->neighbours(i, nb);
      EXPECT_FALSE(nb.empty()) << "node " << i;
      EXPECT_TRUE(std::is_sorted(nb.begin(), nb.end()));
      EXPECT_EQ(std::adjacent_find(nb.begin(), nb.end()), nb.end()) << "node " << i << ": repeated neighbour";
      EXPECT_EQ(std::find(nb.begin(), nb.end(), i), nb.end()) << "node " << i << " is its own neighbour";
    }
  }
  EXPECT_THROW(s->neighbours(n, nb), Error);
  EXPECT_THROW(s->neighbours(-1, nb), Error);
}

TEST_P(SchemeConformance, NodesInCapEqualABruteForceScan) {
  const auto s = make_scheme(GetParam().name, GetParam().resolution());
  const std::int64_t n = s->num_nodes();
  std::vector<Eigen::Vector3d> node(static_cast<std::size_t>(n));
  for (std::int64_t i = 0; i < n; ++i) node[static_cast<std::size_t>(i)] = s->node_direction(i);
  std::mt19937_64 rng(12);
  std::vector<Eigen::Vector3d> dirs = directions(rng, 12);
  if (n > 100000) dirs.resize(5);                         // the poles and the seam only
  dirs.push_back(node[static_cast<std::size_t>(n / 3)]);  // exactly on a node
  const double h = s->max_node_spacing();
  std::vector<std::int64_t> got;
  for (const Eigen::Vector3d& d : dirs)
    for (double r : {0.0, 0.5 * h, 3 * h, 0.3, 2.0, kPi}) {
      // Nodes within 1e-12 of the boundary may fall either way (the rounding of the normalisation).
      const Eigen::Vector3d u = d.normalized();
      const double c = std::cos(r);
      s->nodes_in_cap(3.0 * d, r, got);
      ASSERT_TRUE(std::is_sorted(got.begin(), got.end()));
      ASSERT_EQ(std::adjacent_find(got.begin(), got.end()), got.end());
      std::size_t k = 0;
      std::int64_t missing = 0, extra = 0;
      for (std::int64_t i = 0; i < n; ++i) {
        const double dot = node[static_cast<std::size_t>(i)].dot(u);
        const bool in = k < got.size() && got[k] == i;
        k += in;
        missing += !in && dot >= c + 1e-12;
        extra += in && dot < c - 1e-12;
      }
      EXPECT_EQ(k, got.size()) << "node indices out of range";
      ASSERT_EQ(missing + extra, 0) << "direction (" << u.transpose() << "), radius " << r << " rad: " << missing
                                    << " nodes of the cap missing, " << extra << " outside it returned";
    }
  EXPECT_THROW(s->nodes_in_cap(Eigen::Vector3d::Zero(), 0.1, got), Error);
  EXPECT_THROW(s->nodes_in_cap(Eigen::Vector3d::UnitZ(), -0.1, got), Error);
  EXPECT_THROW(s->nodes_in_cap(Eigen::Vector3d(std::nan(""), 0, 1), 0.1, got), Error);
}

TEST_P(SchemeConformance, ConformableWithItselfOnly) {
  const std::string& name = GetParam().name;
  const double r = GetParam().resolution();
  const auto s = make_scheme(name, r);
  EXPECT_TRUE(s->conformable(*s));
  EXPECT_TRUE(s->conformable(*make_scheme(name, r)));
  // Another resolution of the same scheme, and every other registered scheme at a resolution of its own.
  const double other = resolution_for_spacing(name, GetParam().spacing_deg == 2.0 ? 1.0 : 2.0);
  if (other != r) {
    EXPECT_FALSE(s->conformable(*make_scheme(name, other)));
  }
  for (const auto& [n2, unit] : scheme_names()) {
    if (n2 != name) {
      EXPECT_FALSE(s->conformable(*make_scheme(n2, resolution_for_spacing(n2, 2.0)))) << n2;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Registered, SchemeConformance, ::testing::ValuesIn(cases()),
                         [](const ::testing::TestParamInfo<Case>& i) {
                           std::string n = i.param.name + (i.param.spacing_deg > 0 ? "_" + std::to_string(int(i.param.spacing_deg)) + "deg" : "_default");
                           for (char& c : n)
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           return n;
                         });
