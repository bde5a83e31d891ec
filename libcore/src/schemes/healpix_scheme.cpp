#include "impinge/schemes/healpix_scheme.hpp"

#include <healpix_base.h>

#include <cmath>
#include <sstream>

#include "impinge/core/error.hpp"

namespace impinge {

struct HealpixScheme::Base : T_Healpix_Base<int64> {
  explicit Base(int64 nside) : T_Healpix_Base<int64>(nside, RING, SET_NSIDE) {}
};

HealpixScheme::HealpixScheme(double nside) {
  std::ostringstream os;
  os << "healpix scheme: nside " << nside << " must be a whole number in [2, 13377] (12 nside^2 nodes; a map holds "
     << "at most 2^31 - 1)";
  require(std::isfinite(nside) && nside >= 2 && nside <= 13377 && nside == std::round(nside), os.str());
  nside_ = static_cast<std::int64_t>(nside);
  base_ = std::make_shared<const Base>(nside_);
  max_spacing_ = std::sqrt(2.0) * base_->max_pixrad();
}

Eigen::Vector3d HealpixScheme::node_direction(std::int64_t i) const {
  const vec3 v = base_->pix2vec(i);
  return Eigen::Vector3d(v.x, v.y, v.z).normalized();
}

void HealpixScheme::node_angles(std::int64_t first, std::int64_t count, double* phi, double* theta) const {
  for (std::int64_t j = 0; j < count; ++j) {
    const pointing a = base_->pix2ang(first + j);
    phi[j] = a.theta;  // HEALPix' theta is the colatitude: our phi (thesis Eq. 5)
    theta[j] = a.phi;
  }
}

std::int64_t HealpixScheme::node(const Eigen::Vector3d& u) const {
  const Eigen::Vector3d d = u.normalized();
  return base_->vec2pix(vec3(d.x(), d.y(), d.z()));
}

void HealpixScheme::stencil_at(double x, double y, double z, std::int64_t nodes[4], double w[4]) const {
  fix_arr<int64, 4> pix;
  fix_arr<double, 4> wgt;
  // The library wants the azimuth in [0, 2 pi): with a negative one its polar-cap branch returns
  // negative pixel indices (found by the conformance test).
  double phi = std::atan2(y, x);
  if (phi < 0) phi += 2 * M_PI;
  if (phi >= 2 * M_PI) phi = 0;
  base_->get_interpol(pointing(std::atan2(std::sqrt(x * x + y * y), z), phi), pix, wgt);
  for (int k = 0; k < 4; ++k) nodes[k] = pix[k], w[k] = wgt[k];
}

}  // namespace impinge
