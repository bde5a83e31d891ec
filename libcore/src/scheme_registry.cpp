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
  std::function<std::shared_ptr<const SamplingScheme>(double)> make;
};
const std::vector<Entry>& registry() {
  static const std::vector<Entry> entries{
      {"equiangular", "precision_deg", [](double p) { return std::make_shared<EquiangularGrid>(p); }},
      {"helix", "turns", [](double k) { return std::make_shared<HelixScheme>(k); }},
      {"helix-eq10", "turns", [](double k) { return std::make_shared<HelixScheme>(k, TraveledDistance::fitted); }},
      {"conchoid", "precision_deg", [](double p) { return std::make_shared<ConchoidGrid>(p); }},
  };
  return entries;
}
}  // namespace

std::shared_ptr<const SamplingScheme> make_scheme(const std::string& name, double resolution) {
  std::string known;
  for (const Entry& e : registry()) {
    if (name == e.name) return e.make(resolution);
    known += std::string(known.empty() ? "" : ", ") + e.name;
  }
  throw Error("sampling scheme '" + name + "': unknown (registered: " + known + ")");
}

std::vector<std::pair<std::string, std::string>> scheme_names() {
  std::vector<std::pair<std::string, std::string>> out;
  for (const Entry& e : registry()) out.emplace_back(e.name, e.resolution_name);
  return out;
}

}  // namespace impinge
