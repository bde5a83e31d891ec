#include "impinge/io/motion.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
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

// The cells of a CSV row (RFC 4180): comma-separated, each trimmed; a cell in double quotes may hold commas and ""
// for a quote, and is the text inside them ("time_s" is the column time_s). Errors name `path` and `line_no`.
std::vector<std::string> csv_cells(const std::string& line, const std::string& path, std::size_t line_no) {
  const auto where = [&] { return path + ":" + std::to_string(line_no); };
  std::vector<std::string> out;
  std::size_t i = 0;
  for (;;) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
    std::string cell;
    if (i < line.size() && line[i] == '"') {
      const std::size_t open = i++;
      for (;; ++i) {
        require(i < line.size(), [&] {
          return where() + ": the quote opened at column " + std::to_string(open + 1) + " is not closed";
        });
        if (line[i] == '"' && i + 1 < line.size() && line[i + 1] == '"') {
          cell += '"', ++i;
        } else if (line[i] == '"') {
          break;
        } else {
          cell += line[i];
        }
      }
      ++i;  // past the closing quote: only blanks may come before the next comma
      while (i < line.size() && std::isspace(static_cast<unsigned char>(line[i]))) ++i;
      require(i == line.size() || line[i] == ',', [&] {
        return where() + ": text after the quoted cell at column " + std::to_string(open + 1) + ": '" +
               line.substr(i, 20) + "'";
      });
    } else {
      const std::size_t comma = std::min(line.find(',', i), line.size());
      cell = trim(line.substr(i, comma - i));
      i = comma;
    }
    out.push_back(std::move(cell));
    if (i >= line.size()) break;
    ++i;  // past the comma: a cell follows (empty at the end of the line)
  }
  return out;
}

std::vector<std::string> split(const std::string& line, bool csv, const std::string& path, std::size_t line_no) {
  std::vector<std::string> out;
  if (csv) {
    out = csv_cells(line, path, line_no);
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

namespace {

/// An OpenSim header up to "endheader": the angles' unit (degrees 1, radians kRadToDeg) and nRows (-1: not given).
struct OpenSimHeader {
  double scale = 1;
  long long rows = -1;
  bool in_degrees = true;
};

OpenSimHeader read_opensim_header(std::istream& in, const std::string& path, std::size_t& line_no) {
  OpenSimHeader h;
  std::string line;
  int in_degrees = -1;
  bool end = false;
  while (std::getline(in, line)) {
    ++line_no;
    const std::string t = lower(trim(line));
    if (t == "endheader") {
      end = true;
      break;
    }
    const std::string value = trim(t.substr(t.find('=') == std::string::npos ? t.size() : t.find('=') + 1));
    if (t.rfind("indegrees", 0) == 0) {
      require(value == "yes" || value == "no",
              path + ":" + std::to_string(line_no) + ": unknown unit 'inDegrees=" + value + "' (yes or no)");
      in_degrees = value == "yes";
    } else if (t.rfind("nrows", 0) == 0) {
      char* stop = nullptr;
      h.rows = std::strtoll(value.c_str(), &stop, 10);
      require(!value.empty() && *stop == '\0' && h.rows >= 0,
              path + ":" + std::to_string(line_no) + ": 'nRows=" + value + "' is not a row count");
    }
  }
  require(line_no > 0, path + ": empty motion file");
  require(end, path + ": no 'endheader' line: not an OpenSim motion/storage file");
  require(in_degrees >= 0, path + ": the header has no inDegrees=yes|no line: the angles' unit is unknown");
  h.in_degrees = in_degrees == 1;
  h.scale = h.in_degrees ? 1.0 : kRadToDeg;
  return h;
}

/// The columns of time and the three angles among `labels` (the header row at `line_no`); each must appear once.
std::array<std::size_t, 4> find_columns(const std::vector<std::string>& labels, bool opensim, Side side,
                                        const std::string& path, std::size_t line_no) {
  const std::string s = side == Side::right ? "_r" : "_l";
  const std::vector<std::string> wanted =
      opensim ? std::vector<std::string>{"time", "hip_flexion" + s, "hip_adduction" + s, "hip_rotation" + s}
              : std::vector<std::string>{"time_s", "flexion_deg", "adduction_deg", "internal_rotation_deg"};
  std::array<std::size_t, 4> col{};
  for (int k = 0; k < 4; ++k) {
    const auto matches = [&](const std::string& l) {
      return l == wanted[k] || (opensim && (ends_with(l, "/" + wanted[k]) || ends_with(l, "/" + wanted[k] + "/value")));
    };
    const auto it = std::find_if(labels.begin(), labels.end(), matches);
    require(it != labels.end(), [&] {
      std::string found;
      for (const std::string& l : labels) found += (found.empty() ? "'" : ", '") + l + "'";
      return path + ":" + std::to_string(line_no) + ": missing column '" + wanted[k] + "' (the header's columns: " +
             found + ")";
    });
    const auto again = std::find_if(it + 1, labels.end(), matches);
    require(again == labels.end(), [&] {
      return path + ":" + std::to_string(line_no) + ": column '" + wanted[k] + "' appears twice (columns " +
             std::to_string(it - labels.begin() + 1) + " and " + std::to_string(again - labels.begin() + 1) +
             "): which one is meant?";
    });
    col[static_cast<std::size_t>(k)] = static_cast<std::size_t>(it - labels.begin());
  }
  return col;
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
  // A UTF-8 byte-order mark (spreadsheets write one) is not part of the first line.
  char bom[3] = {};
  if (!in.read(bom, 3) || bom[0] != '\xEF' || bom[1] != '\xBB' || bom[2] != '\xBF') {
    in.clear();
    in.seekg(0);
  }
  std::string line;
  std::size_t line_no = 0;
  const OpenSimHeader header = opensim ? read_opensim_header(in, path, line_no) : OpenSimHeader{};
  // Column labels.
  std::vector<std::string> labels;
  while (std::getline(in, line)) {
    ++line_no;
    if (!trim(line).empty()) {
      labels = split(line, !opensim, path, line_no);
      break;
    }
  }
  require(!labels.empty(), path + ": empty motion file (no header row)");
  const std::array<std::size_t, 4> col = find_columns(labels, opensim, side, path, line_no);
  while (std::getline(in, line)) {
    ++line_no;
    if (trim(line).empty()) continue;
    const std::vector<std::string> cells = split(line, !opensim, path, line_no);
    require(cells.size() == labels.size(), [&] {
      return path + ":" + std::to_string(line_no) + ": the row has " + std::to_string(cells.size()) +
             " cells, the header " + std::to_string(labels.size()) + ": a missing or extra value would shift the "
             "columns";
    });
    double v[4];
    for (std::size_t k = 0; k < 4; ++k) {
      const std::string where = path + ":" + std::to_string(line_no) + ": column '" + labels[col[k]] + "'";
      v[k] = number(cells[col[k]], where);
      // An angle beyond a turn is not a hip's: a unit mixed up (degrees in a file that says radians), said here.
      require(k == 0 || std::abs(v[k] * header.scale) <= 360, [&] {
        char deg[32];
        std::snprintf(deg, sizeof deg, "%.1f", v[k] * header.scale);
        return where + ": " + cells[col[k]] + (header.in_degrees ? " deg" : " rad = " + std::string(deg) + " deg") +
               " is beyond +-360 deg" +
               (header.in_degrees ? "" : ": the header says inDegrees=no (radians); are the values degrees?");
      });
    }
    require(m.time_s.empty() || v[0] >= m.time_s.back(),
            path + ":" + std::to_string(line_no) + ": column '" + labels[col[0]] + "': time decreases");
    m.time_s.push_back(v[0]);
    m.angles.push_back(PoseAngles{v[1] * header.scale, v[2] * header.scale, v[3] * header.scale});
  }
  require(!m.angles.empty(), path + ": the motion has no frames");
  require(header.rows < 0 || static_cast<std::size_t>(header.rows) == m.angles.size(), [&] {
    return path + ": the header says nRows=" + std::to_string(header.rows) + ", the file holds " +
           std::to_string(m.angles.size()) + " rows: truncated or edited?";
  });
  return m;
}

}  // namespace impinge
