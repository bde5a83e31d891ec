#pragma once
/// @file fibonacci_scheme.hpp
/// The spherical Fibonacci lattice (Swinbank and Purser 2006) with the O(1) inverse of Keinert et
/// al. 2015 ("Spherical Fibonacci Mapping", ACM Trans. Graph. 34(6):193). Node i of n lies at
/// z_i = 1 - (2 i + 1) / n, azimuth 2 pi frac(i Phi) (Phi the golden ratio): equal area per node,
/// the most even covering of the schemes here at equal node count.
///
/// Look-up: in the (azimuth, z) plane, which is area-preserving, the nodes near a direction form a
/// lattice whose basis is the pair of Fibonacci numbers (F_k, F_k+1) chosen from the direction's z
/// (Keinert et al., sec. 3.2): F_k steps along the lattice change the azimuth by
/// 2 pi (frac((F_k + 1) Phi) - (Phi - 1)) and z by -2 F_k / n. The direction's lattice coordinates
/// give the parallelogram cell that holds it; the cell is split by its diagonal that is shorter on
/// the sphere (the local Delaunay triangulation), and the look-up is barycentric in that triangle
/// (three nodes; the fourth slot repeats one of them with weight 0). Across the boundary between two bases (a change of k)
/// the triangulations differ, so the look-up jumps there by at most the interpolation error. Near the
/// poles a lattice corner can fall outside [0, n): it is replaced by the nearest valid node (node 0
/// or n - 1), which is first order within about one node spacing of the pole.
///
/// Source: impinge (new sampling schemes; not in the thesis).

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "impinge/schemes/sampling_scheme.hpp"

namespace impinge {

class FibonacciScheme : public SchemeImpl<FibonacciScheme> {
 public:
  /// n >= 16 integral nodes, at most 2^31 - 1 (what a map holds). Throws impinge::Error otherwise.
  explicit FibonacciScheme(double nodes);

  std::string name() const override { return "fibonacci"; }
  std::string resolution_name() const override { return "nodes"; }
  double resolution() const override { return double(n_); }
  std::int64_t num_nodes() const override { return n_; }
  Eigen::Vector3d node_direction(std::int64_t i) const override;
  void node_angles(std::int64_t first, std::int64_t count, double* phi, double* theta) const override;
  /// The nearest of the four corners of the lattice cell that holds u (Keinert et al.'s inverse).
  std::int64_t node(const Eigen::Vector3d& u) const override;
  /// Longest edge of the look-up's triangles, radians: measured (first order in the spacing) over
  /// the lattice bases at 4,096 latitudes.
  double max_node_spacing() const override { return max_spacing_; }
  /// Barycentric stencil in the local Delaunay triangle (see the file comment).
  void stencil_at(double x, double y, double z, std::int64_t nodes[4], double w[4]) const;
  /// Block stencils (SamplingScheme::stencils_soa): the same computation as stencil_at, branch-free
  /// over the block so that it vectorises (AVX-512, AVX2 or plain, chosen at run time). With the
  /// native kernels (kernels.hpp) on an AVX-512 CPU, a block whose directions lie in fewer than
  /// kZoneWindow zones reads its zone parameters from registers instead of gathering them; the
  /// result differs from the generic kernel's by the rounding of fused multiply-adds (tested).
  void stencils_soa(const double* x, const double* y, const double* z, int n, std::int32_t* nodes,
                    double* w) const override;

  /// Zones the look-up can choose, at most: k = 2 .. 33 covers n < Phi^68 / (pi sqrt 5), far
  /// beyond the 2^31 nodes a map holds.
  static constexpr int kMaxZones = 32;
  /// Zones the AVX-512 block look-up holds in registers: a block whose directions span fewer
  /// zones takes its zone parameters from registers (the tables are padded by this many).
  static constexpr int kZoneWindow = 8;
  /// The lattice bases of the zones k = 2 .. k_max a look-up can choose, by zone (index k - 2),
  /// as arrays for the block look-up: Fibonacci numbers f0 = F_k, f1 = F_k+1; the inverse m of the
  /// basis matrix ((a0, a1), (z0, z1)) (lattice coordinates = m (azimuth, z - z_0)); a0 a1 and
  /// z0 z1 (which diagonal of a cell is shorter); and each zone's least n pi sqrt(5) (1 - z^2),
  /// Phi^(2k); each table padded to kMaxZones + kZoneWindow entries (starts with +inf).
  struct Zones {
    std::vector<double> f0, f1, m00, m01, m10, m11, a0a1, z0z1, start;
  };

 private:
  Zones zones_;
  /// Lattice cell of direction (x, y, z), in the block look-up's zone: corner indices i[4] of
  /// (c, c + e0, c + e1, c + e0 + e1), unclamped.
  void cell(double x, double y, double z, std::int64_t i[4]) const;
  /// Azimuth of node i in [0, 2 pi).
  double azimuth(std::int64_t i) const;
  std::int64_t n_;
  double inv_n_;
  double max_spacing_;
};

}  // namespace impinge
