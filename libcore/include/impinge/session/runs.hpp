#pragma once
/// @file runs.hpp
/// The loops every front end runs on a Session: both scans at every frame of a motion, and the ROM
/// search (limits, ROM map, envelope), with their records as tables (the CLI's frames.csv,
/// rom_limits.csv, rom_map.csv and rom_envelope.csv; the Python module's dicts).

#include <Eigen/Core>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "impinge/clinical/rom.hpp"
#include "impinge/session/records.hpp"
#include "impinge/session/session.hpp"

namespace impinge {

/// One frame of a motion run, as the loop hands it to its caller.
struct MotionFrame {
  std::size_t index = 0;
  double time_s = 0;
  PoseAngles angles;                         ///< degrees, ISB
  FemurPose pose;                            ///< the femur's rotation and translation, joint frame
  /// The translation by the joint-centre method (HipJoint::joint_translation), input-frame axes, mm.
  Eigen::Vector3d joint_translation = Eigen::Vector3d::Zero();
  const PoseResult* result = nullptr;        ///< both scans (valid during the callback)
  ClockSummary ball_clock, socket_clock;     ///< closest hours (NaN with scan neutral)
  /// The socket vertex with the least gap, as Session::report_point gives it (pelvic frame with
  /// anatomical neutral, else the input frame), mm; NaN when no socket vertex was tested.
  Eigen::Vector3d socket_closest = Eigen::Vector3d::Constant(std::nan(""));
  /// Its class (HipJoint::contact_class): articular on the lunate surface, else intra- or
  /// extra-articular; none when no socket vertex was tested.
  ContactClass socket_closest_class = ContactClass::none;
  double detection_ms = 0;                   ///< both scans of this frame
};

/// The columns of a motion table for `levels` (frames.csv): frame, time_s, the three angles, both
/// least gaps (mm), penetrating areas (mm^2), the socket's area per level, both closest clock hours,
/// the socket's closest point (x, y, z mm) and its contact class, the femur's translation by the
/// joint-centre method (joint_translation_x/y/z_mm, input-frame axes), and detection_ms (with the
/// translation's iteration).
std::vector<std::string> motion_columns(const ImpingementLevels& levels);
/// One frame's row of that table.
nlohmann::json motion_row(const MotionFrame& frame);

/// Both scans at every pose of `angles` (k poses, degrees; `time_s`: k times or empty for the
/// index), calling `on_frame` for each, in order, on the calling thread. The frames are scanned on the
/// OpenMP threads (omp_get_max_threads), each taking the next frame, at most 16 per thread ahead of the
/// last frame handed over; the calling thread hands the frames over as they become ready and scans when
/// the next one is not, so that what `on_frame` does (writing a file) overlaps the other threads' scans.
/// Returns the wall time of the scans and the hand-overs, ms (the frames' own detection_ms add up to
/// more on several threads). Throws what `on_frame` throws (no frame after it is handed over), or the
/// error of the first frame whose scan failed (after the frames before it are handed over); times of
/// another length than the angles are an error.
double run_motion(const Session& session, const std::vector<PoseAngles>& angles, const std::vector<double>& time_s,
                  const std::function<void(const MotionFrame&)>& on_frame);

/// What a ROM run computes (RomOptions: threshold, search step and range). The front ends' defaults are
/// RunOptions::clinical()'s (option_table.hpp); these are the library's.
struct RomRequest {
  RomOptions search;
  bool limits = true;                     ///< the limits of the standard motions (rom_limits.csv)
  bool map = true;                        ///< the ROM map: the largest internal rotation per flexion x adduction
  /// The ROM map's flexion angles, deg (0..120 step 5, the thesis' sec. 5.2 range); empty: the default.
  std::vector<double> map_flexion_deg = angle_steps(0, 120, 5);
  /// The ROM map's adduction angles, deg (-20..40 step 5); empty: the default.
  std::vector<double> map_adduction_deg = angle_steps(-20, 40, 5);
  /// from, from + step, ... up to `to` (whole degrees).
  static std::vector<double> angle_steps(int from, int to, int step) {
    std::vector<double> v;
    for (int x = from; x <= to; x += step) v.push_back(x);
    return v;
  }
  bool envelope = false;                  ///< the ROM envelope (rom_envelope)
  RomEnvelopeOptions envelope_options;
  /// With the limits and anatomical neutral, the limits of the same motions in the other pelvic frame too
  /// (RomRun::other_limits: the ISB and the anterior pelvic plane frames side by side in rom_limits.csv).
  bool both_frames = true;
  /// With the limits and `labrum.enabled`: the acetabular labrum (HipJoint::with_labrum) and each motion's labral
  /// limit beside its bony one (RomRun::labrum; rom_limits.csv's labral columns). The ROM map and envelope stay bony.
  LabrumOptions labrum;
};

/// A ROM run's labrum (RomRequest::labrum): the labral hip and each standard motion's first contact of the femur
/// with the labrum alone (searched as the bony limits, with its own baseline at neutral).
struct LabrumRun {
  LabrumOptions options;                 ///< width and height asked for, mm
  std::shared_ptr<const HipJoint> hip;   ///< HipJoint::with_labrum of the session's hip
  RomBaseline baseline;                  ///< the labrum at neutral (labrum vertices in contact there are excluded)
  std::vector<RomLimit> contacts;        ///< one per motion: the femur's first contact with the labrum
  double ms = 0;                         ///< building the labral hip and its searches, ms
};

/// A motion's limit with the labrum: the first of its bony limit and its first labral contact (labral_limit).
struct LabralLimit {
  double limit_deg = std::numeric_limits<double>::quiet_NaN();  ///< NaN when free or not reachable
  RomLimitStatus status = RomLimitStatus::free;
  ContactClass contact_class = ContactClass::none;  ///< labral when the labrum is met first, else the bony limit's
  double labrum_contact_deg = std::numeric_limits<double>::quiet_NaN();  ///< first contact with the labrum alone
  /// How much the labrum lowers the limit: bony limit less labral limit, deg (0 when the bone is met first); NaN
  /// unless both are numbers (a motion free of bone but stopped by the labrum reads NaN: see the statuses).
  double lowering_deg = std::numeric_limits<double>::quiet_NaN();
};

/// The results of a ROM run and their cost.
struct RomRun {
  RomOptions search;
  RomBaseline baseline;                  ///< the neutral scan (vertices in contact there are excluded)
  std::vector<StandardMotion> motions;   ///< standard_motions()
  std::vector<RomLimit> limits;          ///< one per motion
  /// The same motions with their angles in the other pelvic frame (HipJoint::femur_rotation(angles, frame):
  /// about that frame's axes, from its neutral, with its own baseline there), one per motion; empty with scan
  /// neutral, without RomRequest::both_frames, or when that frame cannot be built (other_frame_note).
  std::vector<RomLimit> other_limits;
  /// With RomContacts::impingement and articular zones: the same motions searched with RomContacts::all (every
  /// contact counts), so that a contact the limit set aside as the joint surfaces meeting is said, with where
  /// (rom_limits_table's set_aside_* columns; issue 81); else empty.
  std::vector<RomLimit> all_contact_limits;
  std::optional<PelvisFrameKind> frame;        ///< the pelvic frame of limits' angles (empty: scan neutral)
  std::optional<PelvisFrameKind> other_frame;  ///< the frame of other_limits
  std::string other_frame_note;                ///< why other_limits is empty, else empty
  double other_limits_ms = 0;                  ///< their wall time, ms (baseline included)
  std::vector<double> map_flexion_deg, map_adduction_deg;
  std::vector<RomMapCell> map;           ///< flexion-major; empty without a map
  std::optional<RomEnvelope> envelope;
  RomEnvelopeOptions envelope_options;
  std::optional<LabrumRun> labrum;       ///< with RomRequest::labrum (and the limits)
  double limits_ms = 0, map_ms = 0, envelope_ms = 0;  ///< wall time, ms (the baseline counts with the limits)
  std::int64_t limit_evaluations = 0, map_evaluations = 0;
  std::int64_t vertices_looked_up = 0, vertices_skipped = 0;  ///< over limits, map and envelope
};

/// The session options a ROM run with `search` needs, from `options`: the distance hierarchies only for
/// RomMetric::distance, with a reach of max(threshold, 0) + 1 mm unless `options` gives one; levels on the
/// radial gap (a ROM run classifies no levels, so their thresholds do not constrain the reach). Source:
/// `impinge rom --metric`.
SessionOptions rom_session_options(SessionOptions options, const RomOptions& search);

/// The ROM limits of the standard motions from neutral (find_rom_limits), then the map and the
/// envelope as requested. Throws impinge::Error on bad options (RomOptions, RomEnvelopeOptions).
RomRun run_rom(const Session& session, const RomRequest& request);

/// rom_limits.csv: motion, limit_deg, first_contact_deg (where the bones first touch: limit_deg at contact
/// depth 0, else the depth-0 search's; RomLimit::first_contact_deg), status, limited_by, contact_class, pelvis_clock_h, femur_clock_h,
/// min_gap_at_limit_mm, monotone, contact_at_start, contact_x/y/z_mm (input frame),
/// joint_translation_x/y/z_mm (the femur's translation at the limit, input-frame axes), evaluations,
/// normal_deg and normal_source (the active range of living subjects, published_normal_range),
/// soft_tissue_first, pelvic_frame (the frame of limit_deg), limit_isb_deg, status_isb, limit_app_deg and
/// status_app (the motion's limit with its angles in each pelvic frame: one is limit_deg, the other
/// RomRun::other_limits; null with scan neutral), bony_normal_deg, bony_normal_frame and bony_normal_source
/// (published simulated bony ROM of normal hips, published_bony_range), femoral_zone and pelvic_zone (where the
/// limit's contact lies on each bone: RomLimit), set_aside_contact_deg, set_aside_contact_class,
/// set_aside_femoral_zone, set_aside_pelvic_zone (the first contact of every vertex, RomRun::all_contact_limits,
/// when it comes before the limit: the joint surfaces meeting, which the limit does not count; null/empty
/// otherwise), note; with RomRun::labrum also labral_limit_deg, labral_status, labral_contact_class,
/// labrum_contact_deg and labral_lowering_deg (labral_limit), last.
Table rom_limits_table(const Session& session, const RomRun& run);
/// The limit of motion `k` of `run` with its labrum (run.labrum set, k < run.motions.size()): not reachable when
/// either the bony search or the labral one cannot reach the motion's start; else the lesser of the bony limit
/// and the first labral contact (a contact at the start counting as 0 deg, a free motion as none), its status and
/// class with it (the bone's on a tie); free when neither is met. Throws impinge::Error without a labrum or with
/// k out of range. Source: impinge (issue 81).
LabralLimit labral_limit(const RomRun& run, std::size_t k);
/// The labrum of `run` (run.labrum) in the input frame of `session`, mm: the mesh `impinge rom --labrum` writes
/// (labrum.ply). Throws impinge::Error without a labrum.
TriangleMesh labrum_input(const Session& session, const RomRun& run);

/// rom_map.csv: flexion_deg, adduction_deg, max_internal_rotation_deg, status.
Table rom_map_table(const RomRun& run);
/// rom_envelope.csv: the valid runs of internal rotation per flexion and adduction (from, to).
Table rom_envelope_table(const RomRun& run);
/// The ROM part of summary.json: threshold, search, limits, envelope figures, counts, timings; with RomRun::labrum
/// a "labrum" object (its dimensions and their sources, mesh size, neutral clearance, each motion's labral limit).
nlohmann::json rom_record(const RomRun& run);

}  // namespace impinge
