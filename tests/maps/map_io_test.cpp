// Map files. Invariants: a saved map loads back bit for bit with its scheme, resolution and COR,
// for every registered scheme and both value types; every corruption (any single flipped byte,
// truncation at any length, trailing bytes, wrong magic or version, unknown scheme, node count or
// value type that does not match) is an error naming the file, never a wrong map.
#include "impinge/maps/map_io.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <random>

#include "impinge/core/error.hpp"
#include "impinge/detection/joint.hpp"
#include "impinge/io/generated_models.hpp"
#include "impinge/sampling/sampling.hpp"
#include "test_support.hpp"

using namespace impinge;

namespace {
std::vector<char> read_bytes(const std::string& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}
void write_bytes(const std::string& p, const std::vector<char>& b) {
  std::ofstream os(p, std::ios::binary);
  os.write(b.data(), static_cast<std::streamsize>(b.size()));
}
RadialDistanceMap sampled(const std::string& scheme, double resolution) {
  const HipModel h = make_hip_model({});
  RadialDistanceMap map(make_scheme(scheme, resolution));
  sample_surface(h.socket, h.cor, SamplingOptions{}, map);
  return map;
}
}  // namespace

TEST(MapIo, RoundTripEveryRegisteredSchemeBitForBit) {
  const std::string d = test::temp_dir("map_io");
  for (const auto& [name, res_name] : scheme_names()) {
    SCOPED_TRACE(name);
    const double res = resolution_for_spacing(name, 2.0);
    const RadialDistanceMap m = sampled(name, res);
    ASSERT_GT(m.nodes_covered(), 0);
    const Eigen::Vector3d cor(1.5, -2.25, 1e3);
    save_map(d + "/m.map", m, cor);
    Eigen::Vector3d c;
    const RadialDistanceMap l = load_map<float>(d + "/m.map", &c);
    EXPECT_EQ(l.scheme().name(), name);
    EXPECT_EQ(l.scheme().resolution(), res);
    EXPECT_EQ(c, cor);
    ASSERT_EQ(l.num_nodes(), m.num_nodes());
    EXPECT_EQ(std::memcmp(l.data(), m.data(), sizeof(float) * static_cast<std::size_t>(m.num_nodes())), 0);
    // A sparse map saves as the same file.
    RadialDistanceMap sp = m;
    sp.make_sparse(25.0);
    save_map(d + "/s.map", sp, cor);
    const RadialDistanceMap ls = load_map<float>(d + "/s.map");
    for (std::int64_t i = 0; i < m.num_nodes(); ++i) {
      const float a = ls.at(i), b = sp.at(i);
      ASSERT_EQ(std::memcmp(&a, &b, sizeof a), 0) << name << " node " << i;
    }
  }
  // Double maps, and the value type must match.
  RadialDistanceMapDouble dm(make_scheme("equiangular", 5.0));
  for (std::int64_t i = 0; i < dm.num_nodes(); ++i) dm.data()[i] = i % 3 ? 10.0 + i : dm.no_surface();
  save_map(d + "/d.map", dm, Eigen::Vector3d::Zero());
  const RadialDistanceMapDouble dl = load_map<double>(d + "/d.map");
  EXPECT_EQ(std::memcmp(dl.data(), dm.data(), sizeof(double) * static_cast<std::size_t>(dm.num_nodes())), 0);
  EXPECT_THROW(load_map<float>(d + "/d.map"), Error);
}

TEST(MapIo, EveryCorruptionIsAnErrorNamingTheFile) {
  const std::string d = test::temp_dir("map_io_bad");
  save_map(d + "/good.map", sampled("equiangular", 10.0), Eigen::Vector3d(0, 0, 0));
  const std::vector<char> good = read_bytes(d + "/good.map");
  const std::string p = d + "/bad.map";
  auto expect_error = [&](const std::vector<char>& bytes, const std::string& fragment, const std::string& what) {
    write_bytes(p, bytes);
    try {
      load_map<float>(p);
      ADD_FAILURE() << what << ": loaded";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(p), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << what << ": " << e.what();
    }
  };
  // Every single flipped byte (each bit pattern 0x01 and 0x80), every truncation.
  for (std::size_t i = 0; i < good.size(); ++i)
    for (const char x : {char(0x01), char(0x80)}) {
      std::vector<char> b = good;
      b[i] ^= x;
      expect_error(b, "", "byte " + std::to_string(i));
    }
  for (std::size_t n = 0; n < good.size(); n += 7) expect_error({good.begin(), good.begin() + n}, "", "length");
  std::vector<char> longer = good;
  longer.push_back(0);
  expect_error(longer, "", "trailing byte");
  // Fields that are consistent with a recomputed checksum are still checked.
  auto resealed = [](std::vector<char> b) {
    const std::uint64_t h = fnv1a64(b.data(), b.size() - 8);
    std::memcpy(b.data() + b.size() - 8, &h, 8);
    return b;
  };
  std::vector<char> v = good;
  v[8] = 2;
  expect_error(resealed(v), "version 2", "version");
  std::vector<char> s = good;
  s[16] = 'X';  // "equiangular" -> "Xquiangular"
  expect_error(resealed(s), "unknown", "scheme");
  std::vector<char> neg = good;
  const float minus = -1.0f;
  std::memcpy(neg.data() + neg.size() - 8 - 4, &minus, 4);
  expect_error(resealed(neg), "must be > 0", "negative distance");
  EXPECT_THROW(load_map<float>(d + "/absent.map"), Error);
}

TEST(MapIo, AJointFromSavedMapsGivesTheSameGaps) {
  const std::string d = test::temp_dir("map_io_joint");
  const HipModel h = make_hip_model({});
  JointOptions o;
  o.scheme = make_scheme("equiangular", 1.0);
  const Joint built(h.ball, h.socket, h.cor, o);
  save_map(d + "/ball.map", built.ball().map, h.cor);
  save_map(d + "/socket.map", built.socket().map, h.cor);
  Eigen::Vector3d cb, cs;
  const Joint loaded(h.ball, h.socket, h.cor, o, load_map<float>(d + "/ball.map", &cb),
                     load_map<float>(d + "/socket.map", &cs));
  EXPECT_EQ(cb, h.cor);
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const PoseResult a = built.detect(R), b = loaded.detect(R);
  EXPECT_EQ(a.ball_gaps.status, b.ball_gaps.status);
  for (std::size_t i = 0; i < a.ball_gaps.gap_mm.size(); ++i)
    if (!std::isnan(a.ball_gaps.gap_mm[i])) {
      EXPECT_EQ(a.ball_gaps.gap_mm[i], b.ball_gaps.gap_mm[i]);
    }
  EXPECT_EQ(a.socket.min_gap_mm, b.socket.min_gap_mm);
  // A map of another resolution is refused.
  JointOptions other = o;
  other.scheme = make_scheme("equiangular", 2.0);
  EXPECT_THROW(Joint(h.ball, h.socket, h.cor, other, load_map<float>(d + "/ball.map"), load_map<float>(d + "/socket.map")),
               Error);
}
