// Motion files (CSV and OpenSim .mot/.sto). Invariants: values read back as written (degrees;
// radians converted), columns found by name in any order, the side picks _r or _l, and every
// malformed file is a one-line error naming the file, the line and the column.
#include "impinge/io/motion.hpp"

#include <gtest/gtest.h>

#include "impinge/core/error.hpp"
#include "test_support.hpp"

using namespace impinge;
using impinge::test::temp_dir;
using impinge::test::write_text;

namespace {
std::string error_of(const std::string& path, Side side = Side::right) {
  try {
    load_motion(path, side);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}
// No nRows line: the files below hold various row counts (a wrong nRows is an error, tested below).
const char* kMotHeader = "walk\nversion=1\nDataType=double\nnColumns=5\ninDegrees=yes\nendheader\n";
}  // namespace

TEST(Motion, CsvColumnsByNameInAnyOrder) {
  const std::string d = temp_dir("motion_csv");
  write_text(d + "/m.csv",
             "adduction_deg,time_s,internal_rotation_deg,flexion_deg,note\n1.5,0,-3,10,x\n2,0.01,4,20.25,y\n");
  const Motion m = load_motion(d + "/m.csv", Side::right);
  ASSERT_EQ(m.frames(), 2u);
  EXPECT_EQ(m.format, "csv");
  EXPECT_EQ(m.time_s[1], 0.01);
  EXPECT_EQ(m.angles[1].flexion_deg, 20.25);
  EXPECT_EQ(m.angles[0].adduction_deg, 1.5);
  EXPECT_EQ(m.angles[0].internal_rotation_deg, -3);
}

// Issue 80: a spreadsheet's CSV (a UTF-8 byte-order mark, every cell quoted, a quoted note holding commas and a
// quote) was "missing column 'time_s'". It is the same motion as the plain file; a column truly missing is named
// with the columns the header has; a quote left open or text after one is named with its column.
TEST(Motion, CsvWithAByteOrderMarkAndQuotedCellsIsThePlainFile) {
  const std::string d = temp_dir("motion_quoted");
  write_text(d + "/plain.csv", "time_s,flexion_deg,adduction_deg,internal_rotation_deg,note\n0,10,1.5,-3,a\n"
                               "0.5,20.25,2,4,b\n");
  write_text(d + "/sheet.csv", "\xEF\xBB\xBF\"time_s\", \"flexion_deg\",\"adduction_deg\",\"internal_rotation_deg\","
                               "\"note\"\r\n\"0\",\"10\",\"1.5\",\"-3\",\"a, \"\"b\"\", c\"\r\n"
                               "0.5,20.25 , 2,\"4\",\"\"\r\n");
  const Motion plain = load_motion(d + "/plain.csv", Side::right);
  const Motion sheet = load_motion(d + "/sheet.csv", Side::right);
  ASSERT_EQ(sheet.frames(), 2u);
  EXPECT_EQ(sheet.time_s, plain.time_s);
  for (std::size_t k = 0; k < 2; ++k) {
    EXPECT_EQ(sheet.angles[k].flexion_deg, plain.angles[k].flexion_deg);
    EXPECT_EQ(sheet.angles[k].adduction_deg, plain.angles[k].adduction_deg);
    EXPECT_EQ(sheet.angles[k].internal_rotation_deg, plain.angles[k].internal_rotation_deg);
  }
  write_text(d + "/time.csv", "\xEF\xBB\xBF\"time\",flexion_deg,adduction_deg,internal_rotation_deg\n0,1,2,3\n");
  EXPECT_EQ(error_of(d + "/time.csv"), d + "/time.csv:1: missing column 'time_s' (the header's columns: 'time', "
                                           "'flexion_deg', 'adduction_deg', 'internal_rotation_deg')");
  write_text(d + "/open.csv", "time_s,flexion_deg,adduction_deg,internal_rotation_deg\n0,\"1,2,3\n");
  EXPECT_EQ(error_of(d + "/open.csv"), d + "/open.csv:2: the quote opened at column 3 is not closed");
  write_text(d + "/after.csv", "time_s,\"flexion\"_deg,adduction_deg,internal_rotation_deg\n0,1,2,3\n");
  EXPECT_EQ(error_of(d + "/after.csv"), d + "/after.csv:1: text after the quoted cell at column 8: '_deg,adduction_deg,i'");
}

TEST(Motion, OpenSimDegreesRadiansSidesAndPathLabels) {
  const std::string d = temp_dir("motion_mot");
  write_text(d + "/a.mot", std::string(kMotHeader) +
                               "time\tpelvis_tilt\thip_flexion_r\thip_adduction_r\thip_rotation_r\thip_flexion_l\t"
                               "hip_adduction_l\thip_rotation_l\n"
                               "0.0\t1\t30\t-5\t7\t-10\t2\t3\n0.5\t1\t31\t-6\t8\t-11\t3\t4\n");
  const Motion r = load_motion(d + "/a.mot", Side::right);
  ASSERT_EQ(r.frames(), 2u);
  EXPECT_EQ(r.format, "opensim");
  EXPECT_EQ(r.angles[1].flexion_deg, 31);
  EXPECT_EQ(r.angles[1].adduction_deg, -6);
  EXPECT_EQ(r.angles[1].internal_rotation_deg, 8);
  const Motion l = load_motion(d + "/a.mot", Side::left);
  EXPECT_EQ(l.angles[0].flexion_deg, -10);
  EXPECT_EQ(l.angles[0].internal_rotation_deg, 3);
  // OpenSim 4 storage in radians with path labels.
  write_text(d + "/b.sto",
             "states\ninDegrees=no\nendheader\ntime /jointset/hip_r/hip_flexion_r/value "
             "/jointset/hip_r/hip_adduction_r/value /jointset/hip_r/hip_rotation_r/value\n0 1.5707963267948966 0 "
             "-0.5\n");
  const Motion b = load_motion(d + "/b.sto", Side::right);
  EXPECT_NEAR(b.angles[0].flexion_deg, 90, 1e-12);
  EXPECT_NEAR(b.angles[0].internal_rotation_deg, -0.5 * 180 / M_PI, 1e-12);
  // An empty cell in a column the motion does not use leaves the row's angles where they are (a whitespace
  // split would move flexion to adduction's value).
  write_text(d + "/c.mot", std::string(kMotHeader) +
                               "time\tpelvis_tilt\thip_flexion_r\thip_adduction_r\thip_rotation_r\n0\t\t30\t-5\t7\n");
  const Motion c = load_motion(d + "/c.mot", Side::right);
  EXPECT_EQ(c.angles[0].flexion_deg, 30);
  EXPECT_EQ(c.angles[0].adduction_deg, -5);
  EXPECT_EQ(c.angles[0].internal_rotation_deg, 7);
}

TEST(Motion, BadFilesAreOneLineErrorsNamingFileLineAndColumn) {
  const std::string d = temp_dir("motion_bad");
  auto check = [&](const std::string& name, const std::string& text, const std::string& expect) {
    write_text(d + "/" + name, text);
    const std::string e = error_of(d + "/" + name);
    EXPECT_NE(e.find(d + "/" + name), std::string::npos) << e;
    EXPECT_NE(e.find(expect), std::string::npos) << "expected '" << expect << "' in: " << e;
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  };
  check("missing.csv", "time_s,flexion_deg,adduction_deg\n0,1,2\n", ":1: missing column 'internal_rotation_deg'");
  check("text.csv", "time_s,flexion_deg,adduction_deg,internal_rotation_deg\n0,1,2,3\n0.1,1,abc,3\n",
        ":3: column 'adduction_deg': 'abc' is not a number");
  check("nan.csv", "time_s,flexion_deg,adduction_deg,internal_rotation_deg\n0,nan,2,3\n",
        ":2: column 'flexion_deg': 'nan' is not finite");
  check("short.csv", "time_s,flexion_deg,adduction_deg,internal_rotation_deg\n0,1,2\n", ":2: the row has 3 cells, the header 4");
  // An empty cell of a tab-separated OpenSim file is a cell, not a gap that shifts the row (issue 48).
  check("empty_cell.mot", std::string(kMotHeader) +
                              "time\tpelvis_tilt\thip_flexion_r\thip_adduction_r\thip_rotation_r\n0\t1\t30\t-5\t7\n"
                              "0.5\t1\t\t-6\t8\n",
        ":9: column 'hip_flexion_r'");
  check("back.csv", "time_s,flexion_deg,adduction_deg,internal_rotation_deg\n1,1,2,3\n0.5,1,2,3\n",
        ":3: column 'time_s': time decreases");
  check("empty.csv", "", "empty motion file");
  check("noframes.csv", "time_s,flexion_deg,adduction_deg,internal_rotation_deg\n", "no frames");
  check("unit.mot", "x\ninDegrees=maybe\nendheader\n", ":2: unknown unit 'inDegrees=maybe'");
  check("nounit.mot", "x\nendheader\ntime hip_flexion_r\n", "unit is unknown");
  check("noend.mot", "x\ninDegrees=yes\n", "no 'endheader'");
  check("nocol.mot", std::string(kMotHeader) + "time\thip_flexion_r\thip_adduction_r\n0\t1\t2\n",
        ":7: missing column 'hip_rotation_r'");
  // Issue 80: what a real file gets wrong is said, not read into poses.
  check("truncated.mot", "w\nnRows=3\ninDegrees=yes\nendheader\ntime\thip_flexion_r\thip_adduction_r\thip_rotation_r\n"
                         "0\t1\t2\t3\n0.1\t1\t2\t3\n",
        "the header says nRows=3, the file holds 2 rows");
  check("rows.mot", "w\nnRows=many\ninDegrees=yes\nendheader\n", ":2: 'nRows=many' is not a row count");
  check("degrees.mot", "w\ninDegrees=no\nendheader\ntime\thip_flexion_r\thip_adduction_r\thip_rotation_r\n"
                       "0\t0.5\t0\t0\n0.1\t30\t5\t10\n",
        ":6: column 'hip_flexion_r': 30 rad = 1718.9 deg is beyond +-360 deg: the header says inDegrees=no");
  check("turn.csv", "time_s,flexion_deg,adduction_deg,internal_rotation_deg\n0,1,2,370\n",
        ":2: column 'internal_rotation_deg': 370 deg is beyond +-360 deg");
  check("twice.csv", "time_s,flexion_deg,adduction_deg,flexion_deg,internal_rotation_deg\n0,1,2,3,4\n",
        ":1: column 'flexion_deg' appears twice (columns 2 and 4)");
  EXPECT_NE(error_of(d + "/absent.mot").find("cannot open"), std::string::npos);
}
