// The option table (session/option_table.hpp). Invariants: every row is complete and named once; a
// row's get reads back what its set stored (so the defaults shown are the values used); values outside
// a row's range or choices are refused with a message naming the option, the value and what is valid;
// the CLI texts parse to the same values as the typed ones; the presets differ from the library's
// structs exactly where they say. Front ends against the table: python/tests/test_options.py.
#include "impinge/session/option_table.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "impinge/core/error.hpp"
#include "test_support.hpp"

namespace impinge {
namespace {

using test::error_of;

TEST(OptionTable, EveryRowCompleteAndNamedOnce) {
  std::set<std::string> names, keys;
  for (const OptionRow& r : option_table()) {
    SCOPED_TRACE(r.name);
    EXPECT_FALSE(r.name.empty());
    EXPECT_FALSE(r.key.empty());
    EXPECT_GT(r.help.size(), 10u);
    EXPECT_NE(r.uses, 0u);
    EXPECT_TRUE(r.set && r.get);
    EXPECT_TRUE(names.insert(r.name).second) << "two rows named " << r.name;
    EXPECT_TRUE(keys.insert(r.key).second) << "two rows keyed " << r.key;
    EXPECT_EQ(find_option(r.name), &r);
    EXPECT_EQ(find_option(r.key), &r);
    if (r.type == OptionType::choice) {
      EXPECT_GE(r.choices.size(), 2u);
    }
    if (r.type == OptionType::number || r.type == OptionType::integer) {
      EXPECT_LT(r.min, r.max);
    }
    // Its default is a valid value: setting it changes nothing.
    RunOptions o = RunOptions::clinical();
    const OptionValue d = r.get(o);
    r.set(o, d, r.name);
    EXPECT_EQ(option_text(r, r.get(o)), option_text(r, d));
  }
  EXPECT_EQ(option_table().front().name, "preset");  // applied first by every front end
}

TEST(OptionTable, NumbersReadBackAtBothEndsOfTheirRangeAndAreRefusedBeyond) {
  for (const OptionRow& r : option_table()) {
    if (r.type != OptionType::number && r.type != OptionType::integer) continue;
    SCOPED_TRACE(r.name);
    RunOptions o = RunOptions::clinical();
    for (const double x : {r.min, r.max}) {
      r.set(o, x, "--" + r.name);
      EXPECT_EQ(std::get<double>(r.get(o)), x);
    }
    const double below = r.min - std::max(1.0, std::fabs(r.min));
    const std::string e = error_of([&] { r.set(o, below, "--" + r.name); });
    EXPECT_NE(e.find("--" + r.name + ": "), std::string::npos) << e;
    EXPECT_NE(e.find("outside the valid range"), std::string::npos) << e;
    EXPECT_NE(error_of([&] { r.set(o, std::nan(""), "--" + r.name); }).find("not a finite number"), std::string::npos);
  }
}

TEST(OptionTable, TextsParseAsTheTypedValues) {
  const OptionRow& radius = *find_option("max-radius");
  RunOptions o = RunOptions::clinical();
  radius.set(o, parse_option_text(radius, "12.5", "--max-radius"), "--max-radius");
  EXPECT_EQ(o.session.maps.max_radius_mm, 12.5);
  EXPECT_NE(error_of([&] { parse_option_text(radius, "12.5mm", "--max-radius"); }).find("'12.5mm' is not a finite"),
            std::string::npos);
  EXPECT_NE(error_of([&] { parse_option_text(radius, "inf", "--max-radius"); }).find("not a finite"), std::string::npos);
  const OptionRow& sparse = *find_option("sparse");  // the one row whose range is open above
  sparse.set(o, parse_option_text(sparse, "inf", "--sparse"), "--sparse");
  EXPECT_TRUE(std::isinf(o.session.maps.sparse_mm));
  const OptionRow& cor = *find_option("cor");
  cor.set(o, parse_option_text(cor, "1,2,3", "--cor"), "--cor");
  ASSERT_TRUE(o.session.cor.given);
  EXPECT_EQ(*o.session.cor.given, Eigen::Vector3d(1, 2, 3));
  cor.set(o, parse_option_text(cor, "auto", "--cor"), "--cor");
  EXPECT_FALSE(o.session.cor.given);
  EXPECT_NE(error_of([&] { cor.set(o, std::vector<double>{1, 2}, "cor"); }).find("cor: expected 3 numbers, got 2"),
            std::string::npos);
  const OptionRow& distances = *find_option("distances");
  distances.set(o, parse_option_text(distances, "off", "--distances"), "--distances");
  EXPECT_FALSE(o.session.maps.distances);
  EXPECT_NE(error_of([&] { parse_option_text(distances, "maybe", "--distances"); }).find("not on or off"),
            std::string::npos);
  const OptionRow& metric = *find_option("metric");
  metric.set(o, std::string("radial"), "--metric");
  EXPECT_EQ(o.rom.search.metric, RomMetric::radial);
  EXPECT_EQ(error_of([&] { metric.set(o, std::string("euclid"), "--metric"); }),
            "--metric: 'euclid' is not one of distance, radial");
  const OptionRow& layers = *find_option("layers");
  EXPECT_EQ(error_of([&] { layers.set(o, 2.5, "layers"); }), "layers: 2.5 is not a whole number");
  const OptionRow& no_map = *find_option("no-map");  // a flag that clears a member
  no_map.set(o, true, "--no-map");
  EXPECT_FALSE(o.rom.map);
  EXPECT_EQ(std::get<bool>(no_map.get(o)), true);
}

TEST(OptionTable, PresetsDifferFromTheLibraryDefaultsWhereTheySay) {
  const RunOptions c = RunOptions::clinical(), t = RunOptions::thesis(), lib;
  EXPECT_EQ(lib.session.maps.layers, 0);
  EXPECT_FALSE(lib.session.maps.distances);
  EXPECT_EQ(c.session.maps.layers, 4);
  EXPECT_TRUE(c.session.maps.distances);
  EXPECT_EQ(c.rom.search.metric, RomMetric::distance);
  EXPECT_EQ(c.rom.map_flexion_deg.size(), 25u);
  EXPECT_EQ(c.rom.map_adduction_deg.size(), 13u);
  EXPECT_TRUE(c.session.frames.joint_centre.empty());  // follows the neutral
  EXPECT_EQ(t.session.maps.layers, 0);
  EXPECT_FALSE(t.session.maps.distances);
  EXPECT_EQ(t.session.frames.joint_centre, "femoral-head");
  EXPECT_EQ(t.rom.search.metric, RomMetric::radial);
  EXPECT_EQ(t.rom.search.contacts, RomContacts::all);
  EXPECT_EQ(t.rom.search.contact_depth_mm, 0);
  // The preset row: thesis keeps the inputs and the command, resets maps, frames and ROM.
  RunOptions o = RunOptions::clinical();
  o.session.input.subject = "s.json";
  o.command.out = "out";
  o.session.maps.precision = 0.25;
  find_option("preset")->set(o, std::string("thesis"), "--preset");
  EXPECT_EQ(o.session.input.subject, "s.json");
  EXPECT_EQ(o.command.out, "out");
  EXPECT_EQ(o.session.maps.precision, 0);
  EXPECT_EQ(o.session.frames.joint_centre, "femoral-head");
  EXPECT_EQ(std::get<std::string>(find_option("preset")->get(o)), "thesis");
  EXPECT_EQ(error_of([] { RunOptions::named("fast", "--preset"); }), "--preset: 'fast' is not one of clinical, thesis");
}

}  // namespace
}  // namespace impinge
