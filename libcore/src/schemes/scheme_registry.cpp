// The registry of sampling schemes: one line per scheme.
#include <algorithm>
#include <cmath>
#include <functional>

#include "impinge/core/error.hpp"
#include "impinge/core/spherical_frame.hpp"
#include "impinge/schemes/conchoid_grid.hpp"
#include "impinge/schemes/equiangular_grid.hpp"
#include "impinge/schemes/fibonacci_scheme.hpp"
#include "impinge/schemes/healpix_scheme.hpp"
#include "impinge/schemes/helix_scheme.hpp"
#include "impinge/schemes/octahedral_scheme.hpp"
#include "impinge/schemes/sampling_scheme.hpp"

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
      {"fibonacci", "nodes", 0, Resolution::whole_count,
       [](double n) { return std::make_shared<FibonacciScheme>(n); }},
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
  const Entry& e = entry(name);
  try {
    return e.make(resolution);
  } catch (const Error& err) {  // name the scheme in every refusal
    const std::string what = err.what();
    if (what.find(name) != std::string::npos) throw;
    throw Error("sampling scheme '" + name + "': " + what);
  }
}

double default_resolution(const std::string& name) {
  const Entry& e = entry(name);
  return e.default_resolution > 0 ? e.default_resolution : resolution_for_spacing(name, 0.5);
}

double resolution_for_spacing(const std::string& name, double spacing_deg) {
  const Entry& e = entry(name);
  require(std::isfinite(spacing_deg) && spacing_deg > 0 && spacing_deg <= 90,
          "sampling scheme '" + name + "': node spacing " + std::to_string(spacing_deg) + " deg outside (0, 90]");
  // The finest spacing searched: 0.01 deg is 6.5e8 nodes (2.6 GB) per equiangular map; below 0.0055 deg no
  // equiangular grid fits a map's 2^31 - 1 nodes, and the search for one would not end.
  require(spacing_deg >= 0.01, [&] {
    return "sampling scheme '" + name + "': node spacing " + std::to_string(spacing_deg) +
           " deg is finer than the finest searched, 0.01 deg (6.5e8 nodes, 2.6 GB per map)";
  });
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
  // A whole count k (turns, cells, nside, nodes; finer when larger), from the smallest the scheme
  // accepts. Bracket the target by doubling, then narrow the bracket [lo, hi] (spacing(lo) > target >=
  // spacing(hi)) with power-law guesses (spacings fall as k^-a: a = 1 for turns and cells, 1/2 for node
  // counts) until hi = lo + 1. The bracket, not monotonicity, makes hi the coarsest that reaches it.
  double lo = 2;
  double s_lo = 0;
  for (;; lo *= 2) {
    try {
      s_lo = spacing(lo);
      break;
    } catch (const Error&) {
      require(lo < 1e9, "sampling scheme '" + name + "': accepts no whole-count resolution");
    }
  }
  if (s_lo <= target) return lo;
  double hi = lo, s_hi = s_lo;
  while (s_hi > target) {
    lo = hi, s_lo = s_hi;
    hi *= 2;
    require(hi < 1e12, "sampling scheme '" + name + "': no resolution reaches a node spacing of " +
                           std::to_string(spacing_deg) + " deg");
    s_hi = spacing(hi);
  }
  while (hi - lo > 1) {
    const double a = std::log(s_lo / s_hi) / std::log(hi / lo);
    double k = a > 0 ? std::round(lo * std::pow(s_lo / target, 1 / a)) : std::round((lo + hi) / 2);
    k = std::clamp(k, lo + 1, hi - 1);
    const double s_k = spacing(k);
    if (s_k <= target) {
      hi = k, s_hi = s_k;
      // The guess tends to land just inside: test its coarser neighbour before guessing again.
      if (hi - lo > 1) {
        const double s_below = spacing(hi - 1);
        if (s_below > target) return hi;
        hi = hi - 1, s_hi = s_below;
      }
    } else {
      lo = k, s_lo = s_k;
      if (hi - lo > 1) {
        const double s_above = spacing(lo + 1);
        if (s_above <= target) return lo + 1;
        lo = lo + 1, s_lo = s_above;
      }
    }
  }
  return hi;
}

std::vector<std::pair<std::string, std::string>> scheme_names() {
  std::vector<std::pair<std::string, std::string>> out;
  for (const Entry& e : registry()) out.emplace_back(e.name, e.resolution_name);
  return out;
}

}  // namespace impinge
