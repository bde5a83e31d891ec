// Uses the installed library as a C++ study would: a generated hip set up by the session layer
// (the CLI's and Python's set-up), one pose, the summary record; and the plain Joint underneath.
// Oracle: the generated hip's true COR is given, so the session reports it back unchanged, and both
// paths give the same least gap.
#include <cmath>
#include <iostream>

#include "impinge/detection/joint.hpp"
#include "impinge/io/generated_models.hpp"
#include "impinge/session/records.hpp"
#include "impinge/session/session.hpp"

int main() {
  impinge::HipModelOptions o;
  const impinge::HipModel h = impinge::make_hip_model(o);

  impinge::SessionOptions so;
  so.input.ball_mesh = h.ball;
  so.input.socket_mesh = h.socket;
  so.cor.given = h.cor;
  so.hip.neutral = impinge::Neutral::scan;
  so.grid.precision = 1.0;
  const impinge::Session session(so);
  const impinge::PoseResult r = session.hip().detect(impinge::PoseAngles{});
  const nlohmann::json setup = impinge::setup_record(session);

  impinge::JointOptions jo;
  jo.scheme = impinge::make_scheme("equiangular", 1.0);
  const impinge::Joint joint(h.ball, h.socket, h.cor, jo);
  const impinge::PoseResult plain = joint.detect(Eigen::Matrix3d::Identity());

  std::cout << "consumer: ball min gap " << r.ball.min_gap_mm << " mm (plain Joint " << plain.ball.min_gap_mm
            << " mm), COR " << setup["head_centre_mm"].dump() << "\n";
  const bool ok = std::isfinite(r.ball.min_gap_mm) && r.ball.min_gap_mm > 0 &&
                  r.ball.min_gap_mm == plain.ball.min_gap_mm && setup["head_centre_mm"][0].get<double>() == h.cor.x();
  return ok ? 0 : 1;
}
