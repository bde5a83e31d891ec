#include "impinge/io/motion.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <sstream>

#include "impinge/core/error.hpp"
#include "impinge/core/spherical_frame.hpp"

namespace impinge {

namespace {

std::string trim(const std::string& s) {
  std::size_t a = 0, b = s.size();
  while (a < b && std::isspace(static_cast<unsigned char>(s[a]))) ++a;
  while (b > a && std::isspace(static_cast<unsigned char>(s[b - 1]))) --b;
  return s.substr(a, b - a);
}

std::vector<std::string> split(const std::string& line, bool csv) {
  std::vector<std::string> out;
  if (csv) {
    std::stringstream ss(line);
    std::string item;
    while (std::getline(ss, item, ',')) out.push_back(trim(item));
    if (!line.empty() && line.back() == ',') out.emplace_back();
  } else if (line.find('\t') != std::string::npos) {
    // OpenSim writes tabs: every tab separates two cells, so an empty cell stays a cell (collapsing the
    // white space would shift the row's values one column left).
    std::stringstream ss(line);
    std::string item;
    while (std::getline(ss, item, '\t')) out.push_back(trim(item));
    if (line.back() == '\t') out.emplace_back();
    while (!out.empty() && out.back().empty()) out.pop_back();  // trailing tabs: no cells
  } else {
    std::stringstream ss(line);
    std::string item;
    while (ss >> item) out.push_back(item);
  }
  return out;
}

bool ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

double number(const std::string& cell, const std::string& where) {
  double v = 0;
  bool ok = false;
  try {
    std::size_t used = 0;
    v = std::stod(cell, &used);
    ok = used == cell.size();
  } catch (const std::exception&) {
  }
  require(ok, [&] { return where + ": '" + cell + "' is not a number"; });
  require(std::isfinite(v), [&] { return where + ": '" + cell + "' is not finite"; });
  return v;
}

}  // namespace

Motion load_motion(const std::string& path, Side side) {
  std::ifstream in(path);
  require(in.good(), path + ": cannot open motion file");
  Motion m;
  m.source = path;
  const std::string ext = lower(path.size() >= 4 ? path.substr(path.size() - 4) : path);
  const bool opensim = ext == ".mot" || ext == ".sto";
  m.format = opensim ? "opensim" : "csv";
  std::string line;
  std::size_t line_no = 0;
  double scale = 1;  // to degrees
  if (opensim) {
    int in_degrees = -1;
    bool end = false;
    while (std::getline(in, line)) {
      ++line_no;
      const std::string t = lower(trim(line));
      if (t == "endheader") {
        end = true;
        break;
      }
      if (t.rfind("indegrees", 0) == 0) {
        const std::string v = trim(t.substr(t.find('=') == std::string::npos ? t.size() : t.find('=') + 1));
        require(v == "yes" || v == "no",
                path + ":" + std::to_string(line_no) + ": unknown unit 'inDegrees=" + v + "' (yes or no)");
        in_degrees = v == "yes";
      }
    }
    require(line_no > 0, path + ": empty motion file");
    require(end, path + ": no 'endheader' line: not an OpenSim motion/storage file");
    require(in_degrees >= 0, path + ": the header has no inDegrees=yes|no line: the angles' unit is unknown");
    scale = in_degrees ? 1.0 : kRadToDeg;
  }
  // Column labels.
  std::vector<std::string> labels;
  while (std::getline(in, line)) {
    ++line_no;
    if (!trim(line).empty()) {
      labels = split(line, !opensim);
      break;
    }
  }
  require(!labels.empty(), path + ": empty motion file (no header row)");
  const std::string s = side == Side::right ? "_r" : "_l";
  const std::vector<std::string> wanted =
      opensim ? std::vector<std::string>{"time", "hip_flexion" + s, "hip_adduction" + s, "hip_rotation" + s}
              : std::vector<std::string>{"time_s", "flexion_deg", "adduction_deg", "internal_rotation_deg"};
  std::size_t col[4];
  for (int k = 0; k < 4; ++k) {
    const auto it = std::find_if(labels.begin(), labels.end(), [&](const std::string& l) {
      return l == wanted[k] || (opensim && (ends_with(l, "/" + wanted[k]) || ends_with(l, "/" + wanted[k] + "/value")));
    });
    require(it != labels.end(), path + ":" + std::to_string(line_no) + ": missing column '" + wanted[k] + "'");
    col[k] = static_cast<std::size_t>(it - labels.begin());
  }
  while (std::getline(in, line)) {
    ++line_no;
    if (trim(line).empty()) continue;
    const std::vector<std::string> cells = split(line, !opensim);
    require(cells.size() == labels.size(), [&] {
      return path + ":" + std::to_string(line_no) + ": the row has " + std::to_string(cells.size()) +
             " cells, the header " + std::to_string(labels.size()) + ": a missing or extra value would shift the "
             "columns";
    });
    double v[4];
    for (int k = 0; k < 4; ++k) {
      const std::string where = path + ":" + std::to_string(line_no) + ": column '" + labels[col[k]] + "'";
      require(col[k] < cells.size(), where + ": the row has only " + std::to_string(cells.size()) + " cells");
      v[k] = number(cells[col[k]], where);
    }
    require(m.time_s.empty() || v[0] >= m.time_s.back(),
            path + ":" + std::to_string(line_no) + ": column '" + labels[col[0]] + "': time decreases");
    m.time_s.push_back(v[0]);
    m.angles.push_back(PoseAngles{v[1] * scale, v[2] * scale, v[3] * scale});
  }
  require(!m.angles.empty(), path + ": the motion has no frames");
  return m;
}

}  // namespace impinge
