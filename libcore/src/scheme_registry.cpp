// The registry of sampling schemes: one line per scheme.
#include <cmath>
#include <functional>

#include "impinge/conchoid_grid.hpp"
#include "impinge/equiangular_grid.hpp"
#include "impinge/error.hpp"
#include "impinge/healpix_scheme.hpp"
#include "impinge/helix_scheme.hpp"
#include "impinge/octahedral_scheme.hpp"
#include "impinge/sampling_scheme.hpp"
#include "impinge/spherical_frame.hpp"

namespace impinge {

namespace {
/// How a scheme's resolution parameter runs, for resolution_for_spacing.
enum class Resolution {
  degrees_dividing_180,  ///< a precision p in degrees with 180 / p integral; finer is smaller
  whole_count,           ///< a whole number (turns, rings) of at least 2; finer is larger
};
struct Entry {
  const char* name;
  const char* resolution_name;
  double default_resolution;  // the scheme's equivalent of 0.5 deg node spacing; 0: resolution_for_spacing(0.5)
  Resolution kind;
  std::function<std::shared_ptr<const SamplingScheme>(double)> make;
};
const std::vector<Entry>& registry() {
  static const std::vector<Entry> entries{
      {"equiangular", "precision_deg", 0.5, Resolution::degrees_dividing_180,
       [](double p) { return std::make_shared<EquiangularGrid>(p); }},
      {"helix", "turns", matched_helix_turns(0.5), Resolution::whole_count,
       [](double k) { return std::make_shared<HelixScheme>(k); }},
      {"helix-eq10", "turns", matched_helix_turns(0.5), Resolution::whole_count,
       [](double k) { return std::make_shared<HelixScheme>(k, TraveledDistance::fitted); }},
      {"conchoid", "precision_deg", 0.5, Resolution::degrees_dividing_180,
       [](double p) { return std::make_shared<ConchoidGrid>(p); }},
      {"octahedral", "cells_per_side", 0, Resolution::whole_count,
       [](double n) { return std::make_shared<OctahedralScheme>(n); }},
      {"healpix", "nside", 0, Resolution::whole_count,
       [](double n) { return std::make_shared<HealpixScheme>(n); }},
  };
  return entries;
}

const Entry& entry(const std::string& name) {
  std::string known;
  for (const Entry& e : registry()) {
    if (name == e.name) return e;
    known += std::string(known.empty() ? "" : ", ") + e.name;
  }
  throw Error("sampling scheme '" + name + "': unknown (registered: " + known + ")");
}
}  // namespace

std::shared_ptr<const SamplingScheme> make_scheme(const std::string& name, double resolution) {
  return entry(name).make(resolution);
}

double default_resolution(const std::string& name) {
  const Entry& e = entry(name);
  return e.default_resolution > 0 ? e.default_resolution : resolution_for_spacing(name, 0.5);
}

double resolution_for_spacing(const std::string& name, double spacing_deg) {
  const Entry& e = entry(name);
  require(std::isfinite(spacing_deg) && spacing_deg > 0 && spacing_deg <= 90,
          "sampling scheme '" + name + "': node spacing " + std::to_string(spacing_deg) + " deg outside (0, 90]");
  const double target = spacing_deg * kDegToRad * (1 + 1e-12);
  auto spacing = [&](double r) { return e.make(r)->max_node_spacing(); };
  if (e.kind == Resolution::degrees_dividing_180) {
    // p = 180 / n for n = 2, 3, ...: the first n the scheme accepts (the conchoid grid wants 90 / p
    // integral too) with a small enough spacing.
    for (long n = std::max(2L, long(std::ceil(180 / spacing_deg - 1e-9)));; ++n) {
      const double p = 180.0 / double(n);
      double s = 0;
      try {
        s = spacing(p);
      } catch (const Error&) {
        continue;  // not a resolution of this scheme
      }
      if (s <= target) return p;
      require(n < 100 * long(std::ceil(180 / spacing_deg)) + 1000,
              "sampling scheme '" + name + "': no resolution reaches a node spacing of " + std::to_string(spacing_deg) + " deg");
    }
  }
  // A whole count k >= 2: from the estimate k ~ (k0 s(k0)) / target, step to the smallest k that
  // reaches the target (the spacing falls as k grows).
  const double k0 = std::max(2.0, matched_helix_turns(spacing_deg));
  double k = std::max(2.0, std::ceil(k0 * spacing(k0) / target));
  while (spacing(k) > target) ++k;
  while (k > 2 && spacing(k - 1) <= target) --k;
  return k;
}

std::vector<std::pair<std::string, std::string>> scheme_names() {
  std::vector<std::pair<std::string, std::string>> out;
  for (const Entry& e : registry()) out.emplace_back(e.name, e.resolution_name);
  return out;
}

}  // namespace impinge
