#pragma once
/// @file healpix_scheme.hpp
/// HEALPix sampling (Gorski et al. 2005, "HEALPix: a framework for high-resolution discretization
/// and fast analysis of data distributed on the sphere", ApJ 622:759), through the HEALPix C++
/// library (Debian's libhealpix-cxx-dev): 12 N_side^2 equal-area pixels on iso-latitude rings,
/// one node at each pixel centre, ring ordering, and the library's own 4-pixel interpolation
/// (T_Healpix_Base::get_interpol: linear in azimuth on the two bracketing rings, then linear in
/// z = cos(polar angle) between them; near the poles the missing ring is the pole's 4 pixels).
/// Any N_side >= 1 (ring ordering does not need a power of two).
///
/// Source: impinge (new sampling schemes; not in the thesis).

#include <cstdint>
#include <memory>
#include <string>

#include "impinge/schemes/sampling_scheme.hpp"

namespace impinge {

class HealpixScheme : public SchemeImpl<HealpixScheme> {
 public:
  /// N_side in [2, 13377] integral (12 N_side^2 nodes fit a map). Throws impinge::Error otherwise.
  explicit HealpixScheme(double nside);

  std::string name() const override { return "healpix"; }
  std::string resolution_name() const override { return "nside"; }
  double resolution() const override { return double(nside_); }
  std::int64_t num_nodes() const override { return 12 * nside_ * nside_; }
  Eigen::Vector3d node_direction(std::int64_t i) const override;
  /// Angles of the pixel centres (T_Healpix_Base::pix2ang): the resampling fast path.
  void node_angles(std::int64_t first, std::int64_t count, double* phi, double* theta) const override;
  /// The pixel that holds u (T_Healpix_Base::vec2pix).
  std::int64_t node(const Eigen::Vector3d& u) const override;
  /// sqrt(2) times the library's max_pixrad (the largest distance from a pixel centre to its
  /// corners): the distance between edge-neighbouring centres of a square pixel of that radius;
  /// radians.
  double max_node_spacing() const override { return max_spacing_; }
  /// The library's 4-pixel interpolation of the direction of (x, y, z) (any nonzero length).
  void stencil_at(double x, double y, double z, std::int64_t nodes[4], double w[4]) const;

 private:
  struct Base;  // the library's T_Healpix_Base<int64>, kept out of this header
  std::shared_ptr<const Base> base_;
  std::int64_t nside_;
  double max_spacing_;
};

}  // namespace impinge
