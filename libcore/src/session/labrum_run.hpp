#pragma once
// The labrum's part of a ROM run (runs.hpp's RomRequest::labrum, RomRun::labrum), apart from runs.cpp.
#include "impinge/session/runs.hpp"

namespace impinge::detail {

/// The labral hip of `session` and each of run.motions' first contact with the labrum (run.labrum), with
/// request.search and a baseline at neutral. Throws impinge::Error as HipJoint::with_labrum does, naming the option.
void run_labrum(const Session& session, const RomRequest& request, RomRun& run);
/// rom_limits.csv's labral columns (labral_limit of each row's motion), appended to `table` (one row per motion).
void add_labral_columns(Table& table, const RomRun& run);
/// summary.json's "labrum" object.
nlohmann::json labrum_record(const RomRun& run);

}  // namespace impinge::detail
