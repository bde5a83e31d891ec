#include "impinge/radial_distance_map.hpp"

namespace impinge {
template class RadialDistanceMapT<float>;
template class RadialDistanceMapT<double>;
}  // namespace impinge
