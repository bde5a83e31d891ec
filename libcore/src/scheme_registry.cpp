// The registry of sampling schemes: one line per scheme.
#include <functional>

#include "impinge/conchoid_grid.hpp"
#include "impinge/equiangular_grid.hpp"
#include "impinge/error.hpp"
#include "impinge/helix_scheme.hpp"
#include "impinge/sampling_scheme.hpp"

namespace impinge {

namespace {
struct Entry {
  const char* name;
  const char* resolution_name;
  double default_resolution;  // the scheme's equivalent of 0.5 deg node spacing
  std::function<std::shared_ptr<const SamplingScheme>(double)> make;
};
const std::vector<Entry>& registry() {
  static const std::vector<Entry> entries{
      {"equiangular", "precision_deg", 0.5, [](double p) { return std::make_shared<EquiangularGrid>(p); }},
      {"helix", "turns", matched_helix_turns(0.5), [](double k) { return std::make_shared<HelixScheme>(k); }},
      {"helix-eq10", "turns", matched_helix_turns(0.5), [](double k) { return std::make_shared<HelixScheme>(k, TraveledDistance::fitted); }},
      {"conchoid", "precision_deg", 0.5, [](double p) { return std::make_shared<ConchoidGrid>(p); }},
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

double default_resolution(const std::string& name) { return entry(name).default_resolution; }

std::vector<std::pair<std::string, std::string>> scheme_names() {
  std::vector<std::pair<std::string, std::string>> out;
  for (const Entry& e : registry()) out.emplace_back(e.name, e.resolution_name);
  return out;
}

}  // namespace impinge
