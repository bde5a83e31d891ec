// Uses the installed library: a generated hip, both maps, one pose; prints the minimum gaps.
// The gap between a sphere head of radius r and a concentric cup of radius R is R - r everywhere.
#include <cmath>
#include <iostream>

#include "impinge/detection/joint.hpp"
#include "impinge/io/generated_models.hpp"

int main() {
  impinge::HipModelOptions o;
  const impinge::HipModel h = impinge::make_hip_model(o);
  impinge::JointOptions jo;
  jo.scheme = impinge::make_scheme("equiangular", 1.0);
  const impinge::Joint joint(h.ball, h.socket, h.cor, jo);
  const impinge::PoseResult r = joint.detect(Eigen::Matrix3d::Identity());
  std::cout << "consumer: ball min gap " << r.ball.min_gap_mm << " mm, socket min gap " << r.socket.min_gap_mm
            << " mm\n";
  return std::isfinite(r.ball.min_gap_mm) && r.ball.min_gap_mm > 0 ? 0 : 1;
}
