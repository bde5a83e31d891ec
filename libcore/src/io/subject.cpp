#include "impinge/io/subject.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <nlohmann/json.hpp>

#include "impinge/anatomy/femur_frame.hpp"
#include "impinge/anatomy/pelvis_frame.hpp"
#include "impinge/core/atomic_file.hpp"
#include "impinge/core/error.hpp"

namespace impinge {

FrameConvention parse_frame(const std::string& s, const std::string& context) {
  if (s == "LPS") return FrameConvention::LPS;
  if (s == "RAS") return FrameConvention::RAS;
  throw Error(context + ": frame '" + s + "' is neither LPS nor RAS");
}

Side parse_side(const std::string& s, const std::string& context) {
  if (s == "right") return Side::right;
  if (s == "left") return Side::left;
  throw Error(context + ": side '" + s + "' is neither right nor left");
}

const std::vector<std::string>& subject_keys() {
  static const std::vector<std::string> keys{"side",      "frame",     "units",       "femur",
                                             "pelvis",    "neutral",   "landmarks",   "generated",
                                             "true_cor_mm", "head_radius_mm", "name", "source",
                                             "citation",  "description"};
  return keys;
}

namespace {
// Line and column (1-based) of byte `offset` of `text`.
std::string line_and_column(const std::string& text, std::size_t offset) {
  offset = std::min(offset, text.size());
  const std::size_t line = 1 + static_cast<std::size_t>(std::count(text.begin(), text.begin() + std::ptrdiff_t(offset), '\n'));
  const std::size_t start = offset == 0 ? 0 : text.rfind('\n', offset - 1);
  const std::size_t column = start == std::string::npos ? offset + 1 : offset - start;
  return "line " + std::to_string(line) + ", column " + std::to_string(column);
}

// The JSON value that is the whole of `text` (the file `path`): not valid JSON, data after the value, and a key
// given twice in one object are errors naming the file and the line and column or the key.
nlohmann::json parse_json_text(const std::string& text, const std::string& path) {
  // A key given twice in one object (nlohmann keeps the last without a word): found by the parser's callback, the
  // enclosing objects' keys giving its place ("landmarks.ASIS_r").
  std::vector<std::vector<std::string>> keys;  // per open object, its keys so far
  std::vector<std::string> place;              // per open object, the key it sits under
  std::string twice;
  auto seen = [&](int, nlohmann::json::parse_event_t event, nlohmann::json& parsed) {
    using E = nlohmann::json::parse_event_t;
    if (event == E::object_start) {
      place.push_back(keys.empty() || keys.back().empty() ? std::string() : keys.back().back());
      keys.emplace_back();
    } else if (event == E::object_end && !keys.empty()) {
      keys.pop_back(), place.pop_back();
    } else if (event == E::key && !keys.empty()) {
      const std::string key = parsed.get<std::string>();
      if (twice.empty() && std::find(keys.back().begin(), keys.back().end(), key) != keys.back().end()) {
        for (const std::string& p : place) twice += p.empty() ? "" : p + ".";
        twice += key;
      }
      keys.back().push_back(key);
    }
    return true;
  };
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text, seen);
  } catch (const nlohmann::json::parse_error& e) {
    // The whole file is one value: a second value or anything else after it ("{...} {...}", "{...} x") is refused.
    std::size_t at = e.byte == 0 ? 0 : e.byte - 1;
    const std::string what = e.what();
    if (what.find("expected end of input") != std::string::npos) {
      while (at < text.size() && std::isspace(static_cast<unsigned char>(text[at]))) ++at;
      std::string start = text.substr(at, 20);
      start = start.substr(0, start.find_first_of("\r\n"));
      throw Error(path + ": " + line_and_column(text, at) + " (offset " + std::to_string(at) + "): '" + start +
                  "...' after the JSON object: a subject file holds one object");
    }
    const std::size_t colon = what.find(": ", what.find("parse error"));
    throw Error(path + ": not valid JSON at " + line_and_column(text, at) + ": " +
                (colon == std::string::npos ? what : what.substr(colon + 2)));
  }
  require(twice.empty(), [&] { return path + ": key '" + twice + "' appears twice: which value is meant?"; });
  return j;
}
}  // namespace

SubjectInfo load_subject(const std::string& json_path) {
  namespace fs = std::filesystem;
  std::ifstream in(json_path, std::ios::binary);
  require(in.good(), json_path + ": cannot open subject file");
  std::ostringstream text;
  text << in.rdbuf();
  nlohmann::json j = parse_json_text(text.str(), json_path);
  auto str = [&](const char* key) -> std::string {
    require(j.contains(key), json_path + ": missing key '" + key + "'");
    require(j[key].is_string(), json_path + ": key '" + key + "' must be a string");
    return j[key].get<std::string>();
  };
  // Every key is one impinge reads (a misspelled one would be dropped without a word); keys starting with '_'
  // are the writer's own notes. `impinge generate` adds generated, true_cor_mm and head_radius_mm.
  require(j.is_object(), json_path + ": expected a JSON object {\"side\": ..., \"frame\": ..., ...}");
  for (const auto& [key, value] : j.items()) {
    bool known = !key.empty() && key[0] == '_';
    for (const std::string& k : subject_keys()) known = known || key == k;
    require(known, [&] {
      std::string list;
      for (const std::string& k : subject_keys()) list += (list.empty() ? "" : ", ") + k;
      return json_path + ": unknown key '" + key + "' (known: " + list + "; keys starting with '_' are notes)";
    });
  }
  SubjectInfo s;
  const fs::path dir = fs::path(json_path).parent_path();
  s.name = fs::absolute(dir).filename().string();
  s.side = parse_side(str("side"), json_path);
  s.frame = parse_frame(str("frame"), json_path);
  if (j.contains("units")) require(str("units") == "mm", json_path + ": units must be 'mm'");
  s.femur_path = (dir / str("femur")).string();
  s.pelvis_path = (dir / str("pelvis")).string();
  if (j.contains("neutral")) {
    s.neutral = str("neutral");
    parse_neutral(s.neutral, json_path + ": key 'neutral'");
  }
  if (j.contains("landmarks")) {
    const auto& lm = j["landmarks"];
    require(lm.is_object(), json_path + ": key 'landmarks' must be an object {name: [x, y, z]}");
    for (const auto& [name, value] : lm.items()) {
      bool known = name == "hip_centre";
      for (const char* n : kPelvisLandmarkNames) known = known || name == n;
      for (const char* n : kFemurLandmarkNames) known = known || name == n;
      require(known, json_path + ": landmarks: unknown name '" + name + "'");
      bool ok = value.is_array() && value.size() == 3;
      Eigen::Vector3d p = Eigen::Vector3d::Zero();
      for (std::size_t k = 0; ok && k < 3; ++k) {
        ok = value[k].is_number();
        if (ok) p[static_cast<Eigen::Index>(k)] = value[k].get<double>();
      }
      require(ok && p.allFinite(), json_path + ": landmarks: '" + name + "' must be three finite numbers [x, y, z] (mm)");
      s.landmarks[name] = p;
    }
  }
  if (j.contains("generated")) {
    require(j["generated"].is_boolean(), json_path + ": key 'generated' must be true or false");
    s.generated = j["generated"].get<bool>();
  }
  if (j.contains("true_cor_mm")) {
    const auto& c = j["true_cor_mm"];
    bool ok = c.is_array() && c.size() == 3;
    Eigen::Vector3d p = Eigen::Vector3d::Zero();
    for (std::size_t k = 0; ok && k < 3; ++k) {
      ok = c[k].is_number();
      if (ok) p[static_cast<Eigen::Index>(k)] = c[k].get<double>();
    }
    require(ok && p.allFinite(), json_path + ": key 'true_cor_mm' must be three finite numbers [x, y, z] (mm)");
    s.true_cor_mm = p;
  }
  if (j.contains("head_radius_mm")) {
    const auto& r = j["head_radius_mm"];
    require(r.is_number() && std::isfinite(r.get<double>()) && r.get<double>() > 0,
            json_path + ": key 'head_radius_mm' must be a number > 0 (mm)");
    s.head_radius_mm = r.get<double>();
  }
  return s;
}

void save_subject(const std::string& json_path, const SubjectInfo& s) {
  namespace fs = std::filesystem;
  // Both the folder and the meshes resolved through the file system (symbolic links, '..'), so that a mesh in the
  // json's folder (or below it) is named relative to it, any other by its absolute path.
  const fs::path dir = fs::weakly_canonical(fs::absolute(fs::path(json_path))).parent_path();
  auto file = [&](const std::string& path) {
    const fs::path p = fs::weakly_canonical(fs::absolute(path));
    const fs::path rel = p.lexically_relative(dir);
    return (!rel.empty() && *rel.begin() != "..") ? rel.generic_string() : p.string();
  };
  nlohmann::json j;
  j["side"] = s.side == Side::right ? "right" : "left";
  j["frame"] = s.frame == FrameConvention::LPS ? "LPS" : "RAS";
  j["units"] = "mm";
  j["femur"] = file(s.femur_path);
  j["pelvis"] = file(s.pelvis_path);
  if (!s.neutral.empty()) {
    parse_neutral(s.neutral, json_path + ": neutral");
    j["neutral"] = s.neutral;
  }
  for (const auto& [name, p] : s.landmarks) j["landmarks"][name] = {p.x(), p.y(), p.z()};
  if (s.generated) {
    j["generated"] = true;
    if (s.true_cor_mm) j["true_cor_mm"] = {s.true_cor_mm->x(), s.true_cor_mm->y(), s.true_cor_mm->z()};
    if (std::isfinite(s.head_radius_mm)) j["head_radius_mm"] = s.head_radius_mm;
  }
  for (const auto& [key, value] : j.items()) {
    const auto& keys = subject_keys();
    require(std::find(keys.begin(), keys.end(), key) != keys.end(),
            json_path + ": save_subject would write key '" + key + "', which load_subject does not read");
  }
  write_file_atomically(json_path, j.dump(2) + "\n");
}

Eigen::Matrix3d to_working_frame(FrameConvention frame) {
  Eigen::Matrix3d M = Eigen::Matrix3d::Identity();
  if (frame == FrameConvention::LPS) {
    M(0, 0) = -1;
    M(1, 1) = -1;
  }
  return M;
}

void transform_vertices(Vertices& V, const Eigen::Matrix3d& M) { V = (V * M.transpose()).eval(); }

}  // namespace impinge
