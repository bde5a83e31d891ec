#include "impinge/maps/layered_map.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "impinge/core/error.hpp"

namespace impinge {

double signed_radial_distance(const RayCrossing* c, int n, bool complete, double r) {
  const double inf = std::numeric_limits<double>::infinity();
  int j = 0;  // crossings at or before r
  while (j < n && c[j].distance_mm <= r) ++j;
  if (j == n && !complete) return std::numeric_limits<double>::quiet_NaN();
  if (n == 0) return inf;
  const bool inside = j > 0 ? c[j - 1].entering : !c[0].entering;
  double d = inf;
  if (j > 0) d = r - c[j - 1].distance_mm;
  if (j < n) d = std::min(d, c[j].distance_mm - r);
  return inside ? -d : d;
}

LayeredMap::LayeredMap(std::shared_ptr<const SamplingScheme> scheme, int layers)
    : scheme_(std::move(scheme)), layers_(layers) {
  require(scheme_ != nullptr, "layered map: no sampling scheme");
  require(layers >= 1 && layers <= kMaxLayers, "layered map: layers must be 1 to " + std::to_string(kMaxLayers) +
                                                   ", not " + std::to_string(layers));
  num_nodes_ = scheme_->num_nodes();
  require(num_nodes_ <= kMaxMapNodes, "layered map: the " + scheme_->name() + " scheme has too many nodes (" +
                                          std::to_string(num_nodes_) + ")");
  value_.assign(static_cast<std::size_t>(num_nodes_) * static_cast<std::size_t>(layers_),
                std::numeric_limits<float>::infinity());
  count_.assign(static_cast<std::size_t>(num_nodes_), 0);
}

void LayeredMap::set(std::int64_t i, const std::vector<RayCrossing>& c) {
  require(i >= 0 && i < num_nodes_, [&] { return "layered map: node " + std::to_string(i) + " out of range"; });
  const int k = std::min<int>(layers_, static_cast<int>(c.size()));
  float* v = value_.data() + static_cast<std::size_t>(i) * static_cast<std::size_t>(layers_);
  for (int j = 0; j < layers_; ++j)
    v[j] = j < k ? static_cast<float>(c[static_cast<std::size_t>(j)].entering ? -c[static_cast<std::size_t>(j)].distance_mm
                                                                             : c[static_cast<std::size_t>(j)].distance_mm)
                 : std::numeric_limits<float>::infinity();
  count_[static_cast<std::size_t>(i)] =
      static_cast<std::uint8_t>(k | (static_cast<int>(c.size()) > layers_ ? 0x80 : 0));
}

double LayeredMap::node_signed_distance(std::int64_t i, double r) const {
  RayCrossing c[kMaxLayers];
  const int n = count(i);
  for (int k = 0; k < n; ++k) c[k] = crossing(i, k);
  return signed_radial_distance(c, n, !truncated(i), r);
}

void LayeredMap::signed_distance_many_soa(const double* x, const double* y, const double* z, std::int64_t n,
                                          double* out, std::uint8_t* exact_needed, double spread_mm) const {
  std::int32_t nodes[4 * kStencilBlock];
  double w[4 * kStencilBlock];
  for (std::int64_t b = 0; b < n; b += kStencilBlock) {
    const int m = static_cast<int>(std::min<std::int64_t>(kStencilBlock, n - b));
    scheme_->stencils_soa(x + b, y + b, z + b, m, nodes, w);
    for (int j = 0; j < m; ++j) {
      const std::int64_t p = b + j;
      const double r = std::sqrt(x[p] * x[p] + y[p] * y[p] + z[p] * z[p]);
      double sum = 0, weight = 0;
      bool unknown = !(r > 0);
      int first = -1;
      bool disagree = false;
      for (int k = 0; k < 4; ++k) {
        const double wk = w[k * m + j];
        if (!(wk > 0)) continue;
        const std::int64_t i = nodes[k * m + j];
        if (exact_needed != nullptr) {
          if (first < 0) {
            first = static_cast<int>(i);
          } else if (!disagree) {
            const std::int64_t f = first;
            disagree = count_[static_cast<std::size_t>(i)] != count_[static_cast<std::size_t>(f)];
            for (int l = 0; !disagree && l < count(i); ++l)
              disagree = std::abs(crossing(i, l).distance_mm - crossing(f, l).distance_mm) > spread_mm;
          }
        }
        const double s = node_signed_distance(i, r);
        if (std::isnan(s)) unknown = true;
        if (std::isfinite(s)) sum += wk * s, weight += wk;
      }
      out[p] = unknown ? std::numeric_limits<double>::quiet_NaN()
                       : weight > 0 ? sum / weight
                                    : std::numeric_limits<double>::infinity();
      if (exact_needed != nullptr) exact_needed[p] = disagree ? 1 : 0;
    }
  }
}

std::uint64_t radial_shell_bits(double lo, double hi, double bin_mm) {
  auto bin = [&](double r) {
    const double b = r / bin_mm;
    return b >= 63 ? 63 : b > 0 ? static_cast<int>(b) : 0;
  };
  std::uint64_t m = 0;
  for (int k = bin(lo); k <= bin(hi); ++k) m |= std::uint64_t(1) << k;
  return m;
}

std::uint64_t LayeredMap::occupancy(std::int64_t i, double bin_mm) const {
  auto span = [&](double a, double b) { return radial_shell_bits(a, b, bin_mm); };
  const int n = count(i);
  if (n == 0) return truncated(i) ? ~std::uint64_t(0) : 0;
  std::uint64_t m = 0;
  // Inside from the COR to the first crossing when that one leaves the solid.
  double from = crossing(i, 0).entering ? -1 : 0;
  for (int k = 0; k < n; ++k) {
    const RayCrossing c = crossing(i, k);
    m |= span(c.distance_mm, c.distance_mm);
    if (c.entering) {
      from = c.distance_mm;
    } else if (from >= 0) {
      m |= span(from, c.distance_mm);
      from = -1;
    }
  }
  // Inside beyond the last crossing (a mesh not closed), or unknown beyond it: to the last shell.
  if (from >= 0 || truncated(i)) m |= span(crossing(i, n - 1).distance_mm, 1e300);
  return m;
}

}  // namespace impinge
