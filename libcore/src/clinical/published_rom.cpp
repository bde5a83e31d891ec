#include "impinge/clinical/published_rom.hpp"

#include <cmath>
#include <limits>

namespace impinge {

PublishedRange published_normal_range(const std::string& m) {
  constexpr const char* aaos = "AAOS 1965, Joint Motion: Method of Measuring and Recording";
  constexpr const char* kouyoumdjian = "Kouyoumdjian et al. 2012, Orthop Traumatol Surg Res 98:17-23";
  if (m == "flexion") return {120, aaos};
  if (m == "extension") return {30, aaos};
  if (m == "abduction") return {45, aaos};
  if (m == "adduction") return {30, aaos};
  if (m == "internal_rotation") return {35.2, kouyoumdjian};
  if (m == "external_rotation") return {41.8, kouyoumdjian};
  if (m == "internal_rotation_90_flexion") return {37.9, kouyoumdjian};
  if (m == "external_rotation_90_flexion") return {40.6, kouyoumdjian};
  return {std::numeric_limits<double>::quiet_NaN(), ""};
}

BonyRange published_bony_range(const std::string& m) {
  if (m == "fadir")
    return {27.9, "not stated",
            "Audenaert et al. 2012, Am J Sports Med 40:1329-1336: 10 healthy controls, 3-D computational simulation "
            "of the impingement test (flexion, adduction, internal rotation), mean internal rotation"};
  return {std::numeric_limits<double>::quiet_NaN(), "", ""};
}

bool soft_tissue_first(const std::string& motion, double limit_deg) {
  const PublishedRange r = published_normal_range(motion);
  if (std::isnan(r.normal_deg)) return false;
  return std::isnan(limit_deg) || limit_deg > r.normal_deg;
}

}  // namespace impinge
