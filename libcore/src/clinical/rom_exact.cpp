#include "clinical/rom_exact.hpp"

#include <cmath>
#include <limits>
#include <vector>

namespace impinge {
namespace rom_detail {
namespace {
// Per face, 1 when any of its corners is not skipped.
std::vector<std::uint8_t> faces_counted(const Faces& F, const std::vector<std::uint8_t>& skip) {
  std::vector<std::uint8_t> out(static_cast<std::size_t>(F.rows()));
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    for (int c = 0; c < 3; ++c) out[static_cast<std::size_t>(f)] |= skip[static_cast<std::size_t>(F(f, c))] == 0;
  return out;
}
}  // namespace

std::shared_ptr<const MeshContact> baseline_contact(const Joint& joint, const RomBaseline& base,
                                                    const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
                                                    double threshold) {
  auto contact = std::make_shared<MeshContact>(joint.ball().relative, joint.ball().mesh.F, joint.socket().relative,
                                               joint.socket().mesh.F);
  std::vector<std::uint8_t> ball = faces_counted(joint.ball().mesh.F, base.skip_ball);
  std::vector<std::uint8_t> socket = faces_counted(joint.socket().mesh.F, base.skip_socket);
  // Every pair within the threshold at the baseline, counted or not (as every vertex within it is
  // skipped, whatever its class), is left out: a face the pose classes as counted later must not bring
  // a pre-existing overlap with it.
  for (const auto& [a, b] : contact->pairs_within(R, t, threshold, MeshContact::Query{}))
    ball[static_cast<std::size_t>(a)] = 0, socket[static_cast<std::size_t>(b)] = 0;
  contact->set_counted(std::move(ball), std::move(socket));
  return contact;
}

ExactScanner::ExactScanner(const Joint& joint, const RomBaseline& base, double cut)
    : joint_(joint), base_(base), contact_(*base.contact), pelvis_(base), cut_(cut) {}

MeshContact::Query ExactScanner::query_at(const Eigen::Matrix3d& R, const Eigen::Vector3d& t, double reach,
                                          bool first) const {
  MeshContact::Query q;
  q.reach = reach, q.first = first;
  if (!pelvis_.classed()) return q;
  // A pelvis triangle counts at this pose when one of its corners does (CompactScanner::take's rule).
  q.b_counts_now = [this, Rt = Eigen::Matrix3d(R.transpose()), t](std::int64_t f) {
    const Faces& F = joint_.socket().mesh.F;
    for (int c = 0; c < 3; ++c) {
      const auto v = static_cast<std::size_t>(F(static_cast<Eigen::Index>(f), c));
      if (base_.skip_socket[v]) continue;
      const Eigen::Vector3d y = Rt * (joint_.socket().relative.row(static_cast<Eigen::Index>(v)).transpose() - t);
      if (pelvis_.counts(y)) return true;
    }
    return false;
  };
  return q;
}

Least ExactScanner::operator()(const Eigen::Matrix3d& R, const Eigen::Vector3d& t, bool full) const {
  const MeshContact::Query q = query_at(R, t, full ? std::numeric_limits<double>::infinity() : cut_, !full);
  const MeshContact::Closest c = contact_.least(R, t, q);
  Least l;
  l.gap = c.distance;
  if (c.face_a < 0) return l;
  // The counted corner nearest the contact: of the femur's triangle when it counts, else of the pelvis'.
  const bool ball = contact_.counted_a(c.face_a);
  const Faces& F = ball ? joint_.ball().mesh.F : joint_.socket().mesh.F;
  const Vertices& V = ball ? joint_.ball().relative : joint_.socket().relative;
  const Eigen::Index f = static_cast<Eigen::Index>(ball ? c.face_a : c.face_b);
  const Eigen::Vector3d& near = ball ? c.on_a : c.on_b;
  const Eigen::Matrix3d Rt = R.transpose();
  auto counted = [&](std::size_t v) {
    if (ball) return base_.skip_ball[v] == 0;
    const Eigen::Vector3d y = Rt * (V.row(static_cast<Eigen::Index>(v)).transpose() - t);
    return base_.skip_socket[v] == 0 &&
           (!pelvis_.classed() || pelvis_.counts(y));
  };
  double best = std::numeric_limits<double>::infinity();
  for (int pass = 0; pass < 2 && !std::isfinite(best); ++pass)  // a counted corner; failing that, any
    for (int k = 0; k < 3; ++k) {
      const auto v = static_cast<std::size_t>(F(f, k));
      const Eigen::Vector3d p = ball ? Eigen::Vector3d(R * V.row(F(f, k)).transpose() + t)
                                     : Eigen::Vector3d(V.row(F(f, k)).transpose());
      const double d = (p - near).squaredNorm();
      if ((pass == 1 || counted(v)) && d < best) best = d, l.vertex = v;
    }
  l.ball = ball;
  l.point = near;  // on the surface of that corner's bone (the two coincide where the surfaces cross)
  return l;
}

}  // namespace rom_detail
}  // namespace impinge
