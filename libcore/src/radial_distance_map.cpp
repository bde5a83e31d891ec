#include "impinge/radial_distance_map.hpp"

#include "impinge/error.hpp"

namespace impinge {

template <typename Scalar>
const EquiangularGrid& RadialDistanceMapT<Scalar>::grid() const {
  const auto* g = dynamic_cast<const EquiangularGrid*>(scheme_.get());
  require(g != nullptr, "this operation needs an equiangular map; the map uses the '" + scheme_->name() + "' scheme");
  return *g;
}

template class RadialDistanceMapT<float>;
template class RadialDistanceMapT<double>;
}  // namespace impinge
