// The option table (session/option_table.hpp). Invariants: every row is complete and named once; a
// row's get reads back what its set stored (so the defaults shown are the values used); values outside
// a row's range or choices are refused with a message naming the option, the value and what is valid;
// the CLI texts parse to the same values as the typed ones; the presets differ from the library's
// structs exactly where they say. Front ends against the table: python/tests/test_options.py.
#include "impinge/session/option_table.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>

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

// Issue 80: --triangles' help said it took 20 and up while the row refused below 50. A help text that states a
// range ("[50, 20000000]", "(0, 90]") states the row's own, the one its values are checked against.
TEST(OptionTable, ARangeInAHelpTextIsTheRowsRange) {
  const std::regex written(R"([\[(](-?[0-9.e+]+|-?inf), (-?[0-9.e+]+|inf)\])");
  int stated = 0;
  for (const OptionRow& r : option_table()) {
    if (r.type != OptionType::number && r.type != OptionType::integer) continue;
    SCOPED_TRACE(r.name + ": " + r.help);
    for (std::sregex_iterator m(r.help.begin(), r.help.end(), written), end; m != end; ++m, ++stated) {
      EXPECT_EQ(std::stod((*m)[1]), r.min);
      EXPECT_EQ(std::stod((*m)[2]), r.max);
      EXPECT_EQ(m->str()[0] == '(', r.min_open);
    }
  }
  EXPECT_GE(stated, 1);  // --triangles states its range
  const OptionRow* triangles = find_option("triangles");
  ASSERT_NE(triangles, nullptr);
  EXPECT_NE(triangles->help.find("[50, 20000000]"), std::string::npos) << triangles->help;
  RunOptions o = RunOptions::clinical();
  EXPECT_NO_THROW(triangles->set(o, 50.0, "--triangles"));
  EXPECT_EQ(error_of([&] { triangles->set(o, 49.0, "--triangles"); }),
            "--triangles: 49 is outside the valid range [50, 20000000]");
}

TEST(OptionTable, NumbersReadBackAtBothEndsOfTheirRangeAndAreRefusedBeyond) {
  for (const OptionRow& r : option_table()) {
    if (r.type != OptionType::number && r.type != OptionType::integer) continue;
    SCOPED_TRACE(r.name);
    RunOptions o = RunOptions::clinical();
    const double lowest = r.min_open ? std::nextafter(r.min, r.max) : r.min;  // the least valid value
    for (const double x : {lowest, r.max}) {
      r.set(o, x, "--" + r.name);
      EXPECT_EQ(std::get<double>(r.get(o)), x);
    }
    if (r.min_open) {
      EXPECT_NE(error_of([&] { r.set(o, r.min, "--" + r.name); }).find("outside the valid range ("), std::string::npos);
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
  EXPECT_EQ(o.session.hip.joint.max_radius_mm, 12.5);
  EXPECT_NE(error_of([&] { parse_option_text(radius, "12.5mm", "--max-radius"); }).find("'12.5mm' is not a finite"),
            std::string::npos);
  radius.set(o, 0.0, "--max-radius");  // 0: every vertex, the field's infinity
  EXPECT_TRUE(std::isinf(o.session.hip.joint.max_radius_mm));
  EXPECT_EQ(std::get<double>(radius.get(o)), 0.0);
  const OptionRow& layers_row = *find_option("layers");  // a row whose range is closed above
  EXPECT_NE(error_of([&] { parse_option_text(layers_row, "inf", "--layers"); }).find("not a whole number"),
            std::string::npos);
  const OptionRow& sparse = *find_option("sparse");  // a row whose range is open above, 0 meaning dense maps
  sparse.set(o, parse_option_text(sparse, "inf", "--sparse"), "--sparse");
  EXPECT_TRUE(o.session.hip.joint.sparse_maps);
  EXPECT_TRUE(std::isinf(o.session.hip.joint.sparse_region_mm));
  sparse.set(o, 0.0, "--sparse");
  EXPECT_FALSE(o.session.hip.joint.sparse_maps);
  EXPECT_EQ(std::get<double>(sparse.get(o)), 0.0);
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
  EXPECT_FALSE(o.session.hip.joint.distances);
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

// Issue 78: a numeric row's range is its field's declaration (a Range beside the field in its struct), never
// numbers written into the row: every t.number / t.integer call of option_rows.cpp names a k...Range.
TEST(OptionTable, RowRangesAreTheFieldsDeclarations) {
  std::ifstream f(std::string(IMPINGE_SOURCE_DIR) + "/libcore/src/session/option_rows.cpp");
  ASSERT_TRUE(f) << "option_rows.cpp not found";
  std::stringstream text;
  text << f.rdbuf();
  const std::string src = text.str();
  const std::regex call(R"(t\.(number|integer)\(\s*"([a-z-]+)\"([^;]*?)\"[A-Z][^A-Z"])");
  int calls = 0;
  for (auto it = std::sregex_iterator(src.begin(), src.end(), call); it != std::sregex_iterator(); ++it, ++calls) {
    const std::string name = (*it)[2], args = (*it)[3];
    SCOPED_TRACE(name);
    EXPECT_TRUE(std::regex_search(args, std::regex(R"([A-Za-z]+::k[A-Za-z]+Range)"))) << args;
    EXPECT_FALSE(std::regex_search(args, std::regex(R"(,\s*-?[0-9][0-9.e]*\s*,)"))) << "a literal range: " << args;
  }
  EXPECT_GE(calls, 25);
}

// The table's ranges and the library's checks are one: every value a numeric row of the joint accepts at either
// end of its range, the session's set-up (resolved_hip_options: JointOptions::validate) accepts too, and the
// values the library refuses the row refuses (issue 78's four mismatches: layers, layered-spacing,
// extra-articular-radius, discontinuity-tolerance).
TEST(OptionTable, TheLibraryAcceptsWhatTheTableAccepts) {
  for (const OptionRow& r : option_table()) {
    if ((r.type != OptionType::number && r.type != OptionType::integer) || !(r.uses & use_joint)) continue;
    if (r.name == "resolution" || r.name == "turns" || r.name == "max-memory") continue;  // the scheme's own check
    SCOPED_TRACE(r.name);
    for (const double x : {r.min_open ? std::nextafter(r.min, r.max) : r.min, r.max}) {
      RunOptions o = RunOptions::clinical();
      r.set(o, x, r.name);
      EXPECT_EQ(error_of([&] { resolved_hip_options(o.session); }), "(no error)") << x;
    }
  }
  RunOptions o = RunOptions::clinical();
  EXPECT_NE(error_of([&] { find_option("layers")->set(o, 17.0, "layers"); }).find("[0, 16]"), std::string::npos);
  EXPECT_NE(error_of([&] { find_option("layered-spacing")->set(o, 91.0, "x"); }).find("[0, 90]"), std::string::npos);
  EXPECT_NE(error_of([&] { find_option("extra-articular-radius")->set(o, 0.0, "x"); }).find("(0, inf]"),
            std::string::npos);
  EXPECT_NE(error_of([&] { find_option("discontinuity-tolerance")->set(o, 0.0, "x"); }).find("(0, 1000]"),
            std::string::npos);
}

// Each choice row's choices are its enum's name table, and each name reads back as itself.
TEST(OptionTable, ChoicesAreTheEnumsNames) {
  EXPECT_EQ(find_option("mode")->choices, enum_choices(kDistanceModeNames));
  EXPECT_EQ(find_option("sampling")->choices, enum_choices(kSamplingMethodNames));
  EXPECT_EQ(find_option("neutral")->choices, enum_choices(kNeutralNames));
  EXPECT_EQ(find_option("joint-centre")->choices, enum_choices(kJointCentreMethodNames));
  EXPECT_EQ(find_option("pelvis-frame")->choices, enum_choices(kPelvisFrameKindNames));
  EXPECT_EQ(find_option("femur-frame")->choices, enum_choices(kFemurFrameKindNames));
  EXPECT_EQ(find_option("levels-on")->choices, enum_choices(kLevelQuantityNames));
  EXPECT_EQ(find_option("metric")->choices, enum_choices(kRomMetricNames));
  EXPECT_EQ(find_option("contacts")->choices, enum_choices(kRomContactsNames));
  EXPECT_EQ(find_option("resect")->choices, enum_choices(kResectBonesNames));
  for (const OptionRow& r : option_table()) {
    if (r.type != OptionType::choice) continue;
    SCOPED_TRACE(r.name);
    for (const std::string& c : r.choices) {
      RunOptions o = RunOptions::clinical();
      r.set(o, c, r.name);
      EXPECT_EQ(std::get<std::string>(r.get(o)), c);
    }
    RunOptions o = RunOptions::clinical();
    EXPECT_NE(error_of([&] { r.set(o, std::string("cubic"), "--" + r.name); }).find("'cubic' is not one of"),
              std::string::npos);
  }
  EXPECT_EQ(to_string(JointCentreMethod::femoral_head), std::string("femoral-head"));
  EXPECT_EQ(parse_joint_centre("femoral_head", "x"), JointCentreMethod::femoral_head);  // underscores accepted
  EXPECT_EQ(to_string(SamplingMethod::ray_cast_bvh), std::string("ray-cast-bvh"));
}

TEST(OptionTable, PresetsDifferFromTheLibraryDefaultsWhereTheySay) {
  const RunOptions c = RunOptions::clinical(), t = RunOptions::thesis(), lib;
  EXPECT_EQ(lib.session.hip.joint.layers, 0);
  EXPECT_FALSE(lib.session.hip.joint.distances);
  EXPECT_EQ(c.session.hip.joint.layers, 4);
  EXPECT_TRUE(c.session.hip.joint.distances);
  EXPECT_EQ(c.rom.search.metric, RomMetric::distance);
  EXPECT_EQ(c.rom.map_flexion_deg.size(), 25u);
  EXPECT_EQ(c.rom.map_adduction_deg.size(), 13u);
  EXPECT_FALSE(c.session.hip.joint_centre);  // follows the neutral
  EXPECT_EQ(t.session.hip.joint.layers, 0);
  EXPECT_FALSE(t.session.hip.joint.distances);
  EXPECT_EQ(t.session.hip.joint_centre, JointCentreMethod::femoral_head);
  EXPECT_EQ(t.rom.search.metric, RomMetric::radial);
  EXPECT_EQ(t.rom.search.contacts, RomContacts::all);
  EXPECT_EQ(t.rom.search.contact_depth_mm, 0);
  // The preset row: thesis keeps the inputs and the command, resets maps, frames and ROM.
  RunOptions o = RunOptions::clinical();
  o.session.input.subject = "s.json";
  o.command.out = "out";
  o.session.grid.precision = 0.25;
  find_option("preset")->set(o, std::string("thesis"), "--preset");
  EXPECT_EQ(o.session.input.subject, "s.json");
  EXPECT_EQ(o.command.out, "out");
  EXPECT_EQ(o.session.grid.precision, 0);
  EXPECT_EQ(o.session.hip.joint_centre, JointCentreMethod::femoral_head);
  EXPECT_EQ(std::get<std::string>(find_option("preset")->get(o)), "thesis");
  EXPECT_EQ(error_of([] { RunOptions::named("fast", "--preset"); }), "--preset: 'fast' is not one of clinical, thesis");
}

}  // namespace
}  // namespace impinge
