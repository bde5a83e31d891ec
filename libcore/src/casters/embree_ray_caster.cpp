#include "impinge/casters/embree_ray_caster.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "impinge/core/error.hpp"

#ifdef IMPINGE_HAVE_EMBREE
#include <embree3/rtcore.h>
#endif

namespace impinge {

void throw_embree_error(int rtc_error, const std::string& what) {
  if (rtc_error == 4) throw OutOfMemory("out of memory " + what);  // RTC_ERROR_OUT_OF_MEMORY
  static const char* const names[] = {"none", "unknown", "invalid argument", "invalid operation", "out of memory",
                                      "unsupported CPU", "cancelled"};
  const char* name = rtc_error >= 0 && rtc_error <= 6 ? names[rtc_error] : "not an Embree error code";
  throw Error("embree: " + what + " failed (RTCError " + std::to_string(rtc_error) + ": " + name + ")");
}

#ifdef IMPINGE_HAVE_EMBREE
bool have_embree() { return true; }

struct EmbreeRayCaster::Impl {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  bool filterable = false;
  ~Impl() {
    if (scene) rtcReleaseScene(scene);
    if (device) rtcReleaseDevice(device);
  }
  void check(const std::string& what) const {
    const RTCError e = rtcGetDeviceError(device);
    if (e != RTC_ERROR_NONE) throw_embree_error(int(e), what);
  }
};

EmbreeRayCaster::EmbreeRayCaster(const TriangleMesh& mesh, const Eigen::Vector3d& origin, bool robust,
                                 HierarchyBuild build)
    : impl_(std::make_unique<Impl>()) {
  validate_mesh(mesh);
  require(origin.allFinite(), "embree: origin is not finite (" + mesh.source + ")");
  impl_->device = rtcNewDevice(build == HierarchyBuild::fast ? "threads=1,tri_accel=bvh4.triangle4v,tri_builder=morton"
                                                             : "threads=1");
  // A device that could not be made (its threads, its memory): the error is the thread's (a null device's).
  if (impl_->device == nullptr)
    throw_embree_error(int(rtcGetDeviceError(nullptr)), "making the ray-casting device for " + mesh.source);
  impl_->scene = rtcNewScene(impl_->device);
  RTCGeometry g = rtcNewGeometry(impl_->device, RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                         3 * sizeof(float), static_cast<std::size_t>(mesh.V.rows())));
  for (Eigen::Index i = 0; i < mesh.V.rows(); ++i)
    for (int k = 0; k < 3; ++k) vb[3 * i + k] = static_cast<float>(mesh.V(i, k) - origin[k]);
  auto* ib = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
      g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), static_cast<std::size_t>(mesh.F.rows())));
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) ib[3 * f + k] = static_cast<unsigned>(mesh.F(f, k));
  rtcCommitGeometry(g);
  rtcAttachGeometry(impl_->scene, g);
  rtcReleaseGeometry(g);
  rtcSetSceneBuildQuality(impl_->scene, RTC_BUILD_QUALITY_HIGH);
  if (robust)
    rtcSetSceneFlags(impl_->scene, RTCSceneFlags(RTC_SCENE_FLAG_ROBUST | RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION));
  impl_->filterable = robust;

  rtcCommitScene(impl_->scene);
  impl_->check("building the ray-casting hierarchy of " + mesh.source + " (" + std::to_string(mesh.F.rows()) +
               " triangles)");
}

EmbreeRayCaster::~EmbreeRayCaster() = default;
EmbreeRayCaster::EmbreeRayCaster(EmbreeRayCaster&&) noexcept = default;
EmbreeRayCaster& EmbreeRayCaster::operator=(EmbreeRayCaster&&) noexcept = default;

namespace {
void init_ray(RTCRayHit& rh, float dx, float dy, float dz) {
  rh.ray.org_x = rh.ray.org_y = rh.ray.org_z = 0.f;
  rh.ray.dir_x = dx, rh.ray.dir_y = dy, rh.ray.dir_z = dz;
  rh.ray.tnear = 0.f;
  rh.ray.tfar = std::numeric_limits<float>::infinity();
  rh.ray.mask = 0xFFFFFFFFu;
  rh.ray.flags = 0;
  rh.ray.time = 0.f;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
}
/// Rays from 0 along (dx, dy, dz) of any length: tfar is in units of that length.
void init_ray8(RTCRayHit8& rh, int j, float dx, float dy, float dz) {
  rh.ray.org_x[j] = rh.ray.org_y[j] = rh.ray.org_z[j] = 0.f;
  rh.ray.dir_x[j] = dx, rh.ray.dir_y[j] = dy, rh.ray.dir_z[j] = dz;
  rh.ray.tnear[j] = 0.f;
  rh.ray.tfar[j] = std::numeric_limits<float>::infinity();
  rh.ray.mask[j] = 0xFFFFFFFFu;
  rh.ray.flags[j] = 0;
  rh.ray.time[j] = 0.f;
  rh.hit.geomID[j] = RTC_INVALID_GEOMETRY_ID;
}
}  // namespace

float EmbreeRayCaster::first_hit(float dx, float dy, float dz) const {
  const float len = std::sqrt(dx * dx + dy * dy + dz * dz);
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  RTCRayHit rh;
  init_ray(rh, dx / len, dy / len, dz / len);
  rtcIntersect1(impl_->scene, &ctx, &rh);
  return rh.hit.geomID == RTC_INVALID_GEOMETRY_ID ? std::numeric_limits<float>::infinity() : rh.ray.tfar;
}

float EmbreeRayCaster::least_hit(const float* dirs, int k, float within) const {
  require(k >= 1 && k <= 4, "embree: least_hit takes 1 to 4 rays");
  require(within >= 0, "embree: least_hit's rays end at a distance >= 0 mm");
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  alignas(16) int valid[4] = {0, 0, 0, 0};
  alignas(16) RTCRayHit4 rh;
  for (int j = 0; j < 4; ++j) {
    const int i = j < k ? j : 0;
    const float x = dirs[3 * i], y = dirs[3 * i + 1], z = dirs[3 * i + 2];
    const float len = std::sqrt(x * x + y * y + z * z);
    rh.ray.org_x[j] = rh.ray.org_y[j] = rh.ray.org_z[j] = 0.f;
    rh.ray.dir_x[j] = x / len, rh.ray.dir_y[j] = y / len, rh.ray.dir_z[j] = z / len;
    rh.ray.tnear[j] = 0.f;
    rh.ray.tfar[j] = within;
    rh.ray.mask[j] = 0xFFFFFFFFu;
    rh.ray.flags[j] = 0;
    rh.ray.time[j] = 0.f;
    rh.hit.geomID[j] = RTC_INVALID_GEOMETRY_ID;
    valid[j] = j < k ? -1 : 0;
  }
  rtcIntersect4(valid, impl_->scene, &ctx, &rh);
  float best = std::numeric_limits<float>::infinity();
  for (int j = 0; j < k; ++j)
    if (rh.hit.geomID[j] != RTC_INVALID_GEOMETRY_ID) best = std::min(best, rh.ray.tfar[j]);
  return best;
}

namespace {
/// The intersect context of all_hits: Embree's context first, so the filter can reach the list.
struct AllHitsContext {
  RTCIntersectContext context;
  std::vector<std::pair<float, unsigned>>* out;
};
void record_and_reject(const RTCFilterFunctionNArguments* args) {
  auto* c = reinterpret_cast<const AllHitsContext*>(args->context);
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] == 0) continue;
    c->out->emplace_back(RTCRayN_tfar(args->ray, args->N, i), RTCHitN_primID(args->hit, args->N, i));
    args->valid[i] = 0;  // rejected: the traversal goes on to the next candidate
  }
}
}  // namespace

void EmbreeRayCaster::all_hits(float dx, float dy, float dz, std::vector<std::pair<float, unsigned>>& out) const {
  require(impl_->filterable, "embree: all_hits needs a scene built with robust = true");
  const float len = std::sqrt(dx * dx + dy * dy + dz * dz);
  AllHitsContext c;
  rtcInitIntersectContext(&c.context);
  c.context.filter = record_and_reject;
  c.out = &out;
  RTCRayHit rh;
  init_ray(rh, dx / len, dy / len, dz / len);
  rtcIntersect1(impl_->scene, &c.context, &rh);
}

void EmbreeRayCaster::scan_gaps(const double* x, const double* y, const double* z, std::int64_t n,
                                const Eigen::Matrix3d& R, const Eigen::Vector3d& t, double side, float* gap_mm,
                                bool packet8) const {
  const double s = side;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  // Unit direction and radius of vertex j after the pose.
  auto pose = [&](std::int64_t j, float& ux, float& uy, float& uz, double& r) {
    const Eigen::Vector3d q = R * Eigen::Vector3d(x[j], y[j], z[j]) + t;
    r = q.norm();
    ux = static_cast<float>(q.x() / r), uy = static_cast<float>(q.y() / r), uz = static_cast<float>(q.z() / r);
  };
  if (!packet8) {
    for (std::int64_t j = 0; j < n; ++j) {
      float ux, uy, uz;
      double r;
      pose(j, ux, uy, uz, r);
      RTCRayHit rh;
      init_ray(rh, ux, uy, uz);
      rtcIntersect1(impl_->scene, &ctx, &rh);
      gap_mm[j] =
          (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID || !(r > 0)) ? nan : static_cast<float>(s * (rh.ray.tfar - r));
    }
    return;
  }
  alignas(32) RTCRayHit8 rh;
  alignas(32) int valid[8];
  double radius[8];
  for (std::int64_t b = 0; b < n; b += 8) {
    const int m = static_cast<int>(std::min<std::int64_t>(8, n - b));
    for (int j = 0; j < 8; ++j) {
      float ux = 0, uy = 0, uz = 1;
      radius[j] = 0;
      if (j < m) pose(b + j, ux, uy, uz, radius[j]);
      valid[j] = j < m ? -1 : 0;
      init_ray8(rh, j, ux, uy, uz);
    }
    rtcIntersect8(valid, impl_->scene, &ctx, &rh);
    for (int j = 0; j < m; ++j)
      gap_mm[b + j] = (rh.hit.geomID[j] == RTC_INVALID_GEOMETRY_ID || !(radius[j] > 0))
                          ? nan
                          : static_cast<float>(s * (rh.ray.tfar[j] - radius[j]));
  }
}

template <typename Scalar>
std::int64_t EmbreeRayCaster::fill_map(RadialDistanceMapT<Scalar>& map) const {
  const SamplingScheme& scheme = map.scheme();
  const std::int64_t n = map.num_nodes();
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;  // neighbouring nodes: coherent rays
  alignas(32) RTCRayHit8 rh;
  alignas(32) int valid[8];
  double phi[8], theta[8];
  std::int64_t covered = 0;
  Scalar* d = map.data();
  for (std::int64_t b = 0; b < n; b += 8) {
    const int m = static_cast<int>(std::min<std::int64_t>(8, n - b));
    scheme.node_angles(b, m, phi, theta);
    for (int j = 0; j < 8; ++j) {
      const double p = j < m ? phi[j] : 0, q = j < m ? theta[j] : 0;
      valid[j] = j < m ? -1 : 0;
      init_ray8(rh, j, static_cast<float>(std::sin(p) * std::cos(q)), static_cast<float>(std::sin(p) * std::sin(q)),
                static_cast<float>(std::cos(p)));
    }
    rtcIntersect8(valid, impl_->scene, &ctx, &rh);
    for (int j = 0; j < m; ++j) {
      const bool hit = rh.hit.geomID[j] != RTC_INVALID_GEOMETRY_ID;
      d[b + j] = hit ? static_cast<Scalar>(rh.ray.tfar[j]) : RadialDistanceMapT<Scalar>::no_surface();
      covered += hit;
    }
  }
  return covered;
}

#else
bool have_embree() { return false; }
struct EmbreeRayCaster::Impl {};
EmbreeRayCaster::EmbreeRayCaster(const TriangleMesh& mesh, const Eigen::Vector3d&, bool, HierarchyBuild) {
  require(false, "embree: this build has no Embree 3 (install libembree-dev and reconfigure); mesh " + mesh.source);
}
EmbreeRayCaster::~EmbreeRayCaster() = default;
float EmbreeRayCaster::least_hit(const float*, int, float) const { return std::numeric_limits<float>::quiet_NaN(); }
EmbreeRayCaster::EmbreeRayCaster(EmbreeRayCaster&&) noexcept = default;
EmbreeRayCaster& EmbreeRayCaster::operator=(EmbreeRayCaster&&) noexcept = default;
float EmbreeRayCaster::first_hit(float, float, float) const { return 0; }
void EmbreeRayCaster::all_hits(float, float, float, std::vector<std::pair<float, unsigned>>&) const {}
void EmbreeRayCaster::scan_gaps(const ScanSet&, const Eigen::Matrix3d&, const Eigen::Vector3d&, ScanSide, float*,
                                bool) const {}
template <typename Scalar>
std::int64_t EmbreeRayCaster::fill_map(RadialDistanceMapT<Scalar>&) const {
  return 0;
}
#endif

template std::int64_t EmbreeRayCaster::fill_map<float>(RadialDistanceMapT<float>&) const;
template std::int64_t EmbreeRayCaster::fill_map<double>(RadialDistanceMapT<double>&) const;

}  // namespace impinge
