#include "impinge/schemes/sampling_scheme.hpp"

#include "impinge/core/spherical_frame.hpp"

namespace impinge {

void SamplingScheme::node_angles(std::int64_t first, std::int64_t count, double* phi, double* theta) const {
  for (std::int64_t j = 0; j < count; ++j) {
    const SphericalCoordinates s = to_spherical(node_direction(first + j));
    phi[j] = s.phi;
    theta[j] = s.theta;
  }
}

}  // namespace impinge
