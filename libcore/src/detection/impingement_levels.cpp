#include "impinge/detection/impingement_levels.hpp"

#include <sstream>

#include <algorithm>
#include <cmath>

#include "impinge/core/error.hpp"
#include "impinge/core/parse.hpp"

namespace impinge {

std::uint8_t ImpingementLevels::level(double gap_mm) const {
  const std::size_t last = thresholds_mm.size() - 1;
  if (gap_mm <= thresholds_mm[last]) return static_cast<std::uint8_t>(last + 1);
  std::uint8_t k = 0;
  for (std::size_t i = 0; i < last; ++i)
    if (gap_mm < thresholds_mm[i]) k = static_cast<std::uint8_t>(i + 1);
  return k;
}

void ImpingementLevels::validate() const {
  require(!thresholds_mm.empty() && thresholds_mm.size() < 250, "impingement levels: need 1 to 249 thresholds");
  for (std::size_t i = 0; i < thresholds_mm.size(); ++i) {
    require(std::isfinite(thresholds_mm[i]), [&] {
      return "impingement levels: threshold " + std::to_string(i + 1) + " (" + std::to_string(thresholds_mm[i]) +
             " mm) is not finite";
    });
    if (i > 0)
      require(thresholds_mm[i] < thresholds_mm[i - 1], [&] {
        std::ostringstream o;
        o << "impingement levels: threshold " << i + 1 << " (" << thresholds_mm[i] << " mm) is not below threshold "
          << i << " (" << thresholds_mm[i - 1] << " mm): the thresholds must decrease, e.g. 4,2.667,1.333,0";
        return o.str();
      });
  }
}

std::string ImpingementLevels::name(int level) const {
  static const char* names[] = {"none", "yellow", "orange", "red", "purple"};
  if (count() == 5 && level >= 0 && level < 5) return names[level];
  if (level == 0) return "none";
  return "level_" + std::to_string(level);
}

std::array<std::uint8_t, 3> level_colour(std::uint8_t level, int level_count, bool is_ball) {
  if (level == 255) return {200, 200, 200};
  if (level == 0) return is_ball ? std::array<std::uint8_t, 3>{40, 170, 60} : std::array<std::uint8_t, 3>{50, 100, 220};
  static const std::array<std::uint8_t, 3> ramp[] = {{255, 230, 0}, {255, 140, 0}, {220, 20, 20}, {140, 0, 200}};
  // Map levels 1..count-1 onto yellow..purple, purple always last.
  const int k = level_count <= 2 ? 3 : static_cast<int>(std::lround(3.0 * (level - 1) / (level_count - 2)));
  return ramp[std::clamp(k, 0, 3)];
}

ImpingementLevels parse_levels(const std::string& csv) {
  ImpingementLevels lv;
  lv.thresholds_mm = parse_number_list(csv, "impingement levels");
  lv.validate();
  return lv;
}

}  // namespace impinge
