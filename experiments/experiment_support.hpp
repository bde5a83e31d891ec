#pragma once
// Shared pieces of the experiment drivers: command line, subjects, timing, CSV and meta.json.
#include <chrono>
#include <cmath>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

#include "impinge/anatomy/pose.hpp"
#include "impinge/anatomy/sphere_fit.hpp"
#include "impinge/core/mesh.hpp"
#include "impinge/detection/joint.hpp"
#include "impinge/io/generated_models.hpp"
#include "impinge/session/session.hpp"

namespace impinge::experiment {

/// Command-line options every driver accepts.
struct Args {
  std::string out = "results";  ///< results root; the driver writes OUT/NN_name/
  std::string data;             ///< folder of real subjects (one sub-folder with subject.json each)
  bool quick = false;           ///< coarse resolutions, fewer repetitions
  int repetitions = 5;          ///< timing repetitions (median reported); quick: 3
};

/// Parse argv (--out, --data, --quick, --repetitions). Exits on --help or a bad option.
Args parse_args(int argc, char** argv, const std::string& description);

/// A joint to run on: a real subject or a generated one, in the anatomical frame.
struct Subject {
  std::string name;    ///< folder name or "generated-3k"
  std::string source;  ///< citation / generator
  bool generated = false;
  Side side = Side::right;
  TriangleMesh femur, pelvis;
  Landmarks landmarks;  ///< given in subject.json (anatomical frame, mm); none for generated
  Eigen::Vector3d true_cor = Eigen::Vector3d::Constant(std::nan(""));  ///< known for generated
};

/// The report's one set of impingement levels (mm, on the gap): beyond 6 mm apart (the thesis' blue, sec. 5.2),
/// 4-6, 2-4, 0-2 (the thesis' red: within 2 mm), at or below 0. Every experiment whose figures colour levels
/// uses it (analysis/render.py's REPORT_LEVELS_MM is the same set).
inline const std::vector<double> kReportLevelsMm{6.0, 4.0, 2.0, 0.0};

/// A generated hip (make_hip_model) as a subject named `name`: its meshes, the true COR, scan neutral.
Subject generated_subject(const HipModel& h, const std::string& name, const std::string& source);

/// Every real subject under args.data (sorted by name; none when the folder is absent), then
/// the generated hip model(s) with the given triangle counts.
std::vector<Subject> load_subjects(const Args& args, const std::vector<int>& generated_triangles);

/// The COR of a subject: the true centre for generated models; for real ones the session layer's
/// automatic policy (find_centre_of_rotation: locate_femoral_head), as the CLI and Python find it.
/// mm, anatomical frame.
Eigen::Vector3d subject_cor(const Subject& s);

/// The femoral head of a real subject as the session layer's automatic policy finds it (centre,
/// radius, rms residual; anatomical frame, mm). Throws impinge::Error when no head is found.
SphereFitResult subject_head(const Subject& s);

/// Session options for a subject (the same set-up as the CLI's and Python's): its meshes in memory
/// (anatomical frame, RAS), its side; anatomical neutral for real subjects, scan neutral and the
/// true COR for generated ones; the thesis' femoral-head joint centre; the rest of `o` (grid, maps,
/// detection) as given.
SessionOptions session_options(const Subject& s, SessionOptions o = {});

/// Unit direction in which the femur is pushed into the acetabulum: from the COR towards the
/// centroid of the pelvis vertices within `radius_mm` of it (the acetabular fossa side).
Eigen::Vector3d push_direction(const TriangleMesh& pelvis, const Eigen::Vector3d& cor, double radius_mm = 45);

/// Median wall time in ms of `fn` over `reps` runs after one warm-up run.
double median_ms(const std::function<void()>& fn, int reps);

/// A timing's spread (issue 51: every timing with its spread): median and quartiles (ms; linear interpolation
/// between order statistics, numpy's default) of `runs` wall times.
struct Timing {
  double median_ms = std::nan(""), q25_ms = std::nan(""), q75_ms = std::nan("");
  int runs = 0;
};

/// The median and quartiles of `ms` (wall times, ms); NaNs when `ms` is empty.
Timing summarize(std::vector<double> ms);

/// Wall times (ms) of several configurations timed alternately: one warm-up run of each, then `reps` rounds in which
/// each runs once, in order, so that a drift of the machine (another process, the clock) falls on all of them alike
/// and their ratios can be taken round by round (paired). Returns runs[k][r]: the k-th function's time in round r.
std::vector<std::vector<double>> run_alternated(const std::vector<std::function<void()>>& fns, int reps);

/// Round-by-round sums of runs (ms): the time of configurations that make one job (a pose's two scans).
std::vector<double> round_sums(const std::vector<std::vector<double>>& runs, const std::vector<std::size_t>& which);

/// OUT/NN_name, created.
std::string experiment_dir(const Args& args, const std::string& name);

/// Write DIR/meta.json with the fields every driver's meta.json has (the Python drivers' write_meta in
/// experiment_support.py writes the same; tools/check-report checks it): experiment (DIR's name),
/// git_commit (with "-dirty" when tracked files outside results/ differ), date (UTC), quick,
/// repetitions, timing, data_folder, parameters (`params`), versions, compiler, kernels, cores and
/// machine (machine_description(): CPU model, family, clock, caches, topology (sockets, cores, SMT siblings),
/// memory, hypervisor, kernel).
void write_meta(const std::string& dir, const Args& args, nlohmann::json params);

/// Minimal CSV writer: header once, then rows of already-formatted cells.
/// A CSV file written whole when the writer goes out of scope (write_file_atomically): a killed or failed
/// run leaves no truncated CSV. A write failure then ends the process with exit code 2, naming the file.
class CsvWriter {
 public:
  CsvWriter(const std::string& path, const std::vector<std::string>& header);
  ~CsvWriter();
  CsvWriter(const CsvWriter&) = delete;
  CsvWriter& operator=(const CsvWriter&) = delete;
  template <typename... T>
  void row(const T&... cells) {
    std::size_t k = 0;
    ((os_ << (k++ ? "," : "") << cell(cells)), ...);
    os_ << "\n";
  }

 private:
  // Text with a comma, quote or line break is quoted (RFC 4180), so a note cannot shift the columns.
  static std::string cell(const std::string& s) {
    if (s.find_first_of(",\"\n") == std::string::npos) return s;
    std::string q = "\"";
    for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
    return q + "\"";
  }
  static std::string cell(const char* s) { return cell(std::string(s)); }
  template <typename N>
  static std::string cell(N x) {
    if constexpr (std::is_floating_point_v<N>) {
      if (!std::isfinite(static_cast<double>(x))) return "nan";
      std::ostringstream o;
      o.precision(9);
      o << x;
      return o.str();
    } else {
      return std::to_string(x);
    }
  }
  std::string path_;
  std::ostringstream os_;
};

/// Write the part of `body` within `radius_mm` of the COR as a gap PLY (write_gap_ply): its vertices
/// mapped by R (3 x 3, joint frame -> output frame), each vertex's gap from `gaps` (nullptr: untested,
/// grey), level and colour under `levels`. For the shaded renders of experiments 08 and 09.
void write_region_ply(const std::string& path, const JointBody& body, const Eigen::Matrix3d& R, double radius_mm,
                      const ScanGaps* gaps, const ImpingementLevels& levels, bool is_ball);

/// Print a progress line to stderr ("[08_distance_maps] 3/24 lhdl-ct p=0.1 exact").
void progress(const std::string& experiment, int done, int total, const std::string& what);

}  // namespace impinge::experiment
