#include "impinge/core/parse.hpp"

#include <cmath>
#include <sstream>

#include "impinge/core/error.hpp"

namespace impinge {

std::vector<double> parse_number_list(const std::string& text, const std::string& what, std::size_t count) {
  std::vector<double> v;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    bool ok = false;
    try {
      std::size_t used = 0;
      v.push_back(std::stod(item, &used));
      ok = used == item.size() && std::isfinite(v.back());
    } catch (const std::exception&) {
    }
    if (!ok) throw Error(what + " '" + text + "': '" + item + "' is not a finite number");
  }
  require(!v.empty(), what + " '" + text + "': no numbers given");
  if (count > 0)
    require(v.size() == count,
            what + " '" + text + "': expected " + std::to_string(count) + " comma-separated numbers");
  return v;
}

}  // namespace impinge
