#pragma once
/// @file outputs.hpp
/// A run's output folder, and the posed bones with their gaps as mesh files, in the input frame: PLY per
/// bone (the CLI's femur_gaps.ply and pelvis_gaps.ply) and one VTK PolyData per motion frame (ParaView).
/// Every file is written whole or not at all (core/atomic_file.hpp).

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "impinge/detection/joint.hpp"
#include "impinge/io/generated_models.hpp"
#include "impinge/io/motion.hpp"
#include "impinge/session/session.hpp"

namespace impinge {

/// The file a run keeps in its output folder while it writes: its outputs are complete only when
/// summary.json is there and this file is not.
inline constexpr const char* kIncompleteMarker = "INCOMPLETE";

/// The lock a run holds on its output folder from begin_output_folder to end_output_folder: "PID HOST impinge COMMAND
/// STARTED" (issue 80: two runs on one --out wrote into each other's files).
inline constexpr const char* kOutputLock = ".impinge.lock";

/// Open `dir` for a run's outputs: create it, take its lock (kOutputLock; a live run's lock on this machine, or any
/// on another host, is refused naming the holder; one left by a run that ended, or an empty one from a full disk, is
/// taken over), create `subfolders` inside it (a subfolder that is a symbolic link is refused: files would be written
/// outside `dir`), remove what a previous run of `command` left (command_outputs: its whole output set, so that a
/// reused folder holds only this run's files; other files are left alone), and write kIncompleteMarker (saying which
/// command started when). Throws impinge::Error naming the folder; the lock is released when it throws.
void begin_output_folder(const std::string& dir, const std::string& command,
                         const std::vector<std::string>& subfolders = {});
/// Every file `command` ("distance", "motion", "rom", "morphology", "plan") may write in its output folder, relative
/// to it; "*" in a last path part matches any text (gaps/frame_*.vtp). Empty for another command.
std::vector<std::string> command_outputs(const std::string& command);

/// Mark `dir`'s outputs complete (remove kIncompleteMarker) and release its lock: call after its last file,
/// summary.json. A run that ends by an error keeps its lock file, which the next run takes over (its process ended).
void end_output_folder(const std::string& dir);

/// The impingement level of every vertex of `gaps` under `levels` by quantity `levels_on` (vertex_level:
/// 255 where the vertex has no value). Length: the body's vertex count.
std::vector<std::uint8_t> vertex_levels(const ScanGaps& gaps, const ImpingementLevels& levels,
                                        LevelQuantity levels_on = LevelQuantity::radial_gap);

/// Both bones at one pose as binary PLY (write_gap_ply: x y z gap_mm; level and its colour): the
/// femur at `pose` (joint frame) into `ball_path`, the pelvis into `socket_path`; vertices
/// in the input frame, mm, in the meshes' vertex order. Throws impinge::Error naming a file on I/O
/// errors.
void write_pose_plys(const std::string& ball_path, const std::string& socket_path, const Session& session,
                     const PoseResult& result, const FemurPose& pose);

/// Both bones in one VTK PolyData (.vtp): the femur at `pose` (joint frame), then the pelvis,
/// with point arrays gap_mm (float32, NaN untested), level (uint8, 255 untested) and body (0
/// femur, 1 pelvis); input frame, mm. Throws impinge::Error naming the file on I/O errors.
void write_pose_vtp(const std::string& path, const Session& session, const PoseResult& result,
                    const FemurPose& pose);

/// Both maps of `session` as PNG images (write_map_png: the map over (theta, phi)) in `dir`: femur_map.png and
/// pelvis_map.png, each on its own thread. Throws impinge::Error naming a file on I/O errors.
void write_map_pngs(const std::string& dir, const Session& session);

/// `impinge generate`: a generated hip (make_hip_model(options)) written into `dir` as femur_r.ply, pelvis.ply and
/// subject.json (save_subject: right side, RAS, mm, scan neutral, "generated" with its true centre and head
/// radius), the folder opened and closed as every run's (begin_output_folder). Returns the model. Throws
/// impinge::Error as make_hip_model does, or naming the file it cannot write.
HipModel write_generated_hip(const std::string& dir, const HipModelOptions& options);

/// What write_motion_files did: the motion's detection time (ms, run_motion), its VTP files, and the time spent
/// writing (ms).
struct MotionFiles {
  double detect_ms = 0;
  std::size_t vtp_files = 0;
  int vtp_every = 1;
  double write_ms = 0;
};

/// `impinge motion`'s files in `dir` (opened by begin_output_folder with the subfolder "gaps"): frames.csv (one
/// motion_row per frame) and, every `vtp_every` frames (0: every frame up to 100 frames, else at most 100
/// files), the posed bones as gaps/frame_NNNNNN.vtp (write_pose_vtp) listed by time in gaps.pvd (ParaView).
/// `on_frame(done, total)`, when given, is called after each frame (a progress bar). Throws impinge::Error as
/// run_motion does, or naming a file.
MotionFiles write_motion_files(const std::string& dir, const Session& session, const Motion& motion, int vtp_every,
                               const std::function<void(std::size_t, std::size_t)>& on_frame = {});

}  // namespace impinge
