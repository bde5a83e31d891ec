// The labrum in a ROM run (issue 81): the labral hip, its searches, its columns and record.
#include "labrum_run.hpp"

#include <cmath>
#include <limits>

#include "impinge/core/error.hpp"
#include "impinge/core/timing.hpp"

namespace impinge {

namespace {
constexpr const char* kWidthSource = "Tan et al. 2001, Am J Orthop 30:809 (55 embalmed hips: mean width 5.3 mm)";
constexpr const char* kHeightSource =
    "Won et al. 2003, Yonsei Med J 44:855 (54 cadaveric labra: anterior heights 7.0 and 7.4 mm, 4.0-6.8 mm elsewhere)";
constexpr const char* kLoweringSource =
    "PMC7754612 (19 CT arthrograms: the labrum lowered simulated internal rotation in flexion by a median 18 deg, "
    "IQR 15-25)";

// The angle at which a search met its body: 0 at the start, the limit, or +inf when free.
double met_at(const RomLimit& l) {
  if (l.status == RomLimitStatus::contact_at_start) return 0;
  if (l.status == RomLimitStatus::limited) return l.limit_deg;
  return std::numeric_limits<double>::infinity();
}
}  // namespace

LabralLimit labral_limit(const RomRun& run, std::size_t k) {
  require(run.labrum.has_value(), "labral limit: the ROM run has no labrum (--labrum)");
  require(k < run.motions.size() && k < run.limits.size() && k < run.labrum->contacts.size(),
          "labral limit: motion " + std::to_string(k) + " out of range");
  const RomLimit& bone = run.limits[k];
  const RomLimit& lab = run.labrum->contacts[k];
  LabralLimit out;
  out.labrum_contact_deg = lab.status == RomLimitStatus::contact_at_start ? 0.0 : lab.limit_deg;
  if (bone.status == RomLimitStatus::not_reachable || lab.status == RomLimitStatus::not_reachable) {
    out.status = RomLimitStatus::not_reachable;
    out.contact_class = bone.status == RomLimitStatus::not_reachable ? bone.contact_class : ContactClass::labral;
    return out;
  }
  const double b = met_at(bone), l = met_at(lab);
  const bool labrum_first = l < b;
  const RomLimit& first = labrum_first ? lab : bone;
  out.status = first.status;
  out.contact_class = first.contact_class;
  if (std::isfinite(std::min(b, l))) out.limit_deg = std::min(b, l);
  if (std::isfinite(b)) out.lowering_deg = b - std::min(b, l);
  return out;
}

TriangleMesh labrum_input(const Session& s, const RomRun& run) {
  require(run.labrum.has_value() && run.labrum->hip, "labrum: the ROM run has no labrum (--labrum)");
  const HipJoint& hip = *run.labrum->hip;
  TriangleMesh m = hip.joint().socket().mesh;  // joint frame, about the COR
  const Eigen::Matrix3d A = s.to_input() * hip.joint_to_working();
  const Eigen::Vector3d c = s.to_input(hip.cor());
  m.V = ((m.V * A.transpose()).rowwise() + c.transpose()).eval();
  return m;
}

namespace detail {

void run_labrum(const Session& s, const RomRequest& q, RomRun& run) {
  const auto t0 = Clock::now();
  LabrumRun L;
  L.options = q.labrum;
  try {
    L.hip = s.hip().with_labrum(q.labrum.width_mm, q.labrum.height_mm);
  } catch (const Error& e) {
    throw Error(std::string("--labrum: ") + e.what());
  }
  L.baseline = rom_baseline(*L.hip, L.hip->femur_rotation({}), q.search);
  L.contacts = find_rom_limits(*L.hip, run.motions, q.search, L.baseline);
  L.ms = ms_since(t0);
  run.labrum = std::move(L);
}

void add_labral_columns(Table& t, const RomRun& run) {
  for (const char* c : {"labral_limit_deg", "labral_status", "labral_contact_class", "labrum_contact_deg",
                        "labral_lowering_deg"})
    t.columns.emplace_back(c);
  for (std::size_t k = 0; k < t.rows.size(); ++k) {
    const LabralLimit l = labral_limit(run, k);
    for (nlohmann::json x : {number_or_null(l.limit_deg), nlohmann::json(to_string(l.status)),
                             nlohmann::json(to_string(l.contact_class)), number_or_null(l.labrum_contact_deg),
                             number_or_null(l.lowering_deg)})
      t.rows[k].push_back(std::move(x));
  }
}

nlohmann::json labrum_record(const RomRun& run) {
  const LabrumRun& L = *run.labrum;
  const JointBody& body = L.hip->joint().socket();
  nlohmann::json limits = nlohmann::json::array();
  for (std::size_t k = 0; k < run.motions.size(); ++k) {
    const LabralLimit l = labral_limit(run, k);
    limits.push_back({{"motion", run.motions[k].name},
                      {"bony_limit_deg", number_or_null(run.limits[k].limit_deg)},
                      {"bony_status", to_string(run.limits[k].status)},
                      {"labral_limit_deg", number_or_null(l.limit_deg)},
                      {"labral_status", to_string(l.status)},
                      {"labral_contact_class", to_string(l.contact_class)},
                      {"labrum_contact_deg", number_or_null(l.labrum_contact_deg)},
                      {"labral_lowering_deg", number_or_null(l.lowering_deg)},
                      {"note", L.contacts[k].note}});
  }
  return {{"width_mm", L.options.width_mm},
          {"height_mm", L.options.height_mm},
          {"width_default_source", kWidthSource},
          {"height_default_source", kHeightSource},
          {"geometry", "a ring of right-triangular cross-section on the rim (make_labrum): base across the rim from "
                       "the acetabular sphere outwards, apex along the sphere's tangent out of the acetabulum"},
          {"vertices", body.mesh.V.rows()},
          {"triangles", body.mesh.F.rows()},
          {"neutral_min_gap_mm", number_or_null(L.baseline.min_gap_mm)},
          {"excluded_vertices", L.baseline.excluded_vertices},
          {"published_internal_rotation_lowering", kLoweringSource},
          {"limits", limits},
          {"ms", L.ms}};
}

}  // namespace detail
}  // namespace impinge
