#include "impinge/maps/map_io.hpp"

#include <sstream>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <vector>

#include "impinge/core/atomic_file.hpp"
#include "impinge/core/error.hpp"

namespace impinge {

namespace {
constexpr char kMagic[8] = {'I', 'M', 'P', 'M', 'A', 'P', '\r', '\n'};
constexpr std::uint32_t kVersion = 1;

template <typename T>
void put(std::vector<char>& b, const T& v) {
  const char* p = reinterpret_cast<const char*>(&v);
  b.insert(b.end(), p, p + sizeof(T));
}

// Bounds-checked reader over the file's bytes.
struct Reader {
  const std::vector<char>& b;
  std::size_t pos = 0;
  const std::string& path;
  template <typename T>
  T get(const char* field) {
    require(pos + sizeof(T) <= b.size(), path + ": truncated map file (at " + field + ")");
    T v;
    std::memcpy(&v, b.data() + pos, sizeof(T));
    pos += sizeof(T);
    return v;
  }
};
}  // namespace

std::uint64_t fnv1a64(const void* data, std::size_t n, std::uint64_t h) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < n; ++i) h = (h ^ p[i]) * 1099511628211ull;
  return h;
}

template <typename Scalar>
void save_map(const std::string& path, const RadialDistanceMapT<Scalar>& map, const Eigen::Vector3d& cor) {
  require(cor.allFinite(), path + ": the map's COR is not finite");
  const std::string name = map.scheme().name();
  std::vector<char> b(kMagic, kMagic + 8);
  put(b, kVersion);
  put(b, static_cast<std::uint32_t>(name.size()));
  b.insert(b.end(), name.begin(), name.end());
  put(b, map.scheme().resolution());
  put(b, static_cast<std::uint32_t>(sizeof(Scalar)));
  put(b, static_cast<std::int64_t>(map.num_nodes()));
  for (int c = 0; c < 3; ++c) put(b, cor[c]);
  if (!map.sparse()) {
    const char* v = reinterpret_cast<const char*>(map.data());
    b.insert(b.end(), v, v + map.num_nodes() * static_cast<std::int64_t>(sizeof(Scalar)));
  } else {  // the same file as the dense map: every node, absent tiles as "no surface"
    for (std::int64_t i = 0; i < map.num_nodes(); ++i) put(b, map.at(i));
  }
  put(b, fnv1a64(b.data(), b.size()));
  write_file_atomically(path, std::string_view(b.data(), b.size()));
}

template <typename Scalar>
RadialDistanceMapT<Scalar> load_map(const std::string& path, Eigen::Vector3d* cor) {
  std::ifstream in(path, std::ios::binary);
  require(in.good(), path + ": cannot open map file");
  const std::vector<char> b((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  require(b.size() >= 8 + 8 && std::memcmp(b.data(), kMagic, 8) == 0, path + ": not an impinge map file (bad magic)");
  // Checksum first: any flipped byte is reported as corruption before fields are trusted.
  std::uint64_t stored;
  std::memcpy(&stored, b.data() + b.size() - 8, 8);
  require(fnv1a64(b.data(), b.size() - 8) == stored, path + ": checksum mismatch (corrupt or truncated map file)");
  Reader r{b, 8, path};
  const auto version = r.get<std::uint32_t>("version");
  require(version == kVersion, path + ": map file version " + std::to_string(version) + " (this build reads 1)");
  const auto len = r.get<std::uint32_t>("name_length");
  require(len >= 1 && len <= 64 && r.pos + len <= b.size(), path + ": bad scheme name length " + std::to_string(len));
  const std::string name(b.data() + r.pos, len);
  r.pos += len;
  const auto resolution = r.get<double>("resolution");
  std::shared_ptr<const SamplingScheme> scheme;
  try {
    scheme = make_scheme(name, resolution);
  } catch (const Error& e) {
    throw Error(path + ": " + e.what());
  }
  const auto value_bytes = r.get<std::uint32_t>("value_bytes");
  require(value_bytes == sizeof(Scalar), path + ": values are " + std::to_string(value_bytes) +
                                             "-byte, this map type holds " + std::to_string(sizeof(Scalar)) + "-byte");
  const auto n = r.get<std::int64_t>("num_nodes");
  require(n == scheme->num_nodes(), path + ": " + std::to_string(n) + " nodes, the scheme " + name + " at " +
                                        std::to_string(resolution) + " has " + std::to_string(scheme->num_nodes()));
  Eigen::Vector3d c;
  for (int k = 0; k < 3; ++k) c[k] = r.get<double>("cor");
  require(c.allFinite(), path + ": the COR is not finite");
  require(b.size() - r.pos == static_cast<std::size_t>(n) * sizeof(Scalar) + 8,
          path + ": file length does not match " + std::to_string(n) + " nodes (truncated or trailing bytes)");
  RadialDistanceMapT<Scalar> map(scheme);
  std::memcpy(map.data(), b.data() + r.pos, static_cast<std::size_t>(n) * sizeof(Scalar));
  for (std::int64_t i = 0; i < n; ++i) {
    const Scalar d = map.at(i);
    require(d > 0 && !std::isnan(d), [&] {
      return path + ": node " + std::to_string(i) + " has distance " + std::to_string(d) + " (must be > 0 or +inf)";
    });
  }
  if (cor != nullptr) *cor = c;
  return map;
}

template void save_map<float>(const std::string&, const RadialDistanceMapT<float>&, const Eigen::Vector3d&);
template void save_map<double>(const std::string&, const RadialDistanceMapT<double>&, const Eigen::Vector3d&);
template RadialDistanceMapT<float> load_map<float>(const std::string&, Eigen::Vector3d*);
template RadialDistanceMapT<double> load_map<double>(const std::string&, Eigen::Vector3d*);

}  // namespace impinge
