#include "impinge/io/vtk_output.hpp"

#include <cstring>
#include <fstream>
#include <iomanip>
#include <sstream>

#include "impinge/core/atomic_file.hpp"
#include "impinge/core/error.hpp"

namespace impinge {

namespace {
struct Block {
  std::string header;  // the DataArray element without its offset
  std::vector<char> bytes;
};
template <typename T>
std::vector<char> as_bytes(const std::vector<T>& v) {
  std::vector<char> b(v.size() * sizeof(T));
  if (!v.empty()) std::memcpy(b.data(), v.data(), b.size());
  return b;
}
}  // namespace

void write_vtp(const std::string& path, PointsRef V, const Faces& F, const std::vector<PointArray>& arrays) {
  const Eigen::Index n = V.rows(), m = F.rows();
  require(F.size() == 0 || (F.minCoeff() >= 0 && F.maxCoeff() < n),
          path + ": a triangle indexes a vertex outside [0, " + std::to_string(n) + ")");
  std::vector<Block> blocks;
  std::vector<Block> point_data;
  for (const PointArray& a : arrays) {
    const bool f = !a.f32.empty() || a.u8.empty();
    const std::size_t len = f ? a.f32.size() : a.u8.size();
    require(len == static_cast<std::size_t>(n), path + ": point array '" + a.name + "' has " + std::to_string(len) +
                                                    " values for " + std::to_string(n) + " points");
    point_data.push_back({std::string("<DataArray type=\"") + (f ? "Float32" : "UInt8") + "\" Name=\"" + a.name +
                              "\" format=\"appended\"",
                          f ? as_bytes(a.f32) : as_bytes(a.u8)});
  }
  std::vector<float> pts(static_cast<std::size_t>(3 * n));
  for (Eigen::Index i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) pts[static_cast<std::size_t>(3 * i + c)] = static_cast<float>(V(i, c));
  std::vector<std::int32_t> conn(static_cast<std::size_t>(3 * m)), offs(static_cast<std::size_t>(m));
  for (Eigen::Index f = 0; f < m; ++f) {
    for (int c = 0; c < 3; ++c) conn[static_cast<std::size_t>(3 * f + c)] = F(f, c);
    offs[static_cast<std::size_t>(f)] = static_cast<std::int32_t>(3 * (f + 1));
  }
  std::ostringstream xml;
  std::uint64_t offset = 0;
  auto element = [&](const Block& b) {
    xml << "        " << b.header << " offset=\"" << offset << "\"/>\n";
    offset += sizeof(std::uint64_t) + b.bytes.size();
  };
  const Block points{"<DataArray type=\"Float32\" NumberOfComponents=\"3\" format=\"appended\"", as_bytes(pts)};
  const Block connectivity{"<DataArray type=\"Int32\" Name=\"connectivity\" format=\"appended\"", as_bytes(conn)};
  const Block offsets{"<DataArray type=\"Int32\" Name=\"offsets\" format=\"appended\"", as_bytes(offs)};
  xml << "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"LittleEndian\" "
         "header_type=\"UInt64\">\n  <PolyData>\n    <Piece NumberOfPoints=\""
      << n << "\" NumberOfVerts=\"0\" NumberOfLines=\"0\" NumberOfStrips=\"0\" NumberOfPolys=\"" << m << "\">\n";
  xml << "      <PointData>\n";
  for (const Block& b : point_data) element(b);
  xml << "      </PointData>\n      <Points>\n";
  element(points);
  xml << "      </Points>\n      <Polys>\n";
  element(connectivity);
  element(offsets);
  xml << "      </Polys>\n    </Piece>\n  </PolyData>\n  <AppendedData encoding=\"raw\">\n   _";
  std::ostringstream os(std::ios::binary);
  const std::string head = xml.str();
  os.write(head.data(), static_cast<std::streamsize>(head.size()));
  auto raw = [&](const Block& b) {
    const std::uint64_t len = b.bytes.size();
    os.write(reinterpret_cast<const char*>(&len), sizeof len);
    os.write(b.bytes.data(), static_cast<std::streamsize>(b.bytes.size()));
  };
  for (const Block& b : point_data) raw(b);
  raw(points);
  raw(connectivity);
  raw(offsets);
  os << "\n  </AppendedData>\n</VTKFile>\n";
  write_file_atomically(path, os.str());
}

void write_pvd(const std::string& path, const std::vector<PvdEntry>& entries) {
  std::ostringstream os;
  os << "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"1.0\" byte_order=\"LittleEndian\">\n"
        "  <Collection>\n";
  os << std::setprecision(9);
  for (const PvdEntry& e : entries)
    os << "    <DataSet timestep=\"" << e.time_s << "\" group=\"\" part=\"0\" file=\"" << e.file << "\"/>\n";
  os << "  </Collection>\n</VTKFile>\n";
  write_file_atomically(path, os.str());
}

}  // namespace impinge
