// A plan run's outputs (plan_run.hpp): its record, plan.json, and the resected meshes.
#include <cmath>

#include "impinge/io/mesh_io.hpp"
#include "impinge/io/vtk_output.hpp"
#include "impinge/session/plan_run.hpp"
#include "impinge/session/records.hpp"

namespace impinge {

namespace {

/// One bone's resection in plan.json: whether resected, volume (mm^3), area (mm^2), deepest and mean cut (mm),
/// vertices (all, at the safety depth, held by thickness) and the clock extent (hours; k: 0 femur, 1 pelvis).
nlohmann::json bone_record(const PlanRun& run, const BoneResection& b, int k) {
  nlohmann::json r = {{"resected", b.allowed},
                      {"volume_mm3", b.volume_mm3},
                      {"area_mm2", b.area_mm2},
                      {"deepest_cut_mm", b.deepest_cut_mm},
                      {"mean_depth_mm", b.mean_depth_mm},
                      {"vertices", b.vertices},
                      {"vertices_at_safety_depth", b.capped_vertices},
                      {"vertices_held_by_thickness", b.thin_vertices},
                      {"clock_from_h", number_or_null(run.clock_from_h[k])},
                      {"clock_to_h", number_or_null(run.clock_to_h[k])}};
  return r;
}

/// A point or vector (input frame), NaN entries as null.
nlohmann::json point(const Eigen::Vector3d& v) {
  return {number_or_null(v.x()), number_or_null(v.y()), number_or_null(v.z())};
}

/// A target's clearance in the final placement (PlanTargetCheck's clearance_*; mm, and deg or frame); with the labrum
/// also least_labrum_mm.
nlohmann::json clearance_record(const PlanRun& run, const PlanTargetCheck& c) {
  nlohmann::json r = {{"required_mm", run.plan.options.clearance_mm},
          {"least_mm", number_or_null(c.clearance_least_mm)},
          {"least_at", number_or_null(c.clearance_least_at)},
          {"at_target_mm", number_or_null(c.clearance_at_target_mm)},
          {"poses", c.clearance_poses},
          {"met", c.clearance_met},
          {"least_any_mm", number_or_null(c.clearance_least_any_mm)},
          {"definition",
           "in the final placement, over the poses the plan cleared: the least signed distance between the vertices "
           "the plan follows (the ROM search's, joint surfaces left out) and the other bone (least_mm, where: "
           "least_at, deg or frame; at the target's own pose: at_target_mm); least_any_mm: over every vertex, the "
           "joint surfaces too (the plan does not follow these: a contact classed articular shows there)"}};
  if (run.labrum) {
    r["least_labrum_mm"] = number_or_null(c.clearance_least_labrum_mm);
    r["labrum"] = "with the labrum the femur is also kept the clearance from the labrum: least_mm, at_target_mm and "
                  "least_any_mm are the lesser of the bones' and the femur's to the labrum (least_labrum_mm: that "
                  "one alone)";
  }
  return r;
}

/// A standard motion's labral limits before and after (PlanTargetCheck::labral_*), into target record `t`, and which
/// limit the plan targeted.
void add_labral_limits(nlohmann::json& t, const PlanTargetCheck& c) {
  t["limit_targeted"] = "labral";
  t["labral_limit_before_deg"] = number_or_null(c.labral_before->limit_deg);
  t["labral_status_before"] = to_string(c.labral_before->status);
  t["labral_contact_class_before"] = to_string(c.labral_before->contact_class);
  t["labral_limit_after_deg"] = number_or_null(c.labral_after->limit_deg);
  t["labral_status_after"] = to_string(c.labral_after->status);
  t["labral_contact_class_after"] = to_string(c.labral_after->contact_class);
}

/// plan.json's "labrum" (with the labrum): its dimensions, what the plan targets, and the labrum's displacement
/// between the plan's session and the last check's (mm).
nlohmann::json labrum_plan_record(const PlanRun& run) {
  return {{"width_mm", run.labrum->width_mm},
          {"height_mm", run.labrum->height_mm},
          {"vertices", run.labrum_mesh.V.rows()},
          {"moved_mm", number_or_null(run.labrum_moved_mm)},
          {"targeted", "labral limits"},
          {"definition",
           "the acetabular labrum (impinge rom --labrum; labrum.ply, input frame) is a soft-tissue body: the plan "
           "targets each motion's labral limit (the first of the bony limit and the femur's first contact with the "
           "labrum: labral_limit_*), cutting the femur so that at every target pose it clears both the pelvis and "
           "the labrum by the clearance. The labrum is never cut, and a contact with it is cleared on the femur "
           "alone (with --resect both the rim is trimmed for bony contacts only). limit_before_deg and "
           "limit_after_deg stay the bony limits. moved_mm: the largest distance between the labrum's vertices here "
           "and the labrum the last check built again on the bones after (impinge, issue 81)"}};
}

/// The femur's alpha angles (deg) before and after the resection, per head-neck clock hour 1..12 and the largest;
/// after: null when not measured. Needs run.before.
nlohmann::json alpha_record(const PlanRun& run) {
  nlohmann::json a = nlohmann::json::object();
  a["before_deg"] = nlohmann::json::array();
  a["after_deg"] = nlohmann::json::array();
  for (int h = 0; h < 12; ++h) {
    a["before_deg"].push_back(number_or_null(run.before->alpha_deg[static_cast<std::size_t>(h)]));
    a["after_deg"].push_back(run.after ? number_or_null(run.after->alpha_deg[static_cast<std::size_t>(h)]) : nullptr);
  }
  a["max_before_deg"] = number_or_null(run.before->alpha_max_deg);
  a["max_after_deg"] = run.after ? number_or_null(run.after->alpha_max_deg) : nullptr;
  a["definition"] = "alpha angle per head-neck clock hour 1..12 (Notzli et al. 2002; impinge morphology)";
  a["axes"] = {{"frame", "femur before the resection"},
               {"head_centre_mm", point(run.reference_head_centre_mm)},
               {"head_radius_mm", number_or_null(run.reference_head_radius_mm)},
               {"neck_axis", point(run.reference_neck_axis)},
               {"definition",
                "before and after measured about the same head sphere, neck axis (head-neck clock) and frames, those "
                "of the femur before the resection (impinge morphology on the input, input frame): the resected "
                "femur's own are not fitted again, so only the cut changes an angle"}};
  return a;
}

/// plan.json's targets: each one's angle (deg), whether met (its limit, its clearance in the final placement: mm),
/// what the plan reached and its note; a standard motion's limits (deg) and statuses before and after and its
/// shortfall (deg), a motion file's frames in contact.
nlohmann::json targets_record(const PlanRun& run) {
  nlohmann::json targets = nlohmann::json::array();
  for (std::size_t k = 0; k < run.targets.size(); ++k) {
    const PlanTargetCheck& c = run.targets[k];
    const ResectionTargetResult& r = run.plan.targets[k];
    nlohmann::json t = {{"target", c.name},
                        {"target_deg", number_or_null(c.target_deg)},
                        {"met", c.met},
                        {"limit_met", c.limit_met},
                        {"clearance", clearance_record(run, c)},
                        {"planned_reachable", r.reachable},
                        {"planned_reachable_deg", number_or_null(r.reachable_deg)},
                        {"poses", r.poses},
                        {"poses_cleared", r.poses_cleared},
                        {"note", r.note}};
    if (!std::isnan(c.target_deg)) {
      t["limit_before_deg"] = number_or_null(c.before.limit_deg);
      t["status_before"] = to_string(c.before.status);
      t["limit_after_deg"] = number_or_null(c.after.limit_deg);
      t["status_after"] = to_string(c.after.status);
      t["shortfall_deg"] = c.shortfall_deg;
      if (c.labral_before && c.labral_after) add_labral_limits(t, c);
    } else {
      t["frames_in_contact_before"] = c.frames_in_contact_before;
      t["frames_in_contact_after"] = c.frames_in_contact_after;
    }
    targets.push_back(t);
  }
  return targets;
}

}  // namespace

nlohmann::json plan_record(const PlanRun& run) {
  nlohmann::json j;
  const ResectionOptions& o = run.plan.options;
  j["subject"] = run.subject;
  j["femur"] = run.femur_source;
  j["pelvis"] = run.pelvis_source;
  j["head_centre_mm"] = {run.head_centre_mm.x(), run.head_centre_mm.y(), run.head_centre_mm.z()};
  j["input_frame"] = run.input_frame == FrameConvention::LPS ? "LPS" : "RAS";
  // The frames of the angles and where the head centre came from (issue 81): the targets' and limits' angles are
  // joint angles in the pelvic frame named here, as rom_limits.csv's pelvic_frame.
  j["pelvic_frame"] = run.pelvic_frame;
  j["pose_convention"] =
      "ISB joint coordinate system (Wu et al. 2002) in the pelvic frame pelvic_frame: flexion, adduction and internal "
      "rotation positive; left hips mirrored";
  j["head_centre_obtained"] = run.cor_method;
  j["method"] =
      "least removal: per vertex, the depth that keeps every target pose's counted contacts at least the clearance "
      "apart (exact signed distances, iterated on the resected bones), widened to what a spherical burr cuts, "
      "capped at the safety depth, never on the articular surfaces (impinge, clinical/resection.hpp)";
  j["options"] = {{"resect", to_string(o.bones)},
                  {"clearance_mm", o.clearance_mm},
                  {"burr_radius_mm", o.burr_radius_mm},
                  {"max_depth_fraction", run.request.max_depth_fraction},
                  {"max_depth_mm", run.request.max_depth_mm},
                  {"tolerance_mm", o.tolerance_mm}};
  j["neck_diameter_mm"] = number_or_null(run.neck_diameter_mm);
  j["safety_depth"] = {{"value_mm", run.safety_depth_mm},
                       {"source", "Mardones et al. 2005, J Bone Joint Surg Am 87:273 (30 % of the neck's diameter)"}};
  j["femur_resection"] = bone_record(run, run.plan.femur, 0);
  j["pelvis_resection"] = bone_record(run, run.plan.pelvis, 1);
  if (run.before) j["femur_resection"]["alpha"] = alpha_record(run);
  j["targets"] = targets_record(run);
  if (run.labrum) j["labrum"] = labrum_plan_record(run);
  j["all_targets_met"] = run.all_met;
  j["clearance_met"] = run.clearance_met;
  j["placement"] = {
      {"head_centre_before_mm", point(run.head_centre_mm)},
      {"head_centre_final_mm", point(run.final_head_centre_mm)},
      {"head_centre_shift_mm", number_or_null((run.final_head_centre_mm - run.head_centre_mm).norm())},
      {"definition",
       "the check's placement (the last check): a new session on the resected bones, as `impinge rom` on the written "
       "meshes, its femoral head, equidistant joint centre, acetabulum and joint surfaces found on them; each target's "
       "limit and clearance are checked there (input frame, mm)"}};
  j["plan"] = {{"iterations", run.plan.iterations},
               {"rounds", run.plan.rounds},
               {"passes", run.plan.passes},
               {"residual_mm", run.plan.residual_mm},
               {"poses", run.plan.poses},
               {"contacts", run.plan.contacts}};
  j["timings_ms"] = {{"setup", run.setup_ms},
                     {"limits_before", run.before_ms},
                     {"plan", run.plan_ms},
                     {"check", run.check_ms},
                     {"total", run.total_ms}};
  j["notes"] = run.notes;
  j["warnings"] = run.warnings;
  j["meshes"] = run.meshes;
  return j;
}

void write_plan_meshes(const std::string& dir, const PlanRun& run) {
  auto one = [&](const TriangleMesh& m, const BoneResection& b, const std::vector<double>& hours, const char* stem) {
    std::vector<PointArray> arrays(1);
    arrays[0].name = "resection_mm";
    for (double d : b.depth_mm) arrays[0].f32.push_back(static_cast<float>(d));
    if (!hours.empty()) {
      PointArray h;
      h.name = "clock_hour";
      for (double x : hours) h.f32.push_back(static_cast<float>(x));
      arrays.push_back(h);
    }
    write_ply(dir + "/" + stem + ".ply", m, arrays);
    write_vtp(dir + "/" + stem + ".vtp", m.V, m.F, arrays);
  };
  if (run.plan.femur.allowed) one(run.femur_resected, run.plan.femur, run.femur_hours, "femur_resected");
  if (run.plan.pelvis.allowed) one(run.pelvis_resected, run.plan.pelvis, run.pelvis_hours, "pelvis_resected");
  if (run.labrum) write_ply(dir + "/labrum.ply", run.labrum_mesh);
}

}  // namespace impinge
