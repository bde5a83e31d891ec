#include "experiment_support.hpp"

#include "impinge/core/atomic_file.hpp"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <iostream>

#include "impinge/core/error.hpp"
#include "impinge/core/kernels.hpp"
#include "impinge/core/provenance.hpp"
#include "impinge/core/timing.hpp"
#include "impinge/io/mesh_io.hpp"
#include "impinge/io/subject.hpp"
#include "impinge/session/session.hpp"

namespace impinge::experiment {

namespace fs = std::filesystem;

const std::string& source_commit();  // below; read when the driver starts

Args parse_args(int argc, char** argv, const std::string& description) {
  CLI::App app{description};
  Args a;
  app.add_option("--out", a.out, "Results root (writes OUT/NN_name/)")->capture_default_str();
  app.add_option("--data", a.data, "Folder of real subjects (skipped when absent)");
  app.add_flag("--quick", a.quick, "Coarse resolutions and fewer repetitions");
  int reps = 0;
  app.add_option("--repetitions", reps, "Timing repetitions (default 5, quick 3)");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    std::exit(app.exit(e));
  }
  a.repetitions = reps > 0 ? reps : (a.quick ? 3 : 5);
  (void)source_commit();  // the commit this run is made from (meta.json)
  return a;
}

std::vector<Subject> load_subjects(const Args& args, const std::vector<int>& generated_triangles) {
  std::vector<Subject> out;
  if (!args.data.empty() && fs::is_directory(args.data)) {
    std::vector<fs::path> dirs;
    for (const auto& e : fs::directory_iterator(args.data))
      if (fs::exists(e.path() / "subject.json")) dirs.push_back(e.path());
    std::sort(dirs.begin(), dirs.end());
    for (const auto& d : dirs) {
      SessionInput in;
      in.subject = (d / "subject.json").string();
      LoadedInput li = load_input(in);  // meshes in the anatomical frame, as every front end reads them
      Subject s;
      s.name = li.name;
      s.source = "shared/data/hips/" + li.name;
      s.side = li.side;
      s.femur = std::move(li.femur);
      s.pelvis = std::move(li.pelvis);
      s.landmarks = std::move(li.landmarks);
      out.push_back(std::move(s));
    }
  }
  for (int t : generated_triangles) {
    HipModelOptions o;
    o.target_triangles = t;
    o.cam_height_mm = 2.0;
    out.push_back(generated_subject(make_hip_model(o),
                                    "generated-" + (t % 1000 == 0 ? std::to_string(t / 1000) + "k" : std::to_string(t)),
                                    "make_hip_model(target_triangles=" + std::to_string(t) + ", cam_height_mm=2)"));
  }
  return out;
}

Subject generated_subject(const HipModel& h, const std::string& name, const std::string& source) {
  Subject s;
  s.name = name;
  s.source = source;
  s.generated = true;
  s.femur = h.ball;
  s.pelvis = h.socket;
  s.true_cor = h.cor;
  return s;
}

SphereFitResult subject_head(const Subject& s) {
  LoadedInput in;
  in.femur = s.femur;
  in.pelvis = s.pelvis;
  in.side = s.side;
  in.landmarks = s.landmarks;
  return find_centre_of_rotation(in, {}).head;
}

Eigen::Vector3d subject_cor(const Subject& s) { return s.generated ? s.true_cor : subject_head(s).centre; }

SessionOptions session_options(const Subject& s, SessionOptions o) {
  o.input.ball_mesh = s.femur;
  o.input.socket_mesh = s.pelvis;
  o.input.side = s.side == Side::right ? "right" : "left";
  o.input.frame = "RAS";
  o.input.landmarks = s.landmarks;
  o.hip.neutral = s.generated ? Neutral::scan : Neutral::anatomical;
  // The thesis' method (issue 29: the thesis experiments keep it).
  o.hip.joint_centre = JointCentreMethod::femoral_head;
  if (s.generated) {
    o.cor.given = s.true_cor;
    o.cor.allow_any = true;  // the true centre: no fitted head to check it against (a partial femur)
  }
  return o;
}

Eigen::Vector3d push_direction(const TriangleMesh& pelvis, const Eigen::Vector3d& cor, double radius_mm) {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  int n = 0;
  for (Eigen::Index i = 0; i < pelvis.V.rows(); ++i) {
    const Eigen::Vector3d p = pelvis.V.row(i).transpose() - cor;
    if (p.norm() <= radius_mm) c += p, ++n;
  }
  if (n == 0 || c.norm() == 0) return Eigen::Vector3d::UnitX();
  return c.normalized();
}

double median_ms(const std::function<void()>& fn, int reps) {
  fn();
  std::vector<double> t;
  for (int i = 0; i < std::max(1, reps); ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    fn();
    t.push_back(ms_since(t0));
  }
  return summarize(std::move(t)).median_ms;
}

Timing summarize(std::vector<double> ms) {
  Timing t;
  t.runs = static_cast<int>(ms.size());
  if (ms.empty()) return t;
  std::sort(ms.begin(), ms.end());
  auto quantile = [&](double q) {
    const double pos = q * double(ms.size() - 1);
    const auto i = static_cast<std::size_t>(pos);
    return i + 1 < ms.size() ? ms[i] + (pos - double(i)) * (ms[i + 1] - ms[i]) : ms[i];
  };
  t.median_ms = quantile(0.5), t.q25_ms = quantile(0.25), t.q75_ms = quantile(0.75);
  return t;
}

std::vector<std::vector<double>> run_alternated(const std::vector<std::function<void()>>& fns, int reps) {
  for (const auto& fn : fns) fn();  // warm-up: caches, page faults, lazy set-up
  std::vector<std::vector<double>> runs(fns.size());
  for (int r = 0; r < std::max(1, reps); ++r)
    for (std::size_t k = 0; k < fns.size(); ++k) {
      const auto t0 = std::chrono::steady_clock::now();
      fns[k]();
      runs[k].push_back(ms_since(t0));
    }
  return runs;
}

std::vector<double> round_sums(const std::vector<std::vector<double>>& runs, const std::vector<std::size_t>& which) {
  std::vector<double> sum(which.empty() ? 0 : runs.at(which[0]).size(), 0.0);
  for (std::size_t k : which)
    for (std::size_t r = 0; r < sum.size(); ++r) sum[r] += runs.at(k).at(r);
  return sum;
}

std::string experiment_dir(const Args& args, const std::string& name) {
  const fs::path d = fs::path(args.out) / name;
  fs::create_directories(d);
  return d.string();
}

namespace {
std::string command_output(const std::string& cmd) {
  std::string out;
  if (FILE* p = popen(cmd.c_str(), "r")) {
    char buf[256];
    while (fgets(buf, sizeof buf, p) != nullptr) out += buf;
    pclose(p);
  }
  while (!out.empty() && (out.back() == '\n' || out.back() == ' ')) out.pop_back();
  return out;
}
}  // namespace

/// The commit of the source tree, "-dirty" when a tracked source file differs from it (the results
/// folder left out: a reproduction rewrites it as it goes, which would otherwise mark every experiment
/// after the first). Read once, when the driver starts: the commit the run is made from, not whatever
/// the tree holds when it ends.
const std::string& source_commit() {
  static const std::string c = [] {
    const std::string commit = command_output("git -C '" IMPINGE_SOURCE_DIR "' rev-parse HEAD 2>/dev/null");
    const std::string dirty = command_output("git -C '" IMPINGE_SOURCE_DIR
                                             "' status --porcelain --untracked-files=no -- . ':(exclude)results' "
                                             "2>/dev/null");
    return commit.empty() ? std::string("unknown") : commit + (dirty.empty() ? "" : "-dirty");
  }();
  return c;
}

void write_meta(const std::string& dir, const Args& args, nlohmann::json params) {
  nlohmann::json m;
  m["experiment"] = fs::path(dir).filename().string();
  m["git_commit"] = source_commit();
  const std::time_t now = std::time(nullptr);
  char buf[64];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
  m["date"] = buf;
  m["quick"] = args.quick;
  m["repetitions"] = args.repetitions;
  m["timing"] = "median wall time after one warm-up run, single thread";
  m["data_folder"] = args.data.empty() || !fs::is_directory(args.data) ? nlohmann::json(nullptr) : nlohmann::json(args.data);
  m["parameters"] = std::move(params);
  m["versions"] = {{"impinge", IMPINGE_VERSION}};
  m["compiler"] = compiler_description();
  m["kernels"] = kernel_description();  // which dispatched kernels ran (IMPINGE_KERNELS)
  m["cores"] = command_output("nproc");
  nlohmann::json machine = nlohmann::json::object();
  for (const auto& [key, value] : machine_description()) machine[key] = value;
  m["machine"] = std::move(machine);
  write_file_atomically((fs::path(dir) / "meta.json").string(), m.dump(2) + "\n");
}

CsvWriter::CsvWriter(const std::string& path, const std::vector<std::string>& header) : path_(path) {
  require(fs::is_directory(fs::path(path).parent_path().empty() ? "." : fs::path(path).parent_path()),
          path + ": its folder does not exist");
  for (std::size_t k = 0; k < header.size(); ++k) os_ << (k ? "," : "") << header[k];
  os_ << "\n";
}

CsvWriter::~CsvWriter() {
  try {
    write_file_atomically(path_, os_.str());
  } catch (const std::exception& e) {  // a result not written is a failed experiment, not a warning
    std::cerr << "experiment: error: " << e.what() << std::endl;
    std::_Exit(2);
  }
}

void progress(const std::string& experiment, int done, int total, const std::string& what) {
  std::cerr << "[" << experiment << "] " << done << "/" << total << " " << what << std::endl;
}

void write_region_ply(const std::string& path, const JointBody& body, const Eigen::Matrix3d& R, double radius_mm,
                      const ScanGaps* gaps, const ImpingementLevels& levels, bool is_ball) {
  std::vector<std::uint8_t> keep(static_cast<std::size_t>(body.relative.rows()));
  for (Eigen::Index i = 0; i < body.relative.rows(); ++i)
    keep[static_cast<std::size_t>(i)] = body.relative.row(i).norm() <= radius_mm;
  std::vector<Eigen::Index> kept;
  TriangleMesh region = submesh(body.mesh, keep, &kept);
  const auto n = static_cast<Eigen::Index>(kept.size());
  Eigen::VectorXf gap(n);
  Eigen::Matrix<unsigned char, Eigen::Dynamic, 1> level(n);
  Eigen::Matrix<unsigned char, Eigen::Dynamic, 3, Eigen::RowMajor> rgb(n, 3);
  for (Eigen::Index k = 0; k < n; ++k) {
    const Eigen::Index i = kept[static_cast<std::size_t>(k)];
    region.V.row(k) = (R * body.relative.row(i).transpose()).transpose();
    gap[k] = gaps != nullptr ? gaps->gap_mm[static_cast<std::size_t>(i)] : std::nanf("");
    level[k] = std::isnan(gap[k]) ? 255 : levels.level(gap[k]);
    const auto c = level_colour(level[k], levels.count(), is_ball);
    rgb.row(k) << c[0], c[1], c[2];
  }
  write_gap_ply(path, region.V, region.F, gap, level, rgb);
}

}  // namespace impinge::experiment
