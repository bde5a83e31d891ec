// run_plan (session/plan_run.hpp) and plan_resection beneath it against an independent oracle: a generated hip
// with a 3 mm cam and the same hip without it (make_hip_model; the same faces, the cam a bump of known volume).
// The cam-free hip's ROM limits are what a plan on the cam hip must restore: planned with them as targets, the
// resected femur (a new session, as `impinge rom` on the written mesh) reaches each within 0.5 deg, the plan removes
// more than nothing and at most 1.2 times the cam's volume (enclosed volumes, divergence theorem), mostly where the
// cam was, never outwards, and keeps the input's faces. The CLI's and Python's runs: python/tests/test_plan.py.
#include "impinge/session/plan_run.hpp"

#include <gtest/gtest.h>

#include <map>

#include "impinge/io/generated_models.hpp"
#include "impinge/session/option_table.hpp"
#include "test_support.hpp"

namespace impinge {
namespace {

const char* const kTargets[] = {"flexion", "abduction", "internal_rotation"};

HipModel model(double cam_mm) {
  HipModelOptions g;
  g.target_triangles = 12000;
  g.cam_height_mm = cam_mm;
  return make_hip_model(g);
}

// The CLI's set-up (the clinical preset) of a generated hip: scan neutral, its true centre, 0.5 deg.
SessionOptions options_of(const TriangleMesh& femur, const TriangleMesh& pelvis, const Eigen::Vector3d& cor) {
  SessionOptions o = RunOptions::clinical().session;
  o.input.ball_mesh = femur;
  o.input.socket_mesh = pelvis;
  o.hip.neutral = Neutral::scan;
  o.cor.given = cor;
  o.cor.allow_any = true;  // the true centre of a proximal femur
  o.grid.precision = 0.5;
  return o;
}

RomRequest limits_only() {
  RomRequest q = RunOptions::clinical().rom;
  q.map = false;
  return q;
}

std::map<std::string, double> limits(const SessionOptions& o) {
  const Session s(rom_session_options(o, limits_only().search));
  const RomRun run = run_rom(s, limits_only());
  std::map<std::string, double> out;
  for (std::size_t k = 0; k < run.motions.size(); ++k) out[run.motions[k].name] = run.limits[k].limit_deg;
  return out;
}

TEST(PlanRun, APlanRestoresTheCamFreeLimitsRemovingAboutTheCam) {
  const HipModel free = model(0), cam = model(3);
  ASSERT_TRUE(free.ball.F == cam.ball.F);
  const std::map<std::string, double> free_limits = limits(options_of(free.ball, free.socket, free.cor));
  const std::map<std::string, double> cam_limits = limits(options_of(cam.ball, cam.socket, cam.cor));
  std::string target;
  for (const char* m : kTargets) {
    EXPECT_LT(cam_limits.at(m), free_limits.at(m) - 5) << m;  // the cam limits these motions
    target += (target.empty() ? "" : ",") + std::string(m) + "=" + std::to_string(free_limits.at(m));
  }
  PlanRequest request;
  request.target = target;
  const PlanRun p = run_plan(options_of(cam.ball, cam.socket, cam.cor), limits_only(), request);
  EXPECT_TRUE(p.all_met);
  // The check, independently: a new session on the resected femur and the untouched pelvis.
  ASSERT_TRUE(p.femur_resected.F == cam.ball.F);  // the input's faces
  const std::map<std::string, double> after = limits(options_of(p.femur_resected, cam.socket, cam.cor));
  for (const char* m : kTargets) EXPECT_GE(after.at(m), free_limits.at(m) - 0.5) << m;
  // Volume: at most 1.2 times the cam's, as the plan reports it.
  const double cam_volume = enclosed_volume(cam.ball.V, cam.ball.F) - enclosed_volume(free.ball.V, free.ball.F);
  const double removed = enclosed_volume(cam.ball.V, cam.ball.F) - enclosed_volume(p.femur_resected.V, cam.ball.F);
  EXPECT_GT(cam_volume, 10);
  EXPECT_GT(removed, 0);
  EXPECT_LE(removed, 1.2 * cam_volume);
  EXPECT_NEAR(p.plan.femur.volume_mm3, removed, std::max(0.5, 0.02 * removed));
  // Never outwards (each vertex moves against the input's outward normal, found here from the faces, oriented by
  // the signed volume, and by its reported depth); most of the removal (depth x vertex area) where the cam was.
  const Eigen::Index n = cam.ball.V.rows();
  ASSERT_EQ(p.plan.femur.depth_mm.size(), std::size_t(n));
  Eigen::VectorXd area = Eigen::VectorXd::Zero(n);
  Vertices normal = Vertices::Zero(n, 3);
  double signed_volume = 0;
  for (Eigen::Index f = 0; f < cam.ball.F.rows(); ++f) {
    const Eigen::Vector3d a = cam.ball.V.row(cam.ball.F(f, 0)), b = cam.ball.V.row(cam.ball.F(f, 1)),
                          c = cam.ball.V.row(cam.ball.F(f, 2));
    const Eigen::Vector3d cross = (b - a).cross(c - a);
    signed_volume += a.dot(b.cross(c)) / 6;
    for (int k = 0; k < 3; ++k) area[cam.ball.F(f, k)] += cross.norm() / 6, normal.row(cam.ball.F(f, k)) += cross;
  }
  const double outward = signed_volume > 0 ? 1 : -1;
  double on_cam = 0, all = 0;
  for (Eigen::Index i = 0; i < n; ++i) {
    const double d = p.plan.femur.depth_mm[std::size_t(i)];
    const Eigen::Vector3d move = (p.femur_resected.V.row(i) - cam.ball.V.row(i)).transpose();
    const Eigen::Vector3d nrm = outward * normal.row(i).transpose().normalized();
    EXPECT_LE(move.dot(nrm), 1e-6) << "vertex " << i << " moved outwards";
    EXPECT_NEAR(move.norm(), d, 1e-4) << "vertex " << i;  // moved by its reported depth
    all += area[i] * d;
    if ((cam.ball.V.row(i) - free.ball.V.row(i)).norm() > 0.05) on_cam += area[i] * d;
  }
  EXPECT_GT(on_cam, 0.5 * all);
}

TEST(PlanRun, BadRequestsNameTheOption) {
  const HipModel h = model(0);
  PlanRequest request;
  request.target = "flexion=100";
  request.step_deg = 0.01;
  EXPECT_NE(test::error_of([&] { run_plan(options_of(h.ball, h.socket, h.cor), limits_only(), request); })
                .find("plan-step 0.01 deg is outside the valid range [0.05, 5] deg"),
            std::string::npos);
  request.step_deg = 0.5;
  request.target = "pirouette=100";
  EXPECT_NE(test::error_of([&] { run_plan(options_of(h.ball, h.socket, h.cor), limits_only(), request); })
                .find("pirouette"),
            std::string::npos);
}

}  // namespace
}  // namespace impinge
