#include "impinge/casters/fcl_collision.hpp"

#include <vector>

#include "impinge/core/error.hpp"

#ifdef IMPINGE_HAVE_FCL
#include <fcl/geometry/bvh/BVH_model.h>
#include <fcl/narrowphase/collision.h>
#include <fcl/narrowphase/collision_object.h>
#include <fcl/narrowphase/distance.h>
#endif

namespace impinge {

#ifdef IMPINGE_HAVE_FCL
bool have_fcl() { return true; }

namespace {
using Model = fcl::BVHModel<fcl::OBBRSSd>;
std::shared_ptr<Model> build_model(const TriangleMesh& mesh, const Eigen::Vector3d& cor) {
  validate_mesh(mesh);
  std::vector<fcl::Vector3d> v(static_cast<std::size_t>(mesh.V.rows()));
  for (Eigen::Index i = 0; i < mesh.V.rows(); ++i) v[static_cast<std::size_t>(i)] = mesh.V.row(i).transpose() - cor;
  std::vector<fcl::Triangle> f(static_cast<std::size_t>(mesh.F.rows()));
  for (Eigen::Index i = 0; i < mesh.F.rows(); ++i)
    f[static_cast<std::size_t>(i)] =
        fcl::Triangle(static_cast<std::size_t>(mesh.F(i, 0)), static_cast<std::size_t>(mesh.F(i, 1)),
                      static_cast<std::size_t>(mesh.F(i, 2)));
  auto m = std::make_shared<Model>();
  require(m->beginModel() == fcl::BVH_OK, "fcl: beginModel failed for " + mesh.source);
  require(m->addSubModel(v, f) == fcl::BVH_OK, "fcl: addSubModel failed for " + mesh.source);
  require(m->endModel() == fcl::BVH_OK, "fcl: endModel failed for " + mesh.source);
  return m;
}
fcl::Transform3d pose(const Eigen::Matrix3d& R, const Eigen::Vector3d& t) {
  fcl::Transform3d T = fcl::Transform3d::Identity();
  T.linear() = R;
  T.translation() = t;
  return T;
}
}  // namespace

struct FclJoint::Impl {
  std::shared_ptr<Model> ball, socket;
};

FclJoint::FclJoint(const TriangleMesh& ball, const TriangleMesh& socket, const Eigen::Vector3d& cor)
    : impl_(std::make_unique<Impl>()) {
  require(cor.allFinite(), "fcl: centre of rotation is not finite");
  impl_->ball = build_model(ball, cor);
  impl_->socket = build_model(socket, cor);
}
FclJoint::~FclJoint() = default;
FclJoint::FclJoint(FclJoint&&) noexcept = default;
FclJoint& FclJoint::operator=(FclJoint&&) noexcept = default;

FclContacts FclJoint::collide(const Eigen::Matrix3d& R, const Eigen::Vector3d& t, std::int64_t max_contacts) const {
  require(max_contacts >= 1, "fcl: max_contacts must be >= 1");
  const fcl::CollisionObjectd a(impl_->ball, pose(R, t)), b(impl_->socket, fcl::Transform3d::Identity());
  fcl::CollisionRequestd req(static_cast<std::size_t>(max_contacts), false);
  fcl::CollisionResultd res;
  fcl::collide(&a, &b, req, res);
  FclContacts c;
  c.contacts = static_cast<std::int64_t>(res.numContacts());
  c.capped = c.contacts >= max_contacts;
  return c;
}

double FclJoint::distance(const Eigen::Matrix3d& R, const Eigen::Vector3d& t) const {
  const fcl::CollisionObjectd a(impl_->ball, pose(R, t)), b(impl_->socket, fcl::Transform3d::Identity());
  fcl::DistanceRequestd req;
  fcl::DistanceResultd res;
  fcl::distance(&a, &b, req, res);
  return res.min_distance;
}

#else
bool have_fcl() { return false; }
struct FclJoint::Impl {};
FclJoint::FclJoint(const TriangleMesh& ball, const TriangleMesh&, const Eigen::Vector3d&) {
  require(false, "fcl: this build has no FCL (install libfcl-dev and reconfigure); mesh " + ball.source);
}
FclJoint::~FclJoint() = default;
FclJoint::FclJoint(FclJoint&&) noexcept = default;
FclJoint& FclJoint::operator=(FclJoint&&) noexcept = default;
FclContacts FclJoint::collide(const Eigen::Matrix3d&, const Eigen::Vector3d&, std::int64_t) const { return {}; }
double FclJoint::distance(const Eigen::Matrix3d&, const Eigen::Vector3d&) const { return 0; }
#endif

}  // namespace impinge
