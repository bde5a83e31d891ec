#include "io/mesh_readers.hpp"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <sstream>
#include <vector>

#include "impinge/core/error.hpp"

namespace impinge::detail {

namespace {

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f'; }

std::vector<std::string> tokens(const std::string& line) {
  std::vector<std::string> out;
  std::istringstream in(line);
  std::string t;
  while (in >> t) out.push_back(t);
  return out;
}

// 1-based line of byte `offset` in `bytes`.
std::size_t line_of(const std::string& bytes, std::size_t offset) {
  return 1 + static_cast<std::size_t>(std::count(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(
                                                                    std::min(offset, bytes.size())), '\n'));
}

// A whole token as an integer in [lo, hi]; false if it is not one.
bool parse_integer(const std::string& t, long long lo, long long hi, long long& out) {
  if (t.empty()) return false;
  errno = 0;
  char* end = nullptr;
  const long long v = std::strtoll(t.c_str(), &end, 10);
  if (errno != 0 || end != t.c_str() + t.size() || v < lo || v > hi) return false;
  out = v;
  return true;
}

// A whole token as a double (nan and inf parse; validate_mesh refuses them with the vertex named).
bool parse_real(const std::string& t, double& out) {
  if (t.empty()) return false;
  char* end = nullptr;
  out = std::strtod(t.c_str(), &end);
  return end == t.c_str() + t.size();
}

// ---------------------------------------------------------------------------------------------
// PLY

struct PlyType {
  const char* names[2];
  int bytes;
  bool integer;
  bool is_signed;
};
const PlyType kPlyTypes[] = {
    {{"char", "int8"}, 1, true, true},      {{"uchar", "uint8"}, 1, true, false},
    {{"short", "int16"}, 2, true, true},    {{"ushort", "uint16"}, 2, true, false},
    {{"int", "int32"}, 4, true, true},      {{"uint", "uint32"}, 4, true, false},
    {{"float", "float32"}, 4, false, true}, {{"double", "float64"}, 8, false, true},
};

const PlyType* ply_type(const std::string& name) {
  for (const PlyType& t : kPlyTypes)
    if (name == t.names[0] || name == t.names[1]) return &t;
  return nullptr;
}

struct PlyProperty {
  std::string name;
  const PlyType* type = nullptr;        // value type
  const PlyType* count_type = nullptr;  // list count type; null for a scalar
};

struct PlyElement {
  std::string name;
  std::uint64_t count = 0;
  std::vector<PlyProperty> properties;
};

enum class PlyFormat { ascii, little, big };

// Which value is being read, described only when an error needs it (the body loop reads millions).
struct PlyWhere {
  const std::string& element;
  std::uint64_t index;
  const std::string& property;
  const char* suffix = "";
  std::string text() const {
    return element + " " + std::to_string(index) + ", property '" + property + "'" + suffix;
  }
};

// Reads values of the body in order, ascii tokens or binary bytes, with every access bounds-checked.
class PlyBody {
 public:
  PlyBody(const std::string& path, const std::string& bytes, std::size_t start, PlyFormat format)
      : path_(path), bytes_(bytes), pos_(start), format_(format) {}

  std::size_t remaining() const { return bytes_.size() - pos_; }

  double real(const PlyType& t, const PlyWhere& where) {
    if (format_ == PlyFormat::ascii) {
      const std::string tok = token(where);
      double v = 0;
      if (!parse_real(tok, v)) fail(where.text() + ": '" + tok + "' is not a number");
      if (t.integer) {
        long long i = 0;
        if (!parse_integer(tok, LLONG_MIN, LLONG_MAX, i)) fail(where.text() + ": '" + tok + "' is not an integer");
      }
      return v;
    }
    return binary(t, where);
  }

  long long integer(const PlyType& t, const PlyWhere& where) {
    if (!t.integer) fail(where.text() + ": has a floating-point type; an integer type is needed");
    if (format_ == PlyFormat::ascii) {
      const std::string tok = token(where);
      long long v = 0;
      const long long hi = t.is_signed ? (1LL << (8 * t.bytes - 1)) - 1 : (1LL << (8 * t.bytes)) - 1;
      const long long lo = t.is_signed ? -hi - 1 : 0;
      if (!parse_integer(tok, lo, hi, v)) fail(where.text() + ": '" + tok + "' is not an integer of its type");
      return v;
    }
    return static_cast<long long>(binary(t, where));
  }

  // After the last element: only whitespace may follow.
  void expect_end() {
    while (pos_ < bytes_.size() && is_space(bytes_[pos_])) ++pos_;
    if (pos_ < bytes_.size())
      fail(std::to_string(bytes_.size() - pos_) + " bytes of data after the last element");
  }

  [[noreturn]] void fail(const std::string& message) const {
    std::ostringstream os;
    os << path_ << ": cannot parse PLY: ";
    if (format_ == PlyFormat::ascii)
      os << "line " << line_of(bytes_, pos_) << ": ";
    else
      os << "byte " << pos_ << ": ";
    os << message;
    throw Error(os.str());
  }

 private:
  std::string token(const PlyWhere& where) {
    while (pos_ < bytes_.size() && is_space(bytes_[pos_])) ++pos_;
    const std::size_t a = pos_;
    while (pos_ < bytes_.size() && !is_space(bytes_[pos_])) ++pos_;
    if (a == pos_) fail(where.text() + ": the file ends here (truncated?)");
    return bytes_.substr(a, pos_ - a);
  }

  double binary(const PlyType& t, const PlyWhere& where) {
    if (remaining() < static_cast<std::size_t>(t.bytes)) fail(where.text() + ": the file ends here (truncated?)");
    unsigned char b[8];
    std::memcpy(b, bytes_.data() + pos_, static_cast<std::size_t>(t.bytes));
    pos_ += static_cast<std::size_t>(t.bytes);
    if (format_ == PlyFormat::big) std::reverse(b, b + t.bytes);
    switch (t.bytes * (t.integer ? (t.is_signed ? 1 : -1) : 10)) {
      case 1: return static_cast<std::int8_t>(b[0]);
      case -1: return b[0];
      case 2: { std::int16_t v; std::memcpy(&v, b, 2); return v; }
      case -2: { std::uint16_t v; std::memcpy(&v, b, 2); return v; }
      case 4: { std::int32_t v; std::memcpy(&v, b, 4); return v; }
      case -4: { std::uint32_t v; std::memcpy(&v, b, 4); return v; }
      case 40: { float v; std::memcpy(&v, b, 4); return v; }
      default: { double v; std::memcpy(&v, b, 8); return v; }
    }
  }

  const std::string& path_;
  const std::string& bytes_;
  std::size_t pos_;
  PlyFormat format_;
};

}  // namespace

namespace {

// A PLY header: the format, the elements with their properties, and where the body starts.
struct PlyHeader {
  PlyFormat format = PlyFormat::ascii;
  std::vector<PlyElement> elements;
  std::size_t body_start = 0;
};

// Parse the header: lines up to `end_header`. Throws impinge::Error naming `path` and the line.
PlyHeader parse_ply_header(const std::string& path, const std::string& bytes) {
  auto header_error = [&](std::size_t line, const std::string& message) {
    throw Error(path + ": cannot parse PLY: header line " + std::to_string(line) + ": " + message);
  };
  std::size_t pos = 0, line_no = 0;
  PlyFormat format = PlyFormat::ascii;
  bool have_format = false;
  std::vector<PlyElement> elements;
  for (;;) {
    if (pos >= bytes.size()) header_error(line_no, "no 'end_header' line: not a PLY file or a truncated header");
    std::size_t eol = bytes.find('\n', pos);
    if (eol == std::string::npos) eol = bytes.size();
    std::string line = bytes.substr(pos, eol - pos);
    if (!line.empty() && line.back() == '\r') line.pop_back();
    pos = std::min(eol + 1, bytes.size());
    ++line_no;
    const std::vector<std::string> t = tokens(line);
    if (line_no == 1) {
      if (line != "ply") header_error(1, "the file does not start with 'ply': not a PLY file");
      continue;
    }
    if (t.empty()) continue;
    if (t[0] == "comment" || t[0] == "obj_info") continue;
    if (t[0] == "end_header") {
      if (t.size() != 1) header_error(line_no, "'end_header' followed by other text");
      break;
    }
    if (t[0] == "format") {
      if (t.size() != 3 || t[2] != "1.0") header_error(line_no, "expected 'format ascii|binary_little_endian|binary_big_endian 1.0'");
      if (t[1] == "ascii") format = PlyFormat::ascii;
      else if (t[1] == "binary_little_endian") format = PlyFormat::little;
      else if (t[1] == "binary_big_endian") format = PlyFormat::big;
      else header_error(line_no, "unknown format '" + t[1] + "'");
      have_format = true;
    } else if (t[0] == "element") {
      long long n = 0;
      if (t.size() != 3 || !parse_integer(t[2], 0, INT_MAX, n))
        header_error(line_no, "expected 'element NAME COUNT' with a count in [0, " + std::to_string(INT_MAX) + "]");
      elements.push_back({t[1], static_cast<std::uint64_t>(n), {}});
    } else if (t[0] == "property") {
      if (elements.empty()) header_error(line_no, "a property before any element");
      PlyProperty p;
      if (t.size() == 5 && t[1] == "list") {
        p.count_type = ply_type(t[2]);
        p.type = ply_type(t[3]);
        p.name = t[4];
        if (p.count_type == nullptr || !p.count_type->integer)
          header_error(line_no, "list count type '" + t[2] + "' is not an integer type");
        if (p.type == nullptr) header_error(line_no, "unknown type '" + t[3] + "'");
      } else if (t.size() == 3) {
        p.type = ply_type(t[1]);
        p.name = t[2];
        if (p.type == nullptr) header_error(line_no, "unknown type '" + t[1] + "'");
      } else {
        header_error(line_no, "expected 'property TYPE NAME' or 'property list COUNT_TYPE TYPE NAME'");
      }
      elements.back().properties.push_back(p);
    } else {
      header_error(line_no, "unknown keyword '" + t[0] + "'");
    }
  }
  if (!have_format) header_error(line_no, "no 'format' line");
  // Binary bodies written on Windows may follow "end_header\r\n"; the \n is already consumed.
  return {format, std::move(elements), pos};
}

// Where the mesh is in the elements: the vertex element and its x, y, z properties, the face element
// and its vertex-index list. Throws impinge::Error naming `path` when one is missing or out of order.
struct PlyLayout {
  int vertex_el = -1, face_el = -1, xyz[3] = {-1, -1, -1}, face_list = -1;
};
PlyLayout find_ply_layout(const std::string& path, const std::vector<PlyElement>& elements) {
  PlyLayout L;
  int &vertex_el = L.vertex_el, &face_el = L.face_el, &face_list = L.face_list;
  int* xyz = L.xyz;
  for (std::size_t e = 0; e < elements.size(); ++e) {
    const PlyElement& el = elements[e];
    if (el.name == "vertex" && vertex_el < 0) {
      vertex_el = static_cast<int>(e);
      for (std::size_t k = 0; k < el.properties.size(); ++k)
        for (int c = 0; c < 3; ++c)
          if (el.properties[k].name == std::string(1, static_cast<char>('x' + c)) && el.properties[k].count_type == nullptr)
            xyz[c] = static_cast<int>(k);
    } else if (el.name == "face" && face_el < 0) {
      face_el = static_cast<int>(e);
      for (std::size_t k = 0; k < el.properties.size(); ++k)
        if ((el.properties[k].name == "vertex_indices" || el.properties[k].name == "vertex_index") &&
            el.properties[k].count_type != nullptr && face_list < 0)
          face_list = static_cast<int>(k);
    }
  }
  if (vertex_el < 0) throw Error(path + ": cannot parse PLY: no 'vertex' element");
  if (xyz[0] < 0 || xyz[1] < 0 || xyz[2] < 0)
    throw Error(path + ": cannot parse PLY: the 'vertex' element lacks a scalar x, y or z property");
  if (face_el < 0) throw Error(path + ": mesh has no triangles (no 'face' element)");
  if (face_list < 0) throw Error(path + ": cannot parse PLY: the 'face' element has no list 'vertex_indices'");
  if (!elements[static_cast<std::size_t>(face_el)].properties[static_cast<std::size_t>(face_list)].type->integer)
    throw Error(path + ": cannot parse PLY: 'vertex_indices' has a floating-point type");

  if (vertex_el > face_el)
    throw Error(path + ": cannot parse PLY: the 'face' element comes before the 'vertex' element");

  return L;
}

}  // namespace

TriangleMesh read_ply(const std::string& path, const std::string& bytes) {
  const PlyHeader header = parse_ply_header(path, bytes);
  const PlyFormat format = header.format;
  const std::vector<PlyElement>& elements = header.elements;
  const PlyLayout layout = find_ply_layout(path, elements);
  const int vertex_el = layout.vertex_el, face_el = layout.face_el, face_list = layout.face_list;
  const int* xyz = layout.xyz;
  PlyBody body(path, bytes, header.body_start, format);
  // Refuse counts the file cannot hold before allocating for them.
  for (const PlyElement& el : elements) {
    std::size_t least = 0;  // bytes per element at least
    for (const PlyProperty& p : el.properties)
      least += format == PlyFormat::ascii ? 2 : static_cast<std::size_t>(p.count_type ? p.count_type->bytes : p.type->bytes);
    if (least > 0 && el.count > (body.remaining() + 1) / least)
      body.fail("element '" + el.name + "' has " + std::to_string(el.count) +
                " entries, more than the rest of the file can hold (truncated?)");
  }
  TriangleMesh mesh;
  mesh.source = path;
  for (std::size_t e = 0; e < elements.size(); ++e) {
    const PlyElement& el = elements[e];
    const bool is_vertex = static_cast<int>(e) == vertex_el, is_face = static_cast<int>(e) == face_el;
    if (el.properties.empty()) continue;  // no data, however large its count
    if (is_vertex) mesh.V.resize(static_cast<Eigen::Index>(el.count), 3);
    if (is_face) mesh.F.resize(static_cast<Eigen::Index>(el.count), 3);
    for (std::uint64_t i = 0; i < el.count; ++i) {
      for (std::size_t k = 0; k < el.properties.size(); ++k) {
        const PlyProperty& p = el.properties[k];
        const PlyWhere what{el.name, i, p.name};
        if (p.count_type == nullptr) {
          const double v = body.real(*p.type, what);
          for (int c = 0; is_vertex && c < 3; ++c)
            if (static_cast<int>(k) == xyz[c]) mesh.V(static_cast<Eigen::Index>(i), c) = v;
          continue;
        }
        const long long n = body.integer(*p.count_type, PlyWhere{el.name, i, p.name, " (list count)"});
        if (n < 0) body.fail(what.text() + ": negative list count " + std::to_string(n));
        if (is_face && static_cast<int>(k) == face_list) {
          if (n != 3) {
            std::ostringstream os;
            os << path << ": face " << i << " has " << n << " vertices; only triangles are supported";
            throw Error(os.str());
          }
          for (int c = 0; c < 3; ++c) {
            const long long idx = body.integer(*p.type, what);
            if (idx < 0 || idx >= static_cast<long long>(mesh.V.rows())) {
              std::ostringstream os;
              os << path << ": face " << i << " has vertex index " << idx << " outside [0, " << mesh.V.rows() << ")";
              throw Error(os.str());
            }
            mesh.F(static_cast<Eigen::Index>(i), c) = static_cast<int>(idx);
          }
          continue;
        }
        const std::size_t item = format == PlyFormat::ascii ? 2 : static_cast<std::size_t>(p.type->bytes);
        if (static_cast<unsigned long long>(n) > (body.remaining() + 1) / item)
          body.fail(what.text() + ": list of " + std::to_string(n) + " entries runs past the end of the file");
        for (long long j = 0; j < n; ++j) body.real(*p.type, what);
      }
    }
  }
  body.expect_end();
  return mesh;
}

// ---------------------------------------------------------------------------------------------
// OFF

TriangleMesh read_off(const std::string& path, const std::string& bytes) {
  std::istringstream in(bytes);
  std::string raw;
  std::size_t line_no = 0;
  // The next line with content, comments removed, as tokens; false at the end of the file.
  auto next = [&](std::vector<std::string>& t) {
    while (std::getline(in, raw)) {
      ++line_no;
      const std::size_t hash = raw.find('#');
      t = tokens(hash == std::string::npos ? raw : raw.substr(0, hash));
      if (!t.empty()) return true;
    }
    return false;
  };
  auto fail = [&](const std::string& message) {
    throw Error(path + ": cannot parse OFF: line " + std::to_string(line_no) + ": " + message);
  };
  std::vector<std::string> t;
  if (!next(t) || t[0] != "OFF") fail("the file does not start with 'OFF'");
  if (t.size() == 1 && !next(t)) fail("no 'vertices faces edges' counts");
  const std::size_t c0 = t[0] == "OFF" ? 1 : 0;  // counts may follow OFF on its line
  long long nv = 0, nf = 0;
  const long long most = static_cast<long long>(std::min<std::size_t>(bytes.size() / 2, INT_MAX));
  if (t.size() < c0 + 2 || !parse_integer(t[c0], 0, most, nv) || !parse_integer(t[c0 + 1], 0, most, nf))
    fail("expected the counts 'vertices faces [edges]', each no more than the file can hold");
  TriangleMesh mesh;
  mesh.source = path;
  mesh.V.resize(nv, 3);
  mesh.F.resize(nf, 3);
  for (long long i = 0; i < nv; ++i) {
    if (!next(t)) fail("the file ends before vertex " + std::to_string(i) + " of " + std::to_string(nv));
    if (t.size() < 3) fail("vertex " + std::to_string(i) + " has fewer than 3 coordinates");
    for (int c = 0; c < 3; ++c) {
      double v = 0;
      if (!parse_real(t[static_cast<std::size_t>(c)], v))
        fail("vertex " + std::to_string(i) + ": '" + t[static_cast<std::size_t>(c)] + "' is not a number");
      mesh.V(i, c) = v;
    }
  }
  for (long long f = 0; f < nf; ++f) {
    if (!next(t)) fail("the file ends before face " + std::to_string(f) + " of " + std::to_string(nf));
    long long n = 0;
    if (!parse_integer(t[0], 0, INT_MAX, n)) fail("face " + std::to_string(f) + ": '" + t[0] + "' is not a vertex count");
    if (n != 3) {
      std::ostringstream os;
      os << path << ": face " << f << " has " << n << " vertices; only triangles are supported";
      throw Error(os.str());
    }
    if (t.size() < 4) fail("face " + std::to_string(f) + " has fewer than 3 indices");
    for (int c = 0; c < 3; ++c) {
      long long idx = 0;
      if (!parse_integer(t[static_cast<std::size_t>(c + 1)], INT_MIN, INT_MAX, idx))
        fail("face " + std::to_string(f) + ": '" + t[static_cast<std::size_t>(c + 1)] + "' is not an index");
      if (idx < 0 || idx >= nv) {
        std::ostringstream os;
        os << path << ": face " << f << " has vertex index " << idx << " outside [0, " << nv << ")";
        throw Error(os.str());
      }
      mesh.F(f, c) = static_cast<int>(idx);
    }
  }
  return mesh;
}

// ---------------------------------------------------------------------------------------------
// OBJ (Wavefront): "v x y z [w]" and "f i j k" lines (i, i/t, i//n, i/t/n; negative indices count back from
// the last vertex read), every other line ignored. Vertices in the file's order, as PLY and OFF give them.

TriangleMesh read_obj(const std::string& path, const std::string& bytes) {
  std::istringstream in(bytes);
  std::string raw;
  std::size_t line_no = 0;
  auto fail = [&](const std::string& message) {
    throw Error(path + ": cannot parse OBJ: line " + std::to_string(line_no) + ": " + message);
  };
  std::vector<double> v;
  std::vector<int> f;
  while (std::getline(in, raw)) {
    ++line_no;
    const std::size_t hash = raw.find('#');
    const std::vector<std::string> t = tokens(hash == std::string::npos ? raw : raw.substr(0, hash));
    if (t.empty()) continue;
    if (t[0] == "v") {
      if (t.size() < 4) fail("a vertex needs x y z");
      for (int c = 1; c <= 3; ++c) {
        double x = 0;
        if (!parse_real(t[static_cast<std::size_t>(c)], x)) fail("'" + t[static_cast<std::size_t>(c)] + "' is not a number");
        v.push_back(x);
      }
      require(v.size() / 3 <= static_cast<std::size_t>(INT_MAX), [&] { return path + ": more vertices than 2^31 - 1"; });
    } else if (t[0] == "f") {
      const std::size_t face = f.size() / 3;
      if (t.size() != 4) {
        std::ostringstream os;
        os << path << ": face " << face << " (line " << line_no << ") has " << t.size() - 1
           << " vertices; only triangles are supported";
        throw Error(os.str());
      }
      const long long nv = static_cast<long long>(v.size() / 3);
      for (std::size_t c = 1; c <= 3; ++c) {
        const std::string index = t[c].substr(0, t[c].find('/'));
        long long i = 0;
        if (!parse_integer(index, -nv, nv, i) || i == 0) {
          std::ostringstream os;
          os << path << ": face " << face << " (line " << line_no << ") has vertex index '" << index << "' outside [1, "
             << nv << "] (or -" << nv << "..-1)";
          throw Error(os.str());
        }
        f.push_back(static_cast<int>(i > 0 ? i - 1 : nv + i));
      }
    }
  }
  TriangleMesh mesh;
  mesh.source = path;
  mesh.V.resize(static_cast<Eigen::Index>(v.size() / 3), 3);
  for (std::size_t k = 0; k < v.size(); ++k) mesh.V(static_cast<Eigen::Index>(k / 3), static_cast<Eigen::Index>(k % 3)) = v[k];
  mesh.F.resize(static_cast<Eigen::Index>(f.size() / 3), 3);
  for (std::size_t k = 0; k < f.size(); ++k) mesh.F(static_cast<Eigen::Index>(k / 3), static_cast<Eigen::Index>(k % 3)) = f[k];
  return mesh;
}

}  // namespace impinge::detail
